"""Reading and writing measured FRFs: CSV files and universal files (type 58).

CSV (conventions.md): one FRF per file, header ``frequency_hz,real,imag``,
one line per frequency, receptance in m/N unless the measurement description
says otherwise.  Values are written with every digit (``repr``), so that
reading a written file gives back the same floats.

UFF: type-58 records ("function at nodal DOF"), read and written with
``pyuff`` in ASCII form, one record per entry of the FRF, function type 4
(frequency response function).  The DOF labels, the quantity and the exact
grid are kept in the five ID lines of each record (``response=LABEL``,
``excitation=LABEL``, ``quantity=NAME``, ``grid start=.. step=.. n=..``), so
that they come back; node numbers and direction codes (``y`` -> 2,
``theta`` -> 6, rotation about z) are filled in for other programs.

Precision of UFF files: pyuff writes the ordinates with 12 significant digits
(``E20.11``), so values come back within 5e-12 relative per real and
imaginary part.  It writes abscissae with 6 significant digits (``E13.5``);
the exact grid is therefore recovered from the ID line for uniform grids,
non-uniform grids are written only when every frequency has at most 6
significant digits, and any other grid is refused with an error that says
what to do.
"""

from __future__ import annotations

import os
import re
from typing import Any

import numpy as np

from ..errors import FileFormatError, InvalidValueError
from ..frf import FRF, QUANTITIES, Frequency

__all__ = ["write_csv", "read_csv", "write_uff", "read_uff"]

CSV_HEADER = "frequency_hz,real,imag"

_DIRECTION = {"y": 2, "theta": 6}  # UFF direction codes: +Y translation, +Z rotation
_DIRECTION_NAME = {2: "y", 6: "theta"}
_SPEC_TYPE = {"receptance": 8, "mobility": 11, "accelerance": 12}  # displacement, velocity, acceleration
_QUANTITY_OF_SPEC = {v: k for k, v in _SPEC_TYPE.items()}
_GRID_LINE = re.compile(r"^grid start=(\S+) step=(\S+) n=(\d+)$")


def _require_frf(frf: Any, function: str) -> FRF:
    if not isinstance(frf, FRF):
        raise InvalidValueError(f"frf: {function} got {type(frf).__name__}; expected an FRF")
    return frf


def _refuse_all_zero(frf: FRF, name: str) -> None:
    """Readers take an FRF that is 0 at every line for a dead channel: such a file is not written."""
    dead = ~np.any(frf.data, axis=0)
    if dead.any():
        i, j = np.argwhere(dead)[0]
        raise InvalidValueError(
            f"frf: cannot write {name}: the entry ({frf.outputs[i]!r}, {frf.inputs[j]!r}) is 0 at every line, "
            "which readers refuse as a dead channel"
        )


# -- CSV ----------------------------------------------------------------------


def write_csv(frf: FRF, path: str | os.PathLike, overwrite: bool = True) -> None:
    """Write a one-entry FRF to a CSV file ``frequency_hz,real,imag``.

    Parameters
    ----------
    frf : FRF
        Shape ``(n_freq, 1, 1)``; select one entry of a larger FRF first,
        e.g. ``frf["tool.tip:y", "tool.tip:y"]``.  The data are written as
        they are (the file does not record labels or quantity).
    path : str or path-like
        The file, written through a temporary file and an atomic rename
        (:func:`substructure.io.replacing`).
    overwrite : bool, default True
        Whether an existing file may be replaced.

    Raises
    ------
    InvalidValueError
        For an FRF of more than one entry or of fewer than 2 lines (which
        no reader takes).
    """
    from . import write_text

    frf = _require_frf(frf, "write_csv")
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
    rows = zip(frf.frequency.hz.tolist(), values.real.tolist(), values.imag.tolist())
    text = "".join(f"{f!r},{re_!r},{im!r}\n" for f, re_, im in rows)
    write_text(path, CSV_HEADER + "\n" + text, overwrite=overwrite)


def read_csv(
    path: str | os.PathLike,
    output: str = "response",
    input: str = "excitation",
    quantity: str | None = None,
) -> FRF:
    """Read a CSV file ``frequency_hz,real,imag`` into a one-entry FRF.

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
    """
    from . import read_text

    name = os.fspath(path)
    lines = read_text(path).splitlines()
    numbered = [(k + 1, line) for k, line in enumerate(lines) if line.strip()]
    if not numbered:
        raise FileFormatError(f"{name}: the file is empty; expected the header {CSV_HEADER!r}")
    first, header = numbered[0]
    if header.replace(" ", "") != CSV_HEADER:  # another program's export: read what is unambiguous
        from .frf_exports import parse_export

        table, lines_of, said = parse_export(numbered, name, quantity)
        return _checked_csv(table, lines_of, name, output, input, quantity or said or "receptance")
    numbered = numbered[1:]
    if len(numbered) < 2:
        raise FileFormatError(
            f"{name}: {len(numbered)} data row(s); an FRF needs at least 2 frequency lines"
        )
    cells = [line.split(",") for _, line in numbered]
    for (number, line), row in zip(numbered, cells):
        if len(row) != 3:
            raise FileFormatError(
                f"{name}, line {number}: {line!r} has {len(row)} value(s); expected 3 "
                "(frequency_hz, real, imag)"
            )
    try:
        table = np.array(cells, dtype=np.float64)
    except ValueError:
        for (number, _), row in zip(numbered, cells):
            for column, cell in zip(CSV_HEADER.split(","), row):
                try:
                    float(cell)
                except ValueError:
                    raise FileFormatError(
                        f"{name}, line {number}: {column} is {cell.strip()!r}; expected a number"
                    ) from None
        raise  # pragma: no cover - numpy and float() disagree on a cell
    lines_of = np.array([number for number, _ in numbered])
    return _checked_csv(table, lines_of, name, output, input, quantity or "receptance")


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
    return FRF.single(Frequency.from_hz(hz), values, output=output, input=input, quantity=quantity)


# -- UFF type 58 --------------------------------------------------------------


def _split_label(label: str) -> tuple[str, str]:
    """Point name and DOF kind of a label; a label without DOF suffix is ``y``."""
    point, _, dof = label.rpartition(":")
    if point and dof in _DIRECTION:
        return point, dof
    return label, "y"


def _exact_uniform(hz: np.ndarray) -> tuple[float, float] | None:
    """``(start, step)`` with ``start + step*arange(n) == hz`` bit for bit, if there is one."""
    raw = [hz[1] - hz[0], (hz[-1] - hz[0]) / (hz.size - 1)]
    candidates = raw + [float(f"{d:.{digits}g}") for d in raw for digits in (15, 12)]
    k = np.arange(hz.size)
    for step in candidates:
        if step > 0 and np.array_equal(hz[0] + step * k, hz):
            return float(hz[0]), float(step)
    return None


def _uff_grid(hz: np.ndarray, name: str) -> tuple[int, str]:
    """Abscissa spacing flag (1 even, 0 uneven) and the ID line that records the grid."""
    grid = _exact_uniform(hz)
    if grid is None:
        as_written = np.char.mod("%13.5e", hz).astype(np.float64)  # what pyuff keeps
        if np.array_equal(as_written, hz):
            return 0, "grid non-uniform"
        step = (hz[-1] - hz[0]) / (hz.size - 1)
        if np.abs(hz[0] + step * np.arange(hz.size) - hz).max() > 1e-12 * hz[-1]:
            raise InvalidValueError(
                f"frf: cannot write {name}: the frequency grid is not uniform and UFF 58 stores "
                "non-uniform frequencies with 6 significant digits only; interpolate to a uniform "
                "grid first (frf.interpolate(Frequency.from_range(...))) or write CSV files"
            )
        grid = (float(hz[0]), float(step))  # uniform up to rounding: read back as start + step*k
    return 1, f"grid start={grid[0]!r} step={grid[1]!r} n={hz.size}"


def write_uff(frf: FRF, path: str | os.PathLike, overwrite: bool = True) -> None:
    """Write an FRF as ASCII type-58 records, one per entry, replacing the file.

    Entries are written output by output, input by input, each with the
    data types and unit exponents of UFF 58 (ordinate: displacement,
    velocity or acceleration, length exponent 1 for ``y`` and 0 for
    ``theta``; denominator: excitation force, force exponent 1, length
    exponent 1 for a moment) and its SI unit label (``"m/N"``,
    ``"m/(N s^2)"``, ...), so that other programs read the quantity and the
    units.  The file is written to a temporary name next to ``path`` and
    renamed (:func:`substructure.io.replacing`), so that a failure leaves an
    existing file untouched.

    Parameters
    ----------
    frf : FRF
        At least 2 frequency lines; labels of at most ~68 ASCII characters.
    path : str or path-like
        The universal file (``.uff`` or ``.unv``).
    overwrite : bool, default True
        Whether an existing file may be replaced.
    """
    import pyuff

    frf = _require_frf(frf, "write_uff")
    name = os.fspath(path)
    hz = frf.frequency.hz
    if hz.size < 2:
        raise InvalidValueError(f"frf: cannot write {name}: UFF 58 needs at least 2 frequency lines")
    _refuse_all_zero(frf, name)
    spacing, grid_line = _uff_grid(hz, name)
    points = list(dict.fromkeys(_split_label(x)[0] for x in frf.outputs + frf.inputs))
    records = []
    for i, output in enumerate(frf.outputs):
        for j, input_ in enumerate(frf.inputs):
            ids = [f"response={output}", f"excitation={input_}", f"quantity={frf.quantity}", grid_line]
            for line in ids:
                if len(line) > 80 or not line.isascii():
                    raise InvalidValueError(
                        f"frf: cannot write {name}: the ID line {line!r} must be ASCII and at most "
                        "80 characters; shorten the label (frf.with_labels)"
                    )
            (out_point, out_dof), (in_point, in_dof) = _split_label(output), _split_label(input_)
            records.append(
                pyuff.prepare_58(
                    id1=ids[0], id2=ids[1], id3=ids[2], id4=ids[3], id5="written by substructure",
                    func_type=4,
                    rsp_node=points.index(out_point) + 1, rsp_dir=_DIRECTION[out_dof],
                    ref_node=points.index(in_point) + 1, ref_dir=_DIRECTION[in_dof],
                    abscissa_spacing=spacing,
                    abscissa_spec_data_type=18, abscissa_axis_units_lab="Hz",
                    ordinate_spec_data_type=_SPEC_TYPE[frf.quantity],
                    ordinate_len_unit_exp=1 if out_dof == "y" else 0, ordinate_force_unit_exp=0,
                    ordinate_temp_unit_exp=0,
                    ordinate_axis_units_lab=frf.unit(output, input_),
                    orddenom_spec_data_type=13,
                    orddenom_len_unit_exp=1 if in_dof == "theta" else 0, orddenom_force_unit_exp=1,
                    orddenom_temp_unit_exp=0,
                    data=np.ascontiguousarray(frf.data[:, i, j]),
                    x=np.array(hz),
                )
            )
    from . import replacing

    with replacing(name, overwrite) as temporary:
        try:
            os.remove(temporary)  # pyuff creates it in "add" mode
            pyuff.UFF(temporary).write_sets(records, mode="add")
        except Exception as exc:  # pyuff raises bare Exception
            raise FileFormatError(f"{name}: cannot write the universal file ({exc})") from None
        if not os.path.exists(temporary) or os.path.getsize(temporary) == 0:
            raise FileFormatError(f"{name}: pyuff wrote an empty file")


def _label(dset: dict, id_key: str, prefix: str, node_key: str, dir_key: str) -> str:
    text = str(dset.get(id_key, "")).strip()
    if text.startswith(prefix) and len(text) > len(prefix):
        return text[len(prefix):]
    direction = abs(int(dset.get(dir_key, 0)))  # -Y is read as +Y, the sign goes to the data (_parse_record)
    dof = _DIRECTION_NAME.get(direction, f"dir{direction}")
    return f"node{int(dset.get(node_key, 0))}:{dof}"


# Function types (record 6, field 1) and specific data types (records 8-10, field 1) of UFF 58.
_FUNCTION_TYPES = {
    0: "general or unknown function", 1: "time response", 2: "auto spectrum", 3: "cross spectrum",
    4: "frequency response function", 5: "transmissibility", 6: "coherence", 7: "auto correlation",
    8: "cross correlation", 9: "power spectral density", 10: "energy spectral density",
    11: "probability density function", 12: "spectrum", 13: "cumulative frequency distribution",
    14: "peaks valley", 15: "stress/cycles", 16: "strain/cycles", 17: "orbit", 18: "mode indicator function",
    19: "force pattern", 20: "partial power", 21: "partial coherence", 22: "eigenvalue", 23: "eigenvector",
    24: "shock response spectrum", 25: "finite impulse response filter", 26: "multiple coherence",
    27: "order function",
}
_DATA_TYPES = {
    0: "unknown", 1: "general", 2: "stress", 3: "strain", 5: "temperature", 6: "heat flux", 8: "displacement",
    9: "reaction force", 11: "velocity", 12: "acceleration", 13: "excitation force", 15: "pressure", 16: "mass",
    17: "time", 18: "frequency", 19: "rpm", 20: "order",
}
_TIME_EXPONENT = {0: "receptance", -1: "mobility", -2: "accelerance"}  # of an FRF unit m^a N^-1 s^t
_TIME_OF = {v: k for k, v in _TIME_EXPONENT.items()}
_NO_LABEL = ("", "NONE", "N/A", "NA", "-")


def _a(word: str) -> str:
    """``word`` with its indefinite article."""
    return f"{'an' if word[:1].lower() in 'aeiou' else 'a'} {word}"


def _unit_of_label(label: Any):
    """A pint Quantity of 1 of the unit an axis units label names; None for no label; ValueError if unreadable.

    Labels of acquisition systems are made readable first: ``g`` is the
    standard acceleration of gravity (not the gram), ``s2`` and ``s²`` are
    ``s^2``.
    """
    from ..units import ureg

    text = str(label if label is not None else "").strip()
    if text.upper() in _NO_LABEL:
        return None
    cleaned = text.replace("²", "^2").replace("³", "^3").replace("·", "*").replace("**", "^")
    cleaned = re.sub(r"(?<![A-Za-z_])g(?![A-Za-z_0-9])", "g_n", cleaned)  # g: gravity, in an FRF label
    cleaned = re.sub(r"([A-Za-z])(\d)", r"\1^\2", cleaned)  # m/s2 -> m/s^2
    try:
        q = ureg.Quantity(1.0, cleaned)
    except Exception:
        raise ValueError(text) from None
    return q


def _exponents(q) -> tuple[int, int, int] | None:
    """``(force, length, time)`` exponents of a unit made of mass, length and time; None otherwise."""
    dims = dict(q.dimensionality)
    if set(dims) - {"[mass]", "[length]", "[time]"}:
        return None
    m, l, t = (dims.get(k, 0) for k in ("[mass]", "[length]", "[time]"))
    if any(float(x) != int(x) for x in (m, l, t)):
        return None
    m, l, t = int(m), int(l), int(t)
    return m, l - m, t + 2 * m  # M^m L^l T^t = F^m L^(l-m) T^(t+2m)


def _frf_unit(dset: dict, where: str):
    """The FRF unit its labels give (a pint Quantity of 1 per force), None without labels.

    Raises FileFormatError for a label that cannot be read or is not a
    response per force.
    """
    from ..units import ureg

    labels = {}
    for key in ("ordinate_axis_units_lab", "orddenom_axis_units_lab"):
        try:
            labels[key] = _unit_of_label(dset.get(key))
        except ValueError as exc:
            raise FileFormatError(
                f"{where}: cannot read the unit label {str(exc)!r} ({key.split('_')[0]}); give the quantity "
                "(receptance, mobility or accelerance, in SI units) to read it as such"
            ) from None
    num, den = labels["ordinate_axis_units_lab"], labels["orddenom_axis_units_lab"]
    if num is None:
        return None
    exps = _exponents(num)
    if exps is not None and exps[0] == -1:  # the whole FRF unit, e.g. (1/N)*(m/s^2)
        return num
    if exps is not None and exps[0] == 0:  # the response alone: the force is the denominator's
        force = ureg.Quantity(1.0, "N") if den is None else den
        fexps = _exponents(force)
        if fexps is not None and fexps[0] == 1 and fexps[2] == 0:
            return num / force
        raise FileFormatError(
            f"{where}: the ordinate denominator's unit {dset.get('orddenom_axis_units_lab')!r} is not a force "
            "or a moment; an FRF here is a response per excitation force"
        )
    raise FileFormatError(
        f"{where}: the unit label {dset.get('ordinate_axis_units_lab')!r} is not a displacement, velocity or "
        "acceleration (per force); this record is not a receptance, mobility or accelerance"
    )


def _record_quantity(dset: dict, where: str, given: str | None, system: tuple[float, float] | None):
    """The quantity of a type-58 record and the factor to SI, from its data types, unit labels and exponents.

    Returns ``(quantity, factor)``; raises FileFormatError when the
    record contradicts itself or does not say what it holds.
    """
    rotation = abs(int(dset.get("rsp_dir", 0) or 0)) in (4, 5, 6)
    moment = abs(int(dset.get("ref_dir", 0) or 0)) in (4, 5, 6)
    length_exponent = (0 if rotation else 1) - (1 if moment else 0)  # y/f: m/N, y/m and theta/f: 1/N, ...
    num_type = int(dset.get("ordinate_spec_data_type", 0) or 0)
    den_type = int(dset.get("orddenom_spec_data_type", 0) or 0)
    if den_type not in (0, 1, 9, 13):
        raise FileFormatError(
            f"{where}: the ordinate denominator is {_a(_DATA_TYPES.get(den_type, f'data type {den_type}'))}; a "
            "receptance, mobility or accelerance is a response per excitation force"
        )
    by_type = {8: "receptance", 11: "mobility", 12: "accelerance"}.get(num_type)
    if by_type is None and num_type not in (0, 1):
        raise FileFormatError(
            f"{where}: the ordinate is {_a(_DATA_TYPES.get(num_type, f'data type {num_type}'))}, not a "
            "displacement, velocity or acceleration: not a receptance, mobility or accelerance"
        )
    stored = str(dset.get("id3", "")).strip()
    ours = stored[len("quantity="):] if stored.startswith("quantity=") else None
    ours = ours if ours in QUANTITIES else None
    try:
        unit = _frf_unit(dset, where)
    except FileFormatError:
        if given is None:
            raise
        unit = None  # the user says what it is: the unreadable label is left aside
    by_label, label_factor = None, None
    label = dset.get("ordinate_axis_units_lab")
    if unit is not None:
        force, length, time = _exponents(unit)
        by_label = _TIME_EXPONENT.get(time)
        if by_label is None or (int(dset.get("rsp_dir", 0) or 0) and length != length_exponent):
            raise FileFormatError(
                f"{where}: the unit label {label!r} is not that of a receptance, mobility or accelerance of "
                f"this record's directions (response {dset.get('rsp_dir')}, reference {dset.get('ref_dir')})"
            )
        label_factor = float(unit.m_as(f"meter ** {length} / newton * second ** {time}"))
    if given is None:
        if by_label is not None and by_type is not None and by_label != by_type:
            raise FileFormatError(
                f"{where}: its data type says {by_type} ({_DATA_TYPES[num_type]}) but its unit label {label!r} "
                f"is that of {_a(by_label)}; give the quantity to say which"
            )
        quantity = by_label or by_type or ours
        if quantity is None:
            raise FileFormatError(
                f"{where}: the record does not say whether it holds a receptance, a mobility or an accelerance "
                f"(ordinate data type {_DATA_TYPES.get(num_type, num_type)}, no unit label); give the quantity "
                "(quantity = \"...\" in the measurement set, or read_uff(..., quantity=...)); values are then "
                "taken in SI units"
            )
        if by_label is not None:
            return quantity, label_factor
    elif by_label == given:
        return given, label_factor
    elif not (by_type == given or (by_label is None and by_type is None)):
        says = f"its unit label {label!r} is that of {_a(by_label)}" if by_label is not None else \
            f"its data type says {by_type} ({_DATA_TYPES[num_type]})"
        raise FileFormatError(f"{where}: the quantity given is {given}, but {says}")
    else:
        quantity = given
    if system is None:
        return quantity, 1.0
    # no labels: the file's unit system (a type-164 record) with the exponents of the data types
    # (UFF 58, Addendum A), or those the record gives for the data type "general"
    length_factor, force_factor = system
    if num_type == 1:
        num_length, num_force = int(dset.get("ordinate_len_unit_exp", 0)), int(dset.get("ordinate_force_unit_exp", 0))
    else:
        num_length, num_force = (0 if rotation else 1), 0
    if den_type == 1:
        den_length, den_force = int(dset.get("orddenom_len_unit_exp", 0)), int(dset.get("orddenom_force_unit_exp", 0))
    else:
        den_length, den_force = (1 if moment else 0), 1
    factor = length_factor ** -(num_length - den_length) * force_factor ** -(num_force - den_force)
    return quantity, factor


def _unit_system(dset: dict, name: str) -> tuple[float, float] | None:
    """``(length, force)`` factors of a type-164 record (file units per SI unit); None for SI."""
    try:
        length, force = float(dset["length"]), float(dset["force"])
    except (KeyError, TypeError, ValueError):
        raise FileFormatError(f"{name}: a units record (type 164) without length and force factors") from None
    if not (np.isfinite(length) and np.isfinite(force) and length > 0 and force > 0):
        raise FileFormatError(f"{name}: the units record (type 164) has factors {length}, {force}; expected > 0")
    return None if length == 1.0 and force == 1.0 else (length, force)


def _abscissa_hz(dset: dict, where: str) -> np.ndarray:
    """The abscissa in Hz: a frequency axis (a label in rad/s is divided by 2 pi); time or orders refused."""
    from ..units import cycles_per_second

    kind = int(dset.get("abscissa_spec_data_type", 0) or 0)
    if kind not in (0, 1, 18):
        raise FileFormatError(
            f"{where}: the abscissa is {_DATA_TYPES.get(kind, f'data type {kind}')}, not frequency; an FRF "
            "is a function of frequency"
        )
    hz = np.asarray(dset["x"], dtype=np.float64)
    label = str(dset.get("abscissa_axis_units_lab") or "").strip()
    try:
        unit = _unit_of_label(label)
    except ValueError:
        try:  # labels in capitals: "HZ", "RPM", "RAD/S"
            unit = _unit_of_label({"hz": "Hz", "khz": "kHz"}.get(label.lower(), label.lower()))
        except ValueError:
            raise FileFormatError(
                f"{where}: cannot read the abscissa's unit label {label!r}; expected a frequency unit "
                "(Hz, rad/s, rpm): convert the file, or export it with the frequency axis in Hz"
            ) from None
    if unit is not None and unit.check("1 / [time]"):
        hz = np.asarray(cycles_per_second(hz * unit, "abscissa"), dtype=np.float64)
    elif unit is not None and not unit.dimensionless:
        raise FileFormatError(
            f"{where}: the abscissa's unit is {dset.get('abscissa_axis_units_lab')!r}, not a frequency"
        )
    return hz


def _parse_record(dset: dict, name: str, number: int, quantity: str | None,
                  system: tuple[float, float] | None = None) -> tuple:
    where = f"{name}, type-58 record {number}"
    function = int(dset.get("func_type", -1))
    if function not in (0, 4) or (function == 0 and int(dset.get("orddenom_spec_data_type", 0) or 0) != 13):
        kind = _FUNCTION_TYPES.get(function, f"function type {function}")
        raise FileFormatError(
            f"{where}: {_a(kind)} (function type {function}), not a frequency response function (type 4); "
            "export the FRFs (H1 or H2) from the acquisition software"
        )
    data = np.asarray(dset["data"])
    if not np.iscomplexobj(data):
        raise FileFormatError(f"{where}: real ordinates; an FRF needs complex data (real and imaginary parts)")
    expected = dset.get("num_pts")
    if expected is not None and int(expected) != data.size:
        raise FileFormatError(
            f"{where}: its header announces {int(expected)} values but it holds {data.size}: the file is "
            "truncated or damaged; copy or export it again"
        )
    if data.size < 2:
        raise FileFormatError(f"{where}: {data.size} frequency line(s); an FRF needs at least 2")
    hz = _abscissa_hz(dset, where)
    grid = _GRID_LINE.match(str(dset.get("id4", "")).strip())
    if grid and int(grid[3]) == hz.size:
        exact = float(grid[1]) + float(grid[2]) * np.arange(hz.size)
        if np.abs(exact - hz).max() <= 1e-5 * np.abs(hz).max():
            hz = exact
    try:
        frequency = Frequency.from_hz(hz)
    except InvalidValueError as exc:
        raise FileFormatError(f"{where}: invalid frequencies ({exc})") from None
    if not np.isfinite(data).all():
        k = int(np.argmax(~np.isfinite(data)))
        raise FileFormatError(f"{where}: the value at {hz[k]:g} Hz is {data[k]}; expected finite values")
    kind, factor = _record_quantity(dset, where, quantity, system)
    # a negative direction code (-Y: the sensor or the hammer along -y) flips the sign of the FRF in +y
    factor *= (-1.0 if int(dset.get("rsp_dir", 0) or 0) < 0 else 1.0) * \
        (-1.0 if int(dset.get("ref_dir", 0) or 0) < 0 else 1.0)
    output = _label(dset, "id1", "response=", "rsp_node", "rsp_dir")
    input_ = _label(dset, "id2", "excitation=", "ref_node", "ref_dir")
    if not np.any(data):
        raise FileFormatError(
            f"{where} (response {output}, excitation {input_}): every value is 0, a dead channel (a sensor "
            "or the hammer not connected?); leave this FRF out or measure it again"
        )
    return frequency, data * factor if factor != 1.0 else data, output, input_, kind


def _check_complete(name: str) -> None:
    """A universal file starts and ends with a ``-1`` line; otherwise it is something else, or was cut off."""
    size = os.path.getsize(name)
    if size == 0:
        raise FileFormatError(f"{name}: the file is empty; no type-58 record")
    with open(name, "rb") as fh:
        head = fh.read(512)
        fh.seek(max(0, size - 512))
        tail = fh.read()
    first = head.lstrip().split(b"\n", 1)[0].strip()
    if first != b"-1":
        raise FileFormatError(
            f"{name}: not a universal file (it starts with {first[:20].decode('latin-1')!r}, not with the line "
            "'    -1' that opens a record)"
        )
    if re.search(rb"(?:^|\s)-1\s*$", tail):  # (binary 58b data end right before the closing "    -1")
        return
    with open(name, "rb") as fh:
        starts = [n + 1 for n, line in enumerate(fh) if line.rstrip()[:6].strip() in (b"58", b"58b")]
    where = f" (the last type-58 record starts at line {starts[-1]})" if starts else ""
    raise FileFormatError(
        f"{name}: the file is truncated: it does not end with the '-1' line that closes a record{where}; "
        "copy or export it again"
    )


def read_uff(path: str | os.PathLike, record: int | None = None, quantity: str | None = None) -> FRF:
    """Read type-58 records of a universal file into an FRF, in SI units.

    Parameters
    ----------
    path : str or path-like
        The universal file (ASCII or binary type 58).
    record : int, optional
        0-based index among the type-58 records: that record alone, as a
        one-entry FRF.  ``None`` reads all of them into one FRF; they must
        share one frequency grid and one quantity, and hold each (output,
        input) pair once and every pair.
    quantity : str, optional
        What the records hold, for records that do not say; a quantity that
        contradicts what a record says is refused.

    Returns
    -------
    FRF
        Frequencies in Hz; the data converted to SI units (m/N, (m/s)/N,
        (m/s^2)/N, ...), with the quantity the records hold.

    Raises
    ------
    FileFormatError
        Naming the file and the record: a missing, empty or truncated file,
        no type-58 record, a record that is not an FRF (a time history, a
        spectrum, a coherence), real ordinates, a dead channel (every value
        0), a record that does not say its quantity (when ``quantity`` is not
        given) or contradicts itself.

    Notes
    -----
    The quantity and the units come from the record (UFF 58, records 8-10):
    the unit labels first (``"(1/N)*(m/s^2)"``, ``"g/N"`` with ``g`` the
    standard gravity, ``"mm/N"``, ``"m/s"`` over ``"N"``), which the format
    says take precedence; else the ordinate's data type (8 displacement,
    11 velocity, 12 acceleration over 13 excitation force) in the units of
    the file's units record (type 164; SI without one), with the unit
    exponents of the data types (or those of the record for the data type
    "general"); else the ID line ``quantity=`` this module writes.  An
    abscissa labelled in rad/s is divided by 2 pi.  Labels come from the ID
    lines this module writes; records of other programs get
    ``"node<N>:y"`` / ``"node<N>:theta"`` (``dir<D>`` for other directions).
    """
    import pyuff

    from . import check_readable_file

    name = check_readable_file(path, "universal file")
    if quantity is not None and quantity not in QUANTITIES:
        raise InvalidValueError(f"quantity: got {quantity!r}; expected one of {', '.join(QUANTITIES)}")
    _check_complete(name)
    try:
        uff = pyuff.UFF(name)
        types = [int(t) for t in uff.get_set_types()]
    except Exception as exc:  # pyuff raises bare Exception
        raise FileFormatError(f"{name}: not a readable universal file ({exc})") from None
    positions = [k for k, t in enumerate(types) if t == 58]
    if not positions:
        found = ", ".join(f"{t} ({_RECORD_TYPES.get(t, 'other')})" for t in sorted(set(types))) or "none"
        raise FileFormatError(f"{name}: no type-58 record (FRF); the file holds record types {found}")
    if record is not None:
        if isinstance(record, bool) or not isinstance(record, (int, np.integer)):
            raise InvalidValueError(f"record: got {record!r}; expected an integer index or None")
        if not 0 <= record < len(positions):
            raise InvalidValueError(
                f"record: got {record}; {name} has {len(positions)} type-58 record(s), "
                f"indices 0..{len(positions) - 1}"
            )
    units = [k for k, t in enumerate(types) if t == 164]
    chosen = range(len(positions)) if record is None else [int(record)]
    parsed = []
    for number in chosen:
        system = None
        before = [k for k in units if k < positions[number]]
        try:
            if before:
                system = _unit_system(uff.read_sets(before[-1]), name)
            dset = uff.read_sets(positions[number])
        except FileFormatError:
            raise
        except Exception as exc:  # pyuff raises bare Exception
            raise FileFormatError(f"{name}, type-58 record {number}: cannot read it ({exc})") from None
        parsed.append((number, *_parse_record(dset, name, number, quantity, system)))
    if len(parsed) == 1:
        _, frequency, data, output, input_, kind = parsed[0]
        return FRF.single(frequency, data, output=output, input=input_, quantity=kind)
    return _assemble(parsed, name)


_RECORD_TYPES = {15: "nodes", 18: "coordinate systems", 55: "data at nodes (modes)", 58: "functions",
                 82: "trace lines", 151: "header", 164: "units", 2411: "nodes", 2412: "elements",
                 2414: "analysis data", 2420: "coordinate systems"}


def _assemble(parsed: list[tuple], name: str) -> FRF:
    first, frequency, _, _, _, kind = parsed[0]
    outputs = list(dict.fromkeys(p[3] for p in parsed))
    inputs = list(dict.fromkeys(p[4] for p in parsed))
    data = np.zeros((frequency.n, len(outputs), len(inputs)), dtype=np.complex128)
    seen: dict[tuple[str, str], int] = {}
    for number, grid, values, output, input_, quantity in parsed:
        if grid != frequency:
            raise FileFormatError(
                f"{name}: type-58 records {first} and {number} have different frequency grids "
                f"({frequency!r}, {grid!r}); read them one at a time with record=N and interpolate"
            )
        if quantity != kind:
            raise FileFormatError(
                f"{name}: type-58 records {first} and {number} hold a {kind} and a {quantity}"
            )
        if (output, input_) in seen:
            raise FileFormatError(
                f"{name}: type-58 records {seen[output, input_]} and {number} both hold "
                f"({output!r}, {input_!r}); read them one at a time with record=N"
            )
        seen[output, input_] = number
        data[:, outputs.index(output), inputs.index(input_)] = values
    missing = [(o, i) for o in outputs for i in inputs if (o, i) not in seen]
    if missing:
        raise FileFormatError(
            f"{name}: the records do not form a full matrix, missing {missing[:4]}"
            f"{' ...' if len(missing) > 4 else ''}; read them one at a time with record=N"
        )
    return FRF(frequency, data, outputs, inputs, kind)
