"""The structure of a LabVIEW measurement file (``.lvm``): its header, its segments and their tables.

The text format National Instruments documents for the Write/Read LabVIEW
Measurement File Express VIs: a file header from ``LabVIEW Measurement``
to ``***End_of_Header***`` (tags ``Separator`` ``Tab`` or ``Comma``,
``Decimal_Separator``, ``X_Columns`` ``No``, ``One`` or ``Multi``), then
segments, each a header of tags with one value per channel (``Channels``,
``Samples``, ``Y_Unit_Label``, ``X_Dimension``, ``X0``, ``Delta_X``) ended
by ``***End_of_Header***``, a line naming the columns (``X_Value`` when the
file has an x column, the channels, ``Comment``) and the rows.
"""

from __future__ import annotations

import re
import warnings

import attrs
import numpy as np

from ..errors import FileFormatError, SubstructureWarning
from ._tap_columns import Columns, is_number, name_and_unit, unit_label
from ._tap_table import parse_rows

_MARK = b"***End_of_Header***"
_TAG_LINE = re.compile(rb"^[ \t]*(?![-+]?(?:nan|inf)(?:inity)?\b)[A-Za-z_*]", re.M | re.I)  # not NaN, Inf


@attrs.frozen
class Segment:
    """One segment: its columns (the x column dropped), their numbers, its time step, start and first line."""

    columns: Columns
    table: np.ndarray
    delta_x: float
    x0: float
    first_line: int


def _utf8(raw: bytes) -> bool:
    try:
        raw.decode("utf-8")
    except UnicodeDecodeError:
        return False
    return True


def _text(raw: bytes) -> str:
    """Header text: UTF-8, else Windows-1252 (what LabVIEW writes on Windows), said once by the reader."""
    return raw.decode("utf-8") if _utf8(raw) else raw.decode("cp1252", "replace")


def _tags(text: str, sep: str) -> dict[str, list[str]]:
    tags: dict[str, list[str]] = {}
    for line in text.splitlines():
        cells = [c.strip() for c in line.split(sep)]
        if cells and cells[0]:
            tags[cells[0]] = [c for c in cells[1:] if c]
    return tags


def _number(text: str, decimal_comma: bool, where: str) -> float:
    try:
        return float(text.replace(",", ".") if decimal_comma else text)
    except ValueError:
        raise FileFormatError(f"{where} is {text!r}; expected a number") from None


def _rows_as_written(body: bytes, first_line: int, names: list[str], sep: str, decimal_comma: bool, name: str,
                     comment: bool) -> tuple[list[str], np.ndarray]:
    """The rows of a segment as LabVIEW writes them, and the names of the columns kept.

    The text of the ``Comment`` column after the numbers is left out, and so
    are the columns empty on every row: the heading ``X_Value`` over empty
    cells (``X_Columns`` ``No``), the channels without samples (``Samples``
    0).  Read line by line: only when the table is not a plain one.
    """
    rows = []
    for raw in body.split(b"\n"):
        line = raw.decode("utf-8", errors="replace").rstrip("\r")
        cells = line.split(sep) if line.strip() else []
        rows.append(cells[:len(names)] if comment and len(cells) > len(names) else cells)
    full = [cells for cells in rows if len(cells) == len(names)]
    keep = [j for j in range(len(names)) if any(cells[j].strip() for cells in full)] if full else []
    if not full or len(keep) == len(names):
        keep = list(range(len(names)))
    text = "\n".join(sep.join(cells[j] for j in keep) if len(cells) == len(names) else sep.join(cells)
                     for cells in rows)
    kept = [names[j] for j in keep]
    return kept, parse_rows((text + "\n").encode("utf-8"), first_line, len(kept), sep, decimal_comma, kept, name)


def read_segments(data: bytes, name: str) -> list[Segment]:
    """The segments of a LabVIEW measurement file, each with its channels' names and units.

    Raises
    ------
    FileFormatError
        Naming the file and the line: no ``LabVIEW Measurement`` header, a
        separator or x-column setting it does not know, a segment without
        ``Delta_X``, different ``Delta_X`` for the channels of one segment, an
        x column that disagrees with ``X0`` and ``Delta_X``, a bad row.
    """
    if not data.lstrip().startswith(b"LabVIEW Measurement"):
        raise FileFormatError(f"{name}, line 1: expected 'LabVIEW Measurement' (the first line of a .lvm file)")
    marks = [m.start() for m in re.finditer(re.escape(_MARK), data)]
    if len(marks) < 2:
        raise FileFormatError(f"{name}: {len(marks)} '***End_of_Header***' marker(s); expected one after the file "
                              "header and one after each segment header")
    if not _utf8(data[:data.find(b"\n", marks[-1]) + 1 or len(data)]):
        warnings.warn(f"{name}: the headers are not UTF-8; read as Windows-1252, the text of Windows programs "
                      "(units such as m/s\u00b2); save the file as UTF-8 to be sure", SubstructureWarning, stacklevel=3)
    header = _text(data[:marks[0]])
    first = _tags(header, "\t") if "\t" in header else _tags(header, ",")
    separator = (first.get("Separator") or ["Tab"])[0]
    if separator not in ("Tab", "Comma"):
        raise FileFormatError(f"{name}: Separator {separator!r}; expected Tab or Comma")
    sep = "\t" if separator == "Tab" else ","
    decimal_comma = (first.get("Decimal_Separator") or ["."])[0] == ","
    if decimal_comma and sep == ",":
        raise FileFormatError(f"{name}: Separator Comma with Decimal_Separator ','; the cells cannot be split")
    x_columns = (first.get("X_Columns") or ["One"])[0]
    if x_columns not in ("No", "One", "Multi"):
        raise FileFormatError(f"{name}: X_Columns {x_columns!r}; expected No, One or Multi")
    segments = []
    seg_start = marks[0] + len(_MARK)
    for k, mark in enumerate(marks[1:]):
        line_of = data.count(b"\n", 0, mark) + 1
        tags = _tags(_text(data[seg_start:mark]), sep)
        where = f"{name}, segment {k + 1} (header ending on line {line_of})"
        names_start = data.find(b"\n", mark) + 1
        names_end = data.find(b"\n", names_start)
        names_end = len(data) if names_end < 0 else names_end
        names = [c.strip() for c in _text(data[names_start:names_end]).rstrip("\r").split(sep)]
        comment = False
        while names and (not names[-1] or names[-1] == "Comment"):
            comment |= names.pop() == "Comment"
        body_start = names_end + 1
        names_line = data.count(b"\n", 0, names_start) + 1
        if names and all(is_number(c, decimal_comma) for c in names):  # no line of names: the rows start at once
            body_start, names_line = names_start, line_of
            x_named = x_columns == "One"
            names = (["X_Value"] if x_named else []) + [f"channel {j + 1}" for j in range(len(names) - x_named)]
        # the rows end where the next segment's header starts: its first line of tags
        end = marks[k + 2] if k + 2 < len(marks) else len(data)
        tag_line = _TAG_LINE.search(data, body_start, end) if end != len(data) else None
        body_end = tag_line.start() if tag_line else end
        x_cols = [j for j, n in enumerate(names) if n == "X_Value"]
        # LabVIEW writes the heading X_Value over an empty first cell of every row when it writes no x column
        if x_columns == "No" and x_cols and x_cols != [0]:
            raise FileFormatError(f"{where}: an X_Value column where the file header says X_Columns No")
        first_row = data.count(b"\n", 0, body_start) + 1
        samples = [int(v) for v in tags.get("Samples", []) if v.isdigit()]
        try:
            table = parse_rows(data, first_row, len(names), sep, decimal_comma, names, name, body_start, body_end)
        except FileFormatError:
            if not (x_columns == "No" and x_cols) and not comment and 0 not in samples:
                raise
            body = data[body_start:body_end]
            s = sep.encode()
            table = None
            if x_columns == "No" and x_cols and not re.search(rb"(?m)^(?!" + re.escape(s) + rb"|\r?$)", body):
                try:  # every row starts with the empty cell: the rest is a plain table (the usual LabVIEW file)
                    table = parse_rows(body.replace(b"\n" + s, b"\n").removeprefix(s), first_row, len(names) - 1,
                                       sep, decimal_comma, names[1:], name)
                    names = names[1:]
                except FileFormatError:
                    table = None
            if table is None:
                names, table = _rows_as_written(body, first_row, names, sep, decimal_comma, name, comment)
            x_cols = [j for j, n in enumerate(names) if n == "X_Value"]
            if x_columns == "No" and x_cols:
                raise FileFormatError(f"{where}: values under X_Value where the file header says X_Columns No") \
                    from None
        if samples and max(samples) > table.shape[0]:
            raise FileFormatError(f"{where}: the segment header announces {max(samples)} samples but its rows hold "
                                  f"{table.shape[0]}: the file is truncated or damaged; copy or export it again")
        steps = tags.get("Delta_X")
        if not steps:
            raise FileFormatError(f"{where}: no Delta_X; expected the time step of the channels")
        deltas = {_number(v, decimal_comma, f"{where}: Delta_X") for v in steps}
        if len(deltas) != 1:
            raise FileFormatError(f"{where}: Delta_X {', '.join(steps)}; expected one time step for all channels")
        delta_x = deltas.pop()
        if not delta_x > 0:
            raise FileFormatError(f"{where}: Delta_X {steps[0]}; expected a positive time step")
        x0 = _number((tags.get("X0") or ["0"])[0], decimal_comma, f"{where}: X0")
        keep = [j for j in range(len(names)) if j not in x_cols]
        if x_cols and table.shape[0]:
            expected = x0 + np.arange(table.shape[0]) * delta_x
            for j in x_cols:
                worst = int(np.argmax(np.abs(table[:, j] - expected)))
                if abs(table[worst, j] - expected[worst]) > 0.5 * delta_x:
                    raise FileFormatError(f"{where}: X_Value {float(table[worst, j])!r} on row {worst + 1} where "
                                          f"X0 + n Delta_X is {float(expected[worst])!r}; expected the x column of a "
                                          "uniform time axis")
        units = [unit_label(u) for u in tags.get("Y_Unit_Label", [])]
        channel_names, channel_units = [], []
        for pos, j in enumerate(keep):
            plain, unit = name_and_unit(names[j])
            said = units[pos] if pos < len(units) else None
            # the segment header's unit first: LabVIEW's channel names carry other words in brackets
            # ('Excitation (Trigger)'); the name's own unit where the header has none
            channel_names.append(plain if said is None or unit is None else names[j])
            channel_units.append(said if said is not None else unit)
        segments.append(Segment(Columns(channel_names, channel_units, names_line),
                                table[:, keep], delta_x, x0, data.count(b"\n", 0, body_start) + 1))
        seg_start = body_end
    return segments
