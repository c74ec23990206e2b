"""What the FRF file formats share: the checks of an FRF to write and the UFF codes.

An FRF to be written must be an :class:`~substructure.frf.FRF` and not all
zeros; the UFF direction codes (``y`` -> 2, ``theta`` -> 6), the specific
data types of the quantities and the ID line of the exact grid are the same
for the writer and the reader.
"""

from __future__ import annotations

import re
from typing import Any

import numpy as np

from ...errors import InvalidValueError
from ...frf import FRF

_DIRECTION = {"y": 2, "theta": 6}  # UFF direction codes: +Y translation, +Z rotation
_DIRECTION_NAME = {2: "y", 6: "theta"}
_SPEC_TYPE = {"receptance": 8, "mobility": 11, "accelerance": 12}  # displacement, velocity, acceleration
_GRID_LINE = re.compile(r"^grid start=(\S+) step=(\S+) n=(\d+)$")


def _require_frf(frf: Any, function: str) -> FRF:
    if not isinstance(frf, FRF):
        raise InvalidValueError(f"frf: {function} got {type(frf).__name__}; expected an FRF")
    return frf


def _refuse_all_zero(frf: FRF, name: str) -> None:
    """Readers take an FRF that is 0 at every line for a dead channel: such a file is not written."""
    dead = ~np.any(frf.data, axis=0)
    if dead.any():
        i, j = np.argwhere(dead)[0]
        raise InvalidValueError(
            f"frf: cannot write {name}: the entry ({frf.outputs[i]!r}, {frf.inputs[j]!r}) is 0 at every line, "
            "which readers refuse as a dead channel"
        )

