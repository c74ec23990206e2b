"""MATLAB files (``.mat``, versions 4 to 7): loaded once, their structures opened into named channels.

:func:`load` reads the bytes (``scipy.io.loadmat``; a version 7.3 file, HDF5,
is refused with how to save it again) and :func:`flatten` gives what they
hold.  Two kinds of structure are read:

- **Signal structures** as Simcenter Testlab (LMS) and tools that copy its
  layout export them: a struct with ``x_values`` (``start_value``,
  ``increment``, ``number_of_values``, ``quantity.label``: the axis, in a
  unit of time for a time record, of frequency for a spectrum or an FRF)
  and ``y_values`` (``values``: the samples, a column a channel when the
  export groups channels; ``quantity.label``: the unit;
  ``quantity.unit_transformation``: ``factor`` and ``offset`` that turn the
  stored values into the label's unit), ``function_record.name`` naming the
  channel(s).  Each channel becomes a :class:`Signal` with its axis.
- **Any other struct**: its fields read as variables of dotted names
  (``tap.force``, ``tap.force_unit``, ``tap.fs``), and a struct array of
  taps (``tap(k).force``) as matrices of a tap a column.

The tap records (``io._tap_mat``) and the measured FRFs
(``frf.files.mat_reader``) read through it.
"""

from __future__ import annotations

from typing import Any

import attrs
import numpy as np

from .errors import FileFormatError

MAX_DEPTH = 6
"""How deep structs are opened (a struct in a struct in ...)."""


@attrs.frozen
class Signal:
    """One channel of a signal structure: ``values`` in ``unit`` (the label; None when it is empty), on an axis
    of ``axis`` (``"time"`` in s or ``"frequency"`` in Hz) starting at ``start`` and stepping by ``step``;
    ``where`` is the struct's variable."""

    values: np.ndarray
    unit: str | None
    axis: str
    start: float
    step: float
    where: str


def load(data: bytes, name: str) -> dict:
    """The variables of the bytes of a MATLAB file (structs as dicts, cells as lists), or a FileFormatError."""
    import io

    from scipy import io as sio

    if b"MATLAB 7.3 MAT-file" in data[:128] or data[512:520] == b"\x89HDF\r\n\x1a\n":
        raise FileFormatError(f"{name}: a MATLAB 7.3 file (HDF5), which is not read; save it again as version 7 "
                              "(in MATLAB: save(file, '-v7'); in Python: scipy.io.savemat)")
    try:
        return sio.loadmat(io.BytesIO(data), simplify_cells=True, chars_as_strings=True)
    except Exception as exc:  # scipy raises several kinds for files that are not MATLAB files
        raise FileFormatError(f"{name}: cannot read the MATLAB file ({exc}); expected a .mat file of version 4 "
                              "to 7") from None


def text_value(value: Any) -> str | None:
    """A MATLAB text (a char array, or a cell of one) stripped, else None."""
    if isinstance(value, str):
        return value.strip()
    array = np.asarray(value)
    if array.dtype.kind in "UO" and array.size == 1 and isinstance(array.item(), str):
        return str(array.item()).strip()
    return None


def _number(value: Any, where: str, name: str) -> float:
    try:
        number = float(np.asarray(value, dtype=float).reshape(-1)[0])
    except (TypeError, ValueError, IndexError):
        shown = "empty" if np.size(value) == 0 else f"{value!r}"
        raise FileFormatError(f"{name}: {where} is {shown}; expected a number") from None
    if not np.isfinite(number):
        raise FileFormatError(f"{name}: {where} is {number!r}; expected a finite number")
    return number


def _structs(value: Any) -> list | None:
    """The elements of a struct array (a list, or an array of objects, of dicts), else None."""
    if isinstance(value, np.ndarray) and value.dtype.kind == "O" and value.size:
        value = list(value.reshape(-1))
    if isinstance(value, list) and value and all(isinstance(v, dict) for v in value):
        return value
    return None


def _is_signal(value: Any) -> bool:
    return isinstance(value, dict) and isinstance(value.get("x_values"), dict) \
        and isinstance(value.get("y_values"), dict)


def flatten(content: dict, name: str) -> tuple[dict[str, Any], dict[str, Signal], list[str]]:
    """The variables of a loaded MATLAB file by dotted name, the channels of its signal structures by name,
    and what was passed over (signal structures of no numbers, or whose axis is neither time nor frequency),
    said in words."""
    variables: dict[str, Any] = {}
    signals: dict[str, Signal] = {}
    skipped: list[str] = []

    def visit(key: str, value: Any, depth: int) -> None:
        elements = _structs(value)
        if _is_signal(value):
            _signal(key, value, name, signals, skipped)
        elif elements is not None and all(_is_signal(e) for e in elements):
            for k, element in enumerate(elements):
                _signal(f"{key}({k + 1})", element, name, signals, skipped)
        elif isinstance(value, dict) or elements is not None:
            if depth >= MAX_DEPTH:
                skipped.append(f"{key} (structs nested deeper than {MAX_DEPTH})")
                return
            fields = value if isinstance(value, dict) else _stacked(key, elements or [], name)
            for field, inner in fields.items():
                visit(f"{key}.{field}", inner, depth + 1)
        else:
            variables[key] = value

    for key, value in content.items():
        if not key.startswith("__"):
            visit(key, value, 0)
    return variables, signals, skipped


def _stacked(key: str, elements: list[dict], name: str) -> dict[str, Any]:
    """The fields of a struct array of taps: vectors as a matrix of a tap a column, texts and numbers that are
    the same in every element as one."""
    fields = list(elements[0])
    for k, element in enumerate(elements[1:], start=2):
        if list(element) != fields:
            raise FileFormatError(f"{name}: the struct array {key!r} has fields {fields} in element 1 and "
                                  f"{list(element)} in element {k}; expected the same fields in every tap")
    out: dict[str, Any] = {}
    for field in fields:
        values = [element[field] for element in elements]
        texts = [text_value(v) for v in values]
        arrays = [np.asarray(v) for v in values]
        if all(t is not None for t in texts):
            if len(set(texts)) > 1:
                raise FileFormatError(f"{name}: {key}(k).{field} differs between the taps "
                                      f"({', '.join(map(repr, texts))}); expected one text for every tap")
            out[field] = texts[0]
        elif all(a.dtype.kind in "iuf" and a.ndim == 0 for a in arrays):
            if len({float(a) for a in arrays}) > 1:
                raise FileFormatError(f"{name}: {key}(k).{field} differs between the taps "
                                      f"({', '.join(f'{float(a):g}' for a in arrays)}); expected one value")
            out[field] = arrays[0]
        elif all(a.dtype.kind in "iuf" and a.ndim == 1 for a in arrays):
            lengths = sorted({a.size for a in arrays})
            if len(lengths) > 1:
                raise FileFormatError(f"{name}: {key}(k).{field} holds vectors of {lengths[0]} to {lengths[-1]} "
                                      "samples; expected taps of one length (cut them to a common length)")
            out[field] = np.column_stack(arrays)
        elif all(_structs(v) is not None or isinstance(v, dict) for v in values):
            out[field] = [v for v in values]
        # anything else (cells of text, mixed fields) is not a channel: passed over as loose cells are
    return out


def _label(quantity: Any) -> str | None:
    return text_value(quantity.get("label")) if isinstance(quantity, dict) else None


def _names(record: Any, count: int) -> list[str | None]:
    """The channels' names of ``function_record.name`` (a text, or a cell of a text a channel)."""
    raw = record.get("name") if isinstance(record, dict) else None
    if raw is None:
        return [None] * count
    text = text_value(raw)
    if text is not None:
        return [text or None] + [None] * (count - 1) if count == 1 else [None] * count
    items = list(np.asarray(raw, dtype=object).reshape(-1))
    names = [text_value(item) or None for item in items]
    return names if len(names) == count else [None] * count


def _axis(label: str | None) -> tuple[str, float] | None:
    """``(axis, factor to s or Hz)`` of an axis label (no label: s), None for another unit."""
    from .units import ureg

    try:
        unit = ureg.Quantity(1.0, (label or "s").strip())
    except Exception:  # pint raises its own errors
        return None
    for axis, si in (("time", "s"), ("frequency", "Hz")):
        if unit.is_compatible_with(si):
            return axis, float(unit.m_as(si))
    return None


def _signal(key: str, value: dict, name: str, signals: dict[str, Signal], skipped: list[str]) -> None:
    """The channels of one signal structure (see the module's docstring)."""
    x, y = value["x_values"], value["y_values"]
    values = np.asarray(y.get("values"))
    if values.dtype.kind not in "iufc" or values.size < 2 or values.ndim > 2:
        skipped.append(f"{key} (its y_values.values are not a vector or a matrix of numbers)")
        return
    x_label = _label(x.get("quantity"))
    axis = _axis(x_label)
    if axis is None:
        skipped.append(f"{key} (its axis is in {x_label!r}, neither time nor frequency)")
        return
    if "increment" not in x:
        raise FileFormatError(f"{name}: {key}.x_values has no increment; expected the step of its axis")
    step = _number(x["increment"], f"{key}.x_values.increment", name) * axis[1]
    start = _number(x.get("start_value", 0.0), f"{key}.x_values.start_value", name) * axis[1]
    if step <= 0:
        unit = "s" if axis[0] == "time" else "Hz"
        raise FileFormatError(f"{name}: {key}.x_values.increment is {step!r} {unit}; expected a positive step")
    samples = values.reshape(-1, 1) if values.ndim == 1 else values
    count = x.get("number_of_values")
    n = None if count is None else int(_number(count, f"{key}.x_values.number_of_values", name))
    if n is not None and samples.shape[0] != n and samples.shape[1] == n:
        samples = samples.T  # a channel a row
    if n is not None and samples.shape[0] != n:
        raise FileFormatError(f"{name}: {key}.y_values.values holds {samples.shape[0]} values a channel, "
                              f"{key}.x_values.number_of_values says {n}; the file contradicts itself")
    quantity = y.get("quantity")
    per_channel = _structs(quantity)
    if per_channel is not None and len(per_channel) != samples.shape[1]:
        raise FileFormatError(f"{name}: {key}.y_values.quantity describes {len(per_channel)} channels, "
                              f"y_values.values holds {samples.shape[1]}")
    names = _names(value.get("function_record"), samples.shape[1])
    for j in range(samples.shape[1]):
        q = per_channel[j] if per_channel is not None else quantity
        transform = q.get("unit_transformation") if isinstance(q, dict) else None
        factor, offset = 1.0, 0.0
        if isinstance(transform, dict):
            where = f"{key}.y_values.quantity.unit_transformation"
            factor = _number(transform.get("factor", 1.0), f"{where}.factor", name)
            offset = _number(transform.get("offset", 0.0), f"{where}.offset", name)
            if factor == 0:
                raise FileFormatError(f"{name}: {where}.factor is 0; expected the factor to the label's unit")
        given = names[j]
        channel = given if given and given not in signals else (key if samples.shape[1] == 1 else f"{key}[{j + 1}]")
        column = samples[:, j]
        with np.errstate(invalid="ignore", over="ignore"):  # a value not finite: its reader refuses it by place
            column = column.astype(np.complex128 if column.dtype.kind == "c" else np.float64) * factor + offset
        signals[channel] = Signal(column, _label(q) or None, axis[0], start, step, key)
