"""Reading universal files: :func:`read_uff`, type-58 records into an FRF in SI units.

Records that are not FRFs are skipped; the others are read with their
labels, quantity and units (``uff_units``),
checked for a complete file, and assembled into one FRF when they share a
grid and a quantity and form a full matrix.
"""

from __future__ import annotations

import os
import re
import warnings
from typing import TYPE_CHECKING

import numpy as np

from ...errors import FileFormatError, InvalidValueError, WindowedFRFWarning
from .._fields import QUANTITIES
from ..axis import Frequency
from ._common import _GRID_LINE, coherence_checked, frf_class

if TYPE_CHECKING:  # the annotations only (frf.response imports this module)
    from ..response import FRF
from .uff_units import _FUNCTION_TYPES, _a, _abscissa_hz, _label, _record_quantity, _unit_system

__all__ = ["read_uff", "read_uff_coherence"]


def _is_frf(dset: dict) -> bool:
    """Whether a type-58 record is a frequency response function (type 4, or "general" over a force)."""
    function = int(dset.get("func_type", -1))
    return function == 4 or (function == 0 and int(dset.get("orddenom_spec_data_type", 0) or 0) == 13)


def _frfs_beside(uff, positions: list[int], number: int, dset: dict) -> list[int]:
    """Reading every record, the indices of the FRFs in a file whose record ``number`` is none (an auto spectrum,
    a coherence), as analysers export a test: the error then names the FRFs' indices to give. Empty when the
    record is an FRF, or when the file holds no FRF at all."""
    if _is_frf(dset) or len(positions) < 2:
        return []
    frfs = []
    for k, position in enumerate(positions):
        try:
            other = dset if k == number else uff.read_sets(position)
        except Exception:  # pyuff raises bare Exception; the record is read (and refused) on its own turn
            return []
        if _is_frf(other):
            frfs.append(k)
    return frfs


def _parse_record(dset: dict, name: str, number: int, quantity: str | None,
                  system: tuple[float, float] | None = None, frfs: list[int] | None = None) -> tuple:
    where = f"{name}, type-58 record {number}"
    function = int(dset.get("func_type", -1))
    if function not in (0, 4) or (function == 0 and int(dset.get("orddenom_spec_data_type", 0) or 0) != 13):
        kind = _FUNCTION_TYPES.get(function, f"function type {function}")
        hint = ("; a coherence beside its FRF is read with it: give the FRF's index as record = N and this one "
                "as coherence_record = M in the measurement set" if function == 6 else
                "; export the FRFs (H1 or H2) from the acquisition software" if not frfs else "")
        if frfs:  # the file holds FRFs beside it: the one meant is to be named
            hint += (f"; the file's FRFs are type-58 record(s) {', '.join(map(str, frfs))}: give the index of the one "
                     f"meant (record = {frfs[0]} in the measurement set, read_uff(..., record={frfs[0]}))")
        raise FileFormatError(
            f"{where}: {_a(kind)} (function type {function}), not a frequency response function (type 4){hint}"
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


_LABEL_LINES = {8: "abscissa_axis_units_lab", 9: "ordinate_axis_units_lab", 10: "orddenom_axis_units_lab"}


def _latin1_labels(uff, position: int, dset: dict) -> None:
    """Unit labels in Latin-1 (``m/s²`` with the byte 0xB2) read from the record's own bytes.

    pyuff decodes a record as UTF-8 and turns a byte that is not UTF-8 into
    U+FFFD, so that ``(1/N)*(m/s\xb2)`` would lose its exponent.  When a
    label holds U+FFFD, its field (columns 48-67 of records 8-10, after the
    ``58`` line) is read again from the file as Latin-1, the single-byte
    code page of the programs that write such files.  Without the record's
    offsets (another pyuff) the label is left as it is, and the reader
    refuses it as unreadable.
    """
    if not any("\ufffd" in str(dset.get(key, "")) for key in _LABEL_LINES.values()):
        return
    try:
        start, end = (int(v) for v in uff._block_ind[position])
        with open(uff._filename, "rb") as fh:
            fh.seek(start)
            block = fh.read(min(end - start + 1, 16 * 1024))
    except (AttributeError, IndexError, TypeError, ValueError, OSError):
        return
    lines = block.splitlines()
    head = next((k for k, line in enumerate(lines) if line.strip() in (b"58", b"58b")), None)
    if head is None or len(lines) <= head + 10:
        return
    for offset, key in _LABEL_LINES.items():
        if "\ufffd" in str(dset.get(key, "")):
            dset[key] = lines[head + offset][47:67].decode("latin-1").strip()


def check_complete(name: str) -> None:
    """A universal file starts and ends with a ``-1`` line; otherwise it is something else, or was cut off.

    The readers of FRFs here and of tap records (:mod:`substructure.io.tap_files`) check it first.
    """
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
        _check_records_closed(name)
        return
    with open(name, "rb") as fh:
        starts = [n + 1 for n, line in enumerate(fh) if line.rstrip()[:6].strip() in (b"58", b"58b")]
    where = f" (the last type-58 record starts at line {starts[-1]})" if starts else ""
    raise FileFormatError(
        f"{name}: the file is truncated: it does not end with the '-1' line that closes a record{where}; "
        "copy or export it again"
    )


def _check_records_closed(name: str) -> None:
    """Every record of an ASCII universal file is closed by its ``-1`` line before the next opens.

    Without the closing line of a record, the next record's opening ``-1``
    closes it and the next record's lines fall outside any record: readers
    then merge or drop them silently.  Files with binary records (``58b``)
    are not scanned (their data may hold any bytes).
    """
    inside = False
    opened = False
    with open(name, "rb") as fh:
        for number, raw in enumerate(fh, start=1):
            line = raw.strip()
            if opened:  # the line after an opening -1 names the record type
                if line.lower().endswith(b"b") or b"b " in line[:8].lower():
                    return  # a binary record: its data are not lines
                opened = False
                continue
            if line == b"-1":
                inside = not inside
                opened = inside
                continue
            if not inside and line:
                raise FileFormatError(
                    f"{name}, line {number}: text outside any record ({line[:20].decode('latin-1')!r}); the "
                    "'-1' line that closes the record before it is missing, so that record and this one "
                    "cannot be told apart: export the file again"
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

    Warns
    -----
    WindowedFRFWarning
        For records whose qualifiers (a type-1858 record right before each)
        say an exponential window (window type 4 or 6): the file does not
        give its time constant, and the FRF is read as it is, every mode
        with the window's damping.

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

    from ..._files import MAX_DATA_BYTES, check_file

    name = check_file(path, "universal file", MAX_DATA_BYTES)
    if quantity is not None and quantity not in QUANTITIES:
        raise InvalidValueError(f"quantity: got {quantity!r}; expected one of {', '.join(QUANTITIES)}")
    check_complete(name)
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
    parsed, windowed = [], []
    for number in chosen:
        if _exponential_window(uff, types, positions[number]):
            windowed.append(number)
        system = None
        before = [k for k in units if k < positions[number]]
        try:
            if before:
                system = _unit_system(uff.read_sets(before[-1]), name)
            dset = uff.read_sets(positions[number])
            _latin1_labels(uff, positions[number], dset)
        except FileFormatError:
            raise
        except Exception as exc:  # pyuff raises bare Exception
            raise FileFormatError(f"{name}, type-58 record {number}: cannot read it ({exc})") from None
        frfs = _frfs_beside(uff, positions, number, dset) if record is None else []
        parsed.append((number, *_parse_record(dset, name, number, quantity, system, frfs)))
    if windowed:
        warnings.warn(f"{name}: type-58 record(s) {', '.join(map(str, windowed))} measured through an exponential "
                      "window (the 1858 record before each says so), whose time constant the file does not give: "
                      "every mode carries the window's damping 1/(tau omega), which raises stability limits; give "
                      "the analyser's value (window_tau_s in a measurement set, --window-tau for lobes); diagnose "
                      "reads it from the noise where the noise shows it", WindowedFRFWarning, stacklevel=3)
    if len(parsed) == 1:
        _, frequency, data, output, input_, kind = parsed[0]
        return frf_class().single(frequency, data, output=output, input=input_, quantity=kind)
    return _assemble(parsed, name)


_EXPONENTIAL = (4, 6)  # the window types of a type-1858 record that are exponential (alone, or with a force window)


def _exponential_window(uff, types: list[int], position: int) -> bool:
    """Whether the type-1858 record right before a type-58 one (its qualifiers, as some analysers write them) says
    the function was measured through an exponential window; False without one, or one that cannot be read."""
    if position == 0 or types[position - 1] != 1858:
        return False
    try:
        qualifiers = uff.read_sets(position - 1)
        return int(qualifiers.get("window_type", 0)) in _EXPONENTIAL
    except Exception:  # pyuff raises bare Exception; the qualifiers are not needed to read the function
        return False


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
    return frf_class()(frequency, data, outputs, inputs, kind)


def read_uff_coherence(path: str | os.PathLike, record: int) -> tuple[np.ndarray, np.ndarray]:
    """Read a coherence record of a universal file (type 58, function type 6), as analysers export it beside
    the FRF.

    Parameters
    ----------
    path : str or path-like
        The universal file (ASCII or binary type 58).
    record : int
        0-based index of the coherence among the file's type-58 records.

    Returns
    -------
    (numpy.ndarray, numpy.ndarray)
        Its frequencies [Hz] and its values in [0, 1].

    Raises
    ------
    FileFormatError
        Naming the file and the record: no such record, a record that is
        not a coherence, values outside [0, 1] or not finite.
    """
    import pyuff

    from ..._files import MAX_DATA_BYTES, check_file

    name = check_file(path, "universal file", MAX_DATA_BYTES)
    check_complete(name)
    try:
        uff = pyuff.UFF(name)
        positions = [k for k, t in enumerate(uff.get_set_types()) if int(t) == 58]
    except Exception as exc:  # pyuff raises bare Exception
        raise FileFormatError(f"{name}: not a readable universal file ({exc})") from None
    if isinstance(record, bool) or not isinstance(record, (int, np.integer)) or not 0 <= record < len(positions):
        raise FileFormatError(f"{name}: coherence record {record!r}; the file has {len(positions)} type-58 "
                              f"record(s), indices 0..{len(positions) - 1}")
    where = f"{name}, type-58 record {record}"
    try:
        dset = uff.read_sets(positions[int(record)])
    except Exception as exc:  # pyuff raises bare Exception
        raise FileFormatError(f"{where}: cannot read it ({exc})") from None
    function = int(dset.get("func_type", -1))
    if function != 6:
        kind = _FUNCTION_TYPES.get(function, f"function type {function}")
        raise FileFormatError(f"{where}: {_a(kind)} (function type {function}), not a coherence (type 6)")
    data = np.asarray(dset["data"])
    values = np.where(np.abs(np.imag(data)) > 1e-9, np.nan, np.real(data)).astype(np.float64)
    return _abscissa_hz(dset, where), coherence_checked(values, where, shown=data)

