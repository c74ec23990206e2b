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
import tempfile
from pathlib import Path
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


# -- CSV ----------------------------------------------------------------------


def write_csv(frf: FRF, path: str | os.PathLike) -> None:
    """Write a one-entry FRF to a CSV file ``frequency_hz,real,imag``.

    Parameters
    ----------
    frf : FRF
        Shape ``(n_freq, 1, 1)``; select one entry of a larger FRF first,
        e.g. ``frf["tool.tip:y", "tool.tip:y"]``.  The data are written as
        they are (the file does not record labels or quantity).
    path : str or path-like
        The file, overwritten if it exists.
    """
    frf = _require_frf(frf, "write_csv")
    if frf.shape[1:] != (1, 1):
        raise InvalidValueError(
            f"frf: a CSV file holds one FRF, this one has {frf.shape[1]}x{frf.shape[2]} entries "
            f"(outputs {list(frf.outputs)}, inputs {list(frf.inputs)}); select one entry first, "
            f"e.g. frf[{frf.outputs[0]!r}, {frf.inputs[0]!r}]"
        )
    values = frf.data[:, 0, 0]
    rows = zip(frf.frequency.hz.tolist(), values.real.tolist(), values.imag.tolist())
    text = "".join(f"{f!r},{re_!r},{im!r}\n" for f, re_, im in rows)
    with open(path, "w", encoding="utf-8", newline="\n") as fh:
        fh.write(CSV_HEADER + "\n" + text)


def read_csv(
    path: str | os.PathLike,
    output: str = "response",
    input: str = "excitation",
    quantity: str = "receptance",
) -> FRF:
    """Read a CSV file ``frequency_hz,real,imag`` into a one-entry FRF.

    Parameters
    ----------
    path : str or path-like
        The file.  Blank lines are ignored; a UTF-8 byte-order mark is allowed.
    output, input : str
        Labels of the response and excitation DOFs, e.g. ``"tool.tip:y"``.
    quantity : {"receptance", "mobility", "accelerance"}
        What the file holds (the file itself does not say).

    Raises
    ------
    FileFormatError
        Naming the file and the line, for a missing file, a wrong header, a
        row without three numbers, NaN or inf, a negative, repeated or
        decreasing frequency, or fewer than two rows.

    Returns
    -------
    FRF
        Shape ``(n_freq, 1, 1)``: frequencies in Hz, values as in the file (SI).
    """
    name = os.fspath(path)
    try:
        with open(path, encoding="utf-8-sig") as fh:
            lines = fh.read().splitlines()
    except FileNotFoundError:
        raise FileFormatError(f"{name}: no such file") from None
    except (OSError, UnicodeDecodeError) as exc:
        raise FileFormatError(f"{name}: cannot read the file ({exc})") from None
    numbered = [(k + 1, line) for k, line in enumerate(lines) if line.strip()]
    if not numbered:
        raise FileFormatError(f"{name}: the file is empty; expected the header {CSV_HEADER!r}")
    first, header = numbered[0]
    if header.replace(" ", "") != CSV_HEADER:
        raise FileFormatError(
            f"{name}, line {first}: header {header!r}; expected {CSV_HEADER!r} "
            "(frequency in Hz, real and imaginary parts)"
        )
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


def write_uff(frf: FRF, path: str | os.PathLike) -> None:
    """Write an FRF as ASCII type-58 records, one per entry, replacing the file.

    Entries are written output by output, input by input.  The file is
    written to a temporary name next to ``path`` and renamed, so that a
    failure leaves an existing file untouched.

    Parameters
    ----------
    frf : FRF
        At least 2 frequency lines; labels of at most ~68 ASCII characters.
    path : str or path-like
        The universal file (``.uff`` or ``.unv``).
    """
    import pyuff

    frf = _require_frf(frf, "write_uff")
    name = os.fspath(path)
    hz = frf.frequency.hz
    if hz.size < 2:
        raise InvalidValueError(f"frf: cannot write {name}: UFF 58 needs at least 2 frequency lines")
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
                    ordinate_axis_units_lab=frf.unit(output, input_),
                    orddenom_spec_data_type=13,
                    data=np.ascontiguousarray(frf.data[:, i, j]),
                    x=np.array(hz),
                )
            )
    try:
        fd, temporary = tempfile.mkstemp(suffix=".uff", dir=os.path.dirname(os.path.abspath(name)))
        os.close(fd)
    except OSError as exc:
        raise FileFormatError(f"{name}: cannot write the universal file ({exc})") from None
    try:
        os.remove(temporary)  # pyuff creates it in "add" mode
        pyuff.UFF(temporary).write_sets(records, mode="add")
        if os.path.getsize(temporary) == 0:
            raise FileFormatError(f"{name}: pyuff wrote an empty file")
        os.replace(temporary, name)
    except FileFormatError:
        raise
    except Exception as exc:  # pyuff raises bare Exception
        raise FileFormatError(f"{name}: cannot write the universal file ({exc})") from None
    finally:
        if os.path.exists(temporary):
            os.remove(temporary)


def _label(dset: dict, id_key: str, prefix: str, node_key: str, dir_key: str) -> str:
    text = str(dset.get(id_key, "")).strip()
    if text.startswith(prefix) and len(text) > len(prefix):
        return text[len(prefix):]
    direction = int(dset.get(dir_key, 0))
    dof = _DIRECTION_NAME.get(direction, f"dir{direction}")
    return f"node{int(dset.get(node_key, 0))}:{dof}"


def _parse_record(dset: dict, name: str, number: int, quantity: str | None) -> tuple:
    where = f"{name}, type-58 record {number}"
    if int(dset.get("func_type", -1)) != 4:
        raise FileFormatError(
            f"{where}: function type {dset.get('func_type')}; expected 4 (frequency response function)"
        )
    data = np.asarray(dset["data"])
    if not np.iscomplexobj(data):
        raise FileFormatError(f"{where}: real ordinates; an FRF needs complex data")
    hz = np.asarray(dset["x"], dtype=np.float64)
    grid = _GRID_LINE.match(str(dset.get("id4", "")).strip())
    if grid and int(grid[3]) == hz.size:
        exact = float(grid[1]) + float(grid[2]) * np.arange(hz.size)
        if np.abs(exact - hz).max() <= 1e-5 * np.abs(hz).max():
            hz = exact
    try:
        frequency = Frequency.from_hz(hz)
    except InvalidValueError as exc:
        raise FileFormatError(f"{where}: invalid frequencies ({exc})") from None
    if quantity is None:
        text = str(dset.get("id3", "")).strip()
        stored = text[len("quantity="):] if text.startswith("quantity=") else None
        spec = _QUANTITY_OF_SPEC.get(int(dset.get("ordinate_spec_data_type", 0)), "receptance")
        quantity = stored if stored in QUANTITIES else spec
    output = _label(dset, "id1", "response=", "rsp_node", "rsp_dir")
    input_ = _label(dset, "id2", "excitation=", "ref_node", "ref_dir")
    return frequency, data, output, input_, quantity


def read_uff(path: str | os.PathLike, record: int | None = None, quantity: str | None = None) -> FRF:
    """Read type-58 records of a universal file into an FRF.

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
        Overrides the quantity; by default taken from the ID line this module
        writes, else from the ordinate data type (8 displacement, 11
        velocity, 12 acceleration), else receptance.

    Notes
    -----
    Labels come from the ID lines this module writes; records of other
    programs get ``"node<N>:y"`` / ``"node<N>:theta"`` (``dir<D>`` for other
    directions).  Values are taken as SI; unit exponents are not applied.

    Returns
    -------
    FRF
        Frequencies in Hz, values in SI units (m/N for a receptance y/f).
    """
    import pyuff

    name = os.fspath(path)
    if not Path(name).is_file():
        raise FileFormatError(f"{name}: no such file")
    if quantity is not None and quantity not in QUANTITIES:
        raise InvalidValueError(f"quantity: got {quantity!r}; expected one of {', '.join(QUANTITIES)}")
    try:
        uff = pyuff.UFF(name)
        types = [int(t) for t in uff.get_set_types()]
    except Exception as exc:  # pyuff raises bare Exception
        raise FileFormatError(f"{name}: not a readable universal file ({exc})") from None
    positions = [k for k, t in enumerate(types) if t == 58]
    if not positions:
        raise FileFormatError(
            f"{name}: no type-58 record (found record types {sorted(set(types)) or 'none'})"
        )
    if record is not None:
        if isinstance(record, bool) or not isinstance(record, (int, np.integer)):
            raise InvalidValueError(f"record: got {record!r}; expected an integer index or None")
        if not 0 <= record < len(positions):
            raise InvalidValueError(
                f"record: got {record}; {name} has {len(positions)} type-58 record(s), "
                f"indices 0..{len(positions) - 1}"
            )
    chosen = range(len(positions)) if record is None else [int(record)]
    parsed = []
    for number in chosen:
        try:
            dset = uff.read_sets(positions[number])
        except Exception as exc:  # pyuff raises bare Exception
            raise FileFormatError(f"{name}, type-58 record {number}: cannot read it ({exc})") from None
        parsed.append((number, *_parse_record(dset, name, number, quantity)))
    if len(parsed) == 1:
        _, frequency, data, output, input_, kind = parsed[0]
        return FRF.single(frequency, data, output=output, input=input_, quantity=kind)
    return _assemble(parsed, name)


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
