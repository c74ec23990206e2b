"""Writing universal files: :func:`write_uff`, one type-58 record per entry of an FRF.

Records are written with ``pyuff`` in ASCII form; the labels, the quantity
and the exact grid go into the ID lines so that they come back, node numbers
and direction codes are filled in for other programs.  A grid whose
frequencies pyuff's 6 significant digits would change, and that is not
uniform, is refused.
"""

from __future__ import annotations

import os
from typing import TYPE_CHECKING

import numpy as np

from ...errors import FileFormatError, InvalidValueError
from ._common import _DIRECTION, _SPEC_TYPE, _refuse_all_zero, _require_frf

if TYPE_CHECKING:  # the annotations only (frf.response imports this module)
    from ..response import FRF

__all__ = ["write_uff"]


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


def write_uff(frf: FRF, path: str | os.PathLike, overwrite: bool = False) -> None:
    """Write an FRF as ASCII type-58 records, one per entry.

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
    overwrite : bool, default False
        Whether an existing file may be replaced; without it an existing
        file is refused.

    Raises
    ------
    OutputExistsError
        (a ``FileExistsError``) When ``path`` exists and ``overwrite`` is
        false, naming the path.
    """
    import pyuff

    from ..._files import file_name

    frf = _require_frf(frf, "write_uff")
    name = file_name(path, "file to write (UFF)")
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
    from ..._files import replacing

    with replacing(name, overwrite) as temporary:
        try:
            os.remove(temporary)  # pyuff creates it in "add" mode
            pyuff.UFF(temporary).write_sets(records, mode="add")
        except Exception as exc:  # pyuff raises bare Exception
            raise FileFormatError(f"{name}: cannot write the universal file ({exc})") from None
        if not os.path.exists(temporary) or os.path.getsize(temporary) == 0:
            raise FileFormatError(f"{name}: pyuff wrote an empty file")

