"""The old place of ``substructure.frf.files.uff_writer``: its names, importable from here as before."""

from __future__ import annotations

from ...frf.files.uff_writer import (  # noqa: F401
    write_uff,
    _exact_uniform,
    _split_label,
    _uff_grid,
)
