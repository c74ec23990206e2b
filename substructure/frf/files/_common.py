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

from ...errors import FileFormatError, InvalidValueError

# The FRF class, registered by substructure.frf.response when it is defined: these modules read
# and write FRFs (FRF.to_csv, FRF.from_uff use them) and so cannot import the module that
# imports them.  Importing any of them imports substructure.frf first, which registers it.
_FRF_CLASS: list[type] = []


def register_frf_class(cls: type) -> None:
    """Register the class files are read into (called once, by ``frf.response``)."""
    _FRF_CLASS[:] = [cls]


def frf_class() -> Any:
    """The FRF class (:class:`substructure.frf.FRF`)."""
    return _FRF_CLASS[0]


_DIRECTION = {"y": 2, "theta": 6}  # UFF direction codes: +Y translation, +Z rotation
_DIRECTION_NAME = {2: "y", 6: "theta"}
_SPEC_TYPE = {"receptance": 8, "mobility": 11, "accelerance": 12}  # displacement, velocity, acceleration
_GRID_LINE = re.compile(r"^grid start=(\S+) step=(\S+) n=(\d+)$")


RECEPTANCE_LIMIT = 1.0
"""The largest receptance magnitude a measured FRF may have, in SI units (1 m/N, 1 rad/(N m), ...).

A machine tool, a bench or any structure a tap test is made on moves far
less than a metre per newton; a larger value is a wrong unit, a wrong
calibration or garbage, and its square overflows in the noise estimate.
Mobilities and accelerances are divided by ``2 pi f`` once or twice first
(lines at 0 Hz are checked for finiteness only)."""


def _beyond_physical(hz: np.ndarray, values: np.ndarray, quantity: str) -> tuple[int, str] | None:
    """The first line whose value is not finite or exceeds :data:`RECEPTANCE_LIMIT`, and what is wrong.

    ``values`` may be ``(n,)`` or ``(n, ...)``, frequency first.
    """
    power = {"receptance": 0, "mobility": 1, "accelerance": 2}.get(quantity, 0)
    with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
        magnitude = np.abs(values).reshape(len(hz), -1).max(axis=1)
        omega = 2 * np.pi * np.asarray(hz, dtype=np.float64)
        receptance = magnitude / omega**power if power else magnitude
        bad = ~np.isfinite(magnitude) | (np.isfinite(receptance) & (receptance > RECEPTANCE_LIMIT))
    if not bad.any():
        return None
    k = int(np.argmax(bad))
    if not np.isfinite(magnitude[k]):
        return k, "its magnitude overflows (is not a finite number)"
    what = "" if not power else f" as a receptance ({magnitude[k]:.3g} / (2 pi f){'^2' if power == 2 else ''})"
    unit = ("a wrong unit (an accelerance or a mobility without its units is read as a receptance: give them, "
            "e.g. `real [m/(N s^2)]`)" if not power else "a wrong unit")
    return k, (f"|H| is {receptance[k]:.3g}{what} in SI units (m/N), more than {RECEPTANCE_LIMIT:g} m/N: no "
               f"structure moves that much; {unit} or a broken export?")


def _shown(text: str, limit: int = 60) -> str:
    """``repr`` of a cell or a line for a message, cut after ``limit`` characters (a line may be megabytes)."""
    text = str(text)
    return repr(text) if len(text) <= limit else f"{text[:limit]!r}... ({len(text):,} characters)"


def _require_frf(frf: Any, function: str) -> Any:
    if not isinstance(frf, frf_class()):
        raise InvalidValueError(f"frf: {function} got {type(frf).__name__}; expected an FRF")
    return frf


def coherence_checked(values: np.ndarray, where: str, shown: np.ndarray | None = None) -> np.ndarray:
    """A coherence read from a file: each value finite and in [0, 1] (rounding above 1 clipped), else a
    ``FileFormatError`` naming ``where`` and the first bad value (as ``shown`` holds it, default ``values``)."""
    bad = ~(np.isfinite(values) & (values >= 0.0) & (values <= 1.0 + 1e-6))
    if bad.any():
        k = int(np.argmax(bad))
        value = np.asarray(values if shown is None else shown)[k].item()  # a Python number: 1.2, not np.float64(1.2)
        raise FileFormatError(f"{where}: value {k + 1} is {value!r}; expected a coherence in [0, 1]")
    return np.minimum(values, 1.0)


def _refuse_all_zero(frf: Any, name: str) -> None:
    """Readers take an FRF that is 0 at every line for a dead channel: such a file is not written."""
    dead = ~np.any(frf.data, axis=0)
    if dead.any():
        i, j = np.argwhere(dead)[0]
        raise InvalidValueError(
            f"frf: cannot write {name}: the entry ({frf.outputs[i]!r}, {frf.inputs[j]!r}) is 0 at every line, "
            "which readers refuse as a dead channel"
        )



class QuantityContradiction(FileFormatError):
    """A file whose header's units say another quantity than the one the caller gave (a ``FileFormatError``)."""


def _contradiction(name: str, line: int, said: str, quantity: str) -> QuantityContradiction:
    """The error for a header whose units say ``said`` where the caller gave ``quantity``."""
    article = "an" if said[0] in "aeiou" else "a"
    return QuantityContradiction(f"{name}, line {line}: the header's units are those of {article} {said}, but the "
                                 f"quantity given is {quantity}")
