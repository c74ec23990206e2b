"""Savitzky-Golay smoothing of measured FRFs (thesis section 3.4).

Closed-form joint identification inverts measured receptance matrices and
amplifies their noise; the thesis filters the measured FRFs with a
Savitzky-Golay filter first.  :func:`smooth` applies
:func:`scipy.signal.savgol_filter` to the real and imaginary parts of every
entry of an FRF along frequency (a local least-squares polynomial fit over a
window of lines, which keeps the shape of peaks far better than a moving
average of the same width).  :func:`choose_window` picks the window from the
data when it is not given: as wide as possible, so that noise is averaged
out, but narrow enough not to flatten the sharpest resonance peak.

The filter assumes equally spaced lines: FRFs on a non-uniform grid are
refused (interpolate them to a uniform grid first, explicitly).
"""

from __future__ import annotations

import numbers
import warnings

import attrs
import numpy as np
from scipy.signal import find_peaks, savgol_coeffs, savgol_filter

from .errors import InvalidValueError, SubstructureWarning
from .frf import FRF, frf_checked
from .units import whole_number

__all__ = ["smooth", "choose_window", "PEAK_BIAS", "CoarseDataWarning"]

PEAK_BIAS = 0.005
"""Largest relative loss of a resonance peak's height that :func:`choose_window` accepts."""

_HALF_POWER = 1.0 / np.sqrt(2.0)


class CoarseDataWarning(SubstructureWarning):
    """The frequency grid is too coarse to smooth the sharpest peak without lowering it."""


def _check_frf(frf: FRF) -> None:
    frf_checked(frf)
    hz = frf.frequency.hz
    if hz.size < 3:
        raise InvalidValueError(f"frf: has {hz.size} frequency line(s); smoothing needs at least 3")
    steps = np.diff(hz)
    if np.ptp(steps) > 1e-6 * steps.mean():
        k = int(np.argmax(np.abs(steps - steps[0]) > 1e-6 * steps.mean()))
        raise InvalidValueError(
            f"frf: the frequency grid is not uniform (step {steps[0]:.6g} Hz at {hz[0]:g} Hz, "
            f"{steps[k]:.6g} Hz at {hz[k]:g} Hz); the Savitzky-Golay filter assumes equally spaced "
            "lines: interpolate to a uniform grid first (frf.interpolate(Frequency.from_range(...)))"
        )


def _check_polyorder(polyorder: object) -> int:
    return whole_number(polyorder, "polyorder", 0, "an integer")


def _floor(polyorder: int) -> int:
    """The smallest window allowed: odd and at least ``polyorder + 2``."""
    w = polyorder + 2
    return w if w % 2 else w + 1


def _peak_loss(window: int, polyorder: int, bandwidth_lines: float) -> float:
    """Relative loss of the peak of ``1 / (1 + 2i k / B)`` (a resonance of half-power bandwidth B lines)."""
    half = window // 2
    k = np.arange(-half, half + 1)
    c = savgol_coeffs(window, polyorder, use="dot")
    return float(1.0 - abs(np.dot(c, 1.0 / (1.0 + 2j * k / bandwidth_lines))))


def _half_power_bandwidths(magnitude: np.ndarray) -> list[float]:
    """Half-power bandwidths, in lines, of the resonance peaks of one ``|FRF|``.

    A local maximum counts as a resonance when ``|FRF|`` falls below
    ``peak / sqrt(2)`` on both sides before rising above the peak (its
    prominence is at least ``(1 - 1/sqrt(2))`` of its height): noise ripples
    and shoulders do not.  Crossings are interpolated linearly between lines.
    """
    peaks, props = find_peaks(magnitude, prominence=0.0)
    widths = []
    for p, prominence in zip(peaks, props["prominences"]):
        level = magnitude[p] * _HALF_POWER
        if prominence < magnitude[p] - level:
            continue
        left = np.nonzero(magnitude[:p] < level)[0]
        right = np.nonzero(magnitude[p + 1:] < level)[0]
        if left.size == 0 or right.size == 0:
            continue
        i, j = left[-1], p + 1 + right[0]  # last line below the level on each side
        x_left = i + (level - magnitude[i]) / (magnitude[i + 1] - magnitude[i])
        x_right = j - 1 + (magnitude[j - 1] - level) / (magnitude[j - 1] - magnitude[j])
        widths.append(float(x_right - x_left))
    return widths


def choose_window(frf: FRF, polyorder: int = 3) -> int:
    """The Savitzky-Golay window (in lines) for an FRF, chosen from its sharpest resonance.

    Rule: find the resonance peaks of ``|FRF|`` of every entry (local maxima
    with a half-power bandwidth: ``|FRF|`` falls below ``peak / sqrt(2)`` on
    both sides), take the narrowest half-power bandwidth ``B`` in lines, and
    return the largest odd window for which the filter lowers the peak of a
    single resonance ``1 / (1 + 2i k / B)`` by at most :data:`PEAK_BIAS`
    (0.5 %).  For ``polyorder = 3`` that is about ``B / 2``.  The window is
    at least the floor ``polyorder + 2`` (odd) and at most the number of lines.

    Parameters
    ----------
    frf : FRF
        On a uniform grid, with at least one resonance peak.
    polyorder : int, default 3
        The polynomial order the window is meant for.

    Returns
    -------
    int
        An odd window length.

    Warns
    -----
    CoarseDataWarning
        (a :class:`~substructure.errors.SubstructureWarning`) when even the
        floor window lowers the sharpest peak by more than :data:`PEAK_BIAS`:
        the grid is too coarse for the damping, measure with a finer
        frequency resolution or do not smooth.

    Raises
    ------
    InvalidValueError
        For a non-uniform grid, or data without a resonance peak (give the
        window explicitly).
    """
    return _choose_window(frf, polyorder)


def _choose_window(frf: FRF, polyorder: int) -> int:
    """:func:`choose_window`; called from the public functions, so its warning points at their caller."""
    _check_frf(frf)
    polyorder = _check_polyorder(polyorder)
    n = frf.frequency.n
    floor = _floor(polyorder)
    if floor > n:
        raise InvalidValueError(
            f"frf: has {n} lines; a polyorder-{polyorder} filter needs a window of at least {floor} lines"
        )
    magnitude = np.abs(frf.data).reshape(n, -1)
    widths = [w for column in magnitude.T for w in _half_power_bandwidths(column)]
    if not widths:
        raise InvalidValueError(
            "frf: no resonance peak with a half-power bandwidth in the data, so the window cannot be "
            "chosen from it; give the window explicitly, smooth(frf, window=...)"
        )
    bandwidth = min(widths)
    if _peak_loss(floor, polyorder, bandwidth) > PEAK_BIAS:
        df = frf.frequency.hz[1] - frf.frequency.hz[0]
        warnings.warn(
            f"the sharpest resonance has a half-power bandwidth of {bandwidth:.3g} lines "
            f"({bandwidth * df:.3g} Hz); even the smallest window ({floor} lines) lowers its peak by "
            f"{100 * _peak_loss(floor, polyorder, bandwidth):.2g} %: the grid is too coarse to smooth "
            "without biasing the peaks (measure with a finer resolution, or do not smooth)",
            CoarseDataWarning,
            stacklevel=3,
        )
        return floor
    largest = n if n % 2 else n - 1
    window = floor
    while window + 2 <= largest and _peak_loss(window + 2, polyorder, bandwidth) <= PEAK_BIAS:
        window += 2
    return window


def smooth(frf: FRF, window: int | None = None, polyorder: int = 3) -> FRF:
    """Savitzky-Golay smoothing of every entry of an FRF along frequency.

    Real and imaginary parts are filtered separately with
    :func:`scipy.signal.savgol_filter` (``mode="interp"``: the first and
    last half-windows are fitted by the polynomial of the edge window).

    Parameters
    ----------
    frf : FRF
        On a uniform frequency grid.
    window : int, optional
        Odd number of lines, larger than ``polyorder`` and at most the
        number of lines; chosen by :func:`choose_window` when not given.
    polyorder : int, default 3
        Order of the local polynomial.

    Returns
    -------
    FRF
        Same axis, labels and quantity.

    Raises
    ------
    InvalidValueError
        For a non-uniform grid, an even window, a window not larger than
        ``polyorder`` or longer than the data.

    Examples
    --------
    >>> smoothed = smooth(measured)               # doctest: +SKIP
    >>> smoothed = smooth(measured, window=11)    # doctest: +SKIP
    """
    _check_frf(frf)
    polyorder = _check_polyorder(polyorder)
    if window is None:
        window = _choose_window(frf, polyorder)
    if isinstance(window, bool) or not isinstance(window, (numbers.Integral, np.integer)):
        raise InvalidValueError(f"window: got {window!r}; expected an odd integer number of lines")
    window = int(window)
    n = frf.frequency.n
    if window % 2 == 0:
        raise InvalidValueError(f"window: got {window}; expected an odd number of lines (e.g. {window + 1})")
    if window <= polyorder:
        raise InvalidValueError(
            f"window: got {window} with polyorder {polyorder}; expected a window larger than polyorder "
            f"(at least {_floor(polyorder)})"
        )
    if window > n:
        raise InvalidValueError(f"window: got {window}; the FRF has only {n} lines")
    real = savgol_filter(frf.data.real, window, polyorder, axis=0, mode="interp")
    imag = savgol_filter(frf.data.imag, window, polyorder, axis=0, mode="interp")
    return attrs.evolve(frf, data=real + 1j * imag)
