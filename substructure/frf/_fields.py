"""The checks and conversions of an FRF's fields: labels, complex data, quantity, axis.

:class:`~substructure.frf.FRF` uses them as attrs converters and validators;
each names the field and what was expected when it refuses a value.
"""

from __future__ import annotations

import numbers
import re
from typing import Any, cast

import numpy as np

from ..errors import InvalidValueError, SubstructureError
from ..units import finite_real
from .axis import Frequency, _readonly

QUANTITIES = ("receptance", "mobility", "accelerance")
"""The quantities an FRF may hold: displacement, velocity or acceleration per load."""


_WORD = re.compile(r"^[A-Za-z_][A-Za-z0-9_]*$")


def check_label(field: str, label: str) -> None:
    """Refuse a DOF label that is neither ``POINT:y`` / ``POINT:theta`` nor a plain channel name.

    A label is a point (:func:`substructure.points.parse_point`, e.g.
    ``"tool.tip-5 mm"``) or a plain name (``"a"``) followed by ``:y`` or
    ``:theta`` (conventions.md), or a plain name alone (letters, digits and
    ``_``: a channel or a direction such as ``"x"``, the default
    ``"response"``), or a universal file's ``node2:dir3`` of another
    program's record.  Anything else (``"tool tip"``, a point without its DOF
    ``"tool.tip"``, ``"tool.tip:z"``) would fail far from where it was given.
    """
    from ..points import parse_point

    if _WORD.match(label):
        return
    name, _, dof = label.rpartition(":")
    if name and _WORD.match(name) and re.match(r"^dir-?\d+$", dof):
        return  # a universal file's node and direction code from another program (NODE:dirCODE)
    if name and dof in ("y", "theta"):
        if _WORD.match(name):
            return
        try:
            parse_point(label)
            return
        except SubstructureError:
            pass
    if not name:
        why = "a point without its DOF" if "." in label or "@" in label else "not a point name"
    elif dof not in ("y", "theta"):
        why = f"unknown DOF {dof!r}"
    else:
        why = f"{name!r} is not a point name"
    raise InvalidValueError(f"{field}: got the label {label!r} ({why}); expected 'POINT:y' or 'POINT:theta' "
                            "(e.g. 'tool.tip:y', 'tool.tip-5 mm:theta'), or a plain name of letters, digits and _")


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
            check_label(field, label)
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
    except (TypeError, ValueError, OverflowError):
        raise InvalidValueError(
            f"data: cannot read {type(value).__name__} as complex numbers; "
            "expected an array of shape (n_freq, n_out, n_in)"
        ) from None


def _check_quantity(instance: Any, attribute: Any, value: Any) -> None:
    if not isinstance(value, str) or value not in QUANTITIES:
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
    if not finite_real(value) or value <= 0:
        raise InvalidValueError(f"{field}: got {value!r}; expected the exponential window's time constant in s "
                                "(a finite number > 0)")
    return float(value)
