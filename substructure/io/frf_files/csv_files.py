"""The old place of ``substructure.frf.files.csv_files``: its names, importable from here as before."""

from __future__ import annotations

from ...frf.files.csv_files import (  # noqa: F401
    COHERENCE_HEADER,
    CSV_HEADER,
    read_csv,
    read_csv_with_coherence,
    write_csv,
    _checked_csv,
    _read_csv,
)
