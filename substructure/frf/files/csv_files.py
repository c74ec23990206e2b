"""CSV files of one FRF: :func:`write_csv` and :func:`read_csv`.

One FRF per file, header ``frequency_hz,real,imag``, one line per frequency,
receptance in m/N unless told otherwise; values are written with every
digit (``repr``) so that a written file reads back to the same floats.  A
mobility or an accelerance is written with its SI unit in the header,
``frequency_hz,real [m/(N s^2)],imag [m/(N s^2)]``, so that it reads back as
what it is (here and in other programs); a receptance keeps the plain header.  A
fourth column ``coherence`` (the ordinary coherence of a tap test, in
[0, 1]) may follow, and after it ``force_noise`` (the variance of H1's
relative error that the hammer's noise gives, per line, a tap test's;
``inf`` where there was no force) and ``truncation`` (the variance of the
relative error the end of the taps leaves), each optional:
:func:`read_csv_with_coherence` returns the coherence, :func:`read_csv`
reads such files too and returns the FRF alone.

An FRF measured through an exponential window (``substructure tap``, where
the response still rang at the end of the taps) has the window's damping in
it; the file says so in a comment line before the header,
``# window_tau_s = 0.0217``, which :func:`read_csv_window` returns (the
``lobes`` command removes that damping, a measurement set compares the
model through the same window).
"""

from __future__ import annotations

import os
import re
import warnings
from typing import TYPE_CHECKING

import numpy as np

from ...errors import FileFormatError, InvalidValueError, WindowedFRFWarning
from .._fields import window_tau as _window_tau
from ..axis import MAX_GRID_LINES, Frequency
from ._common import _contradiction, _refuse_all_zero, _require_frf, _shown, frf_class
from .uff_units import _unit_of_label, frf_quantity

if TYPE_CHECKING:  # the annotations only (frf.response imports this module)
    from ..response import FRF

__all__ = ["write_csv", "read_csv", "read_csv_with_coherence", "read_csv_window"]

CSV_HEADER = "frequency_hz,real,imag"
COHERENCE_HEADER = CSV_HEADER + ",coherence"
FORCE_NOISE_HEADER = COHERENCE_HEADER + ",force_noise"
_VARIANCE_COLUMNS = ("force_noise", "truncation")  # after the coherence, in this order, each optional
_HEADERS = (CSV_HEADER, COHERENCE_HEADER, FORCE_NOISE_HEADER, COHERENCE_HEADER + ",truncation",
            FORCE_NOISE_HEADER + ",truncation")
WINDOW_KEY = "window_tau_s"
"""The comment line before the header that gives the exponential window's time constant [s]."""
_WINDOW_LINE = re.compile(r"#\s*window_tau_s\s*(?:=\s*(.*?))?\s*$")
_UNIT_CELL = re.compile(r"^(?P<name>real|imag)\s*\[(?P<unit>[^\[\]]*)\]$")


def _quantity_of_unit(unit: str, cell: str, name: str, line: int) -> tuple[str, float]:
    """``(quantity, factor to SI)`` of the unit of the package's own value columns, a displacement or a rotation
    (or its velocity, acceleration) per force or moment: ``m/N``, ``m/(N s^2)``, ``1/(N m s)``, ``mm/N``, ``g/N``."""
    try:
        q = _unit_of_label(unit)
    except ValueError:
        q = None
    found = frf_quantity(q)
    if found is None:
        raise FileFormatError(f"{name}, line {line}: column {_shown(cell)}: the unit {_shown(unit)} is not that of a "
                              "receptance, mobility or accelerance (e.g. m/N, m/(N s), m/(N s^2), 1/N, 1/(N m))")
    return found


def _units_header(header: str, name: str, line: int) -> tuple[str, str, float] | None:
    """The package's header with the value columns' unit, ``frequency_hz,real [U],imag [U][,...]``:
    ``(the header without the units, quantity, factor to SI)``; None for any other header."""
    cells = [c.strip() for c in header.lstrip("\ufeff").split(",")]
    if len(cells) < 3 or cells[0] != "frequency_hz":
        return None
    real, imag = _UNIT_CELL.match(cells[1]), _UNIT_CELL.match(cells[2])
    if real is None or imag is None or (real["name"], imag["name"]) != ("real", "imag"):
        return None
    plain = ",".join(["frequency_hz", "real", "imag"] + cells[3:])
    if plain not in _HEADERS:
        return None
    if real["unit"].replace(" ", "") != imag["unit"].replace(" ", ""):
        raise FileFormatError(f"{name}, line {line}: the real and imaginary parts have different units "
                              f"({_shown(real['unit'])} and {_shown(imag['unit'])}); expected one unit")
    kind, factor = _quantity_of_unit(real["unit"], cells[1], name, line)
    return plain, kind, factor


def write_csv(frf: FRF, path: str | os.PathLike, overwrite: bool = False, coherence=None, force_noise=None,
              truncation=None, window_tau: float | None = None) -> None:
    """Write a one-entry FRF to a CSV file ``frequency_hz,real,imag`` (``,coherence`` when given).

    A receptance is written under the plain header ``frequency_hz,real,imag``
    (m/N for ``y/f``).  A mobility or an accelerance is written with the SI
    unit of its values in the header, e.g.
    ``frequency_hz,real [m/(N s^2)],imag [m/(N s^2)]`` for an accelerance
    ``y/f`` (:meth:`FRF.unit`), so that :func:`read_csv`, a measurement set
    and other programs read it back as what it is.

    Parameters
    ----------
    frf : FRF
        Shape ``(n_freq, 1, 1)``; select one entry of a larger FRF first,
        e.g. ``frf["tool.tip:y", "tool.tip:y"]``.  The data are written as
        they are; the file records the quantity (the unit in the header of a
        mobility or an accelerance), not the labels.
    path : str or path-like
        The file, written through a temporary file and an atomic rename
        (:func:`substructure.io.replacing`).
    overwrite : bool, default False
        Whether an existing file may be replaced; without it an existing
        file is refused (:class:`~substructure.errors.OutputExistsError`, a
        ``FileExistsError``, naming the path).
    coherence : array of float, optional
        The coherence (dimensionless, in [0, 1]) on the FRF's lines, written
        as a fourth column ``coherence``.
    force_noise : array of float, optional
        With a coherence: per line, the variance of H1's relative error from
        the hammer's noise (``substructure.tap.TapResult.force_noise``;
        >= 0, ``inf`` allowed), written as a fifth column ``force_noise``.
    truncation : array of float, optional
        With a coherence: per line, the variance of the relative error the
        end of the taps leaves (``substructure.tap.TapResult.truncation``;
        >= 0, ``inf`` allowed), written as the last column ``truncation``.
    window_tau : float, optional
        The time constant [s] of the exponential window the FRF was measured
        through, written as a comment line ``# window_tau_s = ...`` before
        the header (:func:`read_csv_window`).

    Raises
    ------
    InvalidValueError
        For an FRF of more than one entry or of fewer than 2 lines (which
        no reader takes), a coherence of another length or outside [0, 1],
        or a force noise or truncation without a coherence, of another
        length, negative or NaN, or a window time constant that is not a
        number > 0.
    OutputExistsError
        When ``path`` exists and ``overwrite`` is false.
    """
    from ..._files import file_name, write_text

    frf = _require_frf(frf, "write_csv")
    path = file_name(path, "CSV file to write")
    if frf.frequency.n < 2:
        raise InvalidValueError(
            f"frf: cannot write {os.fspath(path)}: an FRF file needs at least 2 frequency lines (readers refuse fewer)"
        )
    if frf.shape[1:] != (1, 1):
        raise InvalidValueError(
            f"frf: a CSV file holds one FRF, this one has {frf.shape[1]}x{frf.shape[2]} entries "
            f"(outputs {list(frf.outputs)}, inputs {list(frf.inputs)}); select one entry first, "
            f"e.g. frf[{frf.outputs[0]!r}, {frf.inputs[0]!r}]"
        )
    values = frf.data[:, 0, 0]
    _refuse_all_zero(frf, os.fspath(path))
    header, columns = CSV_HEADER, [frf.frequency.hz, values.real, values.imag]
    if frf.quantity != "receptance":  # the unit says what the values are
        unit = frf.unit(frf.outputs[0], frf.inputs[0])
        header = f"frequency_hz,real [{unit}],imag [{unit}]"
    if coherence is not None:
        gamma = np.asarray(coherence, dtype=np.float64)
        if gamma.shape != (frf.frequency.n,) or not np.all((gamma >= 0) & (gamma <= 1)):
            raise InvalidValueError(
                f"coherence: cannot write {os.fspath(path)}: expected {frf.frequency.n} values in [0, 1], one per line"
            )
        header, columns = header + ",coherence", columns + [gamma]
    for column, given in zip(_VARIANCE_COLUMNS, (force_noise, truncation)):
        if given is None:
            continue
        v = np.asarray(given, dtype=np.float64)
        if coherence is None or v.shape != (frf.frequency.n,) or not np.all(v >= 0):
            raise InvalidValueError(f"{column}: cannot write {os.fspath(path)}: expected {frf.frequency.n} values "
                                    ">= 0 (inf allowed), one per line, and a coherence")
        header, columns = header + "," + column, columns + [v]
    comment = ""
    if window_tau is not None:
        tau = _window_tau(window_tau)
        comment = (f"# {WINDOW_KEY} = {tau!r}\n# measured through an exponential window exp(-t/tau): every mode "
                   "carries the added damping ratio 1/(tau omega)\n")
    text = "".join(",".join(map(repr, row)) + "\n" for row in zip(*(c.tolist() for c in columns)))
    write_text(path, comment + header + "\n" + text, overwrite=overwrite)


def read_csv_window(path: str | os.PathLike) -> float | None:
    """The exponential window's time constant a CSV file of an FRF declares, or None.

    ``substructure tap`` writes the line ``# window_tau_s = 0.0217`` before
    the header when it applied the window: the FRF is the structure's at
    the complex frequency ``omega - i/tau``, every mode with the added
    damping ratio ``1/(tau omega)``.

    Parameters
    ----------
    path : str or path-like
        The file (see :func:`read_csv`).

    Returns
    -------
    float or None
        ``tau`` [s], or None when the file declares no window.

    Raises
    ------
    FileFormatError
        As :func:`read_csv`, and for a ``window_tau_s`` line whose value is
        not a number > 0 or that is given twice, naming the file and the line.
    """
    return _read_csv(path, "response", "excitation", None)[3]


def _window_line(numbered: list, name: str) -> float | None:
    """The ``# window_tau_s = ...`` line among the comment lines before the header (None without one)."""
    tau, seen = None, None
    for number, line in numbered:
        text = line.strip().lstrip("\ufeff")
        if not text.startswith("#"):
            break
        match = _WINDOW_LINE.match(text)
        if match is None:
            continue
        if seen is not None:
            raise FileFormatError(f"{name}, line {number}: {WINDOW_KEY} is given again (first on line {seen})")
        try:
            tau, seen = _window_tau(float(match.group(1) or "nan")), number
        except ValueError:
            raise FileFormatError(f"{name}, line {number}: {_shown(text)}: expected '# {WINDOW_KEY} = SECONDS', the "
                                  "exponential window's time constant, a number > 0") from None
    return tau


def read_csv(
    path: str | os.PathLike,
    output: str = "response",
    input: str = "excitation",
    quantity: str | None = None,
) -> FRF:
    """Read a CSV file ``frequency_hz,real,imag`` into a one-entry FRF.

    A file with a fourth column ``coherence`` is read too; the coherence is
    checked and returned by :func:`read_csv_with_coherence`.

    Parameters
    ----------
    path : str or path-like
        The file.  Blank lines are ignored; a UTF-8 byte-order mark is allowed.
        Other exports (``;`` or tab separators with decimal commas, comment
        lines, units in the header, magnitude and phase) are read by
        ``substructure.io.frf_exports`` when unambiguous.
    output, input : str
        Labels of the response and excitation DOFs, e.g. ``"tool.tip:y"``.
    quantity : {"receptance", "mobility", "accelerance"}, optional
        What the file holds; default: what the header's units say, else
        receptance.  A quantity that contradicts the header's units is refused.

    Raises
    ------
    FileFormatError
        Naming the file and the line, for a missing file, a directory, a
        wrong header, a row without three numbers, NaN or inf, a negative,
        repeated or decreasing frequency, fewer than two rows, or a dead
        channel (every value 0).

    Returns
    -------
    FRF
        Shape ``(n_freq, 1, 1)``: frequencies in Hz, values as in the file (SI).

    Warns
    -----
    WindowedFRFWarning
        For a file measured through an exponential window (its
        ``# window_tau_s`` line, :func:`read_csv_window`): the FRF is read as
        it is, every mode with the window's damping.
    """
    frf, _, _, window = _read_csv(path, output, input, quantity)
    if window is not None:
        warnings.warn(f"{os.fspath(path)}: measured through an exponential window (tau = {window:.4g} s): every mode "
                      "carries the window's damping 1/(tau omega), which raises stability limits; "
                      "substructure.stability.window_removed takes it out (the lobes command does), a measurement set "
                      "compares the model through the window", WindowedFRFWarning, stacklevel=3)
    return frf


def read_csv_with_coherence(
    path: str | os.PathLike,
    output: str = "response",
    input: str = "excitation",
    quantity: str | None = None,
) -> tuple[FRF, np.ndarray | None]:
    """Read a CSV file ``frequency_hz,real,imag[,coherence]``: the FRF and its coherence.

    Parameters
    ----------
    path : str or path-like
        The file (see :func:`read_csv`).
    output, input : str
        Labels of the response and excitation DOFs.
    quantity : {"receptance", "mobility", "accelerance"}, optional
        What the file holds (see :func:`read_csv`).

    Returns
    -------
    FRF
        Shape ``(n_freq, 1, 1)``.
    numpy.ndarray or None
        The coherence (dimensionless, in [0, 1]) per line, or None for a
        file without the column.

    Raises
    ------
    FileFormatError
        As :func:`read_csv`, and for a coherence that is not a number in
        [0, 1], naming the file and the line.
    """
    frf, _, columns, _ = _read_csv(path, output, input, quantity)
    return frf, columns.get("coherence")


def _read_csv(path, output: str, input: str,
              quantity: str | None) -> tuple[FRF, np.ndarray, dict[str, np.ndarray], float | None]:
    """:func:`read_csv_with_coherence`, with the line of the file each frequency line comes from, the per-line
    columns the file has (``coherence``, ``force_noise``, ``truncation``) by name and the window it declares
    (:func:`read_csv_window`)."""
    from ..._files import MAX_DATA_BYTES, file_name, read_text

    name = file_name(path, "CSV file")
    text = read_text(path, "CSV file", MAX_DATA_BYTES)
    if text.count("\n") > MAX_GRID_LINES + 1000:  # before the lines are split: refused below in any case
        raise FileFormatError(f"{name}: {text.count(chr(10)):,} lines; an FRF has at most {MAX_GRID_LINES:,} "
                              "frequency lines (MAX_GRID_LINES)")
    lines = text.splitlines()
    numbered = [(k + 1, line) for k, line in enumerate(lines) if line.strip()]
    if not numbered:
        raise FileFormatError(f"{name}: the file is empty; expected the header {CSV_HEADER!r}")
    window = _window_line(numbered, name)
    comments = 0
    while comments < len(numbered) and numbered[comments][1].strip().lstrip("\ufeff").startswith("#"):
        comments += 1
    if 0 < comments < len(numbered) and _NUMERIC_ROW.match(numbered[comments][1]):
        # no header but a comment right above the rows, as numpy.savetxt(header=...) writes one: the header when
        # the file reads with it
        line, text = numbered[comments - 1]
        trial = numbered[:comments - 1] + [(line, text.strip().lstrip("\ufeff").lstrip("#").strip())] + \
            numbered[comments:]
        try:
            return _read_numbered(trial, comments - 1, name, output, input, quantity, window)
        except FileFormatError:
            pass
    return _read_numbered(numbered, comments, name, output, input, quantity, window)


_NUMERIC_ROW = re.compile(r"^\s*[-+.\d]+(?:[eE][-+]?\d+)?(?:[\s,;]+[-+.\deE]+)*[\s,;]*$")


def _read_numbered(numbered: list, comments: int, name: str, output: str, input: str, quantity: str | None,
                   window: float | None) -> tuple[FRF, np.ndarray, dict[str, np.ndarray], float | None]:
    """:func:`_read_csv` on the file's non-blank lines, the first ``comments`` of them comments."""
    first, header = numbered[min(comments, len(numbered) - 1)]
    columns = header.replace(" ", "").lstrip("\ufeff")
    said, factor = None, 1.0
    units = _units_header(header, name, first)
    if units is not None:  # the package's header with the unit of a mobility or an accelerance
        columns, said, factor = units
        if quantity is not None and quantity != said:
            raise _contradiction(name, first, said, quantity)
    if columns not in _HEADERS and columns.startswith(CSV_HEADER + ",") and \
            set(columns.split(",")[3:]) <= {"coherence", *_VARIANCE_COLUMNS}:
        raise FileFormatError(f"{name}, line {first}: the columns {_shown(columns)} are the package's in another "
                              f"order or without the coherence; expected {CSV_HEADER!r}, then 'coherence', then "
                              "'force_noise' and 'truncation', each optional, in this order (the last two need the "
                              "coherence)")
    if columns not in _HEADERS:  # another program's export
        from .exports import read_export

        table, lines_of, said, coherence = read_export(numbered, name, quantity)
        frf = _checked_csv(table, lines_of, name, output, input, quantity or said or "receptance")
        return frf, lines_of, {} if coherence is None else {"coherence": coherence}, window
    names = columns.split(",")
    numbered = numbered[comments + 1:]
    if len(numbered) < 2:
        raise FileFormatError(
            f"{name}: {len(numbered)} data row(s); an FRF needs at least 2 frequency lines"
        )
    cells = [line.split(",") for _, line in numbered]
    for (number, line), row in zip(numbered, cells):
        if len(row) != len(names):
            raise FileFormatError(
                f"{name}, line {number}: {_shown(line)} has {len(row)} value(s); expected {len(names)} "
                f"({', '.join(names)})"
            )
    try:
        table = np.array(cells, dtype=np.float64)
    except ValueError:
        for (number, _), row in zip(numbered, cells):
            for column, cell in zip(names, row):
                try:
                    float(cell)
                except ValueError:
                    raise FileFormatError(
                        f"{name}, line {number}: {column} is {_shown(cell.strip())}; expected a number"
                    ) from None
        raise  # pragma: no cover - numpy and float() disagree on a cell
    lines_of = np.array([number for number, _ in numbered])
    found = dict(zip(names[3:], table[:, 3:].T))
    if "coherence" in found:
        coherence = found["coherence"]
        bad = ~(np.isfinite(coherence) & (coherence >= 0.0) & (coherence <= 1.0))
        if bad.any():
            k = int(np.argmax(bad))
            raise FileFormatError(
                f"{name}, line {lines_of[k]}: coherence is {float(coherence[k])!r}; expected a number in [0, 1]"
            )
    for column in _VARIANCE_COLUMNS:
        bad = ~(found[column] >= 0.0) if column in found else None  # NaN and negative values; inf is allowed
        if bad is not None and bad.any():
            k = int(np.argmax(bad))
            raise FileFormatError(f"{name}, line {lines_of[k]}: {column} is {float(found[column][k])!r}; expected "
                                  "a variance >= 0 (inf where the FRF carries nothing)")
    if factor != 1.0:
        table[:, 1:3] *= factor
    frf = _checked_csv(table[:, :3], lines_of, name, output, input, quantity or said or "receptance")
    return frf, lines_of, found, window


def _checked_csv(table: np.ndarray, lines_of: np.ndarray, name: str, output: str, input: str,
                 quantity: str) -> FRF:
    """The FRF of a table ``frequency_hz, real, imag`` (SI) after the checks of every CSV file."""
    if table.shape[0] < 2:
        raise FileFormatError(f"{name}: {table.shape[0]} data row(s); an FRF needs at least 2 frequency lines")
    bad = ~np.isfinite(table)
    if bad.any():
        row, column = np.argwhere(bad)[0]
        raise FileFormatError(
            f"{name}, line {lines_of[row]}: {CSV_HEADER.split(',')[column]} is {table[row, column]}; "
            "expected a finite number"
        )
    hz = table[:, 0]
    if hz[0] < 0:
        raise FileFormatError(f"{name}, line {lines_of[0]}: frequency {float(hz[0])!r} Hz is negative")
    step_bad = np.diff(hz) <= 0
    if step_bad.any():
        k = int(np.argmax(step_bad)) + 1
        raise FileFormatError(
            f"{name}, line {lines_of[k]}: frequency {float(hz[k])!r} Hz does not exceed {float(hz[k - 1])!r} Hz "
            f"of line {lines_of[k - 1]}; frequencies must be strictly increasing, without repeats"
        )
    values = table[:, 1] + 1j * table[:, 2]
    if not np.any(values):
        raise FileFormatError(
            f"{name}: every value is 0, a dead channel (a sensor or the hammer not connected?); leave this "
            "FRF out or measure it again"
        )
    return frf_class().single(Frequency.from_hz(hz), values, output=output, input=input, quantity=quantity)

