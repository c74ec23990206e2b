"""The old place of ``substructure.frf.files.uff_units``: its names, importable from here as before."""

from __future__ import annotations

from ...frf.files.uff_units import (  # noqa: F401
    _DATA_TYPES,
    _FUNCTION_TYPES,
    _NO_LABEL,
    _TIME_EXPONENT,
    _UNREADABLE,
    _a,
    _abscissa_hz,
    _exponents,
    _frf_unit,
    _label,
    _record_quantity,
    _unit_of_label,
    _unit_system,
)
