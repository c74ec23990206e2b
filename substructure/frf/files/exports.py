"""CSV exports of measured FRFs as spreadsheet and acquisition programs write them.

:func:`substructure.io.frf_files.read_csv` reads its own layout
(``frequency_hz,real,imag`` in SI units) directly and hands every other
header to :func:`parse_export`, which reads what is unambiguous and refuses
the rest with what to give instead: comment lines (``#``) before the header,
``;`` or tab separators (with decimal commas), quoted cells, empty trailing
columns, a leading column of row numbers (pandas' index), units in the header (``Frequency [Hz]``, ``Real [mm/N]``,
``Magnitude [g/N]``, ``Phase [deg]``) or in a row of their own under the
names, names of several words one of which says the column (``FRF Real``,
``H1 Imag``), real and imaginary parts or magnitude
and phase, and a fourth column of the coherence (``Coherence``, ``Coh``,
``gamma^2``; no unit, or ``%``).  A magnitude in dB is refused (its
reference is not in the file), and so is a column that is neither of these.
"""

from __future__ import annotations

import csv
import re
from typing import Any

import numpy as np

from ...errors import FileFormatError
from ...units import bare_unit
from ._common import _contradiction, _shown
from .uff_units import _frequency_unit, _unit_of_label, frf_quantity

__all__ = ["parse_export"]

_NAMES = {  # English, and German as German programs export them (Frequenz, Realteil, Betrag, Kohärenz)
    "frequency": {"frequency", "freq", "f", "frequencyhz", "freqhz", "frequencies", "frequenz"},
    "real": {"real", "re", "realpart", "realteil"},
    "imag": {"imag", "im", "imaginary", "imagpart", "imaginarypart", "imaginärteil", "imaginaerteil", "imagteil"},
    "magnitude": {"magnitude", "mag", "amplitude", "abs", "modulus", "betrag"},
    "phase": {"phase", "angle", "arg", "winkel", "phasenwinkel"},
    "coherence": {"coherence", "coh", "gamma2", "gamma^2", "γ2", "γ²", "ordinarycoherence", "kohärenz", "kohaerenz"},
}
_COHERENCE_UNITS = {None: 1.0, "-": 1.0, "1": 1.0, "": 1.0, "%": 0.01}
_HEADER = re.compile(r"^\s*(?P<name>[^\[\(]*?)\s*(?:[\[\(](?P<unit>.*)[\]\)])?\s*$")


def _column(cell: str, name: str, line: int) -> tuple[str, str | None]:
    m = _HEADER.match(cell)
    raw = m["name"] if m else cell
    key = re.sub(r"[\s_\-./]", "", raw.lower())
    unit = (m["unit"] or "").strip() or None if m else None
    if key.endswith("hz") and key[:-2] in _NAMES["frequency"]:
        if unit is not None and unit.replace(" ", "").lower() != "hz":
            raise FileFormatError(f"{name}, line {line}: column {_shown(cell)}: its name says Hz but its unit says "
                                  f"{_shown(unit)}; rename it (e.g. 'Frequency [{unit}]') or correct the unit")
        key, unit = key[:-2], "Hz"  # frequency_hz
    for kind, names in _NAMES.items():
        if key in names:
            return kind, unit
    # a name of several words, one of them the column's kind: 'FRF Real', 'H1 Imag', 'Coherence H1'
    tokens = set(re.split(r"[^0-9a-zäγ²^]+", raw.lower())) - {""}
    if "db" not in tokens:
        found = {kind for kind, names in _NAMES.items() if tokens & names}
        if len(found) == 1:
            return found.pop(), unit
    if "db" in key:
        raise FileFormatError(f"{name}, line {line}: column {_shown(cell)}: a magnitude in dB has no unit of its own "
                              "(dB of what?); export the real and imaginary parts, or the magnitude in a unit "
                              "such as m/N or g/N with the phase")
    raise FileFormatError(
        f"{name}, line {line}: column {_shown(cell)}; expected frequency, then real and imaginary parts or magnitude "
        "and phase, and optionally the coherence (e.g. 'frequency_hz,real,imag' or "
        "'Frequency [Hz];Magnitude [m/N];Phase [deg];Coherence')")


def _is_number(cell: str) -> bool:
    try:
        float(cell.replace(",", "."))
    except ValueError:
        return False
    return True


def _same_unit(a: str, b: str) -> bool:
    """Whether two unit texts (a header's and a units row's) are the same unit, written alike or not."""
    if a.replace(" ", "") == b.replace(" ", ""):
        return True
    try:
        qa, qb = _unit_of_label(a), _unit_of_label(b)
    except ValueError:
        return False
    return qa is not None and qb is not None and qa.dimensionality == qb.dimensionality and \
        abs(float((qa / qb).to_base_units().magnitude) - 1.0) < 1e-12


def _value_unit(unit: str | None, cell: str, name: str, line: int):
    """``(quantity, factor to SI)`` of a value column's unit; ``(None, 1)`` without one."""
    if unit is None:
        return None, 1.0
    if "db" in unit.lower():
        raise FileFormatError(f"{name}, line {line}: column {_shown(cell)}: a magnitude in dB has no unit of its own "
                              "(dB of what?); give the magnitude in a unit such as m/N or g/N")
    try:
        q = _unit_of_label(unit)
    except ValueError:
        q = None
    found = frf_quantity(q, lengths=(1,))
    if found is None:
        raise FileFormatError(f"{name}, line {line}: column {_shown(cell)}: the unit {_shown(unit)} is not that of a "
                              "receptance, mobility or accelerance (e.g. m/N, mm/N, um/N, (m/s^2)/N, g/N)")
    return found


_INDEX_NAMES = {"", "index", "unnamed: 0"}


def _without_index(cells: list[list[str]]) -> list[list[str]]:
    """The table without a leading row-number column, as ``pandas.DataFrame.to_csv`` (an empty or ``index``
    header cell, rows 0, 1, 2, ...) or R's ``write.csv`` (rows 1, 2, ...) write one; the table as it is
    otherwise (a units row under the names may leave the column's cell empty)."""
    if len(cells) < 3 or not cells[0] or cells[0][0].lower() not in _INDEX_NAMES:
        return cells
    body = cells[1:]
    if body[0] and body[0][0] == "" and not any(_is_number(c) for c in body[0][1:]):
        body = body[1:]  # a units row
    start = body[0][0] if body and body[0] else ""
    if start not in ("0", "1") or any(not row or row[0] != str(k + int(start)) for k, row in enumerate(body)):
        return cells
    return [row[1:] for row in cells]


def _header_below(rows: list[tuple[int, str]], name: str) -> tuple[int, str] | None:
    """The first of ``rows`` that reads as a table's header (a frequency column first, every cell a column's
    name), as when a block of metadata lines without ``#`` comes before the table; None without one."""
    for number, line in rows:
        delimiter = ";" if ";" in line else "\t" if "\t" in line else ","
        cells = [c.strip() for c in next(csv.reader([line], delimiter=delimiter))]
        while cells and cells[-1] == "":
            cells.pop()
        if len(cells) < 3:
            continue
        try:
            kinds = [_column(c, name, number)[0] for c in cells]
        except FileFormatError:
            continue
        if kinds[0] == "frequency":
            return number, line
    return None


def parse_export(numbered: list[tuple[int, str]], name: str, quantity: str | None):
    """Read a CSV export whose header is not the package's own.

    Parameters
    ----------
    numbered : list of (int, str)
        The non-blank lines of the file with their 1-based line numbers.
    name : str
        The file, for messages.
    quantity : str or None
        The quantity the caller says the file holds; ``None`` when not said.

    Returns
    -------
    table : numpy.ndarray
        ``(n, 3)``: frequency in Hz, real and imaginary parts in SI units.
    lines : numpy.ndarray
        The line number of each row.
    quantity : str or None
        The quantity the header's units say (``None`` when they say nothing).

    Raises
    ------
    FileFormatError
        Naming the file and the line, for what cannot be read unambiguously
        (a coherence column is checked, and read by
        :func:`~substructure.io.frf_files.read_csv_with_coherence`).
    """
    return read_export(numbered, name, quantity)[:3]


def read_export(numbered: list[tuple[int, str]], name: str, quantity: str | None):
    """:func:`parse_export`, and the coherence column's values in [0, 1] (None without one) as a fourth item."""
    from ...units import cycles_per_second

    rows = [(n, line) for n, line in numbered if not line.lstrip().startswith("#")]
    if not rows:
        raise FileFormatError(f"{name}: only comment lines; expected a header such as 'frequency_hz,real,imag'")
    first, header = rows[0]
    delimiter = ";" if ";" in header else "\t" if "\t" in header else ","
    if delimiter not in header and len(rows) > 1 and not any(d in rows[1][1] for d in ";\t,"):
        # columns separated by blanks (numpy.savetxt's default): the header split as the first row is, its
        # cells by runs of two blanks when single blanks are inside them ('Frequency [Hz]')
        width = len(rows[1][1].split())
        heads = [[c for c in re.split(pattern, header.strip()) if c] for pattern in (r"\s{2,}", r"\s+")]
        delimiter = " "
        cells = [next((h for h in heads if len(h) == width), heads[0])] + [line.split() for _, line in rows[1:]]
    else:
        cells = list(csv.reader([line for _, line in rows], delimiter=delimiter))
    cells = [[c.strip() for c in row] for row in cells]
    for row in cells:
        while row and row[-1] == "":  # an empty trailing column (a spreadsheet's last separator)
            row.pop()
    cells = _without_index(cells)
    try:
        columns = [_column(c, name, first) for c in cells[0]]
    except FileFormatError:
        below = _header_below(rows[1:51], name)
        if below is None:
            raise
        raise FileFormatError(f"{name}, line {first}: {_shown(header)} is not the table's header, line {below[0]} "
                              f"({_shown(below[1])}) is: start the lines above it with '#' (comment lines, such as "
                              "an export's date or channel names, are skipped)") from None
    if len(cells) > 1 and cells[1] and not any(_is_number(c) for c in cells[1]):
        # a row of units under the names (an empty cell: no unit), as acquisition programs export them
        units = cells[1] + [""] * (len(columns) - len(cells[1]))
        for (_, unit), u, cell in zip(columns, units, cells[0]):
            row_unit = bare_unit(u)
            if unit is not None and row_unit is not None and not _same_unit(unit, row_unit):
                raise FileFormatError(f"{name}, line {rows[1][0]}: column {_shown(cell)}: the units row says "
                                      f"{_shown(row_unit)} but the header {_shown(unit)}; give the unit once, "
                                      "or correct the one that is wrong")
        columns = [(kind, unit if unit is not None else bare_unit(u)) for (kind, unit), u in zip(columns, units)]
        cells, rows = [cells[0]] + cells[2:], [rows[0]] + rows[2:]
    kinds = [k for k, _ in columns]
    if kinds[:3] not in (["frequency", "real", "imag"], ["frequency", "magnitude", "phase"]) \
            or kinds[3:] not in ([], ["coherence"]):
        raise FileFormatError(
            f"{name}, line {first}: columns {_shown(delimiter.join(cells[0]))}; expected frequency, then real and "
            "imaginary parts, or frequency, magnitude and phase, in this order (then the coherence, if any)")
    width = len(kinds)
    gamma_factor = _COHERENCE_UNITS.get(columns[3][1]) if width == 4 else 1.0
    if gamma_factor is None:
        raise FileFormatError(f"{name}, line {first}: column {_shown(cells[0][3])}: a coherence has no unit (or %); "
                              f"got {_shown(columns[3][1] or '')}")
    fcell, vcells = cells[0][0], cells[0][1:]
    if columns[0][1] is None:
        raise FileFormatError(f"{name}, line {first}: column {_shown(fcell)} has no unit; name it frequency_hz or give "
                              "the unit, e.g. 'Frequency [Hz]'")
    try:  # as a universal file's abscissa: capitals (HZ, KHZ, RPM) read, MHZ (mHz or MHz?) not
        funit = _frequency_unit(columns[0][1])
        ok = funit is not None and funit.check("1 / [time]")
    except ValueError:
        ok = False
    if not ok:
        raise FileFormatError(f"{name}, line {first}: column {_shown(fcell)}: {_shown(columns[0][1])} is not a "
                              "frequency unit (Hz, kHz, rad/s, rpm)")
    if kinds[1] == "real":
        said = [_value_unit(u, c, name, first) for (_, u), c in zip(columns[1:3], vcells[:2])]
        if said[0] != said[1]:
            raise FileFormatError(f"{name}, line {first}: the real and imaginary parts have different units "
                                  f"({columns[1][1]!r}, {columns[2][1]!r})")
        kind, factor = said[0]
        angle = None
    else:
        kind, factor = _value_unit(columns[1][1], vcells[0], name, first)
        angle = {"deg": np.pi / 180, "degree": np.pi / 180, "degrees": np.pi / 180, "°": np.pi / 180,
                 "rad": 1.0, "radian": 1.0, "radians": 1.0}.get((columns[2][1] or "").lower())
        if angle is None:
            raise FileFormatError(f"{name}, line {first}: column {_shown(vcells[1])}: give the phase's unit, "
                                  "'Phase [deg]' or 'Phase [rad]'")
        if columns[1][1] is None and quantity is None:
            raise FileFormatError(f"{name}, line {first}: column {_shown(vcells[0])} has no unit; give it "
                                  "(e.g. 'Magnitude [m/N]') or say the quantity")
    if kind is not None and quantity is not None and kind != quantity:
        raise _contradiction(name, first, kind, quantity)
    data = cells[1:]
    lines = np.array([n for n, _ in rows[1:]])
    for n, row in zip(lines, data):
        if len(row) != width:
            raise FileFormatError(f"{name}, line {n}: {_shown(delimiter.join(row))} has {len(row)} value(s); "
                                  f"expected {width}")
    text = [[c.replace(",", ".") if delimiter != "," else c for c in row] for row in data]
    try:
        table = np.array(text, dtype=np.float64).reshape(-1, width)
    except ValueError:
        for n, row, written in zip(lines, text, data):
            for column, cell, given in zip(cells[0], row, written):
                try:
                    float(cell)
                except ValueError:
                    hint = (" (with decimal commas, a point is a thousands separator: write the number without it)"
                            if delimiter != "," and "," in given and "." in given else "")
                    raise FileFormatError(f"{name}, line {n}: {_shown(column)} is {_shown(given)}; "
                                          f"expected a number{hint}") from None
        raise  # pragma: no cover - numpy and float() disagree on a cell
    if angle == 1.0 and (np.abs(table[:, 2]) > 2 * np.pi + 1e-9).any():
        k = int(np.argmax(np.abs(table[:, 2]) > 2 * np.pi + 1e-9))
        raise FileFormatError(f"{name}, line {lines[k]}: {cells[0][2]} is {_shown(data[k][2])}, beyond 2 pi: degrees "
                              "labelled rad? Label the column 'Phase [deg]' if so; a phase in rad is read within "
                              "[-2 pi, 2 pi] (wrap an unwrapped phase, or give it in degrees)")
    if angle is not None and (table[:, 1] < 0).any():
        k = int(np.argmax(table[:, 1] < 0))
        raise FileFormatError(f"{name}, line {lines[k]}: {cells[0][1]} is {_shown(data[k][1])}; a magnitude is >= 0 (a "
                              "negative one would turn the phase by 180 degrees): check the export")
    coherence = None
    if width == 4:
        coherence = table[:, 3] * gamma_factor
        bad = ~(np.isfinite(coherence) & (coherence >= 0.0) & (coherence <= 1.0 + 1e-9))
        if bad.any():
            k = int(np.argmax(bad))
            raise FileFormatError(f"{name}, line {lines[k]}: {cells[0][3]} is {_shown(data[k][3])}; expected a "
                                  f"coherence in [0, 1]{' (0 to 100 %)' if gamma_factor != 1.0 else ''}")
        if gamma_factor != 1.0 and np.nanmax(table[:, 3]) <= 1.0:
            raise FileFormatError(f"{name}, line {first}: column {_shown(cells[0][3])} is in %, but no line holds more "
                                  f"than {float(np.nanmax(table[:, 3]))!r} (%): fractions in [0, 1] labelled %? Give "
                                  "the column without a unit if so")
        coherence = np.minimum(coherence, 1.0)
        table = table[:, :3].copy()
    with np.errstate(over="ignore", invalid="ignore"):
        hz: Any = table[:, 0] * funit  # a quantity: the column times its unit
        table[:, 0] = np.asarray(cycles_per_second(hz, fcell), dtype=np.float64)
        if angle is not None:
            value = table[:, 1] * np.exp(1j * table[:, 2] * angle)
            table[:, 1], table[:, 2] = value.real, value.imag
        table[:, 1:] *= factor
    return table, lines, kind, coherence
