"""Study files (internal): a TOML file (and optionally a CSV file of combinations) read into a study.

The public readers are :mod:`substructure.study.reader` and :meth:`Study.from_file`; this module
is below both and takes the class to build, so that ``study`` and ``reader`` do not import each
other.

The format is docs/file-formats.md, "substructure study".  Every problem
of the structure (TOML syntax, unknown or missing keys, wrong types, units
of the values every combination shares, names that do not exist) raises
:class:`~substructure.errors.FileFormatError` whose message starts with
the file and the line and names the key path (``cuts[1].radial_depth``,
``combinations[3].tool.diameter``; for the CSV file the line and the
column).  The values of one combination's tool, holder and joint are
checked when it is computed: a bad combination fails its rows, with the
file and line in the message, and the study goes on.
"""

from __future__ import annotations

import csv
import io
import math
import os
import re
from pathlib import Path
from typing import Any

from .._files import relative_path
from .._toml import TomlDocument, key_path, loads_toml
from ..errors import FileFormatError, SubstructureError
from .settings import Compute, Grid
from .spec import _CUT_KEYS, Combination, Cut, Machine, SurrogateSpec

__all__ = ["read_study", "reads_study", "read_combinations_csv", "TOP_KEYS"]

#: The top-level keys and tables of a study file.
TOP_KEYS = ("name", "joint", "plugins", "combinations_csv", "grid", "compute", "surrogate", "machines", "cuts",
            "combinations")
_MACHINE_KEYS = ("name", "assembly", "supports", "limits")
_COMBINATION_KEYS = ("name", "tool", "holder", "joint", "features", "machines", "cuts")
_GRID_KEYS = ("frequency", "speeds", "sdm_speeds")
_COMPUTE_KEYS = ("at", "lobes", "recommend", "band", "samples", "quantiles", "margin", "speed_tolerance", "figures",
                 "frf_files")
_SURROGATE_KEYS = ("table", "model", "targets", "features")


class _Reader:
    def __init__(self, doc: TomlDocument, base: Path):
        self.source, self.data, self.base, self.doc = doc.source, doc.data, base, doc
        self.where, self.error, self.table = doc.where, doc.error, doc.table
        self.inputs: list[str] = [doc.source]

    def call(self, parts, factory, *args, **kwargs):
        try:
            return factory(*args, **kwargs)
        except FileFormatError:
            raise
        except SubstructureError as exc:
            raise self.doc.wrap(parts, " ".join(str(exc).split())) from None

    def array(self, key: str) -> list:
        value = self.data.get(key, [])
        if not isinstance(value, list) or not all(isinstance(v, dict) for v in value):
            raise self.error([key], f"got {value!r}; expected [[{key}]] tables")
        return value

    def file(self, value, parts) -> str:
        if not isinstance(value, str) or not value.strip():
            raise self.error(parts, f"got {value!r}; expected a file name (relative to the study file)")
        path = value if os.path.isabs(value) else os.path.normpath(relative_path(self.base, value))
        if not os.path.isfile(path):
            raise self.error(parts, f"{value!r}: no such file" + (f" ({path})" if path != value else ""))
        self.inputs.append(path)
        return path

    # -- sections ------------------------------------------------------------------
    def study(self, cls):
        data = self.table(self.data, [], TOP_KEYS, ("name",))
        if not isinstance(data["name"], str) or not data["name"].strip():
            raise self.error(["name"], f"got {data['name']!r}; expected the study's name")
        joint = data.get("joint", "holder-tool")
        if not isinstance(joint, str) or not joint:
            raise self.error(["joint"], f"got {joint!r}; expected the name of the machines' holder-tool joint")
        plugins = data.get("plugins", [])
        if not isinstance(plugins, list) or not all(isinstance(p, str) and p for p in plugins):
            raise self.error(["plugins"], f"got {plugins!r}; expected a list of module names")
        grid = self.call(["grid"], Grid, **self.table(data.get("grid", {}), ["grid"], _GRID_KEYS))
        compute = self.call(["compute"], Compute, **self.table(data.get("compute", {}), ["compute"], _COMPUTE_KEYS))
        surrogate = None
        if "surrogate" in data:
            s = self.table(data["surrogate"], ["surrogate"], _SURROGATE_KEYS, ("table",))
            kw = dict(s)
            kw["table"] = self.file(s["table"], ["surrogate", "table"])
            surrogate = self.call(["surrogate"], SurrogateSpec, **kw)
        machines = [self.machine(m, ["machines", i]) for i, m in enumerate(self.array("machines"))]
        if not machines:
            raise self.error([], "no [[machines]] table; a study needs at least one machine (assembly = \"default\" "
                             "is the built-in one)")
        cuts = [self.cut(c, ["cuts", i]) for i, c in enumerate(self.array("cuts"))]
        combos = [self.combination(c, ["combinations", i]) for i, c in enumerate(self.array("combinations"))]
        if "combinations_csv" in data:
            path = self.file(data["combinations_csv"], ["combinations_csv"])
            combos += read_combinations_csv(path)
        if not combos:
            raise self.error([], "no combinations: give [[combinations]] tables or combinations_csv = \"FILE.csv\"")
        return self.call([], cls, data["name"], machines, combos, cuts, compute, grid, surrogate, joint,
                         tuple(plugins), source=self.source, inputs=tuple(self.inputs))

    def machine(self, table, parts):
        table = self.table(table, parts, _MACHINE_KEYS, ("name",))
        kw = dict(table)
        assembly = table.get("assembly", "default")
        kw["assembly"] = "default" if assembly == "default" else self.file(assembly, parts + ["assembly"])
        return self.call(parts, Machine, **kw, where=f"{self.where(parts)}: {key_path(parts)}")

    def cut(self, table, parts):
        table = self.table(table, parts, _CUT_KEYS, ("name",))
        kw = dict(table)
        if "workpiece_table" in table:
            kw["workpiece_table"] = self.file(table["workpiece_table"], parts + ["workpiece_table"])
        return self.call(parts, Cut, **kw, where=f"{self.where(parts)}: {key_path(parts)}")

    def combination(self, table, parts):
        table = self.table(table, parts, _COMBINATION_KEYS, ("name",))
        return self.call(parts, Combination, **table, where=f"{self.where(parts)}: {key_path(parts)}")


def reads_study(cls: Any, text: str, source: str = "<string>", base: Any = ".") -> Any:
    """A study of class ``cls`` from TOML text (:func:`substructure.study.reader.loads_study`)."""
    return _Reader(loads_toml(text, source, "study"), Path(base)).study(cls)


def read_study(cls: Any, path: Any) -> Any:
    """A study of class ``cls`` from a file (:func:`substructure.study.reader.load_study`)."""
    from ..io import read_text

    name = os.fspath(path)
    return reads_study(cls, read_text(name, "study file"), source=name, base=Path(name).parent)


# -- the CSV file of combinations -------------------------------------------------------------

_HEAD = re.compile(r"^\s*([A-Za-z_][A-Za-z0-9_.]*)\s*(?:\[([^\]]*)\])?\s*$")
_CSV_PREFIXES = ("tool.", "holder.", "joint.k.", "joint.c.", "features.")
_CSV_PLAIN = ("name", "machines", "cuts")
_CONVERT = {"tool.teeth": (int, "a whole number"), "tool.diameter_ratio": (float, "a number")}
_BOOL = ("holder.shank_taper",)


#: The dimension of the columns whose unit the header can be checked against (others: checked per row).
_DIMENSIONS = {"tool.diameter": ("a length", "mm"), "tool.overhang": ("a length", "mm"),
               "tool.flute_length": ("a length", "mm"), "tool.helix": ("an angle", "deg"),
               "joint.k.yf": ("a stiffness", "N/m"), "joint.k.ym": ("a stiffness per radian", "N/rad"),
               "joint.k.tf": ("a stiffness per radian", "N/rad"), "joint.k.tm": ("a rotational stiffness", "N*m/rad"),
               "joint.c.yf": ("a damping", "N*s/m"), "joint.c.ym": ("a damping per radian", "N*s/rad"),
               "joint.c.tf": ("a damping per radian", "N*s/rad"), "joint.c.tm": ("a rotational damping", "N*m*s/rad")}


def _check_unit(column: str, unit: str, where: str) -> None:
    """A header's unit that is no unit, or not of the column's dimension, is refused where the header is read."""
    from ..units import ureg

    try:
        q = ureg.Quantity(1.0, unit)
    except Exception:
        raise FileFormatError(f"{where}: {unit!r} is not a unit; expected a unit such as mm, N/m") from None
    if column in _DIMENSIONS or column.startswith("holder.") and column.endswith(("_length", "_diameter", ".bore")):
        what, example = _DIMENSIONS.get(column, ("a length", "mm"))
        if q.dimensionality != ureg.Quantity(1.0, example).dimensionality:
            raise FileFormatError(f"{where}: the unit {unit!r} is not that of {what} ({column} [{example}])")


def _csv_cell(column: str, unit: str | None, cell: str, where: str):
    if unit is not None:
        try:
            finite = math.isfinite(float(cell))
        except ValueError:
            finite = False
        if not finite:
            raise FileFormatError(f"{where}: {column}: got {cell!r}; expected a finite number (in {unit})")
        return f"{cell} {unit}"
    if column in _CONVERT:
        kind, expected = _CONVERT[column]
        try:
            return kind(cell)
        except ValueError:
            raise FileFormatError(f"{where}: {column}: got {cell!r}; expected {expected}") from None
    if column in _BOOL:
        if cell.lower() not in ("true", "false"):
            raise FileFormatError(f"{where}: {column}: got {cell!r}; expected true or false")
        return cell.lower() == "true"
    if column in ("machines", "cuts"):
        return [v.strip() for v in cell.split(";") if v.strip()]
    return cell


def read_combinations_csv(path: Any) -> list:
    """Combinations from a CSV file: one per line, columns named by the key paths of a combination.

    Parameters
    ----------
    path : str or path
        The CSV file.  Columns: ``name`` (required), ``machines``, ``cuts``
        (names separated by ``;``), and ``tool.KEY``, ``holder.KEY``,
        ``joint.k.ENTRY``, ``joint.c.ENTRY``, ``features.NAME`` with the unit
        in brackets for quantities (``tool.diameter [mm]``); an empty cell
        is a value not given.  Lines starting with ``#`` are comments.

    Returns
    -------
    list of Combination
        In file order, each knowing its file and line.
    """
    from ..io import read_text

    name = os.fspath(path)
    text = read_text(name, "combinations table")
    lines = [(n + 1, line) for n, line in enumerate(text.splitlines()) if line.strip() and not
             line.lstrip().startswith("#")]
    if not lines:
        raise FileFormatError(f"{name}: no header; expected columns such as name,tool.diameter [mm],...")
    rows = list(csv.reader(io.StringIO("\n".join(line for _, line in lines))))
    header, numbers = rows[0], [n for n, _ in lines]
    columns = []
    for i, head in enumerate(header):
        m = _HEAD.match(head)
        if not m:
            raise FileFormatError(f"{name}, line {numbers[0]}: column {i + 1} {head!r}: expected NAME or NAME [UNIT]")
        column, unit = m.group(1), (m.group(2).strip() if m.group(2) is not None else None)
        if column not in _CSV_PLAIN and not column.startswith(_CSV_PREFIXES):
            raise FileFormatError(f"{name}, line {numbers[0]}: column {head!r}: unknown; expected name, machines, "
                                  "cuts, tool.KEY, holder.KEY, joint.k.ENTRY, joint.c.ENTRY or features.NAME")
        if column.startswith(("joint.k.", "joint.c.")) and unit is None:
            raise FileFormatError(f"{name}, line {numbers[0]}: column {head!r}: a joint entry needs its unit, "
                                  "e.g. joint.k.yf [N/m]")
        if unit is not None:
            _check_unit(column, unit, f"{name}, line {numbers[0]}: column {head!r}")
        if column in [c for c, _ in columns]:
            raise FileFormatError(f"{name}, line {numbers[0]}: column {column!r} given twice")
        columns.append((column, unit))
    if "name" not in [c for c, _ in columns]:
        raise FileFormatError(f"{name}, line {numbers[0]}: no column 'name'")
    out = []
    for row, number in zip(rows[1:], numbers[1:]):
        where = f"{name}, line {number}"
        if len(row) != len(columns):
            raise FileFormatError(f"{where}: {len(row)} cells; the header has {len(columns)} columns")
        table: dict[str, Any] = {}
        for (column, unit), cell in zip(columns, row):
            cell = cell.strip()
            if not cell:
                continue
            value = _csv_cell(column, unit, cell, where)
            parts = column.split(".")
            target = table
            for part in parts[:-1]:
                target = target.setdefault(part, {})
            target[parts[-1]] = value
        try:
            out.append(Combination(**table, where=where))
        except TypeError:
            raise FileFormatError(f"{where}: name: missing") from None
        except SubstructureError as exc:
            raise FileFormatError(f"{where}: {' '.join(str(exc).split())}") from None
    return out
