"""Spindle speeds in rpm: :func:`spindle_speeds`, :func:`as_speed_rpm`, :func:`tooth_passing_hz`.

Every speed the stability methods take goes through here.  A speed must
carry an angle-per-time unit (rpm, turn/min, rad/s); a speed in Hz is
refused, because pint converts rpm to Hz as an angular velocity (off by
``2*pi``).  Reading a result (``rpm_values``) takes plain numbers as rpm
too.  Grids are limited to :data:`MAX_SPEEDS` speeds.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import pint

from ..errors import InvalidValueError, UnitError
from ..units import Q_, show_value, teeth_count, ureg

__all__ = ["spindle_speeds", "as_speed_rpm", "tooth_passing_hz", "MAX_SPEEDS"]

MAX_SPEEDS = 100_000
"""Most spindle speeds of one grid (:func:`spindle_speeds`)."""

# -- spindle speeds -----------------------------------------------------------


def _speed_units_ok(q: pint.Quantity) -> bool:
    """True when the unit is an angle per time (rpm, turn/min, rad/s), not a bare 1/time."""
    if not q.check("1 / [time]"):
        return False
    _, root = ureg.get_root_units(q.units)
    return "radian" in str(root)


def _speed_error(field: str, value: Any) -> UnitError:
    return UnitError(
        f"{field}: got {show_value(value)}; expected spindle speeds in rpm with their unit, e.g. "
        "Q_(np.linspace(2000, 20000, 500), 'rpm') or spindle_speeds('2000 rpm', '20000 rpm', '10 rpm')"
    )


def as_speed_rpm(value: Any, field: str = "speeds") -> np.ndarray:
    """Spindle speeds as a 1-D float array in rpm, checked.

    Parameters
    ----------
    value : pint.Quantity or str
        Speeds in an angular-speed unit: ``rpm`` (revolutions per minute),
        ``turn/min``, ``rad/s``.  A scalar gives a one-element array.
    field : str
        Name used in error messages.

    Raises
    ------
    UnitError
        For bare numbers, and for speeds in Hz or 1/s: whether 1 Hz means one
        revolution per second or one radian per second is ambiguous (pint
        takes the second, a factor ``2*pi`` from what a machinist means).
        Convert revolutions per second explicitly with
        :func:`substructure.units.hz_to_rpm`.
    InvalidValueError
        For speeds that are not finite, not positive or not strictly
        increasing.

    Returns
    -------
    ndarray
        The speeds in rpm, 1-D, strictly increasing.
    """
    if not isinstance(value, (str, pint.Quantity)):
        raise _speed_error(field, value)
    speeds = np.atleast_1d(_quantity_rpm(value, field))
    if speeds.ndim != 1 or speeds.size == 0:
        raise InvalidValueError(f"{field}: got shape {speeds.shape}; expected a non-empty 1-D array of speeds")
    if not np.all(np.isfinite(speeds)) or np.any(speeds <= 0):
        raise InvalidValueError(f"{field}: expected finite, positive spindle speeds; got {speeds.min():g} rpm")
    if np.any(np.diff(speeds) <= 0):
        raise InvalidValueError(f"{field}: expected strictly increasing spindle speeds")
    return speeds


def _quantity_rpm(value: str | pint.Quantity, field: str) -> np.ndarray:
    """A string or quantity in an angular-speed unit as rpm, of any shape; Hz and bare 1/s refused."""
    if isinstance(value, str):
        try:
            value = Q_(value)
        except Exception:
            raise _speed_error(field, value) from None
    if not isinstance(value, pint.Quantity):
        raise _speed_error(field, value)
    if value._REGISTRY is not ureg:
        value = Q_(value.magnitude, str(value.units))
    if not _speed_units_ok(value):
        if value.check("1 / [time]"):
            raise UnitError(
                f"{field}: got a speed in {value.units:~P}; a spindle speed is in rpm. "
                "1 Hz is ambiguous (pint reads it as 1 rad/s, a machinist as 1 rev/s = 60 rpm): "
                "give rpm, or convert revolutions per second with substructure.units.hz_to_rpm"
            )
        raise _speed_error(field, value)
    return np.asarray(value.m_as("rpm"), dtype=float)


def rpm_values(value: Any, field: str) -> np.ndarray:
    """Spindle speeds in rpm as an array of the shape given, converted but not otherwise checked.

    What reading a result takes (:meth:`~substructure.stability.Lobes.limit_at` and its
    neighbours): plain numbers are rpm; a string or a quantity is converted from its
    angular-speed unit as :func:`as_speed_rpm` converts it (Hz refused).

    Parameters
    ----------
    value : float, array_like, str or pint.Quantity
        E.g. ``12000``, ``[9000, 12000]``, ``"12000 rpm"``, ``Q_(1200, "rad/s")``.
    field : str
        Name used in error messages.

    Raises
    ------
    UnitError
        For a unit that is not an angular speed, and for Hz or 1/s.
    InvalidValueError
        For values that are not numbers.

    Returns
    -------
    ndarray
        The speeds in rpm, the shape of ``value``.
    """
    if isinstance(value, (str, pint.Quantity)):
        return _quantity_rpm(value, field)
    try:
        return np.asarray(value, dtype=float)
    except (TypeError, ValueError, OverflowError):
        raise InvalidValueError(
            f"{field}: got {show_value(value)}; expected spindle speeds in rpm: numbers, or a string or "
            "quantity with an angular-speed unit such as '12000 rpm' or Q_(1200, 'rad/s')"
        ) from None


def spindle_speeds(start: Any, stop: Any, step: Any) -> pint.Quantity:
    """Grid of spindle speeds ``start + step*k`` up to ``stop`` (included when on the grid), in rpm.

    Parameters
    ----------
    start, stop, step : pint.Quantity or str
        E.g. ``"2000 rpm"``, ``"20000 rpm"``, ``"10 rpm"``.  Hz is refused
        (see :func:`as_speed_rpm`).

    Returns
    -------
    pint.Quantity
        The speeds, an array in rpm.

    Examples
    --------
    >>> spindle_speeds("1000 rpm", "1100 rpm", "50 rpm")
    <Quantity([1000. 1050. 1100.], 'revolutions_per_minute')>
    """
    lo, hi, dn = (float(as_speed_rpm(v, f)[0]) for v, f in ((start, "start"), (stop, "stop"), (step, "step")))
    if hi < lo:
        raise InvalidValueError(f"stop: got {show_value(stop)} below start {show_value(start)}")
    count = (hi - lo) / dn
    if count + 1 > MAX_SPEEDS:
        raise InvalidValueError(
            f"step: {lo:g} to {hi:g} rpm in steps of {dn:g} rpm is {count + 1:.4g} speeds, more than the limit "
            f"MAX_SPEEDS = {MAX_SPEEDS:,}; use a coarser step")
    k = round(count) if abs(count - round(count)) <= 1e-9 * max(1.0, count) else math.floor(count)
    return Q_(lo + dn * np.arange(k + 1), "rpm")


def tooth_passing_hz(speed_rpm: Any, teeth: int) -> np.ndarray:
    """Tooth-passing frequency in Hz: ``teeth * rpm / 60`` (revolutions, not radians).

    Parameters
    ----------
    speed_rpm : array_like
        Spindle speeds in rpm (plain numbers).
    teeth : int
        Number of teeth.

    Returns
    -------
    ndarray
        Tooth-passing frequencies in Hz.

    Raises
    ------
    InvalidValueError
        For teeth that are not a whole number >= 1, or speeds that are not
        finite numbers >= 0 (0 teeth gave 0 Hz; texts were read as numbers).
    """
    teeth = teeth_count(teeth)
    raw = np.asarray(speed_rpm)
    if raw.dtype.kind not in "iuf" or not (np.isfinite(raw).all() and (raw >= 0).all()):
        raise InvalidValueError(f"speed_rpm: got {speed_rpm!r}; expected spindle speeds in rpm, plain numbers >= 0")
    return raw.astype(float) * teeth / 60.0

