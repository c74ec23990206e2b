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
when a file holds more.

TDMS (NI's acquisition): channels found by their ``unit_string`` as columns
are, the time step from ``wf_increment``; :func:`read_tap_tdms`, in
``_tap_tdms``.
"""

from __future__ import annotations

import contextlib
import io
import os
import warnings
from typing import Any

import numpy as np

from .._files import decode_text
from ..errors import FileFormatError, SubstructureError, SubstructureWarning
from ..tap.records import RESPONSE_QUANTITIES, TIME_STEP_TOLERANCE, TapRecord, channel_to_si, unit_of
from ..units import bare_unit
from . import check_readable_file, read_bytes
from ._tap_columns import (MAX_PREAMBLE_LINES, NO_UNIT, Columns, choose, header_cells, is_row, is_unit_row,
                           line_separator, name_and_unit, rate_from_lines)
from ._tap_build import (MAX_RECORD_BYTES, RESPONSES, ROUNDED_TIME_TOLERANCE, build_record, check_quantity_option,
                         option_rate, quantity_of, regular, time_axis, units_of_columns)
from ._tap_table import finite_rows, parse_rows
from ._tap_tdms import read_tap_tdms

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
    name = os.fspath(path)
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
    """The bytes of a text record: UTF-16 re-encoded as UTF-8, a UTF-8 byte-order mark dropped."""
    data = read_bytes(path, "tap record", MAX_RECORD_BYTES)
    if data[:2] in (b"\xff\xfe", b"\xfe\xff"):
        return decode_text(data, name).encode("utf-8")
    return data[3:] if data[:3] == b"\xef\xbb\xbf" else data


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

    name = os.fspath(path)
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
        ``sample_rate`` (Hz) or ``dt`` (s).
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
    functions return them), sharing the time vector or sample rate.

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


_FORCE_TYPES = (9, 13)
_RESPONSE_TYPES = {8: "displacement", 11: "velocity", 12: "acceleration"}


def read_tap_uff(path: str | os.PathLike, sensitivity: Any = None, hammer_sensitivity: Any = None,
                 quantity: str | None = None, force_record: int | None = None,
                 response_record: int | None = None) -> TapRecord:
    """Read a tap record from a universal file: two type-58 time records, the force and the response.

    Parameters
    ----------
    path : str or path-like
        The file.
    sensitivity, hammer_sensitivity : str or pint.Quantity, optional
        As for :func:`read_tap_csv`, for records whose unit label is a voltage.
    quantity : {"acceleration", "velocity", "displacement"}, optional
        What the response is; it must agree with the record (its specific
        data type and unit label).
    force_record, response_record : int, optional
        0-based indices of the two records among the file's type-58 records;
        default: found by their specific data types or unit labels.

    Returns
    -------
    TapRecord
        In SI units; ``force_column`` and ``response_column`` name the records.

    Raises
    ------
    FileFormatError
        Naming the file and the record: no or several candidates for a
        channel, a record that is not a time response, a unit that
        contradicts the specific data type or the options, different time
        axes.
    """
    name, records, kinds = _uff_records(path)
    pair = _uff_pair(name, records, kinds, force_record, response_record)
    return _uff_tap(name, records, kinds, pair, sensitivity, hammer_sensitivity, quantity)


def read_taps_uff(path: str | os.PathLike, sensitivity: Any = None, hammer_sensitivity: Any = None,
                  quantity: str | None = None) -> list[TapRecord]:
    """Read every tap of a universal file: its force records paired in order with its response records.

    A file of one tap reads as :func:`read_tap_uff` does.  A file of several
    taps holds as many force records as response records (a force and its
    response after each other, or all forces first): the k-th force record
    and the k-th response record are the k-th tap, and must share their
    time axis.

    Parameters
    ----------
    path : str or path-like
        The file.
    sensitivity, hammer_sensitivity : str or pint.Quantity, optional
        As for :func:`read_tap_csv`, for records whose unit label is a voltage.
    quantity : {"acceleration", "velocity", "displacement"}, optional
        What the responses are (as for :func:`read_tap_uff`).

    Returns
    -------
    list of TapRecord
        One a tap, in the file's order.

    Raises
    ------
    FileFormatError
        As :func:`read_tap_uff`; also for counts of force and response
        records that do not pair (then choose one tap with
        :func:`read_tap_uff`'s ``force_record`` and ``response_record``).
    """
    name, records, kinds = _uff_records(path)
    forces = [k for k, q in enumerate(kinds) if q == "force"]
    responses = [k for k, q in enumerate(kinds) if q in RESPONSES or q == "response"]
    if len(forces) < 2 or len(forces) != len(responses):
        return [_uff_tap(name, records, kinds, _uff_pair(name, records, kinds, None, None), sensitivity,
                         hammer_sensitivity, quantity)]
    return [_uff_tap(name, records, kinds, pair, sensitivity, hammer_sensitivity, quantity, tap=k + 1)
            for k, pair in enumerate(zip(forces, responses))]


def _uff_records(path) -> tuple[str, list[dict], list[str | None]]:
    """The file's name, its type-58 records (each checked a time record) and what each holds by its data type
    or unit label (``force``, a response quantity, ``response`` or None: not known)."""
    import pyuff

    from ..frf.files.uff_reader import check_complete

    name = check_readable_file(path, "tap record", MAX_RECORD_BYTES)
    check_complete(name)  # a file cut off in a record: said so, not read as the records before the cut
    try:
        with contextlib.redirect_stdout(io.StringIO()):  # pyuff prints some records it reads (not ours to show)
            sets = pyuff.UFF(name).read_sets()
    except Exception as exc:  # pyuff raises many kinds for broken files
        raise FileFormatError(f"{name}: cannot read the universal file ({exc})") from None
    sets = sets if isinstance(sets, list) else [sets]
    records = [s for s in sets if int(s.get("type", 0)) == 58]
    if not records:
        raise FileFormatError(f"{name}: no type-58 record; expected two time records (force and response)")
    for k, r in enumerate(records):
        if int(r.get("func_type", 0)) != 1:
            raise FileFormatError(f"{name}, record {k}: function type {r.get('func_type')}; expected 1 (time "
                                  "response): a tap record holds the time signals, not an FRF")
        announced, held = r.get("num_pts"), np.asarray(r.get("data", [])).size
        if announced is not None and int(announced) != held:
            raise FileFormatError(f"{name}, record {k}: its header announces {int(announced)} samples but it holds "
                                  f"{held}: the file is truncated or damaged; copy or export it again")
    if len(records) < 2:
        raise FileFormatError(f"{name}: one type-58 record; a tap needs two time records, the force and the "
                              "response, sampled together")
    for k, r in enumerate(records):
        _check_abscissa(name, k, r)
    kinds = [_uff_kind(name, records, k) for k in range(len(records))]
    if len(records) == 2 and kinds.count(None) == 1 and _uff_unit(name, records, kinds.index(None)) is not None:
        # two records, one of them known by its type or unit, the other in volts or unlabelled: the other channel
        unknown = kinds.index(None)
        kinds[unknown] = "force" if kinds[1 - unknown] in RESPONSES else "response"
    return name, records, kinds


def _uff_unit(name: str, records: list[dict], k: int):
    label = str(records[k].get("ordinate_axis_units_lab", "") or "").strip()
    if not label or label.upper() in ("NONE", "N/A", "NA", "-"):
        return None
    try:
        return unit_of(label, f"{name}, record {k}")
    except SubstructureError as exc:
        raise FileFormatError(str(exc)) from None


def _uff_kind(name: str, records: list[dict], k: int) -> str | None:
    spec = int(records[k].get("ordinate_spec_data_type", 0))
    u = _uff_unit(name, records, k)
    by_type = "force" if spec in _FORCE_TYPES else _RESPONSE_TYPES.get(spec)
    found = None if u is None else quantity_of(u)  # one quantity at most: the dimensions differ
    by_unit = found if found in ("force", *RESPONSES) else None
    if by_type and by_unit and by_type != by_unit:
        raise FileFormatError(f"{name}, record {k}: the specific data type says {by_type}, the unit label "
                              f"{records[k].get('ordinate_axis_units_lab')!r} says {by_unit}; fix one")
    return by_type or by_unit


def _uff_pair(name: str, records: list[dict], kinds: list, force_record, response_record) -> tuple[int, int]:
    """The indices of the force and the response record: given, or the one candidate of each."""
    # what each record holds by its data type or unit label, for the messages
    held = ", ".join(f"{k} {q or 'not said'}" for k, q in enumerate(kinds))
    if force_record is None:
        found = [k for k, q in enumerate(kinds) if q == "force"]
        if len(found) != 1:
            raise FileFormatError(f"{name}: {len(found)} force records among {len(records)} type-58 records; "
                                  f"give the force record's index (--force-record, 0-based); they hold {held}")
        force_record = found[0]
    if response_record is None:
        found = [k for k, q in enumerate(kinds) if (q in RESPONSES or q == "response") and k != force_record]
        if len(found) != 1:
            raise FileFormatError(f"{name}: {len(found)} response records among {len(records)} type-58 records; "
                                  f"give the response record's index (--response-record, 0-based); they hold {held}")
        response_record = found[0]
    for option, k in (("force_record", force_record), ("response_record", response_record)):
        if not 0 <= k < len(records):
            raise FileFormatError(f"{name}: {option} {k}: the file holds {len(records)} type-58 records "
                                  f"(0 to {len(records) - 1})")
    return force_record, response_record


def _uff_tap(name: str, records: list[dict], kinds: list, pair: tuple[int, int], sensitivity: Any,
             hammer_sensitivity: Any, quantity: str | None, tap: int | None = None) -> TapRecord:
    """The record of the force and the response records ``pair`` (``tap``: its number among the file's taps)."""
    force_record, response_record = pair
    f_set, r_set = records[force_record], records[response_record]
    where = "" if tap is None else f" (tap {tap})"
    t = np.asarray(f_set["x"], dtype=np.float64)
    if np.asarray(r_set["x"]).shape != t.shape or not np.allclose(r_set["x"], t, rtol=1e-9, atol=1e-12):
        raise FileFormatError(f"{name}: records {force_record} and {response_record}{where} have different time "
                              "axes; expected both channels sampled together")
    labels = [f"record {force_record} ({str(f_set.get('id1', '')).strip() or 'force'})",
              f"record {response_record} ({str(r_set.get('id1', '')).strip() or 'response'})"]
    try:
        f_unit = _uff_unit(name, records, force_record) or unit_of("N", name)
        force, _ = channel_to_si(np.real(np.asarray(f_set["data"])), f_unit, f"{name}: {labels[0]}", ("force",),
                                 hammer_sensitivity, "hammer sensitivity (--hammer-sensitivity)")
        r_unit = _uff_unit(name, records, response_record)
        if r_unit is None:
            said = kinds[response_record] if kinds[response_record] in RESPONSES else quantity
            if said is None:
                raise FileFormatError(f"{name}: {labels[1]} has neither a unit label nor a specific data type; "
                                      "give the quantity (--quantity)")
            r_unit = unit_of(RESPONSE_QUANTITIES[said][0], name)
        response, found_q = channel_to_si(np.real(np.asarray(r_set["data"])), r_unit, f"{name}: {labels[1]}",
                                          RESPONSES, sensitivity, "sensitivity (--sensitivity)")
        if kinds[response_record] in RESPONSES and kinds[response_record] != found_q:
            raise FileFormatError(f"{name}: {labels[1]}: the specific data type says {kinds[response_record]}, the "
                                  f"sensitivity makes it {found_q}")
        check_quantity_option(quantity, found_q, f"{name}: {labels[1]}")
        return TapRecord(t, force, response, found_q, name + where, labels[0], labels[1])
    except FileFormatError:
        raise
    except SubstructureError as exc:
        message = str(exc)
        raise FileFormatError(message if message.startswith(name) else f"{name}: {message}") from None


def _check_abscissa(name: str, k: int, record: dict) -> None:
    """Refuse a record whose abscissa is not time (by its data type or unit label) or not uniformly spaced."""
    spec = int(record.get("abscissa_spec_data_type", 0) or 0)
    label = str(record.get("abscissa_axis_units_lab", "") or "").strip()
    if spec not in (0, 17):
        raise FileFormatError(f"{name}, record {k}: abscissa of specific data type {spec}; expected 17 (time) "
                              "or 0: a tap record is sampled in time")
    if label and label.upper() not in ("NONE", "N/A", "NA", "-"):
        try:
            time_like = (1.0 * unit_of(label, f"{name}, record {k}")).check("[time]")
        except SubstructureError:
            time_like = False
        if not time_like:
            raise FileFormatError(f"{name}, record {k}: abscissa in {label!r}; expected a time in s")
    x = record["x"] = regular(np.asarray(record.get("x", []), dtype=np.float64))  # times written rounded: the clock
    if x.size > 2:
        step = np.diff(x)
        mean = (x[-1] - x[0]) / (x.size - 1)
        if not mean > 0 or np.any(np.abs(step - mean) > TIME_STEP_TOLERANCE * mean):
            worst = int(np.argmax(np.abs(step - mean))) + 1
            raise FileFormatError(f"{name}, record {k}: uneven abscissa (sample {worst}: step "
                                  f"{float(step[worst - 1])!r} s, mean {float(mean)!r} s); expected uniform sampling "
                                  "in time")
