"""The columns of a joint-parameter table: parameter units, column headers, values with units.

:data:`PARAMETER_UNITS` gives the SI unit of each joint parameter; the
checks here read a column's header (``NAME [unit]``), make sure a parameter's
unit has its dimension, that the direct terms are positive or non-negative,
sizes (features that are lengths) positive, every value finite and no row
there twice, and convert a value with a unit into the column's
unit.  :class:`~substructure.surrogate.JointTable` uses them when it is
built, read and appended to.
"""

from __future__ import annotations

import math
import re
from typing import Any, Mapping

import numpy as np
import pint

from ..errors import InvalidValueError, UnitError
from ..units import check_number_text, ureg

__all__ = ["PARAMETER_UNITS"]

PARAMETER_UNITS = {
    "k_yf": "N/m", "k_ym": "N", "k_tf": "N/rad", "k_tm": "N*m/rad",
    "c_yf": "N*s/m", "c_ym": "N*s", "c_tf": "N*s/rad", "c_tm": "N*m*s/rad",
}
"""The SI unit of each joint parameter (conventions.md, Joints)."""

def in_si(name: str, unit: str) -> tuple[float, str]:
    """``(factor, unit)``: a joint parameter's values in ``unit`` times ``factor`` are in its SI unit
    (``PARAMETER_UNITS``); a parameter of another name stays in its unit (factor 1)."""
    si = PARAMETER_UNITS.get(name)
    if si is None or unit == si:
        return 1.0, unit
    return float(ureg.Quantity(1.0, unit).m_as(si)), si


_HEADER = re.compile(r"^\s*([A-Za-z_][A-Za-z0-9_]*)\s*(?:\[(.*)\])?\s*$")

_DIRECT = ("k_yf", "k_tm", "c_yf", "c_tm")
"""Direct terms of the joint matrices (conventions.md): positive stiffness, non-negative damping.
The cross terms (``_ym``, ``_tf``) may have either sign."""

_WHAT = {"k": "a stiffness", "c": "a damping"}


def _dimension(unit: str) -> str:
    return str(ureg.Quantity(1.0, unit).dimensionality)


def _check_unit(unit: str, field: str) -> str:
    try:
        q = ureg.Quantity(1.0, unit)
    except Exception:
        raise UnitError(f"{field}: cannot read the unit {unit!r}") from None
    if not isinstance(q, pint.Quantity):
        raise UnitError(f"{field}: cannot read the unit {unit!r}")
    return unit


def _check_parameter_unit(name: str, unit: str, field: str) -> str:
    """A parameter's unit, which must have the dimension of its SI unit when it is a joint parameter."""
    _check_unit(unit, field)
    si = PARAMETER_UNITS.get(name[:-4] if name.endswith("_std") else name)
    if si is not None and _dimension(unit) != _dimension(si):
        raise UnitError(
            f"{field}: the unit {unit!r} ({_dimension(unit)}) is not one of {_WHAT[name[0]]} {name[:4]} "
            f"(in {si}, {_dimension(si)})"
        )
    return unit


def _check_columns(parameters: Mapping[str, str], features: Mapping[str, str | None],
                   columns: Mapping[str, Any], locate, error=InvalidValueError) -> None:
    """Values a joint table may hold: finite numbers, positive direct stiffness, non-negative damping and std,
    positive sizes, no row twice.

    ``locate(i)`` names row ``i`` (0-based) in messages; ``error`` is the class raised.
    """
    both = sorted(set(parameters) & set(features))
    if both:
        raise error(f"joint table: {', '.join(both)} is both a parameter and a feature")
    for name in parameters:
        values = np.asarray(columns[name], dtype=float)
        bad = ~np.isfinite(values)
        if bad.any():
            i = int(np.argmax(bad))
            raise error(f"{locate(i)}: {name} is {values[i]}; expected a finite value")
        if name in _DIRECT:
            wrong = values <= 0 if name.startswith("k") else values < 0
            if wrong.any():
                i = int(np.argmax(wrong))
                expected = "a positive stiffness" if name.startswith("k") else "a damping >= 0"
                raise error(f"{locate(i)}: {name} is {values[i]:g} {parameters[name]}; expected {expected} "
                            "(a direct term of the joint matrix)")
        std_name = name + "_std"
        if std_name in columns:
            stds = np.asarray(columns[std_name], dtype=float)
            wrong = np.isinf(stds) | (stds < 0)
            if wrong.any():
                i = int(np.argmax(wrong))
                raise error(f"{locate(i)}: {std_name} is {stds[i]:g}; expected a standard deviation >= 0 "
                            "(or an empty cell when it is unknown)")
    for name, unit in features.items():
        if unit is None:
            for i, value in enumerate(columns[name]):
                if not isinstance(value, str) or not value.strip():
                    raise error(f"{locate(i)}: {name} is {value!r}; expected a name (a categorical feature)")
            continue
        values = np.asarray(columns[name], dtype=float)
        bad = ~np.isfinite(values)
        if bad.any():
            i = int(np.argmax(bad))
            raise error(f"{locate(i)}: {name} is {values[i]}; expected a finite value")
        if _is_size(unit):
            wrong = values <= 0
            if wrong.any():
                i = int(np.argmax(wrong))
                raise error(f"{locate(i)}: {name} is {values[i]:g} {unit}; expected a size > 0 ({name} is a length)")
    _check_duplicates(parameters, features, columns, locate, error)


def _check_duplicates(parameters: Mapping[str, str], features: Mapping[str, str | None],
                      columns: Mapping[str, Any], locate, error=InvalidValueError) -> None:
    """Refuse two rows equal in every feature and parameter: the same test listed twice.

    Such copies would count as independent tests and make the surrogate (and
    its cross-validation) more certain than one test allows.  Rows with the
    same features but other measured values are repeated tests, and stay.
    """
    names = [*features, *parameters]
    if not names:
        return
    first: dict[tuple, int] = {}
    for i, key in enumerate(zip(*(np.asarray(columns[n]).tolist() for n in names))):
        if key in first:
            j = first[key]
            raise error(f"{locate(i)}: the same joint as {locate(j).rsplit(', ', 1)[-1]} in every feature and "
                        f"parameter ({', '.join(names)}): the same test listed twice; keep it once (a repeated "
                        "test has its own measured values)")
        first[key] = i


def _is_size(unit: str | None) -> bool:
    """Whether a feature in ``unit`` is a size (a length: a diameter, a gauge length), which must be positive."""
    return unit is not None and _dimension(unit) == "[length]"


def _to_unit(value: Any, unit: str, field: str) -> float:
    """``value`` (a quantity or a string with a unit) as a float in ``unit``."""
    if isinstance(value, bool) or isinstance(value, (int, float, np.number)):
        raise UnitError(f"{field}: got the bare number {value!r}; expected a value with a unit like {unit!r}")
    if isinstance(value, str):
        check_number_text(value, field, f"a value with a unit like {unit!r}")  # pint reads "12,5 mm" as 125 mm
        try:
            q = ureg.Quantity(value)
        except Exception:
            raise UnitError(f"{field}: cannot read {value!r} as a quantity; expected a unit like {unit!r}") from None
        if not isinstance(q, pint.Quantity) or q.dimensionless and not ureg.Quantity(1.0, unit).dimensionless:
            raise UnitError(f"{field}: got {value!r} without a unit; the table gives {field} in {unit}")
    elif isinstance(value, pint.Quantity):
        q = value if value._REGISTRY is ureg else ureg.Quantity(str(value))
    else:
        raise UnitError(f"{field}: got {value!r}; expected a value with a unit like {unit!r}")
    if not q.check(_dimension(unit)):
        raise UnitError(
            f"{field}: got {value!r} ({q.dimensionality}); the table gives {field} in {unit} "
            f"({_dimension(unit)}), units that do not match"
        )
    out = float(q.m_as(unit))
    if not math.isfinite(out):
        raise InvalidValueError(f"{field}: got {value!r}; expected a finite value")
    return out


