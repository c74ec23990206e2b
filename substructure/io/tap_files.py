"""Files of tap records: :func:`read_tap_csv` and :func:`read_tap_uff` give :class:`~substructure.tap.TapRecord`.

CSV (docs/file-formats.md, "Tap records"): a header naming every column
with its unit in brackets, ``time [s],force [N],acceleration [m/s^2]``; the
time column is the one in units of time, the force the one in units of
force (or the one named ``force`` or ``hammer``), the response the other
one.  Comment lines start with ``#``.  Channels in ``mV`` or ``V`` need the
sensor's sensitivity.

UFF: type-58 records of function type 1 (time response), abscissa in s; the
force is the record whose ordinate is an excitation force (specific data
type 13) or whose unit label is a force, the response the record of
displacement, velocity or acceleration (types 8, 11, 12) or whose unit
label says so; ``force_record`` and ``response_record`` choose them by index
when a file holds more; :func:`read_tap_uff` and :func:`read_taps_uff`, in
``_tap_uff``.

TDMS (NI's acquisition): channels found by their ``unit_string`` as columns
are, the time step from ``wf_increment``; :func:`read_tap_tdms`, in
``_tap_tdms``.

MATLAB: vectors with ``<name>_unit`` texts, structs and struct arrays of
taps, Simcenter Testlab signal structures; :func:`read_tap_mat` and
:func:`read_taps_mat`, in ``_tap_mat`` and ``_tap_mat_structs``.
"""

from __future__ import annotations

import os
import warnings
from typing import Any

import numpy as np

from .._files import decode_text, file_name
from ..errors import FileFormatError, SubstructureWarning
from ..tap.records import TapRecord
from ..units import bare_unit
from . import read_bytes
from ._tap_columns import (MAX_PREAMBLE_LINES, NO_UNIT, Columns, choose, header_cells, is_row, is_unit_row,
                           line_separator, name_and_unit, rate_from_lines)
from ._tap_build import (MAX_RECORD_BYTES, ROUNDED_TIME_TOLERANCE, build_record, option_rate, time_axis,
                         units_of_columns)
from ._tap_table import finite_rows, parse_rows
from ._tap_tdms import read_tap_tdms
from ._tap_uff import read_tap_uff, read_taps_uff

__all__ = ["read_tap_csv", "read_tap_lvm", "read_tap_mat", "read_taps_mat", "read_tap_tdms", "read_tap_uff",
           "read_taps_uff",
           "MAX_RECORD_BYTES", "ROUNDED_TIME_TOLERANCE"]


def read_tap_csv(path: str | os.PathLike, sensitivity: Any = None, hammer_sensitivity: Any = None,
                 quantity: str | None = None, sample_rate: Any = None, force_column: Any = None,
                 response_column: Any = None) -> TapRecord:
    """Read a CSV or text file of one tap record (or a long record of several taps).

    Parameters
    ----------
    path : str or path-like
        The file: header ``time [s],force [N],acceleration [m/s^2]`` (units
        in brackets, in parentheses ``time (s)``, ``Force/N``, ``Force in
        N``, or in a row of their own under the names; columns separated by
        commas, or by semicolons or tabs with decimal commas allowed in the
        cells, or by whitespace; the response may be ``[g]``, velocity
        ``[m/s]``, ``[mm/s]``, displacement ``[m]``, ``[um]``, or a
        voltage).  Metadata lines may stand before the header (the header is
        the last line above the first row of numbers); without a time
        column, the sample rate comes from such a line (``Sample rate: 51200
        Hz``, ``dt: 1.953125e-05 s``) or from ``sample_rate``.
    sensitivity : str or pint.Quantity, optional
        The response sensor's sensitivity, e.g. ``"10.2 mV/g"``: required
        for a response column in ``mV`` or ``V``, refused otherwise.
    hammer_sensitivity : str or pint.Quantity, optional
        The hammer's, e.g. ``"2.25 mV/N"``, for a force column in volts.
    quantity : {"acceleration", "velocity", "displacement"}, optional
        What the response is; it must agree with the column's unit.
    sample_rate : str, pint.Quantity or float, optional
        Samples per second, e.g. ``"51.2 kHz"`` (a plain number is in Hz):
        for a file without a time column; when the file states a rate or
        has a time column too, they must agree.
    force_column, response_column : int or str, optional
        The force and response columns by name or 1-based index, for files
        of more than one candidate (a second response channel, a trigger).

    Returns
    -------
    TapRecord
        In SI units; ``source`` is the file name.

    Raises
    ------
    FileFormatError
        Naming the file, the line and the column: an empty file, a column
        without a unit, columns that are not one time (or a sample rate),
        one force and one response, a cell that is not a number, NaN
        samples, a contradiction between the header and the options.
    """
    name = file_name(path, "tap record")
    data = _text_bytes(path, name)
    head, start, first_line = _head(data, name)
    row_end = data.find(b"\n", start)
    row = data[start:len(data) if row_end < 0 else row_end].decode("utf-8", "replace").rstrip("\r")
    sep = line_separator(row)
    decimal_comma = sep in ("\t", ";")
    ncols = len([c for c in (row.split() if sep is None else row.split(sep))]) - \
        (1 if sep is not None and len(row.split(sep)) > 1 and not row.split(sep)[-1].strip() else 0)
    content = [(n, t) for n, t in head if t.strip() and not t.lstrip().startswith("#")]
    if not content:
        # a header written as a comment, as numpy.savetxt(header=...) writes it ('# time(s) force(N) ...')
        last = [(n, t) for n, t in head if t.strip()][-1:]
        found = _comment_header(last[0][1], sep, ncols) if last and last[0][1].lstrip().startswith("#") else None
        if found is None:
            raise FileFormatError(f"{name}, line {first_line}: numbers with no header above them; expected a header "
                                  "naming each column, e.g. 'time [s],force [N],acceleration [m/s^2]'")
        content = [(last[0][0], sep.join(found) if sep is not None else "  ".join(found))]
    h_line, h_text = content[-1]
    cells = header_cells(h_text.lstrip("\ufeff"), sep, ncols)
    above = header_cells(content[-2][1].lstrip("\ufeff"), sep, ncols) if len(content) > 1 and is_unit_row(cells) \
        else None
    if above is not None and len(above) == len(cells) and all(name_and_unit(c)[1] is None for c in above):
        columns = Columns(above, [None if (bare_unit(c) or "").lower() in NO_UNIT else bare_unit(c)
                                 for c in cells], content[-2][0])
    else:
        pairs = [name_and_unit(c) for c in cells]
        columns = Columns([n for n, _ in pairs], [u for _, u in pairs], h_line)
    if len(columns.names) != ncols:
        raise FileFormatError(f"{name}, line {columns.line}: the header names {len(columns.names)} columns "
                              f"({', '.join(columns.labels)}), the first row (line {first_line}) has {ncols} values")
    rate = _stated_rate([(n, t.lstrip("#")) for n, t in head if n < columns.line], name, decimal_comma, sample_rate)
    parsed, dims, errors = units_of_columns(columns, name)
    t_col, f_col, r_col = choose(columns, parsed, dims, name, force_column, response_column, rate is not None)
    labels = columns.labels
    used = [k for k in (t_col, f_col, r_col) if k is not None]
    for k in used:
        if columns.units[k] is None:
            raise FileFormatError(f"{name}, line {columns.line}: column {k + 1} {columns.names[k]!r} has no unit in "
                                  "brackets; expected e.g. 'time [s]', 'force [N]', 'acceleration [m/s^2]' "
                                  "(separated by commas, semicolons or tabs; or the units in a row under the names)")
        if errors[k]:
            raise FileFormatError(f"{name}, line {columns.line}: {errors[k]} (column {labels[k]!r})")
    table = parse_rows(data, first_line, ncols, sep, decimal_comma, labels, name, start)
    finite_rows(table[:, used], first_line, [labels[k] for k in used], name, data, start)
    time = None if t_col is None else (table[:, t_col], parsed[t_col], f"the time column {labels[t_col]!r}")
    time_s = time_axis(time, rate, table.shape[0], name)
    return build_record(name, time_s, table[:, f_col], parsed[f_col], labels[f_col], table[:, r_col],
                        parsed[r_col], labels[r_col], sensitivity, hammer_sensitivity, quantity)


def _comment_header(line: str, sep: str | None, ncols: int) -> list[str] | None:
    """The cells of a comment line that names every column with its unit (None when it does not)."""
    body = line.strip().lstrip("#").strip()
    for split in dict.fromkeys((sep, ",", ";", "\t", None)):
        cells = [c.strip().rstrip(",;").strip().strip('"') for c in header_cells(body, split, ncols)]
        cells = [c for c in cells if c]
        if len(cells) == ncols and all(name_and_unit(c)[1] is not None for c in cells):
            return cells
    return None


def _text_bytes(path: str | os.PathLike, name: str) -> bytes:
    """The bytes of a text record: UTF-16 re-encoded as UTF-8, a UTF-8 byte-order mark dropped, lines ended by a
    carriage return alone (as Excel for Mac's "CSV (Macintosh)" writes them) ended by a line feed."""
    data = read_bytes(path, "tap record", MAX_RECORD_BYTES)
    if data[:2] in (b"\xff\xfe", b"\xfe\xff"):
        data = decode_text(data, name).encode("utf-8")
    elif data[:3] == b"\xef\xbb\xbf":
        data = data[3:]
    return data.replace(b"\r", b"\n") if b"\r" in data and b"\n" not in data else data


def _windows_text(line: bytes, name: str, number: int, pos: int, bad: int) -> str:
    """A header line that is not UTF-8, read as Windows-1252 with a warning (what the acquisition programs of
    Windows write: ``m/s²``, ``°C``), or refused when it is not that either."""
    try:
        text = line.decode("cp1252").rstrip("\r")
    except UnicodeDecodeError:
        raise FileFormatError(f"{name}, line {number}: not UTF-8 text (byte {pos + bad}: {line[bad:bad + 1]!r}); "
                              "save the file as UTF-8") from None
    warnings.warn(f"{name}, line {number}: not UTF-8; read as Windows-1252, the text of Windows programs "
                  f"({text.strip()[:80]!r}); save the file as UTF-8 to be sure", SubstructureWarning, stacklevel=3)
    return text


def _head(data: bytes, name: str) -> tuple[list[tuple[int, str]], int, int]:
    """The lines above the first row of numbers, the byte offset of that row and its line number."""
    head: list[tuple[int, str]] = []
    pos, number = 0, 0
    not_first: tuple[int, str] | None = None
    while pos < len(data):
        end = data.find(b"\n", pos)
        end = len(data) if end < 0 else end
        number += 1
        try:
            text = data[pos:end].decode("utf-8").rstrip("\r")
        except UnicodeDecodeError as exc:
            text = _windows_text(data[pos:end], name, number, pos, exc.start)
        stripped = text.strip()
        if stripped and not stripped.startswith("#") and is_row(text):
            return head, pos, number
        if stripped and not stripped.startswith("#") and not_first is None and is_row(text, first=False):
            not_first = number, text  # numbers after a first cell that is not one: a clock time, a date?
        head.append((number, text))
        if number >= MAX_PREAMBLE_LINES:
            break
        pos = end + 1
    if not any(t.strip() and not t.lstrip().startswith("#") for _, t in head):
        raise FileFormatError(f"{name}: the file is empty; expected a header such as "
                              "'time [s],force [N],acceleration [m/s^2]' and one row per sample")
    if not_first is not None:
        sep = line_separator(not_first[1])
        cell = (not_first[1].split() if sep is None else not_first[1].split(sep))[0].strip()
        raise FileFormatError(f"{name}, line {not_first[0]}: the first cell {cell!r} is not a number (a clock time "
                              "or a date?); expected rows of numbers: a time in s, or no time column and the sample "
                              "rate (--sample-rate)")
    if number >= MAX_PREAMBLE_LINES:
        raise FileFormatError(f"{name}: no row of numbers in the first {MAX_PREAMBLE_LINES} lines; expected a "
                              "header and one row per sample")
    raise FileFormatError(f"{name}: a header and no samples; expected one row per sample")


def _stated_rate(preamble: list[tuple[int, str]], name: str, decimal_comma: bool,
                 sample_rate: Any) -> tuple[float, str] | None:
    """The sample rate (Hz) and what states it: the option, the preamble, both when they agree, or None."""
    stated = rate_from_lines(preamble, name, decimal_comma)
    if sample_rate is None:
        return None if stated is None else (stated[0], f"line {stated[1]}")
    hz = option_rate(sample_rate)
    if stated is not None and abs(stated[0] - hz) > 1e-6 * hz:
        raise FileFormatError(f"{name}, line {stated[1]}: the file says {stated[0]:.10g} Hz, --sample-rate "
                              f"{hz:.10g} Hz; leave the option out or fix the file")
    return hz, "--sample-rate"


def read_tap_lvm(path: str | os.PathLike, sensitivity: Any = None, hammer_sensitivity: Any = None,
                 quantity: str | None = None, sample_rate: Any = None, force_column: Any = None,
                 response_column: Any = None) -> list[TapRecord]:
    """Read a LabVIEW measurement file (``.lvm``): one record per run of contiguous segments.

    Parameters
    ----------
    path : str or path-like
        The file: the text format of LabVIEW's Write Measurement File
        (``Separator`` Tab or Comma, ``Decimal_Separator``, ``X_Columns`` No,
        One or Multi; each segment's ``Delta_X`` gives the time step, its
        ``Y_Unit_Label`` or the column names the units).
    sensitivity, hammer_sensitivity : str or pint.Quantity, optional
        As for :func:`read_tap_csv` (``"10.2 mV/g"``, ``"2.25 mV/N"``).
    quantity : {"acceleration", "velocity", "displacement"}, optional
        What the response is; it must agree with the channel's unit.
    sample_rate : str, pint.Quantity or float, optional
        Checked against the file's ``Delta_X`` (Hz; ``"51.2 kHz"``).
    force_column, response_column : int or str, optional
        The channels by name or 1-based index (the x column not counted), as
        for :func:`read_tap_csv`.

    Returns
    -------
    list of TapRecord
        Segments of the same channels whose ``X0`` continues the previous
        segment's time axis are one record; a segment that starts anew
        (another acquisition, a tap of its own) is a record of its own.

    Raises
    ------
    FileFormatError
        Naming the file, the segment or line and the column, as for
        :func:`read_tap_csv`, and for a file that is not a LabVIEW
        measurement file or a segment without ``Delta_X``.
    """
    from ._tap_lvm import read_segments

    name = file_name(path, "tap record")
    data = _text_bytes(path, name)
    segments = read_segments(data, name)
    groups: list[list[Any]] = []
    for seg in segments:
        last = groups[-1][-1] if groups else None
        if last is not None and seg.columns.names == last.columns.names and seg.columns.units == last.columns.units \
                and abs(seg.delta_x - last.delta_x) <= 1e-9 * last.delta_x \
                and abs(seg.x0 - (last.x0 + last.table.shape[0] * last.delta_x)) <= 0.5 * last.delta_x:
            groups[-1].append(seg)
        else:
            groups.append([seg])
    records = []
    for group in groups:
        seg = group[0]
        hz = 1.0 / seg.delta_x
        if sample_rate is not None and abs(option_rate(sample_rate) - hz) > 1e-6 * hz:
            raise FileFormatError(f"{name}, line {seg.columns.line}: Delta_X {seg.delta_x!r} s is {hz:.10g} Hz, "
                                  f"--sample-rate {option_rate(sample_rate):.10g} Hz; leave the option out or fix "
                                  "the file")
        parsed, dims, errors = units_of_columns(seg.columns, name)
        _, f_col, r_col = choose(seg.columns, parsed, dims, name, force_column, response_column, True)
        labels = seg.columns.labels
        for k in (f_col, r_col):
            if seg.columns.units[k] is None:
                raise FileFormatError(f"{name}, line {seg.columns.line}: channel {labels[k]!r} has no unit; "
                                      "expected a Y_Unit_Label line in the segment header (e.g. N, g, m/s^2, mV) "
                                      "or the unit in the name, e.g. 'Force (N)'")
            if errors[k]:
                raise FileFormatError(f"{name}, line {seg.columns.line}: {errors[k]} (channel {labels[k]!r})")
        table = np.concatenate([s.table for s in group]) if len(group) > 1 else seg.table
        bad = ~np.isfinite(table[:, [f_col, r_col]])
        if bad.any():
            row, col = np.argwhere(bad)[0]
            raise FileFormatError(f"{name}, segment starting on line {seg.first_line}, row {row + 1}: channel "
                                  f"{labels[(f_col, r_col)[col]]!r} is {table[row, (f_col, r_col)[col]]}; expected "
                                  "a finite number (a gap in the acquisition?)")
        start = seg.x0 if abs(seg.x0) < 1e6 else 0.0  # an absolute time stamp (seconds since 1904) is not kept
        time_s = start + np.arange(table.shape[0]) * seg.delta_x
        records.append(build_record(name, time_s, table[:, f_col], parsed[f_col], labels[f_col], table[:, r_col],
                                    parsed[r_col], labels[r_col], sensitivity, hammer_sensitivity, quantity))
    return records


def read_tap_mat(path: str | os.PathLike, sensitivity: Any = None, hammer_sensitivity: Any = None,
                 quantity: str | None = None, sample_rate: Any = None, force_column: Any = None,
                 response_column: Any = None) -> TapRecord:
    """Read a tap record from a MATLAB file (``.mat``, versions 4 to 7; 7.3 is refused with how to re-save).

    Parameters
    ----------
    path : str or path-like
        The file: vectors of samples by name (a time vector ``time`` or
        ``t``, in s unless ``time_unit`` says otherwise), each force and
        response vector with its unit in a text variable ``<name>_unit``
        (``force_unit = 'N'``, ``acc_unit = 'g'``, ``'mV'`` with a
        sensitivity); without a time vector, a scalar ``fs`` or
        ``sample_rate`` (Hz) or ``dt`` (s).  Struct fields are variables
        of dotted names (``tap.force``, ``tap.force_unit``); Simcenter
        Testlab signal structures (``x_values``, ``y_values``,
        ``function_record``) are channels with their own unit and clock;
        B&K PULSE's ``Channel_k_Data`` take their unit from
        ``Channel_k_Header.Unit`` and the rate from the text
        ``File_Header.SampleFrequency``.
    sensitivity, hammer_sensitivity : str or pint.Quantity, optional
        As for :func:`read_tap_csv` (``"10.2 mV/g"``, ``"2.25 mV/N"``).
    quantity : {"acceleration", "velocity", "displacement"}, optional
        What the response is; it must agree with its unit.
    sample_rate : str, pint.Quantity or float, optional
        Samples per second (``"51.2 kHz"``; a plain number in Hz), checked
        against the file's rate or time vector when it has one.
    force_column, response_column : int or str, optional
        The force and response vectors by name or 1-based index among the
        file's vectors, when their units do not tell.

    Returns
    -------
    TapRecord
        In SI units; ``source`` is the file name.

    Raises
    ------
    FileFormatError
        Naming the file and the variable: a version 7.3 file, no vectors, a
        force or response without its unit, no or several candidates for a
        channel, no time vector and no sample rate, contradicting rates,
        NaN samples, vectors of different lengths.
    """
    records = read_taps_mat(path, sensitivity, hammer_sensitivity, quantity, sample_rate, force_column,
                            response_column)
    if len(records) > 1:
        raise FileFormatError(f"{os.fspath(path)}: the force and the response are matrices of {len(records)} taps; "
                              "read them with read_taps_mat (the command reads every tap)")
    return records[0]


def read_taps_mat(path: str | os.PathLike, sensitivity: Any = None, hammer_sensitivity: Any = None,
                  quantity: str | None = None, sample_rate: Any = None, force_column: Any = None,
                  response_column: Any = None) -> list[TapRecord]:
    """Read every tap of a MATLAB file: vectors as :func:`read_tap_mat`, or matrices of a tap a column.

    A force and a response that are matrices of one shape hold a tap a
    column (samples along the longer side, as MATLAB's acquisition
    functions return them), sharing the time vector or sample rate; so
    does a struct array of taps (``tap(k).force``, ``tap(k).acc``).

    Parameters
    ----------
    path : str or path-like
        The file (see :func:`read_tap_mat`).
    sensitivity, hammer_sensitivity : str or pint.Quantity, optional
        As for :func:`read_tap_csv`.
    quantity : {"acceleration", "velocity", "displacement"}, optional
        What the response is; it must agree with its unit.
    sample_rate : str, pint.Quantity or float, optional
        As for :func:`read_tap_mat`.
    force_column, response_column : int or str, optional
        The force and response variables by name or 1-based index.

    Returns
    -------
    list of TapRecord
        One a tap, in the matrices' order (``source`` names the file and the tap).

    Raises
    ------
    FileFormatError
        As :func:`read_tap_mat`; also for a force and a response matrix of
        different shapes.
    """
    from ._tap_mat import mat_record

    data = read_bytes(path, "tap record", MAX_RECORD_BYTES)
    return mat_record(path, data, sensitivity, hammer_sensitivity, quantity, sample_rate, force_column,
                      response_column)
