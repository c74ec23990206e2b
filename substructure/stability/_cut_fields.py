"""The checks and conversions of a cut's fields: teeth, lengths, cutting coefficients, mode.

:class:`~substructure.stability.MillingCut` and
:class:`~substructure.stability.TurningCut` use them as attrs converters;
each names the field, what was given and what was expected.
"""

from __future__ import annotations

import numbers
from typing import Any

import pint

from ..errors import InvalidValueError, UnitError
from ..units import quantity, show_value, teeth_count

MILLING_MODES = ("up", "down")
MILLING_ALIASES = {"up": "up", "conventional": "up", "down": "down", "climb": "down"}
"""The shop's words for the milling direction: climb milling is down milling, conventional is up milling."""


def _teeth(value: Any) -> int:
    return teeth_count(value)


def _length(field: str):
    def convert(value: Any) -> pint.Quantity:
        q = quantity(value, field, "[length]")
        if q.magnitude <= 0:
            raise InvalidValueError(f"{field}: got {show_value(value)}; expected a positive length")
        return q

    return convert


def _pressure(field: str, allow_zero: bool):
    def convert(value: Any) -> pint.Quantity:
        if isinstance(value, numbers.Real) and not isinstance(value, bool) and field == "kn":
            raise UnitError(
                f"kn: got the bare number {show_value(value)}; kn is the normal (radial) cutting pressure, e.g. "
                "'100 MPa'. For the ratio Kr = Kn/Kt use MillingCut.from_spec(..., kr=0.16)"
            )
        q = quantity(value, field, "[mass] / [length] / [time] ** 2")
        if q.magnitude < 0 or (q.magnitude == 0 and not allow_zero):
            need = ">= 0" if allow_zero else "> 0"
            raise InvalidValueError(f"{field}: got {show_value(value)}; expected a cutting coefficient {need} "
                                    "(a pressure)")
        return q

    return convert


def _edge(field: str):
    def convert(value: Any) -> pint.Quantity:
        q = quantity(value, field, "[mass] / [time] ** 2")
        if not q.magnitude >= 0:
            raise InvalidValueError(f"{field}: got {show_value(value)}; expected an edge force per length >= 0 "
                                    "(e.g. '20 N/mm')")
        return q

    return convert


def _milling(value: Any) -> str:
    key = value.strip().lower() if isinstance(value, str) else value
    if not isinstance(key, str) or key not in MILLING_ALIASES:
        raise InvalidValueError(f"milling: got {show_value(value)}; expected 'down' (climb) or 'up' (conventional)")
    return MILLING_ALIASES[key]
