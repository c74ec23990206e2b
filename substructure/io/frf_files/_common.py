"""The old place of ``substructure.frf.files._common``: its names, importable from here as before."""

from __future__ import annotations

from ...frf.files._common import (  # noqa: F401
    RECEPTANCE_LIMIT,
    frf_class,
    register_frf_class,
    _DIRECTION,
    _DIRECTION_NAME,
    _FRF_CLASS,
    _GRID_LINE,
    _SPEC_TYPE,
    _beyond_physical,
    _refuse_all_zero,
    _require_frf,
    _shown,
)
