"""The layout of a text tap record: preamble, header, units, the sample rate and the channels chosen.

Acquisition systems write metadata lines before the header (``Sample rate:
51200 Hz``, ``Date: ...``), the units in the names (``Force [N]``, ``Force
(N)``, ``Force/N``, ``Force in N``) or in a row of their own under the
names, and more channels than a tap test needs.  The functions here find the
first row of numbers, the header above it, the sample rate the preamble
states, and the time, force and response columns; every refusal names the
file and the line.
"""

from __future__ import annotations

import re
from typing import Any

import attrs

from ..errors import FileFormatError, SubstructureError
from ..tap.records import unit_of
from ..units import bare_unit

MAX_PREAMBLE_LINES = 2000
"""Lines read before the first row of numbers; a file with none by then is refused."""

_NUMBER = re.compile(r"^[-+]?(?:\d+(?:\.\d*)?|\.\d+)(?:[eE][-+]?\d+)?$|^[-+]?(?:nan|inf|infinity)$", re.I)
_BRACKETS = re.compile(r"^\s*([^\[\]]*?)\s*\[\s*([^\[\]]*?)\s*\]\s*$")
_PARENS = re.compile(r"^\s*([^()\[\]]*?)\s*\(\s*([^()\[\]]*?)\s*\)\s*$")
_IN = re.compile(r"^\s*(.*?[A-Za-z].*?)\s+in\s+(\S.*?)\s*$")
_SLASH = re.compile(r"^\s*([A-Za-z][^/]*?)\s*/\s*(\S.*?)\s*$")
_VALUE = r")\b\s*(?:[\[(]\s*([^\])]*?)\s*[\])])?\s*[:=,;\t ]\s*(.*)$"  # the key's optional [unit], then the value
_RATE_KEY = re.compile(r"^\s*#?\s*(sample[ _-]?rate|sampling[ _-]?rate|sampling[ _-]?frequency|sample[ _-]?frequency"
                       r"|samplerate|fs" + _VALUE, re.I)
_STEP_KEY = re.compile(r"^\s*#?\s*(dt|delta[ _-]?x|delta[ _-]?t|increment|x[ _-]?increment|sample[ _-]?interval"
                       r"|sampling[ _-]?interval|time[ _-]?step" + _VALUE, re.I)
_SAMPLES_PER_SECOND = re.compile(r"^(s/s|sa/s|samples?/s|samples? per second|sps)$", re.I)
_TIME_NAME = re.compile(r"^(time|t|zeit|temps|tiempo|x_value)$", re.I)
NO_UNIT = ("", "-", "--", "n/a", "none")
"""Cells of a row of units that say a column has none (a trigger, a status)."""
_UNIT_WORDS = {"volts": "V", "volt": "V", "millivolts": "mV", "newtons": "N", "newton": "N", "kilonewtons": "kN",
               "pounds": "lbf", "kilogramforce": "kgf", "seconds": "s", "second": "s", "sec": "s",
               "meterspersecondsquared": "m/s^2", "metrespersecondsquared": "m/s^2", "inchespersecondsquared": "in/s^2",
               "meterspersecond": "m/s", "metrespersecond": "m/s", "inchespersecond": "in/s"}


def unit_label(label: str) -> str | None:
    """A unit as NI's software writes it (``Volts``, ``Newtons``, ``MetersPerSecondSquared``) in the form pint
    reads; None for no unit (empty, ``None``, ``EU``: engineering units not named, ``-``)."""
    label = label.strip()
    if not label or label.lower() in ("none", "eu", "-"):
        return None
    return _UNIT_WORDS.get(label.lower().replace(" ", ""), label)


_FORCE_NAME = re.compile(r"\b(force|hammer|kraft|impact)", re.I)
_QUANTITY_NAMES = (("acceleration", re.compile(r"(?<![a-z])(acc|beschl)", re.I)),
                   ("velocity", re.compile(r"(?<![a-z])(vel|vibrometer|ldv|geschw)", re.I)),
                   ("displacement", re.compile(r"(?<![a-z])(disp|proximity|weg(?![a-z]))", re.I)))
"""Words of a response column's name that say its quantity (English and German): a unit of another quantity beside
them is a mistake of the name or of the unit ('acceleration [m/s]'), refused rather than read as the unit says."""


def line_separator(line: str) -> str | None:
    """The separator a line uses: a tab, a semicolon, a comma, or None for whitespace."""
    return "\t" if "\t" in line else ";" if ";" in line else "," if "," in line else None


def unquote(cell: str) -> str:
    """A cell without its blanks and the double quotes around it (``"0.25"``: some exports quote every cell)."""
    cell = cell.strip()
    return cell[1:-1].strip() if len(cell) >= 2 and cell[0] == cell[-1] == '"' else cell


def is_number(cell: str, decimal_comma: bool) -> bool:
    """Whether a cell is one number (``0,5`` too when ``decimal_comma``), quoted or not."""
    cell = unquote(cell)
    return bool(_NUMBER.match(cell.replace(",", ".") if decimal_comma else cell))


def is_row(line: str, first: bool = True) -> bool:
    """Whether a line is a row of numbers: its first cell (unless not ``first``) and half of its cells are numbers."""
    sep = line_separator(line)
    cells = [c for c in (line.split() if sep is None else line.split(sep))]
    if sep is not None and len(cells) > 1 and not cells[-1].strip():
        cells = cells[:-1]
    decimal_comma = sep in ("\t", ";")
    numbers = [is_number(c, decimal_comma) for c in cells]
    if not first:
        return len(cells) > 1 and 2 * sum(numbers[1:]) > len(numbers)
    return bool(cells) and numbers[0] and 2 * sum(numbers) >= len(numbers)


def header_cells(line: str, sep: str | None, ncols: int) -> list[str]:
    """The cells of a header line, split as the rows are (a header of whitespace rows may hold 'time [s]')."""
    if sep is not None:
        cells = line.split(sep)
        while len(cells) > ncols and not cells[-1].strip():
            cells = cells[:-1]
        return [c.strip().strip('"') for c in cells]
    for pattern in (r"\t+|\s{2,}", r"\s+"):
        cells = [c for c in re.split(pattern, line.strip()) if c]
        if len(cells) == ncols:
            return [c.strip('"') for c in cells]
    return [c for c in re.split(r"\t+|\s{2,}", line.strip()) if c]


def name_and_unit(cell: str) -> tuple[str, str | None]:
    """A header cell's name and unit: ``Force [N]``, ``Force (N)``, ``Force in N``, ``Force/N``, or no unit."""
    for pattern in (_BRACKETS, _PARENS, _IN, _SLASH):
        match = pattern.match(cell)
        if match and match.group(1) and match.group(2):
            if pattern in (_IN, _SLASH):  # only when what follows is a unit
                try:
                    unit_of(match.group(2), "")
                except SubstructureError:
                    continue
            return match.group(1), match.group(2)
    return cell.strip(), None


def is_unit_row(cells: list[str]) -> bool:
    """Whether header cells are units alone (``s,N,g``): a row of units under the names."""
    filled = [c for c in cells if c.strip() not in NO_UNIT]
    if not filled:
        return False
    for cell in filled:
        if is_number(cell, False):
            return False
        try:
            unit_of(bare_unit(cell) or "", "")
        except SubstructureError:
            return False
    return True


@attrs.frozen
class Columns:
    """The header of a record: each column's name and unit text (None when it has none), where it was read."""

    names: list[str]
    units: list[str | None]
    line: int | None  # None for a file without lines (a MATLAB file)

    @property
    def labels(self) -> list[str]:
        """``name [unit]`` of each column (the name alone without a unit)."""
        return [f"{n} [{u}]" if u else n for n, u in zip(self.names, self.units)]


def rate_from_lines(lines: list[tuple[int, str]], name: str, decimal_comma: bool) -> tuple[float, int] | None:
    """The sample rate (Hz) a preamble states and the line that states it, or None.

    Recognised: ``Sample rate``, ``Sampling rate``, ``Sampling frequency``,
    ``Fs`` (Hz unless a unit follows: ``51.2 kHz``, ``51200 S/s``) and
    ``dt``, ``Delta_X``, ``Delta t``, ``Increment``, ``Sample interval``,
    ``Time step`` (s unless a unit follows).  Several values on one line
    (one per channel) must agree, and so must the lines that state it.
    """
    found: list[tuple[float, int, str]] = []
    for number, line in lines:
        for pattern, kind in ((_RATE_KEY, "rate"), (_STEP_KEY, "step")):
            match = pattern.match(line)
            if not match:
                continue
            rest = match.group(3).replace("\t", " ").replace(";", " ")
            rest = rest.replace(",", ".") if decimal_comma else rest.replace(",", " ")
            tokens = rest.split()
            values = [float(t) for t in tokens if is_number(t, False)]
            unit_text = match.group(2) or " ".join(t for t in tokens if not is_number(t, False)) or None
            if not values:
                raise FileFormatError(f"{name}, line {number}: {match.group(1)!r} without a number; expected e.g. "
                                      f"'{'Sample rate: 51200 Hz' if kind == 'rate' else 'dt: 1.953125e-05 s'}'")
            if any(abs(v - values[0]) > 1e-9 * abs(values[0]) for v in values):
                raise FileFormatError(f"{name}, line {number}: {match.group(1)!r} gives different values "
                                      f"({', '.join(f'{v:g}' for v in values)}); expected one sample rate for "
                                      "all channels")
            hz = _to_hz(values[0], unit_text, kind, f"{name}, line {number}", match.group(1))
            found.append((hz, number, match.group(1)))
            break
    if not found:
        return None
    hz, number, key = found[0]
    for other, at, other_key in found[1:]:
        if abs(other - hz) > 1e-6 * hz:
            raise FileFormatError(f"{name}, lines {number} and {at}: {key!r} gives {hz:.10g} Hz and "
                                  f"{other_key!r} {other:.10g} Hz; the preamble contradicts itself")
    return hz, number


def _to_hz(value: float, unit_text: str | None, kind: str, where: str, key: str = "") -> float:
    """The sample rate in Hz of a preamble's ``value`` of a rate or a step (``kind``) in ``unit_text``; ``key``:
    the name the file gives it, for messages (a step is named as written, not as the rate it gives)."""
    from ..units import ureg

    if unit_text and _SAMPLES_PER_SECOND.match(unit_text.strip()):
        unit_text = "Hz"
    unit_text = unit_text or ("Hz" if kind == "rate" else "s")
    try:
        q = value * ureg.Quantity(1.0, unit_of(unit_text, where))
    except SubstructureError:
        raise FileFormatError(f"{where}: cannot read the unit {unit_text!r} of the sample "
                              f"{'rate' if kind == 'rate' else 'interval'}; expected e.g. Hz, kHz, S/s or s, ms, us") \
            from None
    if kind == "rate" and q.check("1/[time]"):
        hz = q.m_as("Hz")
    elif kind == "step" and q.check("[time]"):
        hz = 1.0 / q.m_as("s") if q.magnitude else 0.0
    else:
        raise FileFormatError(f"{where}: the sample {'rate' if kind == 'rate' else 'interval'} is in "
                              f"{unit_text!r}; expected {'Hz' if kind == 'rate' else 's'}")
    if kind == "step" and not (q.magnitude > 0 and hz < float("inf")):
        written = f"{value:g}" + (f" {unit_text}" if unit_text else "")
        raise FileFormatError(f"{where}: {key or 'the sample interval'!r} is {written}; expected a positive time "
                              "step")
    if not hz > 0 or hz == float("inf"):
        raise FileFormatError(f"{where}: a sample rate of {hz:g} Hz; expected a positive rate")
    return float(hz)


def pick(option: Any, columns: Columns, what: str, flag: str, name: str) -> int:
    """The 0-based column an option names: a 1-based index, or a column's name or label (any case)."""
    listing = "; ".join(f"{k + 1}: {label}" for k, label in enumerate(columns.labels))
    text = str(option).strip()
    if text.isdigit():
        k = int(text) - 1
        if not 0 <= k < len(columns.names):
            raise FileFormatError(f"{name}: {flag} {text}: the file has {len(columns.names)} columns ({listing})")
        return k
    hits = [k for k, (n, label) in enumerate(zip(columns.names, columns.labels))
            if text.lower() in (n.lower(), label.lower())]
    if len(hits) != 1:
        raise FileFormatError(f"{name}: {flag} {text!r} names {'no' if not hits else len(hits)} columns; "
                              f"expected a name or a 1-based index of the {what} among: {listing}")
    return hits[0]


def choose(columns: Columns, parsed: list[Any], dims: list[str | None], name: str, force_column: Any,
           response_column: Any, has_rate: bool,
           rate_hint: str = "a preamble line such as 'Sample rate: 51200 Hz' or 'dt: 1.953125e-05 s'",
           ) -> tuple[int | None, int, int]:
    """The time (or None), force and response columns of a header.

    ``parsed`` holds each column's pint unit (None when the header has none
    or pint cannot read it), ``dims`` its quantity (``time``, ``force``,
    ``voltage``, ``acceleration``, ``velocity``, ``displacement`` or None).
    """
    where = name if columns.line is None else f"{name}, line {columns.line}"
    labels = columns.labels
    listing = "; ".join(f"{k + 1}: {label}" for k, label in enumerate(labels))
    times = [k for k, d in enumerate(dims) if d == "time" or (columns.units[k] is None
                                                            and _TIME_NAME.match(columns.names[k]))]
    if len(times) > 1:
        raise FileFormatError(f"{where}: {len(times)} columns in units of time ({', '.join(labels)}); expected "
                              "one, e.g. 'time [s]'")
    t_col = times[0] if times else None
    if t_col is not None and len(labels) < 3:
        raise FileFormatError(f"{where}: {len(labels)} columns ({', '.join(labels)}); expected three: time, "
                              "force and one response")
    others = [k for k in range(len(labels)) if k != t_col]
    chosen_force = pick(force_column, columns, "force", "--force-column", name) if force_column is not None else None
    chosen_resp = pick(response_column, columns, "response", "--response-column", name) \
        if response_column is not None else None
    for k, flag in ((chosen_force, "--force-column"), (chosen_resp, "--response-column")):
        if k is not None and k == t_col:
            raise FileFormatError(f"{name}: {flag} names the time column {labels[k]!r}")
    if chosen_force is not None and chosen_force == chosen_resp:
        raise FileFormatError(f"{name}: --force-column and --response-column name the same column "
                              f"{labels[chosen_force]!r}")
    if chosen_force is None:
        forces = [k for k in others if k != chosen_resp and (
            dims[k] == "force" or (dims[k] in ("voltage", None) and _FORCE_NAME.search(columns.names[k])))]
        if not forces and len(others) == 2 and sorted(dims[k] == "voltage" for k in others) == [False, True] \
                and any(dims[k] in ("acceleration", "velocity", "displacement") for k in others):
            # two channels, a response and one in volts (a hammer seen as its voltage): the other channel
            forces = [k for k in others if dims[k] == "voltage"]
        if len(forces) != 1:
            raise FileFormatError(f"{where}: {len(forces)} force columns ({listing}); expected one column in N "
                                  "(or named 'force' or 'hammer', in mV with a hammer sensitivity); choose it "
                                  "with --force-column NAME or INDEX (force_column=)")
        chosen_force = forces[0]
    if chosen_resp is None:
        rest = [k for k in others if k != chosen_force]
        if len(rest) == 1:
            chosen_resp = rest[0]  # time, force and one more: the response, whatever its unit says
        else:
            responses = [k for k in rest if dims[k] in ("acceleration", "velocity", "displacement")]
            if len(responses) != 1:
                raise FileFormatError(f"{where}: {len(responses)} response columns among {len(rest)} that are "
                                      f"neither time nor force ({listing}); choose one with --response-column "
                                      "NAME or INDEX (response_column=)")
            chosen_resp = responses[0]
    said = [q for q, pattern in _QUANTITY_NAMES if pattern.search(columns.names[chosen_resp])]
    if len(said) == 1 and dims[chosen_resp] in ("acceleration", "velocity", "displacement") \
            and said[0] != dims[chosen_resp]:
        raise FileFormatError(f"{where}: column {labels[chosen_resp]!r}: its name says {said[0]} and its unit "
                              f"{dims[chosen_resp]}; correct the one that is wrong (e.g. 'acceleration [m/s^2]', "
                              "'velocity [m/s]')")
    if t_col is None and not has_rate:
        raise no_rate(where, labels, rate_hint)
    return t_col, chosen_force, chosen_resp


def no_rate(where: str, labels: list[str], rate_hint: str) -> FileFormatError:
    """The error of a record without a time column or a sample rate (``rate_hint``: where the file could say it)."""
    return FileFormatError(f"{where}: no column in units of time ({', '.join(labels)}) and no sample rate; give the "
                           f"rate with --sample-rate (e.g. '51.2 kHz', sample_rate=) or {rate_hint}")
