"""Example data shipped with the package: the thesis's tables (facts, as CSV).

The tables of the thesis (Özşahin, *An investigation on dynamic contact
parameters in machining center spindle-tool assemblies*) are included as small
CSV files in ``substructure/data`` so that examples, tests and the demo run
anywhere.  :func:`thesis_table` reads one as a list of rows;
:func:`thesis_joint` gives a joint table as ``k`` and ``c`` mappings that
:class:`~substructure.joints.Joint` accepts.

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

__all__ = ["TABLES", "thesis_table", "thesis_joint"]

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
