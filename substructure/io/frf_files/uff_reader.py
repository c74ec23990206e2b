"""The old place of ``substructure.frf.files.uff_reader``: its names, importable from here as before."""

from __future__ import annotations

from ...frf.files.uff_reader import (  # noqa: F401
    read_uff,
    _LABEL_LINES,
    _RECORD_TYPES,
    _assemble,
    _check_complete,
    _check_records_closed,
    _latin1_labels,
    _parse_record,
)
