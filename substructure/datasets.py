"""Example data shipped with the package: the thesis's tables (facts, as CSV).

The tables of the thesis (Özşahin, *An investigation on dynamic contact
parameters in machining center spindle-tool assemblies*) are included as small
CSV files in ``substructure/data`` so that examples, tests and the demo run
anywhere.  :func:`thesis_table` reads one as a list of rows;
:func:`thesis_joint` gives a joint table as ``k`` and ``c`` mappings that
:class:`~substructure.joints.Joint` accepts.

Real measurements of other projects (MIT, ``substructure/data/real``, its
README names source and licence): :func:`impact_records` gives five raw
impact records (pyFRF) as :class:`~substructure.tap.TapRecord` objects,
:func:`free_free_beam_frfs` three measured accelerances of a free-free beam
(pyuff).

Examples
--------
>>> from substructure.datasets import thesis_joint
>>> k, c = thesis_joint("2.2")
>>> k["yf"]
'41900000.0 N/m'
"""

from __future__ import annotations

import csv
from importlib import resources

from .errors import InvalidValueError

__all__ = ["TABLES", "thesis_table", "thesis_joint", "impact_records", "free_free_beam_frfs"]

TABLES = {
    "2.1": "thesis_table_2_1_spindle_holder_joint.csv",
    "2.2": "thesis_table_2_2_holder_tool_joint.csv",
    "3.1": "thesis_table_3_1_identified_holder_tool.csv",
    "4.1": "thesis_table_4_1_identified_12mm_83mm.csv",
    "4.2": "thesis_table_4_2_ann_holder_tool_kyf.csv",
    "5.1": "thesis_table_5_1_accelerometer_shift.csv",
}
"""Thesis table numbers and their files."""


def thesis_table(table: str) -> list[dict[str, str]]:
    """Rows of a thesis table (``"2.1"``, ``"2.2"``, ``"3.1"``, ``"4.1"``, ``"4.2"``, ``"5.1"``).

    Parameters
    ----------
    table : str
        The table number.

    Returns
    -------
    list of dict
        One ``{column: text}`` per row; the columns name their units.
    """
    if table not in TABLES:
        raise InvalidValueError(f"table: got {table!r}; expected one of {', '.join(TABLES)}")
    text = resources.files("substructure").joinpath("data", TABLES[table]).read_text()
    return list(csv.DictReader(text.splitlines()))


def thesis_joint(table: str = "2.2") -> tuple[dict[str, str], dict[str, str]]:
    """Joint stiffness and damping of thesis Table 2.1 or 2.2 as ``(k, c)`` mappings.

    Units are those of docs/conventions.md (k: N/m, N, N/rad, N*m/rad; c: the same
    times s).

    Parameters
    ----------
    table : {"2.1", "2.2"}
        Table 2.1 (spindle-holder) or 2.2 (holder-tool).

    Returns
    -------
    k : dict of str to str
        Stiffness entries ``yf, ym, tf, tm`` with units (``"4.19e+07 N/m"``).
    c : dict of str to str
        Damping entries with units.
    """
    if table not in ("2.1", "2.2"):
        raise InvalidValueError(f"table: got {table!r}; expected '2.1' or '2.2' (full joint tables)")
    k, c = {}, {}
    for row in thesis_table(table):
        name = row["parameter"]
        target = k if name.startswith("k_") else c
        target[name[2:]] = f"{float(row['value'])!r} {row['unit']}"
    return k, c


def impact_records() -> list:
    """The five raw impact records of the pyFRF project, as tap records.

    25.6 kHz, 1 s each: time [s], force [N] and the response, an
    acceleration (the unit is not documented; m/s^2 is assumed).  Source and
    licence: ``substructure/data/real/README.md``.

    Returns
    -------
    list of TapRecord
        ``source`` is ``"pyfrf:measurements_N.npy"``.
    """
    import numpy as np

    from .tap import TapRecord

    folder = resources.files("substructure").joinpath("data", "real", "pyfrf_impact_raw")
    records = []
    for n in range(1, 6):
        with folder.joinpath(f"measurements_{n}.npy").open("rb") as fh:
            time, force, response = np.load(fh)
        records.append(TapRecord(time, force, response, "acceleration", f"pyfrf:measurements_{n}.npy",
                                 "force [N]", "acceleration [m/s^2]"))
    return records


def free_free_beam_frfs() -> list:
    """The three measured accelerances of a free-free beam of the pyuff project.

    0 to 1000 Hz at 1 Hz; the response at one point, the excitation at three
    (``meas_point_1`` to ``_3``); presumably (m/s^2)/N.  Source and licence:
    ``substructure/data/real/README.md``.

    Returns
    -------
    list of FRF
        Accelerances (``quantity="accelerance"``), outputs ``"response"``,
        inputs ``"point_1"`` to ``"point_3"``.
    """
    import numpy as np

    from .frf import FRF, Frequency

    folder = resources.files("substructure").joinpath("data", "real", "pyuff_meas_points")
    out = []
    for n in range(1, 4):
        text = folder.joinpath(f"meas_point_{n}.txt").read_text()
        values = np.array([complex(line.strip()) for line in text.splitlines() if line.strip()])
        frequency = Frequency.from_hz(np.arange(values.size, dtype=np.float64))
        out.append(FRF.single(frequency, values, output="response", input=f"point_{n}", quantity="accelerance"))
    return out
