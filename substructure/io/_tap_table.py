"""The numeric table of a text tap record: the fast parse of its rows, with the line and column of any bad cell.

A block of rows (bytes, one sample per line, ``ncols`` cells split by one
separator, or by runs of whitespace) is parsed in pieces of about
:data:`CHUNK_BYTES` by ``numpy.fromstring`` after structural checks that
are whole-array operations (the separators and the numbers on each line, no
cell holding two numbers).  A piece that fails a check is read again line by
line in Python, which names the first bad line and cell; a piece that
passes is exactly what the line-by-line reading would give.
"""

from __future__ import annotations

import warnings

import numpy as np

from ..errors import FileFormatError
from ._tap_columns import unquote

CHUNK_BYTES = 8 * 2**20
"""Bytes of rows parsed at once (the working arrays stay a few times this size)."""

def split_cells(line: str, sep: str | None) -> list[str]:
    """The cells of one line: split at ``sep``, or at runs of whitespace for ``None``."""
    return line.split() if sep is None else line.split(sep)


def _slow(text: str, first_line: int, ncols: int, sep: str | None, decimal_comma: bool, labels: list[str],
          name: str) -> np.ndarray:
    """Rows read line by line; raises at the first line or cell that is not a row of ``ncols`` numbers."""
    rows = []
    for k, line in enumerate(text.split("\n")):
        stripped = line.strip()
        if not stripped or stripped.startswith("#"):
            continue
        cells = split_cells(line.rstrip("\r"), sep)
        if sep is not None and len(cells) == ncols + 1 and not cells[-1].strip():
            cells = cells[:-1]  # a separator at the end of every row, as some exports write
        if len(cells) != ncols:
            raise FileFormatError(f"{name}, line {first_line + k}: {len(cells)} value(s); expected {ncols} "
                                  f"({', '.join(labels)})")
        values = []
        for label, cell in zip(labels, cells):
            text_cell = unquote(cell)
            text_cell = text_cell.replace(",", ".") if decimal_comma else text_cell
            try:
                values.append(float(text_cell))
            except ValueError:
                raise FileFormatError(f"{name}, line {first_line + k}: column {label!r} is {cell.strip()!r}; "
                                      "expected a number") from None
        rows.append(values)
    return np.array(rows, dtype=np.float64).reshape(-1, ncols)


def _fast(chunk: bytes, ncols: int, sep: str | None, decimal_comma: bool) -> np.ndarray | None:
    """The rows of ``chunk`` (ending with a newline) by whole-array checks and ``numpy.fromstring``, or None."""
    if b'"' in chunk:  # every cell quoted, as some exports write them: the quotes go, the checks below still hold
        chunk = chunk.replace(b'"', b"")
    b = np.frombuffer(chunk, dtype=np.uint8)
    if b.size == 0 or not chunk.isascii():
        return None
    newlines = np.flatnonzero(b == 10)
    lines = newlines.size
    sep_byte = None if sep is None else ord(sep)
    trailing = False
    body, blanks = chunk, True  # with blanks (or no separator): count the numbers on each line
    if sep is not None and sep_byte is not None:
        where = np.flatnonzero(b == sep_byte)
        per_line = np.bincount(np.searchsorted(newlines, where), minlength=lines)[:lines]
        if not (per_line == ncols - 1).all():
            last = newlines - 1
            last = np.where((last >= 0) & (b[np.maximum(last, 0)] == 13), last - 1, last)
            trailing = bool((per_line == ncols).all() and (last >= 0).all() and (b[last] == sep_byte).all())
            if not trailing:
                return None
        s = sep.encode()
        blanks = b" " in chunk or (sep != "\t" and b"\t" in chunk)
        if not blanks:
            # no blanks: a cell is empty only between two separators or at a line's ends
            if s + s in chunk or b"\n" + s in chunk or chunk.startswith(s) or (
                    not trailing and (s + b"\n" in chunk or s + b"\r" in chunk)):
                return None
        elif _blank_inside_a_cell(b, sep_byte):  # '1 2' would hide an empty cell elsewhere on its line
            return None
        body = chunk.replace(s, b" ")
    if blanks and not _numbers_per_line(body, newlines, ncols):
        return None
    if decimal_comma:
        body = body.replace(b",", b".")
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        try:
            values = np.fromstring(body, dtype=np.float64, sep=" ")  # text mode, not deprecated
        except (ValueError, DeprecationWarning):
            return None
    if values.size != lines * ncols:
        return None
    return values.reshape(lines, ncols)


def _blank_inside_a_cell(b: np.ndarray, sep_byte: int) -> bool:
    """Whether a run of blanks stands between two characters of one cell (not next to a separator or line end)."""
    blank = (b == 32) | ((b == 9) & (sep_byte != 9))
    where = np.flatnonzero(blank)
    if not where.size:
        return False
    starts = where[(where == 0) | ~blank[np.maximum(where - 1, 0)]]
    ends = where[(where == b.size - 1) | ~blank[np.minimum(where + 1, b.size - 1)]]
    before = np.where(starts > 0, b[np.maximum(starts - 1, 0)], 10)
    after = np.where(ends < b.size - 1, b[np.minimum(ends + 1, b.size - 1)], 10)

    def edge(c):
        return (c == sep_byte) | (c == 10) | (c == 13)

    return bool((~edge(before) & ~edge(after)).any())


def _numbers_per_line(body: bytes, newlines: np.ndarray, ncols: int) -> bool:
    """Whether every line of ``body`` holds ``ncols`` runs of non-blank bytes."""
    x = np.frombuffer(body, dtype=np.uint8)
    blank = (x == 32) | (x == 9) | (x == 13) | (x == 10)
    starts = np.flatnonzero(~blank & np.concatenate(([True], blank[:-1])))
    tokens = np.bincount(np.searchsorted(newlines, starts), minlength=newlines.size)[:newlines.size]
    return bool((tokens == ncols).all())


def parse_rows(data: bytes, first_line: int, ncols: int, sep: str | None, decimal_comma: bool,
               labels: list[str], name: str, start: int = 0, end: int | None = None) -> np.ndarray:
    """The numbers of a block of rows, shape ``(rows, ncols)``.

    Parameters
    ----------
    data : bytes
        The file's bytes; the rows are ``data[start:end]``, from the start of
        a line (only pieces of :data:`CHUNK_BYTES` are copied).
    first_line : int
        The file's line number (1-based) of the first row, for messages.
    ncols : int
        Cells per row.
    sep : str or None
        The separator (one character), or None for runs of whitespace.
    decimal_comma : bool
        Whether cells write ``0,5`` for 0.5 (never with ``sep=","``).
    labels : list of str
        The columns' names, for messages.
    name : str
        The file, for messages.
    start, end : int, optional
        The block's first byte and the byte after its last (default: all).

    Returns
    -------
    numpy.ndarray
        The table; blank lines and ``#`` lines are skipped.

    Raises
    ------
    FileFormatError
        Naming the line (and the column): a row of another length, a cell
        that is not a number.
    """
    end = len(data) if end is None else end
    while end > start and data[end - 1] in b" \t\r\n":
        end -= 1
    pieces, line = [], first_line
    while start < end:
        stop = data.find(b"\n", min(start + CHUNK_BYTES, end - 1), end)
        stop = end if stop < 0 else stop + 1
        chunk = data[start:stop]
        chunk = chunk if chunk.endswith(b"\n") else chunk + b"\n"
        table = _fast(chunk, ncols, sep, decimal_comma)
        if table is None:
            table = _slow(chunk.decode("utf-8", errors="replace"), line, ncols, sep, decimal_comma, labels, name)
        pieces.append(table)
        line += chunk.count(b"\n")
        start = stop
    if not pieces:
        return np.empty((0, ncols))
    return pieces[0] if len(pieces) == 1 else np.concatenate(pieces)


def finite_rows(table: np.ndarray, first_line: int, labels: list[str], name: str, data: bytes,
                start: int = 0) -> None:
    """Raise naming the line and column of the first NaN or infinite cell of ``table`` (rows from ``data[start:]``)."""
    bad = ~np.isfinite(table)
    if not bad.any():
        return
    row, column = np.argwhere(bad)[0]
    # the line of that row: rows are the lines that are neither blank nor comments
    line, seen, pos = first_line, -1, start
    while pos < len(data):
        stop = data.find(b"\n", pos)
        stop = len(data) if stop < 0 else stop
        text = data[pos:stop].strip()
        if text and not text.startswith(b"#"):
            seen += 1
            if seen == row:
                break
        line += 1
        pos = stop + 1
    raise FileFormatError(f"{name}, line {line}: column {labels[column]!r} is {table[row, column]}; "
                          "expected a finite number (a gap in the acquisition?)")
