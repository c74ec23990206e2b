"""The frequency axis: :class:`Frequency`, strictly increasing lines in Hz.

Every FRF, measurement and model evaluation lives on one of these; it is
built from a range (``start``, ``stop``, ``step`` with units) or from values,
checked on entry (finite, >= 0, strictly increasing) and never changed.
Band limits are compared with a small tolerance of the largest frequency so
that a grid built by steps and one read from a file as decimals agree.
"""

from __future__ import annotations

import numbers
from typing import Any

import attrs
import numpy as np

from ..errors import InvalidValueError, UnitError
from ..units import cycles_per_second, finite_real, frequency_hz, ureg

__all__ = ["Frequency", "MAX_GRID_LINES"]

ROUNDED_STEP_SHARE = 0.25
"""Largest distance, in steps, of a written value from the uniform grid fitted to them all, for the values to be
read as that grid (times or frequencies written with few digits: ``%.2f`` of a 0.15625 Hz step lies 3 % of a step
off it); a quarter step, so that no value can be taken for its neighbour."""


def rounded_uniform(values: np.ndarray) -> np.ndarray | None:
    """The uniform grid that increasing values written rounded stand for, or None when they are not one.

    The grid is the least-squares line through the values against their index (the rounding of every value
    averages out); the values stand for it when every one lies within :data:`ROUNDED_STEP_SHARE` of a step
    of it.

    Parameters
    ----------
    values : ndarray
        1-D, as written.

    Returns
    -------
    ndarray or None
        The grid, or None (fewer than 3 values, not increasing overall, or a value farther off).
    """
    n = values.size
    if n < 3 or not values[-1] > values[0]:
        return None
    k = np.arange(n, dtype=np.float64)
    step = float(np.dot(k - k.mean(), values - values.mean()) / np.dot(k - k.mean(), k - k.mean()))
    grid = (values.mean() - step * k.mean()) + k * step
    if step > 0 and np.max(np.abs(values - grid)) <= ROUNDED_STEP_SHARE * step:
        return grid
    return None


MAX_GRID_LINES = 1_000_000
"""The most lines :meth:`Frequency.from_range` builds (a grid, with FRFs on it, is held in memory).

A million lines are 5 mHz steps over 5 kHz, beyond any tap test; the
receptance of the built-in assembly on them takes about 0.7 GB.  A larger request is refused before memory is allocated,
naming the number of lines it would have.
"""

# Relative tolerance (of the largest frequency) with which band limits and
# interpolation ranges are compared, so that a grid built as start + step*k
# and one read from a file as decimals are not told apart by rounding.
_GRID_RTOL = 1e-12


def _hz(value: Any, field: str) -> float:
    """A frequency in Hz from a plain number (taken as Hz), a quantity or a string.

    Angular units are converted explicitly (:func:`substructure.units.frequency_hz`).
    """
    if isinstance(value, numbers.Real) and not isinstance(value, bool):
        if not finite_real(value):  # NaN, or an integer beyond every float
            raise InvalidValueError(f"{field}: got {value!r}; expected a finite frequency in Hz")
        return float(value)
    return frequency_hz(value, field)


def _readonly(array: np.ndarray) -> np.ndarray:
    array.flags.writeable = False
    return array


def _hz_array(value: Any) -> np.ndarray:
    if isinstance(value, ureg.Quantity):  # frequencies with their unit: Hz, kHz, rad/s and rpm converted
        if not value.check("1 / [time]"):
            raise UnitError(f"hz: got a quantity in {value.units:~}; expected frequencies (in Hz, or a quantity of "
                            "a frequency unit)")
        value = cycles_per_second(value, "hz")
    if np.iscomplexobj(value):
        raise InvalidValueError("hz: got complex values; expected real frequencies in Hz")
    try:
        return _readonly(np.array(value, dtype=np.float64, copy=True))
    except (TypeError, ValueError, OverflowError):
        raise InvalidValueError(
            f"hz: cannot read {value!r} as numbers; expected a 1-D array of frequencies in Hz"
        ) from None


def _check_hz(instance: Any, attribute: Any, hz: np.ndarray) -> None:
    if hz.ndim != 1 or hz.size == 0:
        raise InvalidValueError(f"hz: got an array of shape {hz.shape}; expected a non-empty 1-D array")
    if not np.isfinite(hz).all():
        i = int(np.argmax(~np.isfinite(hz)))
        raise InvalidValueError(f"hz: got {hz[i]} at index {i}; expected finite frequencies")
    if hz[0] < 0:
        raise InvalidValueError(f"hz: got {hz[0]} Hz at index 0; expected frequencies >= 0")
    if (np.diff(hz) <= 0).any():
        i = int(np.argmax(np.diff(hz) <= 0))
        raise InvalidValueError(
            f"hz: got {hz[i + 1]} Hz at index {i + 1} after {hz[i]} Hz; "
            "expected strictly increasing frequencies"
        )


@attrs.frozen(repr=False)
class Frequency:
    """A strictly increasing axis of frequencies, stored in Hz.

    Parameters
    ----------
    hz : array_like
        Frequencies in Hz, 1-D, non-empty, finite, >= 0 and strictly
        increasing.  Stored as a read-only float64 copy.  Prefer the named
        constructors :meth:`from_range` and :meth:`from_hz`.

    Examples
    --------
    >>> f = Frequency.from_range("20 Hz", "5000 Hz", "2 Hz")
    >>> len(f), f.start, f.stop
    (2491, 20.0, 5000.0)
    """

    hz: np.ndarray = attrs.field(converter=_hz_array, validator=_check_hz, eq=attrs.cmp_using(eq=np.array_equal))

    @classmethod
    def from_range(cls, start: Any, stop: Any, step: Any) -> Frequency:
        """Grid ``start + step*k``, ``k = 0, 1, ...``, up to ``stop`` (included when on the grid).

        Parameters
        ----------
        start, stop, step : pint.Quantity or str
            Frequencies with their unit, e.g. ``"20 Hz"``, ``"5 kHz"``.  Bare
            numbers are rejected.  Angular units are converted explicitly:
            ``"628.3 rad/s"`` is 100 Hz, ``"6000 rpm"`` is 100 Hz
            (:func:`substructure.units.frequency_hz`).  ``stop`` counts as on
            the grid when it is within 1e-9 steps of a grid point.

        Returns
        -------
        Frequency
            At least two lines and at most :data:`~substructure.frf.MAX_GRID_LINES`.

        Raises
        ------
        UnitError
            For a bare number or a value that is not a frequency.
        InvalidValueError
            For ``start < 0``, ``step <= 0``, ``stop < start``, a grid of one
            line (a range needs ``stop >= start + step``) or more lines than
            :data:`~substructure.frf.MAX_GRID_LINES`.
        """
        f0, f1, df = frequency_hz(start, "start"), frequency_hz(stop, "stop"), frequency_hz(step, "step")
        if f0 < 0:
            raise InvalidValueError(f"start: got {start!r}; expected a frequency >= 0 Hz")
        if df <= 0:
            raise InvalidValueError(f"step: got {step!r}; expected a positive frequency step")
        if f1 < f0:
            raise InvalidValueError(f"stop: got {stop!r} below start {start!r}; expected stop >= start")
        count = (f1 - f0) / df
        if count + 1 > MAX_GRID_LINES:
            raise InvalidValueError(
                f"step: {start!r} to {stop!r} in steps of {step!r} makes {count + 1:.3g} lines; the limit is "
                f"{MAX_GRID_LINES:.0e} lines (substructure.frf.MAX_GRID_LINES): choose a larger step"
            )
        nearest = round(count)
        k = nearest if abs(count - nearest) <= 1e-9 * max(1.0, nearest) else int(np.floor(count))
        if k < 1:
            raise InvalidValueError(
                f"stop: {start!r} to {stop!r} in steps of {step!r} is a single line; a grid needs at "
                "least two (stop >= start + step)"
            )
        return cls(f0 + df * np.arange(k + 1))

    @classmethod
    def from_hz(cls, values: Any) -> Frequency:
        """Axis from an array of plain numbers in Hz (not rad/s).

        Pint quantities are refused, to rule out a silent ``2*pi`` between
        rad/s and Hz: convert them explicitly with ``q.m_as("Hz")``.

        Parameters
        ----------
        values : array_like
            Frequencies in Hz, increasing.

        Returns
        -------
        Frequency
            The axis.
        """
        if hasattr(values, "units") and hasattr(values, "magnitude"):
            raise InvalidValueError(
                f"hz: got the quantity {values!r}; from_hz takes plain numbers in Hz, "
                "convert with q.m_as('Hz') (mind rad/s versus Hz)"
            )
        return cls(values)

    @property
    def omega(self) -> np.ndarray:
        """Angular frequencies ``2*pi*hz`` in rad/s (read-only)."""
        return _readonly(2.0 * np.pi * self.hz)

    @property
    def n(self) -> int:
        """Number of frequency lines."""
        return int(self.hz.size)

    def __len__(self) -> int:
        return self.n

    @property
    def start(self) -> float:
        """First frequency in Hz."""
        return float(self.hz[0])

    @property
    def stop(self) -> float:
        """Last frequency in Hz."""
        return float(self.hz[-1])

    def band_mask(self, lo: Any = None, hi: Any = None) -> np.ndarray:
        """Boolean mask of the lines with ``lo <= f <= hi``.

        Parameters
        ----------
        lo, hi : float, pint.Quantity, str or None
            Band limits; plain numbers are in Hz; ``None`` leaves that side open.
            Limits are compared with a relative tolerance of 1e-12 of the
            largest frequency, so that rounding of the grid does not drop a
            line that is meant to be on the limit.

        Returns
        -------
        ndarray
            Boolean, shape ``(n_freq,)``.
        """
        f_lo = -np.inf if lo is None else _hz(lo, "lo")
        f_hi = np.inf if hi is None else _hz(hi, "hi")
        if f_lo > f_hi:
            raise InvalidValueError(f"lo, hi: got lo={lo!r} > hi={hi!r}; expected lo <= hi")
        tol = _GRID_RTOL * max(abs(self.stop), 1.0)
        return (self.hz >= f_lo - tol) & (self.hz <= f_hi + tol)

    def crop(self, lo: Any = None, hi: Any = None) -> Frequency:
        """New axis with the lines of :meth:`band_mask`; an empty band is an error.

        Parameters
        ----------
        lo, hi : float, pint.Quantity, str or None
            Band limits; plain numbers are in Hz; ``None`` leaves that side open.

        Returns
        -------
        Frequency
            The lines with ``lo <= f <= hi``, in Hz.
        """
        mask = self.band_mask(lo, hi)
        if not mask.any():
            raise InvalidValueError(
                f"lo, hi: the band [{lo!r}, {hi!r}] holds no line of the grid "
                f"{self.start:g}..{self.stop:g} Hz"
            )
        return Frequency(self.hz[mask])

    def __hash__(self) -> int:
        return hash(self.hz.tobytes())

    def __repr__(self) -> str:
        if self.n == 1:
            return f"Frequency({self.start:g} Hz)"
        steps = np.diff(self.hz)
        uniform = np.ptp(steps) <= 1e-9 * steps.max()
        spacing = f"step {steps[0]:.6g} Hz" if uniform else "non-uniform"
        return f"Frequency({self.start:g}..{self.stop:g} Hz, n={self.n}, {spacing})"

