"""The one pint unit registry of `substructure`, and the checks at the boundary.

Public constructors take pint quantities or strings that pint parses
(``"60 mm"``, ``"4.19e7 N/m"``).  A bare number where a dimension is expected
is rejected, as is a quantity of the wrong dimension; inside the numerical
core everything is SI floats, converted once here.

Examples
--------
>>> from substructure.units import quantity, to_si
>>> quantity("60 mm", "od", "[length]")
<Quantity(60, 'millimeter')>
>>> to_si("60 mm", "od", "m")
0.06
"""

from __future__ import annotations

import functools
import math
import numbers
import os
import re
import shutil
from typing import Any, cast

import numpy as np
import pint

from .errors import InvalidValueError, UnitError

__all__ = [
    "ureg",
    "Q_",
    "quantity",
    "to_si",
    "dimensionless",
    "whole_number",
    "finite_real",
    "items_of",
    "MAX_REPEATS",
    "format_quantity",
    "rpm_to_hz",
    "hz_to_rpm",
    "frequency_hz",
    "CACHE_VARIABLE",
    "magnitude_in",
    "show_value",
    "instrument_unit",
    "bare_unit",
]

CACHE_VARIABLE = "SUBSTRUCTURE_UNITS_CACHE"
"""Environment variable: the folder of the unit registry's cache, or ``off`` for none.

By default the cache is ``substructure/pint`` in the user's cache folder
(``~/.cache`` on Linux).  Building pint's registry means parsing its
definition files, about 0.15 s; from the cache it takes about 0.02 s.  The
cache is written by the first program that builds the registry (the
installation does it, see docs/performance.md) and holds pint's parsed
definitions only: deleting it is always safe.
"""


def cache_folder() -> str | None:
    """The folder of the unit registry's cache (``CACHE_VARIABLE``), or None when it is off.

    Returns
    -------
    str or None
        A folder path.
    """
    value = os.environ.get(CACHE_VARIABLE)
    if value is not None:
        value = value.strip()
        return None if value.lower() in ("", "off", "none", "0") else value
    import platformdirs  # a dependency of pint

    return str(platformdirs.user_cache_path("substructure", appauthor=False) / "pint")


def _registry() -> pint.UnitRegistry:
    """pint's default registry, its parsed definitions read from the cache when there is one.

    A cache that cannot be read (damaged, written by another pint) is
    removed and written again; when no cache can be used at all, the
    registry is built from pint's definition files, as without a cache.
    """
    folder = cache_folder()
    if folder is not None:
        for attempt in range(2):
            try:
                return pint.UnitRegistry(cache_folder=folder)
            except Exception:  # pint and flexcache raise many kinds for a bad or unwritable cache
                if attempt == 0:
                    shutil.rmtree(folder, ignore_errors=True)
    return pint.UnitRegistry()


ureg = _registry()
"""The registry every quantity of the package belongs to."""
Q_ = ureg.Quantity
"""The quantity class of that registry: ``Q_(12, "mm")`` or ``Q_("12 mm")`` (a :class:`pint.Quantity`)."""

# Human names of the dimensions the package uses, for error messages.
_DIMENSION_NAMES = {
    "[length]": "a length (e.g. '60 mm')",
    "[mass]": "a mass (e.g. '2 g')",
    "[mass] / [length] ** 3": "a density (e.g. '7850 kg/m^3')",
    "[mass] / [length] / [time] ** 2": "a pressure or modulus (e.g. '210 GPa')",
    "[mass] * [length] ** 2": "a rotary inertia (e.g. '5e-8 kg*m^2')",
    "[mass] / [time] ** 2": "a stiffness in N/m (e.g. '4e7 N/m')",
    "[length] * [mass] / [time] ** 2": "a force or N*m/m (e.g. '2e6 N')",
    "[length] ** 2 * [mass] / [time] ** 2": "a moment or N*m/rad (e.g. '6.5e4 N*m/rad')",
    "[mass] / [time]": "a damping in N*s/m (e.g. '54 N*s/m')",
    "[length] * [mass] / [time]": "a damping in N*s (e.g. '22 N*s')",
    "[length] ** 2 * [mass] / [time]": "a damping in N*m*s/rad (e.g. '1 N*m*s/rad')",
    "1 / [time]": "a frequency (e.g. '20 Hz')",
}


_NUMBER = re.compile(r"^\s*[-+]?(\d|\.\d|inf|nan)", re.IGNORECASE)
_SIDE_BY_SIDE = re.compile(r"[\w).]\s+\.?\d")  # "1 2 mm", "1 1/2 in", "20 mm 2": pint multiplies them
_OPERATORS = set(".+-*/^()%_\u00b7\u00d7\u00b0\u00b2\u00b3\u00b9\u2070\u2074\u2075\u2076\u2077\u2078\u2079\u207b")
# besides letters, digits and spaces, what a number and a unit are written with (·, ×, °, superscripts); pint skips
# any other character without a word: "12 − 3 mm" (a Unicode minus) is 36 mm to it, "12 # 3" is 12


def check_number_text(text: str, field: str, expected: str, error: type[Exception] = UnitError) -> None:
    """Refuse a value's text that pint reads as another number than the one written.

    pint drops a comma (``"20,5 mm"`` is 205 mm, ``"1,5"`` is 15) and any
    character it does not know (``"12 \u2212 3 mm"``, a Unicode minus, is
    36 mm), and multiplies numbers written side by side (``"1 2 mm"`` is
    2 mm, ``"1 1/2 in"`` is half an inch): such a text is an error, not a
    guess.
    :func:`quantity` and :func:`dimensionless` check every string; readers
    that hand a string to pint themselves call it first.

    Parameters
    ----------
    text : str
        The value as written.
    field : str
        Name of the field, used in error messages.
    expected : str
        What the field expects, for the message (``"a length (e.g. '60 mm')"``).
    error : type, default UnitError
        The class of the error raised.

    Raises
    ------
    UnitError
        (or ``error``) for a comma or numbers side by side.
    """
    odd = next((c for c in text if not (c.isalnum() or c.isspace() or c in _OPERATORS or c == ",")), None)
    if odd is not None:
        hint = "; write '-' for a minus sign" if odd in "\u2212\u2010\u2011\u2012\u2013\u2014" else ""
        raise error(
            f"{field}: got {show_value(text)}: the character {odd!r} (U+{ord(odd):04X}) is neither part of a number "
            f"nor of a unit, and pint would skip it without a word{hint}; expected {expected}"
        )
    _no_comma(text, field, expected, error)
    m = _SIDE_BY_SIDE.search(text)
    if m:
        raise error(
            f"{field}: got {show_value(text)}: a number written after {text[:m.start() + 1].strip()!r} with "
            f"only a space between would be multiplied into it; write one number and its unit (e.g. '12 mm'); "
            f"expected {expected}"
        )


def _describe(dimension: str) -> str:
    return _DIMENSION_NAMES.get(dimension, f"a quantity of dimension {dimension}")


# Parsing a string with pint takes about 0.3 ms and checking a dimension or
# converting a unit some 30 us: the results are cached per string and per
# unit, and each quantity is made anew from its magnitude and unit (a cached
# Quantity object would be shared between the objects built from it).


@functools.lru_cache(maxsize=8192)
def _parse(text: str) -> tuple[Any, Any]:
    """Magnitude and unit of a string pint reads (exceptions are not cached)."""
    q: Any = ureg.Quantity(text)
    if not isinstance(q, pint.Quantity):
        return q, None
    return q.magnitude, q.units


@functools.lru_cache(maxsize=1024)
def _has_dimension(units: Any, dimension: str) -> bool:
    return ureg.Quantity(1, units).check(dimension)


@functools.lru_cache(maxsize=1024)
def _factor(units: Any, target: str) -> float | None:
    """``x`` in ``units`` is ``x * factor`` in ``target`` (pint's own factor); None for offset units."""
    if ureg.Quantity(0.0, units).m_as(target) != 0.0:  # e.g. degC to K
        return None
    return ureg.Quantity(1.0, units).m_as(target)


def magnitude_in(q: pint.Quantity, unit: str) -> float:
    """The magnitude of a quantity of this registry in ``unit``, as float (as ``q.m_as(unit)``).

    Parameters
    ----------
    q : pint.Quantity
        A scalar quantity of :data:`~substructure.ureg` with the dimension of ``unit``.
    unit : str
        The unit wanted, e.g. ``"m"``.

    Returns
    -------
    float
        The same value as ``float(q.m_as(unit))``, with the conversion factor
        looked up once per unit instead of at every call.
    """
    factor = _factor(q.units, unit)
    if factor is None:
        return float(q.m_as(unit))
    return float(q.magnitude * factor)


def show_value(value: Any) -> str:
    """A value as an error message shows it: in plain words, never a pint repr.

    Parameters
    ----------
    value : object
        What the user gave: a string (shown quoted, as typed), a quantity
        (shown as its number and the full name of its unit, so that a
        misread suffix is visible: ``20 boltzmann_constant`` for ``"20k"``),
        a number or anything else (its ``repr``).

    Returns
    -------
    str
        The text for the message.

    Examples
    --------
    >>> show_value(Q_(20, "k"))
    '20 boltzmann_constant'
    >>> show_value("20 kHz")
    "'20 kHz'"
    """
    if isinstance(value, pint.Quantity):
        m = value.magnitude
        if np.ndim(m) == 0:
            number = f"{float(m):g}" if isinstance(m, numbers.Real) else str(m)
            return f"{number} {value.units}" if not value.dimensionless else number
        arr = np.asarray(m)
        text = np.array2string(arr.ravel()[:4], separator=", ", threshold=4)
        return f"an array {text[:-1]}{', ...]' if arr.size > 4 else ']'} in {value.units}"
    return repr(value)


def _no_comma(text: str, field: str, expected: str, error: type = UnitError) -> None:
    """Refuse a comma in a value's text: pint drops it, so ``"1,5 mm"`` would be 15 mm and ``"1, 5 mm"`` 5 mm."""
    if "," in text:
        raise error(
            f"{field}: cannot read {show_value(text)}: a comma is neither a decimal point nor a thousands "
            f"separator here (write '1.5 mm', '1000 mm'); expected {expected}"
        )


def quantity(value: Any, field: str, dimension: str) -> pint.Quantity:
    """Return ``value`` as a scalar quantity of this registry with ``dimension``.

    Parameters
    ----------
    value : pint.Quantity or str
        The value as given by the user, e.g. ``"60 mm"`` or ``Q_(60, "mm")``.
        Quantities of another registry are converted through their string form.
    field : str
        Name of the field, used in error messages.
    dimension : str
        Expected pint dimensionality, e.g. ``"[length]"``.

    Raises
    ------
    UnitError
        For a bare number, an unparsable string or a wrong dimension.
    InvalidValueError
        For a non-finite magnitude.

    Returns
    -------
    pint.Quantity
        The value, a scalar quantity of :data:`substructure.ureg`, in the units it was given in.
    """
    expected = _describe(dimension)
    if isinstance(value, bool) or isinstance(value, numbers.Number) or isinstance(value, np.ndarray):
        raise UnitError(
            f"{field}: got the bare number {show_value(value)}; expected {expected}, with its unit"
        )
    if isinstance(value, str):
        check_number_text(value, field, expected)
        if not _NUMBER.match(value):  # pint reads "mm" as 1 mm and "a" as 1 year
            raise UnitError(
                f"{field}: cannot read {show_value(value)} as a quantity: it does not start with a number; "
                f"expected {expected}"
            )
        try:
            magnitude, units = _parse(value)
        except Exception as exc:  # pint raises several types for bad strings
            raise UnitError(
                f"{field}: cannot read {show_value(value)} as a quantity ({exc}); expected {expected}"
            ) from None
        if units is not None and units.dimensionless and dimension != "" and units != ureg.dimensionless:
            raise UnitError(  # "20 mil" is an angle in pint (angular mil), "2 %" a ratio
                f"{field}: got {show_value(value)}, whose unit {units} has no dimension (an angle or a ratio); "
                f"expected {expected}" + (" (a thousandth of an inch is 'thou')" if str(units) == "mil" else "")
            )
        if units is None or units.dimensionless and dimension != "":
            raise UnitError(
                f"{field}: got {show_value(value)} without a unit; expected {expected}, with its unit"
            )
        q = ureg.Quantity(magnitude, units)
    elif isinstance(value, pint.Quantity):
        q = value if value._REGISTRY is ureg else ureg.Quantity(str(value))
    else:
        raise UnitError(
            f"{field}: got {show_value(value)} of type {type(value).__name__}; expected {expected}"
        )
    if np.ndim(q.magnitude) != 0:
        raise UnitError(f"{field}: got an array {show_value(value)}; expected a single value")
    _check_angles(q, value, field, dimension, expected)
    if not _has_dimension(q.units, dimension):
        raise UnitError(
            f"{field}: got {show_value(value)} with dimension {q.dimensionality}; expected {expected}"
        )
    if np.iscomplexobj(q.magnitude):
        raise InvalidValueError(f"{field}: got {show_value(value)}; expected a real value")
    try:
        magnitude = float(q.magnitude)
    except (TypeError, ValueError, OverflowError):
        raise InvalidValueError(f"{field}: got {show_value(value)}; expected a real number with its unit") from None
    except OverflowError:  # an integer beyond any float
        magnitude = math.inf
    if not math.isfinite(magnitude):
        raise InvalidValueError(f"{field}: got {show_value(value)}; expected a finite value")
    if not isinstance(q.magnitude, (int, float, np.integer, np.floating)):  # a Fraction, a Decimal: as a float
        q = ureg.Quantity(magnitude, q.units)
    return q


def _check_angles(q: pint.Quantity, value: Any, field: str, dimension: str, expected: str) -> None:
    """Refuse angle units (and other units without a dimension: a percent) that only scale the number: one over
    another (``"12 mm*rad/deg"`` is 687.5 mm), or any in a length (``"12 mm*rad"``); ``"N*m/deg"`` for a
    rotational stiffness is a value, and stays."""
    bare = {name: cast(float, power) for name, power in q.units._units.items() if not ureg.get_dimensionality(name)}
    if not bare or q.units.dimensionless:  # a unit without a dimension alone is judged by the caller
        return
    mixed = any(p > 0 for p in bare.values()) and any(p < 0 for p in bare.values())
    if mixed or dimension == "[length]":
        kept = q.units
        for name, power in bare.items():
            kept = kept / ureg.Unit(name) ** power
        names = " and ".join(sorted(bare))
        its = f"its units {names} have" if len(bare) > 1 else f"its unit {names} has"
        raise UnitError(f"{field}: got {show_value(value)}; {its} no dimension and only scales the number (it is "
                        f"{q.to(kept):~P}); expected {expected}")


def to_si(value: Any, field: str, unit: str) -> float:
    """Check ``value`` and return its magnitude in ``unit`` (an SI unit) as float.

    The dimension expected is that of ``unit``.

    Parameters
    ----------
    value : pint.Quantity or str
        The value as given by the user (``"60 mm"``).
    field : str
        Name of the field, used in error messages.
    unit : str
        The unit to return the magnitude in (``"m"``).

    Returns
    -------
    float
        The magnitude in ``unit``.
    """
    out = magnitude_in(quantity(value, field, _dimension_of(unit)), unit)
    if not math.isfinite(out):  # "1e300 GPa": a finite number whose value in Pa is beyond the floats
        raise InvalidValueError(f"{field}: got {show_value(value)}, which is {out} in {unit}; expected a finite value")
    return out


@functools.lru_cache(maxsize=256)
def _dimension_of(unit: str) -> str:
    return str(ureg.Quantity(1.0, unit).dimensionality)


def whole_number(value: Any, field: str, minimum: int = 0, meaning: str = "a whole number",
                 maximum: int | None = None) -> int:
    """Check a count (a number of lines, steps, teeth, refits): an ``int`` or numpy integer, ``>= minimum``.

    A boolean, a float (even 2.0) or a text is refused: ``True`` passed as 1 and ``2.5`` was cut or failed
    later with a raw ``TypeError``.

    Parameters
    ----------
    value : object
        The value.
    field : str
        Its name in the message (``"bootstrap"``, ``"significance: k"``).
    minimum : int
        The least value allowed.
    meaning : str
        What it is, for the message (``"a whole number of teeth"``).
    maximum : int, optional
        The largest value allowed (a count of refits or samples beyond which the work would never end).

    Returns
    -------
    int
        The value.

    Raises
    ------
    InvalidValueError
        ``"{field}: got {value!r}; expected {meaning} >= {minimum}"``.
    """
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, (int, np.integer)) or value < minimum:
        raise InvalidValueError(f"{field}: got {value!r}; expected {meaning} >= {minimum}")
    if maximum is not None and value > maximum:
        raise InvalidValueError(f"{field}: got {value!r}; expected {meaning} from {minimum} to {maximum:,}")
    return int(value)


def finite_real(value: Any) -> bool:
    """Whether ``value`` is a finite real number (an int, a float, numpy's, a fraction), not a bool, not NaN or
    infinite, and not an integer beyond every float (``10**400``, where ``math.isfinite`` raises ``OverflowError``).

    Parameters
    ----------
    value : object
        The value.

    Returns
    -------
    bool
        True for a finite real number.
    """
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, numbers.Real):
        return False
    try:
        return math.isfinite(value)
    except OverflowError:
        return False


def items_of(value: Any, field: str, what: str) -> list:
    """The items of a sequence given where one is expected, or an error naming ``field`` when ``value`` is a
    text or no sequence at all (a number, None: a scalar quantity says it is iterable and is not).

    Parameters
    ----------
    value : object
        The value given.
    field : str
        Its name in the message.
    what : str
        What the items are, for the message (``"point names"``).

    Returns
    -------
    list
        Its items.
    """
    try:
        if not isinstance(value, (str, bytes)):
            return list(value)
    except TypeError:
        pass
    raise InvalidValueError(f"{field}: got {value!r}; expected a sequence of {what}")


MAX_REPEATS = 10_000
"""The most repetitions of a whole computation (bootstrap refits, samples of a prediction's distribution), in
Python as on the command line: a count beyond every float ran for ever, or asked for gigabytes first."""

MAX_TEETH = 1000
"""The most teeth a cutter is taken to have: slitting saws and large face mills have a few hundred; a million
teeth put the tooth passing frequency in the megahertz and the lobes out of every band, which read as "no limit"."""


def teeth_count(value: Any, field: str = "teeth") -> int:
    """Check a cutter's number of teeth (flutes, inserts): a whole number from 1 to :data:`MAX_TEETH`.

    An ``int``, a numpy integer or a float that is whole (a file's ``4.0``); a boolean or a text is refused.

    Parameters
    ----------
    value : object
        The value.
    field : str
        Its name in the message.

    Returns
    -------
    int
        The number of teeth.

    Raises
    ------
    InvalidValueError
        ``"{field}: got {value!r}; expected a whole number of teeth >= 1 and <= 1000"``.
    """
    whole = isinstance(value, numbers.Integral) or (
        isinstance(value, numbers.Real) and math.isfinite(float(value)) and float(value).is_integer())
    if isinstance(value, (bool, np.bool_)) or not whole or not 1 <= value <= MAX_TEETH:
        raise InvalidValueError(
            f"{field}: got {show_value(value)}; expected a whole number of teeth >= 1 and <= {MAX_TEETH}")
    return int(value)


def dimensionless(value: Any, field: str) -> float:
    """Check a dimensionless value (a plain number or a dimensionless quantity).

    Parameters
    ----------
    value : float or pint.Quantity or str
        The value.
    field : str
        Name of the field, used in error messages.

    Returns
    -------
    float
        The value, finite.
    """
    if isinstance(value, bool):
        raise InvalidValueError(f"{field}: got {show_value(value)}; expected a number")
    if isinstance(value, pint.Quantity):
        if not value.dimensionless:
            raise UnitError(
                f"{field}: got {show_value(value)} with dimension {value.dimensionality}; "
                "expected a dimensionless number"
            )
        value = value.m_as("dimensionless")
    elif isinstance(value, str):
        check_number_text(value, field, "a number", InvalidValueError)
        try:
            q: Any = ureg.Quantity(value)
        except Exception:
            raise InvalidValueError(f"{field}: cannot read {show_value(value)}; expected a number") from None
        return dimensionless(q, field)
    if not isinstance(value, numbers.Real):
        raise InvalidValueError(
            f"{field}: got {show_value(value)} of type {type(value).__name__}; expected a number"
        )
    try:
        value = float(value)
    except OverflowError:  # an integer beyond any float
        raise InvalidValueError(f"{field}: got {show_value(value)}; expected a finite number") from None
    if not math.isfinite(value):
        raise InvalidValueError(f"{field}: got {show_value(value)}; expected a finite number")
    return value


_GRAVITY = re.compile(r"(?<![A-Za-z_0-9])(?:[gG]|gn|g_n)(?![A-Za-z_0-9])")
_POUND = re.compile(r"(?<![A-Za-z_0-9])lbs?(?![A-Za-z_0-9])")
_MIL = re.compile(r"(?<![A-Za-z_0-9])mils?(?![A-Za-z_0-9])")
_IPS = re.compile(r"(?<![A-Za-z_0-9])ips(?![A-Za-z_0-9])")
_POWER = re.compile(r"(?<=[A-Za-z])(-?[0-9]+)(?![0-9.])")  # s2, s-2: an exponent written without ^
_TIMES = re.compile(r"(?<=[A-Za-z0-9])\s*[.\u00b7\u22c5]\s*(?=[A-Za-z])")  # m.s-2, m\u00b7s-2
_SUPERSCRIPTS = str.maketrans("\u207b\u00b9\u00b2\u00b3\u00b5\u03bc", "-123uu")


def bare_unit(cell: str) -> str | None:
    """A unit as a table's cell writes it, without brackets around the whole: ``[Hz]``, ``(m/N)`` (not the
    parentheses of ``(m/s2)/N``); None for an empty cell.

    Parameters
    ----------
    cell : str
        The cell.

    Returns
    -------
    str or None
        The unit's text.
    """
    text = cell.strip()
    if len(text) > 1 and text[0] + text[-1] in ("[]", "()"):
        depth = 0
        for c in text[1:-1]:
            depth += {"(": 1, ")": -1, "[": 1, "]": -1}.get(c, 0)
            if depth < 0:  # the first bracket closes inside: it is not around the whole
                return text
        return text[1:-1].strip() or None
    return text or None


def instrument_unit(text: str) -> pint.Unit:
    """The unit of a channel or axis label as measuring instruments and their programs write it.

    ``g``, ``G`` and ``gn`` (``g_n``) are the standard acceleration of
    gravity (not the gram or the gauss), ``lb`` is the pound-force (not the pound of mass),
    ``mil`` a thousandth of an inch (not the angle) and ``ips`` inches per second:
    the only meanings they have for a sensor, a hammer or an FRF.
    Exponents may be written without ``^`` (``m/s2``, ``m s-2``), as
    superscripts (``m/s\u00b2``, ``m\u00b7s\u207b\u00b2``) or after ``**``; a product with
    ``.`` or ``\u00b7``; micro as ``u``, ``\u00b5`` or ``\u03bc``.

    Parameters
    ----------
    text : str
        The label, e.g. ``"m/s2"``, ``"mV/g"``, ``"(m/s²)/N"``.

    Returns
    -------
    pint.Unit
        The unit, of the package's registry.

    Raises
    ------
    ValueError
        When pint cannot read it (the caller names the field).
    """
    cleaned = _TIMES.sub("*", text.strip().translate(_SUPERSCRIPTS)).replace("**", "^")
    cleaned = _POUND.sub("lbf", _GRAVITY.sub("g0", _POWER.sub(r"^\1", cleaned)))
    cleaned = _IPS.sub("(in/s)", _MIL.sub("thou", cleaned))
    try:
        unit = ureg.Unit(cleaned)
    except Exception:
        raise ValueError(text) from None
    return unit


def format_quantity(q: pint.Quantity) -> str:
    """Format a scalar quantity as a string pint reads back to the same value.

    ``repr`` of the float keeps every digit, so that save/load round-trips
    without loss; integral values are written without a trailing ``.0``.

    Parameters
    ----------
    q : pint.Quantity
        A scalar quantity.

    Returns
    -------
    str
        ``"magnitude unit"`` in the quantity's own unit (``"2.5 mm"``).
    """
    m = q.magnitude
    if isinstance(m, float) and m.is_integer() and abs(m) < 1e15:
        text = str(int(m))
    else:
        text = repr(float(m)) if not isinstance(m, int) else str(m)
    units = f"{q.units:~C}"
    return f"{text} {units}" if units else text


def rpm_to_hz(speed_rpm: float | np.ndarray) -> float | np.ndarray:
    """Revolutions per minute to revolutions per second (Hz): divide by 60.

    An explicit helper on purpose: pint converts ``rpm`` to ``Hz`` as angular
    velocity to frequency, which is off by ``2*pi``.

    Parameters
    ----------
    speed_rpm : float or ndarray
        Speeds in rpm.

    Returns
    -------
    float or ndarray
        The same speeds in revolutions per second (Hz).
    """
    return np.asarray(speed_rpm, dtype=float) / 60.0


def hz_to_rpm(frequency_hz: float | np.ndarray) -> float | np.ndarray:
    """Revolutions per second (Hz) to revolutions per minute: multiply by 60.

    Parameters
    ----------
    frequency_hz : float or ndarray
        Revolutions per second (Hz).

    Returns
    -------
    float or ndarray
        The same speeds in rpm.
    """
    return np.asarray(frequency_hz, dtype=float) * 60.0


def frequency_hz(value: Any, field: str) -> float:
    """A frequency in Hz (cycles per second) from a quantity or a string with its unit.

    The unit says what is counted.  ``Hz``, ``kHz`` and ``1/s`` count cycles
    and are taken as they are.  Angular units count an angle per time and
    are converted by the angle of one cycle, explicitly: ``rad/s`` is divided
    by ``2*pi``, ``deg/s`` by 360, ``rpm`` (revolutions per minute) by 60.
    (pint alone would take ``628.3 rad/s`` as 628.3 Hz and ``6000 rpm`` as
    628.3 Hz, both wrong by ``2*pi``.)

    Parameters
    ----------
    value : pint.Quantity or str
        E.g. ``"20 Hz"``, ``"5 kHz"``, ``"628.3 rad/s"``, ``"6000 rpm"``.
    field : str
        Name of the value in error messages.

    Returns
    -------
    float
        The frequency in Hz.

    Raises
    ------
    UnitError
        For a bare number, a value that is not a frequency, or an angle to a
        power other than one (e.g. ``rad^2/s``).
    """
    return float(cycles_per_second(quantity(value, field, "1 / [time]"), field))


def cycles_per_second(q: pint.Quantity, field: str) -> Any:
    """The magnitude in Hz of a frequency quantity (scalar or array), angular units divided by 2*pi.

    The rule of :func:`frequency_hz` for a quantity already checked to be
    ``1 / [time]``.

    Parameters
    ----------
    q : pint.Quantity
        Of this registry, dimension ``1 / [time]``.
    field : str
        Name of the value in error messages.

    Returns
    -------
    float or numpy.ndarray
        Frequencies in Hz.
    """
    root = q.to_root_units()
    angle = dict(root._units).get("radian", 0)
    if angle == 0:
        return root.magnitude
    if angle == 1:
        return root.magnitude / (2.0 * math.pi)
    raise UnitError(f"{field}: got {show_value(q)}, an angle to the power {angle} per time; expected a frequency")
