"""The old place of ``substructure.frf.files.exports``: its names, importable from here as before."""

from __future__ import annotations

from ...frf.files.exports import (  # noqa: F401
    parse_export,
    _HEADER,
    _NAMES,
    _TIME_EXPONENT,
    _column,
    _value_unit,
)
