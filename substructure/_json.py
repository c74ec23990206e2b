"""Strict JSON: plain data with every NaN and infinity made ``null`` and numpy values made Python's.

The one converter of the package's JSON output (``--json``, the result files of a study,
``Diagnosis.to_json``): JSON has no NaN or Infinity, so what :func:`strict` gives always dumps
with ``allow_nan=False``.  numpy is imported when a value is converted, so that the command
line's parser stays light.
"""

from __future__ import annotations

import json
import math
import os
from typing import Any


def strict(value: Any) -> Any:
    """``value`` made of JSON types only: NaN and infinities become ``null``, numpy values plain ones."""
    import numpy as np

    if isinstance(value, dict):
        return {str(k): strict(v) for k, v in value.items()}
    if isinstance(value, np.ndarray):
        value = value.tolist()
    if isinstance(value, (list, tuple)):
        if all(type(v) is float for v in value):  # a long list of numbers (an FRF): one pass
            return [v if math.isfinite(v) else None for v in value]
        return [strict(v) for v in value]
    if isinstance(value, (bool, np.bool_)):
        return bool(value)
    if isinstance(value, (int, np.integer)):
        return int(value)
    if isinstance(value, (float, np.floating)):
        value = float(value)
        return value if math.isfinite(value) else None
    if isinstance(value, complex):
        raise TypeError(f"JSON output: a complex number {value!r}; give real and imaginary parts")
    if value is None or isinstance(value, str):
        return value
    if isinstance(value, os.PathLike):
        return os.fspath(value)
    raise TypeError(f"JSON output: a {type(value).__name__} is not a JSON value")


def finite(x: Any) -> float | None:
    """``x`` as a float, or None for None, NaN and infinities (a number of strict JSON)."""
    if x is None:
        return None
    x = float(x)
    return x if math.isfinite(x) else None


def json_text(value: Any) -> str:
    """Strict JSON of ``value`` (:func:`strict`): never ``NaN`` or ``Infinity``, which JSON does not have; floats
    keep every digit."""
    return json.dumps(strict(value), allow_nan=False)
