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
    """Each tag's values, in their places (the empty cells between them kept, the trailing ones not)."""
    tags: dict[str, list[str]] = {}
    for line in text.splitlines():
        cells = [c.strip() for c in line.split(sep)]
        if cells and cells[0]:
            values = cells[1:]
            while values and not values[-1]:
                values.pop()
            tags[cells[0]] = values
    return tags


def _of_channel(values: list[str], heading: list[str], j: int) -> str:
    """A segment tag's value for the channel of column ``j`` of the heading ('' for none).

    LabVIEW writes a tag's values under the columns of their channels (empty
    under the x columns of ``X_Columns`` ``Multi``, and under channels
    without a value); values written one a channel with no empty cell
    between them are read in the channels' order.
    """
    if "" in values:
        k = j - (1 if heading and heading[0] == "X_Value" else 0)
    else:
        k = [i for i, n in enumerate(heading) if n != "X_Value"].index(j)
    return values[k] if 0 <= k < len(values) else ""


def _number(text: str, decimal_comma: bool, where: str) -> float:
    try:
        return float(text.replace(",", ".") if decimal_comma else text)
    except ValueError:
        raise FileFormatError(f"{where} is {text!r}; expected a number") from None


def _rows_as_written(body: bytes, first_line: int, names: list[str], sep: str, decimal_comma: bool, name: str,
                     comment: bool) -> tuple[list[int], list[int], np.ndarray]:
    """The rows of a segment as LabVIEW writes them: the columns kept, those left out as short, the table.

    The text of the ``Comment`` column after the numbers is left out, and so
    are the columns empty on every row (the heading ``X_Value`` over empty
    cells of ``X_Columns`` ``No``, a channel without samples) and the
    channels whose samples end before the others' (empty cells after them:
    a channel of another rate).  Read line by line: only when the table is
    not a plain one.
    """
    rows = []
    for raw in body.split(b"\n"):
        line = raw.decode("utf-8", errors="replace").rstrip("\r")
        cells = line.split(sep) if line.strip() else []
        rows.append(cells[:len(names)] if comment and len(cells) > len(names) else cells)
    full = [cells for cells in rows if len(cells) == len(names)]
    keep, short = list(range(len(names))), []
    if full:
        filled = np.array([[bool(c.strip()) for c in cells] for cells in full])
        ends = filled.sum(axis=0)
        leading = np.array([filled[:n, j].all() for j, n in enumerate(ends)])  # filled, then empty to the end
        short = [j for j in range(len(names)) if 0 < ends[j] < len(full) and leading[j] and names[j] != "X_Value"]
        kept = [j for j in range(len(names)) if ends[j] > 0 and j not in short]
        keep = kept if kept else keep
    text = "\n".join(sep.join(cells[j] for j in keep) if len(cells) == len(names) else sep.join(cells)
                     for cells in rows)
    labels = [names[j] for j in keep]
    return keep, short, parse_rows((text + "\n").encode("utf-8"), first_line, len(keep), sep, decimal_comma, labels,
                                   name)


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
        heading = names
        x_cols = [j for j, n in enumerate(heading) if n == "X_Value"]
        # LabVIEW writes the heading X_Value over an empty first cell of every row when it writes no x column
        if x_columns == "No" and x_cols and x_cols != [0]:
            raise FileFormatError(f"{where}: an X_Value column where the file header says X_Columns No")
        first_row = data.count(b"\n", 0, body_start) + 1
        samples = [int(v) if v.isdigit() else -1 for v in tags.get("Samples", [])]
        cols, short = list(range(len(heading))), []
        try:
            table = parse_rows(data, first_row, len(heading), sep, decimal_comma, heading, name, body_start, body_end)
        except FileFormatError:
            if not (x_columns == "No" and x_cols) and not comment and len(set(v for v in samples if v >= 0)) < 2:
                raise
            body = data[body_start:body_end]
            s = sep.encode()
            table = None
            if x_columns == "No" and x_cols and not re.search(rb"(?m)^(?!" + re.escape(s) + rb"|\r?$)", body):
                try:  # every row starts with the empty cell: the rest is a plain table (the usual LabVIEW file)
                    table = parse_rows(body.replace(b"\n" + s, b"\n").removeprefix(s), first_row, len(heading) - 1,
                                       sep, decimal_comma, heading[1:], name)
                    cols = cols[1:]
                except FileFormatError:
                    table = None
            if table is None:
                cols, short, table = _rows_as_written(body, first_row, heading, sep, decimal_comma, name, comment)
            if x_columns == "No" and any(heading[j] == "X_Value" for j in cols):
                raise FileFormatError(f"{where}: values under X_Value where the file header says X_Columns No") \
                    from None
        if short:
            warnings.warn(f"{where}: {', '.join(repr(heading[j]) for j in short)} hold fewer samples than the other "
                          "channels (another rate, or a logger's readings): left out", SubstructureWarning,
                          stacklevel=3)
        x_cols = [k for k, j in enumerate(cols) if heading[j] == "X_Value"]
        keep = [k for k, j in enumerate(cols) if heading[j] != "X_Value"]

        def tag(key: str, j: int) -> str:
            return _of_channel(tags.get(key, []), heading, j)

        counts = [tag("Samples", cols[k]) for k in keep]
        announced = max((int(v) for v in counts if v.isdigit()), default=0)
        if announced > table.shape[0]:
            raise FileFormatError(f"{where}: the segment header announces {announced} samples but its rows hold "
                                  f"{table.shape[0]}: the file is truncated or damaged; copy or export it again")
        steps = [v for v in (tag("Delta_X", cols[k]) for k in keep) if v]
        if not steps:
            raise FileFormatError(f"{where}: no Delta_X; expected the time step of the channels")
        deltas = {_number(v, decimal_comma, f"{where}: Delta_X") for v in steps}
        if len(deltas) != 1:
            raise FileFormatError(f"{where}: Delta_X {', '.join(steps)}; expected one time step for all channels")
        delta_x = deltas.pop()
        if not delta_x > 0:
            raise FileFormatError(f"{where}: Delta_X {steps[0]}; expected a positive time step")
        x0 = _number(next((v for v in (tag("X0", cols[k]) for k in keep) if v), "0"), decimal_comma, f"{where}: X0")
        if x_cols and table.shape[0]:
            expected = x0 + np.arange(table.shape[0]) * delta_x
            for j in x_cols:
                worst = int(np.argmax(np.abs(table[:, j] - expected)))
                if abs(table[worst, j] - expected[worst]) > 0.5 * delta_x:
                    raise FileFormatError(f"{where}: X_Value {float(table[worst, j])!r} on row {worst + 1} where "
                                          f"X0 + n Delta_X is {float(expected[worst])!r}; expected the x column of a "
                                          "uniform time axis")
        channel_names, channel_units = [], []
        for k in keep:
            plain, unit = name_and_unit(heading[cols[k]])
            said = unit_label(tag("Y_Unit_Label", cols[k]))
            # the segment header's unit first: LabVIEW's channel names carry other words in brackets
            # ('Excitation (Trigger)'); the name's own unit where the header has none
            channel_names.append(plain if said is None or unit is None else heading[cols[k]])
            channel_units.append(said if said is not None else unit)
        segments.append(Segment(Columns(channel_names, channel_units, names_line),
                                table[:, keep], delta_x, x0, data.count(b"\n", 0, body_start) + 1))
        seg_start = body_end
    return segments
