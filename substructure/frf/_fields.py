"""The checks and conversions of an FRF's fields: labels, complex data, quantity, axis.

:class:`~substructure.frf.FRF` uses them as attrs converters and validators;
each names the field and what was expected when it refuses a value.
"""

from __future__ import annotations

import math
import numbers
from typing import Any, cast

import numpy as np

from ..errors import InvalidValueError
from .axis import Frequency, _readonly

QUANTITIES = ("receptance", "mobility", "accelerance")
"""The quantities an FRF may hold: displacement, velocity or acceleration per load."""


def _labels(field: str):
    def convert(value: Any) -> tuple[str, ...]:
        if isinstance(value, str):
            value = (value,)
        try:
            labels = tuple(value)
        except TypeError:
            raise InvalidValueError(f"{field}: got {value!r}; expected a sequence of DOF labels") from None
        for label in labels:
            if not isinstance(label, str) or not label.strip() or label != label.strip():
                raise InvalidValueError(
                    f"{field}: got the label {label!r}; expected a non-empty string "
                    "without surrounding spaces, e.g. 'tool.tip:y'"
                )
        if len(set(labels)) != len(labels):
            twice = sorted({x for x in labels if labels.count(x) > 1})
            raise InvalidValueError(f"{field}: the labels {twice} appear more than once")
        if not labels:
            raise InvalidValueError(f"{field}: got no labels; expected at least one")
        return labels

    return convert


def _complex_array(value: Any) -> np.ndarray:
    if (isinstance(value, np.ndarray) and value.dtype == np.complex128 and value.base is None
            and not value.flags.writeable):
        # owned by no other array and read-only: kept as it is (a copy would double the
        # memory of a large FRF); nobody can change it without re-enabling writes on purpose
        return value
    try:
        return _readonly(np.array(value, dtype=np.complex128, copy=True))
    except (TypeError, ValueError):
        raise InvalidValueError(
            f"data: cannot read {type(value).__name__} as complex numbers; "
            "expected an array of shape (n_freq, n_out, n_in)"
        ) from None


def _check_quantity(instance: Any, attribute: Any, value: Any) -> None:
    if value not in QUANTITIES:
        raise InvalidValueError(f"quantity: got {value!r}; expected one of {', '.join(QUANTITIES)}")


def _check_frequency(instance: Any, attribute: Any, value: Any) -> None:
    if not isinstance(value, Frequency):
        raise InvalidValueError(
            f"frequency: got {type(value).__name__}; expected a Frequency, "
            "e.g. Frequency.from_hz(values) or Frequency.from_range('20 Hz', '5000 Hz', '2 Hz')"
        )


def _scalar(value: Any) -> complex | None:
    if isinstance(value, numbers.Number) and not isinstance(value, bool):
        value = complex(cast(Any, value))  # any numbers.Number (Decimal, Fraction, numpy scalars)
        if not np.isfinite(value):
            raise InvalidValueError(f"factor: got {value!r}; expected a finite number")
        return value
    return None


def window_tau(value: Any, field: str = "window_tau") -> float:
    """An exponential window's time constant [s] as a float: a finite number > 0, else an error naming ``field``.

    The one check of ``tau`` for every place that takes it (measurements, FRF files, the noise model, the
    window's removal from fitted modes).
    """
    if isinstance(value, bool) or not isinstance(value, numbers.Real) or not math.isfinite(value) or value <= 0:
        raise InvalidValueError(f"{field}: got {value!r}; expected the exponential window's time constant in s "
                                "(a finite number > 0)")
    return float(value)
