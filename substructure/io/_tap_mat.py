"""MATLAB files of tap records (``.mat``, versions 4 to 7 as ``scipy.io.loadmat`` reads them).

A MATLAB file holds numbers without units, so the rules are names: vectors
of samples (the time ``time`` or ``t`` in s unless a unit is given, the
force and the response), their units in text variables ``<name>_unit``
(``force_unit = 'N'``, ``acc_unit = 'g'``), and, without a time vector, the
sample rate in a scalar ``fs``, ``sample_rate``, ``sampling_rate``,
``sampling_frequency`` (Hz) or the step in ``dt`` (s).  A force or response
vector without its unit is refused: nothing says whether it is in N or kN,
m/s^2 or g.  A force and a response matrix of one shape hold several taps, one a
column.  Structs are opened: their fields are variables of dotted names
(``tap.force``), a struct array of taps a matrix, and the signal structures
of Simcenter Testlab exports channels with their own units and clocks
(``substructure._matlab``).  B&K PULSE exports: ``Channel_k_Header.Unit`` is
the unit of ``Channel_k_Data``, and a rate written as text
(``File_Header.SampleFrequency = '25600'``) is read as a number.  Version
7.3 files are HDF5 and refused with how to re-save them.
"""

from __future__ import annotations

import os
import re
from typing import Any

import numpy as np

from ..errors import FileFormatError
from ..tap.records import TapRecord, unit_of
from ._tap_build import build_record, option_rate, time_axis, units_of_columns
from ._tap_columns import Columns, choose
from .._files import file_name
from .._matlab import Signal, flatten, load, text_value

_TIME = re.compile(r"^(time|t|zeit|time_s)$", re.I)
_RATE = re.compile(r"^(fs|sample_?rate|sampling_?rate|sampling_?frequency|sample_?frequency)$", re.I)
_STEP = re.compile(r"^(dt|delta_?t|delta_?x|increment|sample_?interval)$", re.I)
_UNIT_SUFFIX = re.compile(r"^(.+?)_(unit|units|unit_label)$", re.I)
_HEADER_UNIT = re.compile(r"^(.+)_header\.unit$", re.I)  # B&K PULSE: Channel_1_Header.Unit of Channel_1_Data
_TEXT_NUMBER = re.compile(r"^\s*([-+]?(?:\d+(?:[.,]\d*)?|[.,]\d+)(?:[eE][-+]?\d+)?)\s*(\S.*)?$")


def _leaf(key: str) -> str:
    """The last name of a dotted variable (``tap.fs``: ``fs``)."""
    return key.rsplit(".", 1)[-1]


def mat_record(path: str | os.PathLike, data: bytes, sensitivity: Any, hammer_sensitivity: Any,
               quantity: str | None, sample_rate: Any, force_column: Any, response_column: Any) -> list[TapRecord]:
    """The tap records of the bytes of a MATLAB file (see the module's rules); the options as for text records.

    A force and a response that are matrices of the same shape hold a tap a column (samples along the longer
    side, as MATLAB's acquisition functions return them): a record each."""
    name = file_name(path, "MATLAB file")
    content = load(data, name)
    variables, signals, skipped = flatten(content, name)
    frfs = [s.where for s in signals.values() if s.axis == "frequency" and np.iscomplexobj(s.values)]
    for key, signal in list(signals.items()):  # spectra and FRFs beside the time records: no channels
        if signal.axis != "time" or np.iscomplexobj(signal.values):
            what = "complex values" if np.iscomplexobj(signal.values) else f"an axis in {signal.axis}"
            skipped.append(f"{signal.where} ({what}: a spectrum or an FRF, not a time record)")
            del signals[key]
    units: dict[str, str] = {}
    for key, value in variables.items():
        match = _UNIT_SUFFIX.match(key)
        text = text_value(value)
        if match and text is not None:
            units[match.group(1).lower()] = text
        header = _HEADER_UNIT.match(key)
        if header and text:
            units.setdefault(f"{header.group(1)}_data".lower(), text)
    vectors: dict[str, np.ndarray] = {}
    scalars: dict[str, float] = {}
    taps: dict[str, np.ndarray] = {}  # matrices of one channel, a tap a column (samples along the longer side)
    for key, value in variables.items():
        array = np.asarray(value)
        text = text_value(value)
        if text is not None and (_RATE.match(_leaf(key)) or _STEP.match(_leaf(key))):  # '25600', '2,56E+04 Hz'
            number = _TEXT_NUMBER.match(text)
            if number is None:
                raise FileFormatError(f"{name}: variable {key!r} is {text!r}; expected a number")
            if re.fullmatch(r"[-+]?\d{1,3},\d{3}", number.group(1)):  # 25,600: a thousands separator or a decimal?
                if sample_rate is not None:
                    continue  # the option says it
                raise FileFormatError(f"{name}: variable {key!r} is {text!r}: a decimal comma or a thousands "
                                      "separator? Give the rate with --sample-rate")
            scalars[key] = float(number.group(1).replace(",", "."))
            if number.group(2):
                units.setdefault(key.lower(), number.group(2))
            continue
        if array.dtype.kind not in "iuf":
            if array.dtype.kind == "c":
                skipped.append(f"{key} (complex values: a spectrum or an FRF, not a time record)")
            continue
        if array.ndim == 1 and array.size >= 2:
            vectors[key] = array.astype(np.float64)
        elif array.ndim == 2 and min(array.shape) >= 1 and max(array.shape) >= 2:
            taps[key] = (array if array.shape[0] >= array.shape[1] else array.T).astype(np.float64)
            vectors[key] = taps[key][:, 0]
        elif array.ndim == 0:
            scalars[key] = float(array)
    clocked: dict[str, Signal] = {}  # the columns of signal structures, each with its clock
    for key, signal in signals.items():
        if key in vectors:
            key = f"{signal.where}:{key}"
        vectors[key], clocked[key] = signal.values, signal
        if signal.unit is not None:
            units[key.lower()] = signal.unit
    if not vectors:
        passed = f"; passed over: {'; '.join(skipped)}" if skipped else ""
        hint = (f" (the FRF {frfs[0]!r} is read by a measurement set: file = \"{os.path.basename(name)}\")"
                if frfs else "")
        raise FileFormatError(f"{name}: no vector or matrix of real numbers among the variables "
                              f"({', '.join(variables) or 'none'}){passed}; expected time, force and response "
                              f"vectors, or signal structures of a time record{hint}")
    names = list(vectors)
    columns = Columns(names, [units.get(n.lower()) or ("s" if _TIME.match(_leaf(n)) else None) for n in names], None)
    stated = None
    for key, value in scalars.items():
        for pattern, default, to_hz in ((_RATE, "Hz", lambda q: q.m_as("Hz")), (_STEP, "s", lambda q: 1 / q.m_as("s"))):
            if pattern.match(_leaf(key)):
                unit = unit_of(units.get(key.lower(), default), f"{name}: variable {key!r}")
                try:
                    hz = float(to_hz(value * unit))
                except Exception:
                    raise FileFormatError(f"{name}: variable {key!r} in {units.get(key.lower())!r}; expected "
                                          f"{'a rate in Hz' if default == 'Hz' else 'a step in s'}") from None
                if not np.isfinite(hz) or hz <= 0:
                    raise FileFormatError(f"{name}: variable {key!r} is {value!r}; expected a positive sample rate")
                if stated is not None and abs(stated[0] - hz) > 1e-6 * hz:
                    raise FileFormatError(f"{name}: variables {stated[1]!r} and {key!r} give {stated[0]:.10g} Hz and "
                                          f"{hz:.10g} Hz; the file contradicts itself")
                stated = (hz, key)
    if sample_rate is not None:
        hz = option_rate(sample_rate)
        if stated is not None and abs(stated[0] - hz) > 1e-6 * hz:
            raise FileFormatError(f"{name}: variable {stated[1]!r} says {stated[0]:.10g} Hz, --sample-rate "
                                  f"{hz:.10g} Hz; leave the option out or fix the file")
        stated = (hz, "--sample-rate")
    parsed, dims, errors = units_of_columns(columns, name)
    try:
        t_col, f_col, r_col = choose(columns, parsed, dims, name, force_column, response_column,
                                     stated is not None or bool(clocked), "a scalar variable fs (Hz) or dt (s)")
    except FileFormatError as exc:
        if not skipped:
            raise
        raise FileFormatError(f"{exc}; passed over: {'; '.join(skipped)}") from None
    labels = columns.labels
    for signal in (clocked.get(names[k]) for k in (f_col, r_col)):
        if signal is None:
            continue
        hz, where = 1.0 / signal.step, f"{signal.where}.x_values.increment"
        if stated is not None and abs(stated[0] - hz) > 1e-6 * hz:
            fix = ("leave the option out or fix the file" if stated[1] == "--sample-rate" else
                   "the force and the response must be sampled at one rate" if stated[1].endswith(".increment")
                   else "the file contradicts itself")
            raise FileFormatError(f"{name}: {where} says {hz:.10g} Hz, {stated[1]} {stated[0]:.10g} Hz; {fix}")
        stated = (hz, where)
    for k in (t_col, f_col, r_col):
        if k is None:
            continue
        if columns.units[k] is None:
            if names[k] in clocked:
                raise FileFormatError(f"{name}: the signal {names[k]!r} has no unit (its y_values.quantity.label is "
                                      "empty); export it with its unit")
            raise FileFormatError(f"{name}: variable {names[k]!r} has no unit; add a text variable "
                                  f"{names[k]}_unit (e.g. 'N', 'g', 'm/s^2', 'mV') to the file")
        if errors[k]:
            raise FileFormatError(f"{name}: {errors[k]} (variable {names[k] + '_unit'!r})")
        values = taps.get(names[k], vectors[names[k]][:, None])
        bad = ~np.isfinite(values)
        if bad.any():
            j, tap = np.unravel_index(int(np.argmax(bad)), bad.shape)
            where = f", tap {tap + 1}" if values.shape[1] > 1 else ""
            raise FileFormatError(f"{name}: variable {names[k]!r}{where}, sample {j + 1}: {float(values[j, tap])!r}; "
                                  "expected a finite number (a gap in the acquisition?)")
    force, response = (taps.get(names[k], vectors[names[k]][:, None]) for k in (f_col, r_col))
    clock = None if t_col is None else taps.get(names[t_col])
    if clock is not None and np.any(clock != clock[:, :1]):  # a time per tap: one clock for all, or refused
        raise FileFormatError(f"{name}: the time {names[t_col]!r} is a matrix whose columns differ; expected one "
                              "time vector for every tap")
    if force.shape != response.shape:
        raise FileFormatError(f"{name}: the force {names[f_col]!r} holds {force.shape[1]} tap(s) of {force.shape[0]} "
                              f"samples, the response {names[r_col]!r} {response.shape[1]} of {response.shape[0]}; "
                              "expected a response for every tap (a tap a column)")
    time = None if t_col is None else (vectors[names[t_col]], parsed[t_col], f"the time vector {names[t_col]!r}")
    time_s = time_axis(time, stated, force.shape[0], name)
    several = force.shape[1] > 1
    return [build_record(f"{name} (tap {k + 1})" if several else name, time_s, force[:, k], parsed[f_col],
                         labels[f_col], response[:, k], parsed[r_col], labels[r_col], sensitivity, hammer_sensitivity,
                         quantity) for k in range(force.shape[1])]
