"""Tap records in NI's TDMS files: :func:`read_tap_tdms` (re-exported by :mod:`substructure.io.tap_files`).

A TDMS file (LabVIEW, FlexLogger, DAQExpress, SignalExpress: the binary
format of NI's acquisition) holds groups of channels, each channel with its
properties: the unit in ``unit_string`` (NI's property; ``NI_UnitDescription``
or ``unit`` are read too) and, for a waveform, the time step in
``wf_increment`` [s] and the first sample's time in ``wf_start_offset``.
DAQmx raw data are read scaled, as the acquisition's scales say.
"""

from __future__ import annotations

import os
from typing import Any

import attrs
import numpy as np

from ..errors import FileFormatError
from ..tap.records import TapRecord
from . import check_readable_file
from ._tap_build import MAX_RECORD_BYTES, build_record, option_rate, time_axis, units_of_columns
from ._tap_columns import Columns, choose, no_rate, unit_label

__all__ = ["read_tap_tdms"]

UNIT_PROPERTIES = ("unit_string", "NI_UnitDescription", "unit", "Unit")
"""The channel properties that give a unit, in the order they are read."""


def read_tap_tdms(path: str | os.PathLike, sensitivity: Any = None, hammer_sensitivity: Any = None,
                  quantity: str | None = None, sample_rate: Any = None, force_column: Any = None,
                  response_column: Any = None) -> list[TapRecord]:
    """Read the tap records of a TDMS file: one record per group that holds a force and a response.

    Parameters
    ----------
    path : str or path-like
        The file (``.tdms``).  In each group the force and the response are
        found by their units (the channel property ``unit_string``: ``N``,
        ``g``, ``m/s^2``, ``mV`` with a sensitivity) or names, as columns of
        a text record are; the time by the channels' ``wf_increment``, or a
        channel in units of time.
    sensitivity, hammer_sensitivity : str or pint.Quantity, optional
        As for :func:`~substructure.io.tap_files.read_tap_csv`
        (``"10.2 mV/g"``, ``"2.25 mV/N"``), for channels in volts.
    quantity : {"acceleration", "velocity", "displacement"}, optional
        What the response is; it must agree with the channel's unit.
    sample_rate : str, pint.Quantity or float, optional
        Samples per second (``"51.2 kHz"``; a plain number in Hz), needed
        when the channels carry no ``wf_increment`` and no time channel;
        checked against them when they do.
    force_column, response_column : int or str, optional
        The channels by name or 1-based index within each group, when their
        units do not tell.

    Returns
    -------
    list of TapRecord
        In SI units, one per group with data (a group of channels per tap,
        as some programs log a test; or one long record of several taps,
        which :func:`~substructure.tap.process_taps` splits); ``source``
        names the file and, for a file of several groups, the group.

    Raises
    ------
    FileFormatError
        Naming the file, the group and the channel: a file that is not
        TDMS, no channel with data, channels of different lengths or time
        steps, no or several candidates for a channel, a unit that is
        missing or contradicts the options, a time step that contradicts
        ``sample_rate``, NaN samples.
    """
    from nptdms import TdmsFile

    name = check_readable_file(path, "tap record", MAX_RECORD_BYTES)
    try:
        tdms = TdmsFile.read(name)
    except Exception as exc:  # npTDMS raises several kinds for a file that is not TDMS
        raise FileFormatError(f"{name}: cannot read the TDMS file ({type(exc).__name__}: {exc}); expected a file "
                              "written by NI's acquisition software (LabVIEW, FlexLogger, DAQExpress)") from None
    groups = [(group.name, [c for c in group.channels() if len(c) > 0]) for group in tdms.groups()]
    groups = [(g, channels) for g, channels in groups if channels]
    if not groups:
        raise FileFormatError(f"{name}: no channel with data; expected a force and a response channel")
    several = len(groups) > 1
    records = []
    for group, channels in groups:
        where = f"{name}, group {group!r}"
        records.append(_group_record(name, where, f"{name} [{group}]" if several else name, channels, sensitivity,
                                     hammer_sensitivity, quantity, sample_rate, force_column, response_column))
    return records


def _unit(channel) -> str | None:
    for key in UNIT_PROPERTIES:
        value = channel.properties.get(key)
        if isinstance(value, str) and unit_label(value):
            return unit_label(value)
    return None


def _step(channel, where: str) -> float:
    value = channel.properties["wf_increment"]
    try:
        step = float(value)
    except (TypeError, ValueError, OverflowError):
        raise FileFormatError(f"{where}: channel {channel.name!r}: wf_increment {value!r}; expected a time step in "
                              "s") from None
    if not (np.isfinite(step) and step > 0):
        raise FileFormatError(f"{where}: channel {channel.name!r}: wf_increment {value!r} s; expected a time step "
                              "> 0")
    return step


def _numeric(channel) -> tuple[np.ndarray, str | None] | None:
    """A channel's samples as floats with its unit; a time stamp channel in s from its first sample; None for
    a channel of text or other data (not a candidate)."""
    values = np.asarray(channel[:])
    if values.dtype.kind == "M":  # time stamps (a logger's clock): seconds from the first
        return (values - values[0]) / np.timedelta64(1, "s"), "s"
    if values.dtype.kind in "biuf":
        return values.astype(np.float64, copy=False), _unit(channel)
    return None


def _group_record(name: str, where: str, source: str, channels: list, sensitivity: Any, hammer_sensitivity: Any,
                  quantity: str | None, sample_rate: Any, force_column: Any, response_column: Any) -> TapRecord:
    read = [(c, _numeric(c)) for c in channels]
    kept = [(c, got) for c, got in read if got is not None]
    if len(kept) < 2:
        raise FileFormatError(f"{where}: {len(kept)} channel{'s' if len(kept) != 1 else ''} of numbers "
                              f"({', '.join(c.name for c in channels)}); expected a force and a response channel")
    channels = [c for c, _ in kept]
    samples = [got[0] for _, got in kept]
    columns = Columns([c.name for c in channels], [got[1] for _, got in kept], None)
    per = {k: _step(c, where) for k, c in enumerate(channels) if "wf_increment" in c.properties}
    parsed, dims, errors = units_of_columns(columns, where)
    t_col, f_col, r_col = choose(columns, parsed, dims, where, force_column, response_column,
                                 bool(per) or sample_rate is not None, rate_hint="the channels' wf_increment property")
    # the time steps of the force and the response (a channel of another rate beside them is not read)
    steps = {per[k] for k in (f_col, r_col) if k in per} if len(set(per.values())) > 1 else set(per.values())
    if len(steps) > 1:
        raise FileFormatError(f"{where}: the channels' time steps (wf_increment) differ: "
                              f"{', '.join(f'{s:.10g}' for s in sorted(steps))} s; expected one sample rate")
    stated = None
    if steps:
        stated = (1.0 / steps.pop(), "the channels' wf_increment")
    if sample_rate is not None:
        hz = option_rate(sample_rate)
        if stated is not None and abs(hz - stated[0]) > 1e-6 * stated[0]:
            raise FileFormatError(f"{where}: wf_increment {1.0 / stated[0]!r} s is {stated[0]:.10g} Hz, "
                                  f"--sample-rate {hz:.10g} Hz; leave the option out or fix the file")
        stated = stated or (hz, "--sample-rate")
    if stated is None and t_col is None:  # the steps are those of channels not read
        raise no_rate(where, columns.labels, "the channels' wf_increment property")
    labels = columns.labels
    for k in (f_col, r_col):
        if columns.units[k] is None:
            raise FileFormatError(f"{where}: channel {labels[k]!r} has no unit; expected its property unit_string "
                                  "(e.g. N, g, m/s^2, mV)")
        if errors[k]:
            raise FileFormatError(f"{where}: {errors[k]} (channel {labels[k]!r})")
    used = [k for k in (t_col, f_col, r_col) if k is not None]
    lengths = {samples[k].size for k in used}
    if len(lengths) > 1:
        raise FileFormatError(f"{where}: channels of {', '.join(str(samples[k].size) for k in used)} samples "
                              f"({', '.join(labels[k] for k in used)}); expected one length")
    for k in used:
        bad = np.flatnonzero(~np.isfinite(samples[k]))
        if bad.size:
            raise FileFormatError(f"{where}: channel {labels[k]!r}, sample {bad[0] + 1} is {samples[k][bad[0]]}; "
                                  "expected a finite number (a gap in the acquisition?)")
    n = lengths.pop()
    time = None if t_col is None else (samples[t_col], parsed[t_col], f"channel {labels[t_col]!r}")
    time_s = time_axis(time, stated, n, where)
    if time is None:
        offset = channels[f_col].properties.get("wf_start_offset", 0.0)
        time_s = time_s + (float(offset) if isinstance(offset, (int, float)) and abs(offset) < 1e6 else 0.0)
    record = build_record(where, time_s, samples[f_col], parsed[f_col], labels[f_col], samples[r_col], parsed[r_col],
                          labels[r_col], sensitivity, hammer_sensitivity, quantity)
    return attrs.evolve(record, source=source)
