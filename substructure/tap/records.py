"""Time records of one or several taps: :class:`TapRecord` and the units of its channels.

A record holds the samples of an instrumented hammer (force, N) and of one
response sensor (acceleration m/s^2, velocity m/s or displacement m) on one
uniform time axis.  Channels recorded in volts are converted with the
sensitivity of their sensor (``"10.2 mV/g"``, ``"2.25 mV/N"``): the quantity
of a voltage channel is the denominator of its sensitivity.  Every check
names the record's source and the column.
"""

from __future__ import annotations

import re
from typing import Any

import attrs
import numpy as np

from ..errors import InvalidValueError, UnitError
from ..units import instrument_unit, ureg

__all__ = ["TapRecord", "RESPONSE_QUANTITIES", "MIN_SAMPLES", "TIME_STEP_TOLERANCE", "channel_to_si",
           "unit_of", "quantity_of"]

RESPONSE_QUANTITIES = {
    "acceleration": ("m/s^2", "accelerance"),
    "velocity": ("m/s", "mobility"),
    "displacement": ("m", "receptance"),
}
"""The response quantities: their SI unit and the FRF quantity of response over force."""

MIN_SAMPLES = 16
"""The fewest samples a record may have."""

TIME_STEP_TOLERANCE = 1e-3
"""Largest deviation of one time step from the mean step, relative to the mean step (uniform sampling)."""

def unit_of(text: str, field: str):
    """The pint unit of a unit text of a record (``"m/s^2"``, ``"g"``, ``"mV"``, ``"um"``).

    Read by :func:`substructure.units.instrument_unit`: ``g`` is the
    standard acceleration of gravity (9.80665 m/s^2), ``lb`` the
    pound-force, and exponents may be written ``m/s2``, ``m s-2``.

    Parameters
    ----------
    text : str
        The unit, as in a column header (without brackets).
    field : str
        What the unit belongs to, for messages.

    Returns
    -------
    pint.Unit
        The unit.

    Raises
    ------
    UnitError
        When pint cannot read it.
    """
    try:
        unit = instrument_unit(text)
    except ValueError:
        raise UnitError(f"{field}: cannot read the unit {text!r}; expected e.g. N, m/s^2, g, m/s, mm/s, m, um, "
                        "mV or V") from None
    return unit


def quantity_of(unit) -> str | None:
    """What a unit measures, among the channels of a tap record.

    Parameters
    ----------
    unit : str or pint.Unit
        The unit.

    Returns
    -------
    str or None
        ``"time"``, ``"force"``, ``"voltage"``, ``"acceleration"``,
        ``"velocity"`` or ``"displacement"``; None for another dimension.
    """
    q = ureg.Quantity(1.0, unit)
    for name, dim in (("time", "[time]"), ("force", "[force]"), ("voltage", "[electric_potential]"),
                      ("acceleration", "[acceleration]"), ("velocity", "[velocity]"), ("displacement", "[length]")):
        if q.check(dim):
            return name
    return None


def channel_to_si(values: np.ndarray, unit: Any, field: str, expected: tuple[str, ...],
                  sensitivity: Any = None, sensitivity_option: str = "sensitivity") -> tuple[np.ndarray, str]:
    """A channel in SI units and its physical quantity.

    Parameters
    ----------
    values : numpy.ndarray
        The samples, in ``unit``.
    unit : str or pint.Unit
        The unit of the samples: a physical unit, or a voltage (``mV``, ``V``).
    field : str
        The source and column, for messages (``"tap1.csv: column 'acceleration [g]'"``).
    expected : tuple of str
        The quantities the channel may hold: ``("force",)`` or
        ``("acceleration", "velocity", "displacement")``.
    sensitivity : str or pint.Quantity, optional
        Volts per physical unit (``"10.2 mV/g"``); required for a voltage
        channel, refused for a channel already in physical units.
    sensitivity_option : str
        The option that gives the sensitivity, for messages.

    Returns
    -------
    numpy.ndarray
        The samples in SI units (N, m/s^2, m/s or m).
    str
        The quantity (one of ``expected``).

    Raises
    ------
    UnitError
        For a unit of another quantity, a voltage without sensitivity, a
        sensitivity of the wrong dimension, or a sensitivity given for a
        channel in physical units.
    """
    unit = unit_of(unit, field) if isinstance(unit, str) else unit
    kind = quantity_of(unit)
    names = " or ".join(expected)
    if kind == "voltage":
        if sensitivity is None:
            example = "2.25 mV/N" if expected == ("force",) else "10.2 mV/g"
            raise UnitError(f"{field}: the channel is a voltage ({unit:~}); give the sensor's sensitivity with "
                            f"{sensitivity_option}, e.g. {example}")
        sens = _sensitivity(sensitivity, sensitivity_option)
        physical = ureg.Quantity(1.0, unit) / sens
        quantity = quantity_of(physical.units)
        if quantity not in expected:
            raise UnitError(f"{sensitivity_option}: {sensitivity!s} turns volts into {physical.dimensionality}; "
                            f"{field} should hold {names}")
        si = RESPONSE_QUANTITIES[quantity][0] if quantity != "force" else "N"
        return values * physical.m_as(si), quantity
    if sensitivity is not None:
        raise UnitError(f"{field}: the channel is already in {unit:~}, not a voltage; {sensitivity_option} "
                        f"({sensitivity!s}) applies to a channel in mV or V: leave it out or fix the header")
    if kind not in expected:
        said = (f"an {kind}" if kind[0] in "aeiou" else f"a {kind}") if kind else "of no known quantity"
        raise UnitError(f"{field}: the unit {unit:~} is {said}; "
                        f"expected {names} (or a voltage with a sensitivity)")
    si = RESPONSE_QUANTITIES[kind][0] if kind != "force" else "N"
    return values * ureg.Quantity(1.0, unit).m_as(si), kind


def _sensitivity(value: Any, option: str):
    if isinstance(value, str):
        text = value.strip()
        match = re.match(r"^\s*([-+0-9.eE]+)\s*(.*)$", text)
        if not match or not match.group(2):
            raise UnitError(f"{option}: cannot read {value!r}; expected volts per unit, e.g. 10.2 mV/g or 2.25 mV/N")
        try:
            magnitude = float(match.group(1))
        except ValueError:
            raise UnitError(f"{option}: cannot read {value!r}; expected e.g. 10.2 mV/g") from None
        q = magnitude * ureg.Quantity(1.0, unit_of(match.group(2), option))
    elif hasattr(value, "units"):
        q = ureg.Quantity(str(value)) if value._REGISTRY is not ureg else value
    else:
        raise UnitError(f"{option}: got {value!r}; expected volts per unit with the unit, e.g. 10.2 mV/g")
    if not q.check("[electric_potential]") and not (q * ureg.Quantity(1.0, "N")).check("[electric_potential]") \
            and not any((q * ureg.Quantity(1.0, u)).check("[electric_potential]") for u in ("m/s^2", "m/s", "m")):
        raise UnitError(f"{option}: {value!s} is not volts per unit; expected e.g. 10.2 mV/g or 2.25 mV/N")
    if not np.isfinite(q.magnitude) or q.magnitude <= 0:
        raise InvalidValueError(f"{option}: got {value!s}; expected a positive sensitivity")
    return q


def _array(value: Any, field: str) -> np.ndarray:
    try:
        raw = np.asarray(value)
    except (TypeError, ValueError):
        raise InvalidValueError(f"{field}: got {type(value).__name__}; expected a 1-D array of numbers") from None
    if np.iscomplexobj(raw):  # numpy would drop the imaginary part with a warning
        raise InvalidValueError(f"{field}: got complex samples ({raw.dtype}); expected real samples of a time "
                                "record (a spectrum is not a tap record)")
    try:
        array = np.array(raw, dtype=np.float64)
    except (TypeError, ValueError, OverflowError):
        raise InvalidValueError(f"{field}: got {type(value).__name__}; expected a 1-D array of numbers") from None
    if array.ndim != 1:
        raise InvalidValueError(f"{field}: got shape {array.shape}; expected a 1-D array of samples")
    array.setflags(write=False)
    return array


def _check_quantity(instance: Any, attribute: Any, value: str) -> None:
    if value not in RESPONSE_QUANTITIES:
        raise InvalidValueError(f"quantity: got {value!r}; expected one of {', '.join(RESPONSE_QUANTITIES)}")


@attrs.frozen(repr=False, eq=False)
class TapRecord:
    """The time record of one or several taps: force and response on one uniform time axis.

    Parameters
    ----------
    time : array of float
        Sample times in s, uniformly spaced and increasing.
    force : array of float
        The hammer's force in N.
    response : array of float
        The response in SI units of ``quantity``: m/s^2, m/s or m.
    quantity : {"acceleration", "velocity", "displacement"}
        What the response sensor measured.
    source : str
        Where the record came from (a file name), for messages.
    force_column, response_column : str
        The names of the channels in ``source``, for messages.

    Raises
    ------
    InvalidValueError
        Naming ``source`` and the column: channels of different lengths,
        fewer than 16 samples (``MIN_SAMPLES``), NaN or infinite samples, a
        time axis that is not increasing and uniform.
    """

    time: np.ndarray = attrs.field(converter=lambda v: _array(v, "time"))
    force: np.ndarray = attrs.field(converter=lambda v: _array(v, "force"))
    response: np.ndarray = attrs.field(converter=lambda v: _array(v, "response"))
    quantity: str = attrs.field(default="acceleration", validator=_check_quantity)
    source: str = attrs.field(default="<arrays>")
    force_column: str = attrs.field(default="force")
    response_column: str = attrs.field(default="response")

    def __attrs_post_init__(self) -> None:
        where = self.source
        columns = (("time", self.time), (self.force_column, self.force), (self.response_column, self.response))
        n = self.time.size
        for name, values in columns[1:]:
            if values.size != n:
                raise InvalidValueError(f"{where}: column {name!r} has {values.size} samples, the time column "
                                        f"{n}; the channels of a record must have the same length")
        if n < MIN_SAMPLES:
            raise InvalidValueError(f"{where}: {n} samples; a tap record needs at least {MIN_SAMPLES}")
        for name, values in columns:
            bad = ~np.isfinite(values)
            if bad.any():
                k = int(np.argmax(bad))
                raise InvalidValueError(f"{where}: column {name!r}, sample {k}: {float(values[k])!r}; expected a "
                                        "finite number (a gap in the acquisition?)")
        step = np.diff(self.time)
        mean = (self.time[-1] - self.time[0]) / (n - 1)
        if not mean > 0 or np.any(np.abs(step - mean) > TIME_STEP_TOLERANCE * mean):
            k = int(np.argmax(np.abs(step - mean))) + 1 if mean > 0 else 1
            far = float(np.max(np.abs(self.time)))
            held = float(np.spacing(far))
            hint = (f" (times near {far:.4g} s, which float64 holds only to {held:.2g} s: give them from the "
                    "record's first sample)" if mean > 0 and abs(float(step[k - 1]) - mean) <= 4 * held else "")
            raise InvalidValueError(
                f"{where}: column 'time', sample {k}: step {float(step[k - 1])!r} s where the mean step is "
                f"{float(mean)!r} s; "
                f"expected increasing, uniformly sampled times (one record per sample rate){hint}"
            )

    @classmethod
    def from_samples(cls, force: Any, response: Any, sample_rate: Any, quantity: str = "acceleration",
                     source: str = "<arrays>") -> "TapRecord":
        """A record from samples in SI units and a sample rate, starting at t = 0.

        Parameters
        ----------
        force : array of float
            Force in N.
        response : array of float
            Response in SI units of ``quantity``.
        sample_rate : float, str or pint.Quantity
            Samples per second (plain numbers in Hz, or ``"51.2 kHz"``).
        quantity : {"acceleration", "velocity", "displacement"}
            What the response is.
        source : str
            A name for messages.

        Returns
        -------
        TapRecord
            The record.
        """
        from ..units import frequency_hz

        rate = float(sample_rate) if isinstance(sample_rate, (int, float, np.floating)) else \
            frequency_hz(sample_rate, "sample_rate")
        if not np.isfinite(rate) or rate <= 0:
            raise InvalidValueError(f"sample_rate: got {sample_rate!r}; expected a positive rate in Hz")
        n = np.size(force)
        return cls(np.arange(n) / rate, force, response, quantity, source)

    @property
    def sample_rate(self) -> float:
        """Samples per second (Hz), from the time axis, to 10 significant digits (the rounding of stored times)."""
        return float(f"{(self.time.size - 1) / (self.time[-1] - self.time[0]):.10g}")

    @property
    def duration(self) -> float:
        """Length of the record in s (samples times the time step)."""
        return self.time.size / self.sample_rate

    def __len__(self) -> int:
        return int(self.time.size)

    def __repr__(self) -> str:
        return (f"TapRecord({self.source}, {self.time.size} samples at {self.sample_rate:g} Hz, "
                f"{self.quantity})")
