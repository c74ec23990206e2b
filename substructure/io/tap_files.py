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
"""

from __future__ import annotations

import os
import re
from typing import Any

import numpy as np

from ..errors import FileFormatError, SubstructureError
from ..tap.records import RESPONSE_QUANTITIES, TapRecord, channel_to_si, unit_of
from . import check_readable_file, read_text

__all__ = ["read_tap_csv", "read_tap_uff"]

_COLUMN = re.compile(r"^\s*([^\[\]]*?)\s*\[\s*([^\[\]]*?)\s*\]\s*$")
_COLUMN_PARENS = re.compile(r"^\s*([^()\[\]]*?)\s*\(\s*([^()\[\]]*?)\s*\)\s*$")  # 'time (s)', as exports write it
_RESPONSES = ("acceleration", "velocity", "displacement")


def _check_quantity_option(quantity: str | None, found: str, where: str) -> None:
    if quantity is None:
        return
    if quantity not in RESPONSE_QUANTITIES:
        raise FileFormatError(f"quantity: got {quantity!r}; expected one of {', '.join(RESPONSE_QUANTITIES)}")
    if quantity != found:
        raise FileFormatError(f"{where} holds {'an' if found[0] in 'aeiou' else 'a'} {found}, and the quantity "
                              f"option says {quantity}; leave the option out or fix the file")


def read_tap_csv(path: str | os.PathLike, sensitivity: Any = None, hammer_sensitivity: Any = None,
                 quantity: str | None = None) -> TapRecord:
    """Read a CSV file of one tap record (or a long record of several taps).

    Parameters
    ----------
    path : str or path-like
        The file: header ``time [s],force [N],acceleration [m/s^2]`` (units
        in brackets, or in parentheses ``time (s)``; columns separated by
        commas, or by semicolons or tabs with decimal commas allowed in the
        cells; the response may be ``[g]``, velocity ``[m/s]``,
        ``[mm/s]``, displacement ``[m]``, ``[um]``, or a voltage).
    sensitivity : str or pint.Quantity, optional
        The response sensor's sensitivity, e.g. ``"10.2 mV/g"``: required
        for a response column in ``mV`` or ``V``, refused otherwise.
    hammer_sensitivity : str or pint.Quantity, optional
        The hammer's, e.g. ``"2.25 mV/N"``, for a force column in volts.
    quantity : {"acceleration", "velocity", "displacement"}, optional
        What the response is; it must agree with the column's unit.

    Returns
    -------
    TapRecord
        In SI units; ``source`` is the file name.

    Raises
    ------
    FileFormatError
        Naming the file, the line and the column: an empty file, a column
        without a unit, columns that are not one time, one force and one
        response, a cell that is not a number, NaN samples, a contradiction
        between the header and the options.
    """
    name = os.fspath(path)
    lines = read_text(path).splitlines()
    numbered = [(k + 1, line) for k, line in enumerate(lines) if line.strip() and not line.lstrip().startswith("#")]
    if not numbered:
        raise FileFormatError(f"{name}: the file is empty; expected a header such as "
                              "'time [s],force [N],acceleration [m/s^2]' and one row per sample")
    header_line, header = numbered[0]
    header = header.lstrip("\ufeff")
    # the separator the header uses: a comma, or (acquisition systems of decimal-comma locales) a semicolon
    # or a tab, whose cells may then write 0,5 for 0.5
    sep = "," if "," in header else ";" if ";" in header else "\t" if "\t" in header else ","
    names, units = [], []
    for k, cell in enumerate(header.split(sep)):
        match = _COLUMN.match(cell) or _COLUMN_PARENS.match(cell)
        if not match or not match.group(1) or not match.group(2):
            raise FileFormatError(f"{name}, line {header_line}: column {k + 1} {cell.strip()!r} has no unit in "
                                  "brackets; expected e.g. 'time [s]', 'force [N]', 'acceleration [m/s^2]' "
                                  "(separated by commas, semicolons or tabs)")
        names.append(match.group(1))
        units.append(match.group(2))
    labels = [f"{n} [{u}]" for n, u in zip(names, units)]
    if len(names) != 3:
        raise FileFormatError(f"{name}, line {header_line}: {len(names)} columns ({', '.join(labels)}); expected "
                              "three: time, force and one response")
    parsed = []
    for label, unit in zip(labels, units):
        try:
            parsed.append(unit_of(unit, f"{name}: column {label!r}"))
        except SubstructureError as exc:
            raise FileFormatError(f"{name}, line {header_line}: {str(exc).split(': ', 2)[-1]} (column {label!r})") \
                from None
    times = [k for k, u in enumerate(parsed) if (1.0 * u).check("[time]")]
    if len(times) != 1:
        raise FileFormatError(f"{name}, line {header_line}: {len(times)} columns in units of time "
                              f"({', '.join(labels)}); expected one, e.g. 'time [s]'")
    forces = [k for k, u in enumerate(parsed) if k not in times and (
        (1.0 * u).check("[force]") or names[k].lower() in ("force", "hammer"))]
    if len(forces) != 1:
        raise FileFormatError(f"{name}, line {header_line}: {len(forces)} force columns ({', '.join(labels)}); "
                              "expected one column in N (or named 'force' or 'hammer', in mV with a hammer "
                              "sensitivity)")
    (t_col,), (f_col,) = times, forces
    r_col = ({0, 1, 2} - {t_col, f_col}).pop()
    rows = numbered[1:]
    if not rows:
        raise FileFormatError(f"{name}: a header and no samples; expected one row per sample")
    cells = [line.split(sep) if sep == "," else line.replace(",", ".").split(sep) for _, line in rows]
    for (number, line), row in zip(rows, cells):
        if len(row) != 3:
            raise FileFormatError(f"{name}, line {number}: {len(row)} value(s); expected 3 ({', '.join(labels)})")
    try:
        table = np.array(cells, dtype=np.float64)
    except ValueError:
        for (number, _), row in zip(rows, cells):
            for label, cell in zip(labels, row):
                try:
                    float(cell)
                except ValueError:
                    raise FileFormatError(f"{name}, line {number}: column {label!r} is {cell.strip()!r}; "
                                          "expected a number") from None
        raise  # pragma: no cover
    bad = ~np.isfinite(table)
    if bad.any():
        row, column = np.argwhere(bad)[0]
        raise FileFormatError(f"{name}, line {rows[row][0]}: column {labels[column]!r} is {table[row, column]}; "
                              "expected a finite number (a gap in the acquisition?)")
    try:
        time_s = table[:, t_col] * (1.0 * parsed[t_col]).m_as("s")
        force, _ = channel_to_si(table[:, f_col], parsed[f_col], f"{name}: column {labels[f_col]!r}", ("force",),
                                 hammer_sensitivity, "hammer sensitivity (--hammer-sensitivity)")
        response, found = channel_to_si(table[:, r_col], parsed[r_col], f"{name}: column {labels[r_col]!r}",
                                        _RESPONSES, sensitivity, "sensitivity (--sensitivity)")
        _check_quantity_option(quantity, found, f"{name}: column {labels[r_col]!r}")
        return TapRecord(time_s, force, response, found, name, labels[f_col], labels[r_col])
    except FileFormatError:
        raise
    except SubstructureError as exc:
        message = str(exc)
        raise FileFormatError(message if message.startswith(name) else f"{name}: {message}") from None


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
    import pyuff

    name = check_readable_file(path, "tap record")
    try:
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

    def unit(k: int):
        label = str(records[k].get("ordinate_axis_units_lab", "") or "").strip()
        if not label or label.upper() in ("NONE", "N/A", "NA", "-"):
            return None
        try:
            return unit_of(label, f"{name}, record {k}")
        except SubstructureError as exc:
            raise FileFormatError(str(exc)) from None

    def kind(k: int) -> str | None:
        spec = int(records[k].get("ordinate_spec_data_type", 0))
        u = unit(k)
        by_type = "force" if spec in _FORCE_TYPES else _RESPONSE_TYPES.get(spec)
        by_unit = None
        if u is not None:
            for q in ("force", "acceleration", "velocity", "displacement"):
                if (1.0 * u).check({"force": "[force]", "acceleration": "[acceleration]", "velocity": "[velocity]",
                                    "displacement": "[length]"}[q]):
                    by_unit = q
        if by_type and by_unit and by_type != by_unit:
            raise FileFormatError(f"{name}, record {k}: the specific data type says {by_type}, the unit label "
                                  f"{records[k].get('ordinate_axis_units_lab')!r} says {by_unit}; fix one")
        return by_type or by_unit

    kinds = [kind(k) for k in range(len(records))]
    if force_record is None:
        found = [k for k, q in enumerate(kinds) if q == "force"]
        if len(found) != 1:
            raise FileFormatError(f"{name}: {len(found)} force records among {len(records)} type-58 records; "
                                  "give the force record's index (--force-record, 0-based)")
        force_record = found[0]
    if response_record is None:
        found = [k for k, q in enumerate(kinds) if q in _RESPONSES and k != force_record]
        if len(found) != 1:
            raise FileFormatError(f"{name}: {len(found)} response records among {len(records)} type-58 records; "
                                  "give the response record's index (--response-record, 0-based)")
        response_record = found[0]
    for option, k in (("force_record", force_record), ("response_record", response_record)):
        if not 0 <= k < len(records):
            raise FileFormatError(f"{name}: {option} {k}: the file holds {len(records)} type-58 records "
                                  f"(0 to {len(records) - 1})")
    f_set, r_set = records[force_record], records[response_record]
    t = np.asarray(f_set["x"], dtype=np.float64)
    if np.asarray(r_set["x"]).shape != t.shape or not np.allclose(r_set["x"], t, rtol=1e-9, atol=1e-12):
        raise FileFormatError(f"{name}: records {force_record} and {response_record} have different time axes; "
                              "expected both channels sampled together")
    labels = [f"record {force_record} ({str(f_set.get('id1', '')).strip() or 'force'})",
              f"record {response_record} ({str(r_set.get('id1', '')).strip() or 'response'})"]
    try:
        f_unit = unit(force_record) or unit_of("N", name)
        force, _ = channel_to_si(np.real(np.asarray(f_set["data"])), f_unit, f"{name}: {labels[0]}", ("force",),
                                 hammer_sensitivity, "hammer sensitivity (--hammer-sensitivity)")
        r_unit = unit(response_record)
        if r_unit is None:
            said = kinds[response_record] or quantity
            if said is None:
                raise FileFormatError(f"{name}: {labels[1]} has neither a unit label nor a specific data type; "
                                      "give the quantity (--quantity)")
            r_unit = unit_of(RESPONSE_QUANTITIES[said][0], name)
        response, found_q = channel_to_si(np.real(np.asarray(r_set["data"])), r_unit, f"{name}: {labels[1]}",
                                          _RESPONSES, sensitivity, "sensitivity (--sensitivity)")
        if kinds[response_record] in _RESPONSES and kinds[response_record] != found_q:
            raise FileFormatError(f"{name}: {labels[1]}: the specific data type says {kinds[response_record]}, the "
                                  f"sensitivity makes it {found_q}")
        _check_quantity_option(quantity, found_q, f"{name}: {labels[1]}")
        return TapRecord(t, force, response, found_q, name, labels[0], labels[1])
    except FileFormatError:
        raise
    except SubstructureError as exc:
        message = str(exc)
        raise FileFormatError(message if message.startswith(name) else f"{name}: {message}") from None
