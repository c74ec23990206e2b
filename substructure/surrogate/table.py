"""The joint-parameter table: identified joints and the features they were identified for.

Each row is one identified joint: its parameters (``k_yf``, ``c_yf``, ...) with
units and, when known, their standard deviations, and its features (tool
diameter, gauge length, holder type, clamping torque, anything the user adds).
A feature either has a unit (a number with a unit per row) or is categorical
(a string per row).  The table reads and writes CSV, whose header gives each
column's unit in brackets::

    tool_diameter [mm],gauge_length [mm],holder_type,k_yf [N/m],k_yf_std [N/m]
    12,76,BT40-collet,1.43e7,

Columns named like joint parameters (``k_yf``, ``k_ym``, ``k_tf``, ``k_tm``,
``c_yf``, ...) are parameters, ``NAME_std`` their standard deviations, every
other column a feature.  Identification results append directly
(:meth:`JointTable.append_report`).  Tables are immutable: appending returns
a new table.

The checks of the columns and their units are in ``substructure.surrogate.columns``.
"""

from __future__ import annotations

import csv
import io
import math
from pathlib import Path
from typing import Any, Mapping, Sequence

import attrs
import numpy as np
import pint

from ..errors import FileFormatError, InvalidValueError, UnitError
from ..units import ureg
from .columns import (
    PARAMETER_UNITS, _HEADER, _check_columns, _check_parameter_unit, _check_unit, _dimension, _is_size, _to_unit,
)

__all__ = ["JointTable", "PARAMETER_UNITS", "thesis_table_4_2"]


@attrs.frozen(eq=False)
class JointTable:
    """Identified joint parameters (rows) with their features.

    Parameters
    ----------
    parameters : mapping of str to str
        Parameter name to the unit its column is in, e.g. ``{"k_yf": "N/m"}``.
    features : mapping of str to str or None
        Feature name to its unit, or ``None`` for a categorical feature.
    columns : mapping of str to array
        One array per parameter, per feature and (optional) per ``NAME_std``;
        numbers in the column's unit, NaN for an unknown standard deviation.

    Notes
    -----
    Use :meth:`from_rows`, :meth:`from_csv` or :func:`thesis_table_4_2` rather
    than this constructor.
    """

    parameters: dict = attrs.field(converter=dict)
    features: dict = attrs.field(converter=dict)
    columns: dict = attrs.field(converter=dict)

    def __attrs_post_init__(self) -> None:
        if not self.parameters:
            raise InvalidValueError("joint table: no parameter columns (names like k_yf, c_yf)")
        for name, unit in self.parameters.items():
            _check_parameter_unit(name, unit, name)
        for name, unit in self.features.items():
            if unit is not None:
                _check_unit(unit, name)
        for name in [*self.parameters, *self.features]:
            if name not in self.columns:
                raise InvalidValueError(f"joint table: column {name!r} is missing")
        n = len(next(iter(self.columns.values())))
        for name, col in self.columns.items():
            if len(col) != n:
                raise InvalidValueError(f"joint table: column {name!r} has {len(col)} rows, expected {n}")
        for name in self.parameters:
            self.columns.setdefault(name + "_std", np.full(n, np.nan))
        _check_columns(self.parameters, self.features, self.columns, lambda i: f"joint table, row {i + 1}")

    # -- construction ---------------------------------------------------------------------

    @classmethod
    def empty(cls, parameters: Mapping[str, str], features: Mapping[str, str | None]) -> "JointTable":
        """A table without rows, with the given columns and units.

        Parameters
        ----------
        parameters : mapping of str to str
            Parameter name to unit, e.g. ``{"k_yf": "N/m"}``.
        features : mapping of str to str or None
            Feature name to unit (``{"tool_diameter": "mm"}``), None for a categorical one.

        Returns
        -------
        JointTable
            The empty table.
        """
        cols = {p: np.zeros(0) for p in parameters}
        cols.update({f: np.zeros(0) if u is not None else np.zeros(0, dtype=object) for f, u in features.items()})
        return cls(parameters, features, cols)

    @classmethod
    def from_rows(cls, rows: Sequence[Mapping[str, Any]], parameters: Sequence[str] | None = None) -> "JointTable":
        """A table from rows of quantities (``"12 mm"``) and strings (categorical).

        Parameters are the keys named like joint parameters (or ``parameters``);
        ``NAME_std`` keys are their standard deviations.  The units of the
        first row become the table's units.

        Parameters
        ----------
        rows : sequence of mapping
            ``{"tool_diameter": "12 mm", "gauge_length": "80 mm", "k_yf": "1.4e7 N/m"}`` per row.
        parameters : sequence of str, optional
            Which keys are parameters; default the keys named like joint parameters.

        Returns
        -------
        JointTable
            The table.
        """
        rows = list(rows)
        if not rows:
            raise InvalidValueError("joint table: got no rows (use JointTable.empty for an empty table)")
        first = rows[0]
        pnames = list(parameters) if parameters is not None else [k for k in first if k in PARAMETER_UNITS]
        par_units, feat_units = {}, {}
        for key, value in first.items():
            if key.endswith("_std") and key[:-4] in pnames:
                continue
            unit = None
            if isinstance(value, pint.Quantity):
                unit = f"{value.units:~C}" or None
            elif isinstance(value, str):
                try:
                    q = ureg.Quantity(value)
                    unit = f"{q.units:~C}" if isinstance(q, pint.Quantity) and not q.dimensionless else None
                except Exception:
                    unit = None
            if key in pnames:
                if unit is None:
                    raise UnitError(f"{key}: got {value!r}; a parameter needs a unit, e.g. '1.4e7 N/m'")
                par_units[key] = unit
            else:
                feat_units[key] = unit
        table = cls.empty(par_units, feat_units)
        for row in rows:
            table = table.append(row)
        return table

    @classmethod
    def from_csv(cls, path: str | Path, parameters: Sequence[str] | None = None) -> "JointTable":
        """Read a table written by :meth:`to_csv` (units in brackets in the header).

        Parameters
        ----------
        path : str or os.PathLike
            The CSV file.
        parameters : sequence of str, optional
            Which columns are parameters; default those named like joint parameters.

        Returns
        -------
        JointTable
            The table, in the units of the header.
        """
        from ..io import read_text

        return cls._from_csv_text(read_text(path, "joint table"), str(path), parameters)

    @classmethod
    def _from_csv_text(cls, text: str, where: str, parameters=None) -> "JointTable":
        numbered = [(k + 1, ln) for k, ln in enumerate(text.removeprefix("\ufeff").splitlines())
                    if ln.strip() and not ln.lstrip().startswith("#")]
        if not numbered:
            raise FileFormatError(f"{where}: the joint table is empty (no header, no rows)")
        line_of = [k for k, _ in numbered]
        reader = csv.reader([ln for _, ln in numbered])
        header = next(reader)
        if len(header) == 1 and (";" in header[0] or "\t" in header[0]):
            raise FileFormatError(
                f"{where}, line {line_of[0]}: the header {header[0]!r} has no comma; the columns of a joint table "
                "are separated by commas, with '.' for the decimal point (docs/file-formats.md)")
        names, units = [], []
        for col in header:
            m = _HEADER.match(col)
            if not m:
                raise FileFormatError(
                    f"{where}: cannot read the column header {col!r}; expected 'name [unit]' or 'name'")
            names.append(m.group(1))
            units.append(m.group(2).strip() if m.group(2) else None)
        twice = sorted({n for n in names if names.count(n) > 1})
        if twice:
            raise FileFormatError(f"{where}, line {line_of[0]}: the column {', '.join(twice)} is given more than "
                                  "once; keep one")
        pset = set(parameters) if parameters is not None else {n for n in names if n in PARAMETER_UNITS}
        par_units, feat_units = {}, {}
        for n, u in zip(names, units):
            if n.endswith("_std") and n[:-4] in pset:
                if u is None:  # a std in another unit than its parameter is allowed: never guess which
                    raise FileFormatError(f"{where}, line {line_of[0]}: standard deviation column {n!r} has no "
                                          f"unit (write '{n} [unit]', a unit of {n[:-4]})")
                continue
            try:
                if n in pset:
                    if u is None:
                        raise FileFormatError(f"{where}: parameter column {n!r} has no unit "
                                              f"(write '{n} [{PARAMETER_UNITS.get(n, 'N/m')}]')")
                    par_units[n] = _check_parameter_unit(n, u, f"{where}: column {n}")
                else:
                    feat_units[n] = _check_unit(u, f"{where}: column {n}") if u else None
            except UnitError as exc:
                raise FileFormatError(str(exc)) from None
        for n, u in zip(names, units):
            if n.endswith("_std") and n[:-4] in par_units and u is not None:
                try:
                    _check_parameter_unit(n, u, f"{where}: column {n}")
                    if _dimension(u) != _dimension(par_units[n[:-4]]):
                        raise UnitError(f"{where}: column {n}: the unit {u!r} does not match "
                                        f"{n[:-4]} [{par_units[n[:-4]]}]")
                except UnitError as exc:
                    raise FileFormatError(str(exc)) from None
        if not par_units:
            raise FileFormatError(f"{where}: no parameter column (names like k_yf [N/m])")
        cols: dict[str, list] = {n: [] for n in names}
        for row_index, row in enumerate(reader):
            lineno = line_of[row_index + 1]
            if len(row) != len(names):
                raise FileFormatError(f"{where}, line {lineno}: {len(row)} values, expected {len(names)}")
            for n, u, cell in zip(names, units, row):
                cell = cell.strip()
                if n in feat_units and feat_units[n] is None:
                    if not cell:
                        raise FileFormatError(f"{where}, line {lineno}: {n} is empty")
                    cols[n].append(cell)
                    continue
                if not cell and n.endswith("_std"):
                    cols[n].append(math.nan)
                    continue
                try:
                    value = float(cell)
                except ValueError:
                    raise FileFormatError(f"{where}, line {lineno}: {n} = {cell!r} is not a number") from None
                if not math.isfinite(value):  # an unknown std is an empty cell, never a written nan
                    raise FileFormatError(f"{where}, line {lineno}: {n} = {cell!r}; expected a finite number"
                                          + (" (leave the cell empty for an unknown std)" if n.endswith("_std")
                                             else ""))
                cols[n].append(value)
        arrays = {n: np.array(v, dtype=object if (n in feat_units and feat_units[n] is None) else float)
                  for n, v in cols.items()}
        std_units = {n: u for n, u in zip(names, units) if n.endswith("_std") and n[:-4] in par_units}
        for n, u in std_units.items():
            if u is not None and u != par_units[n[:-4]]:
                arrays[n] = np.array([ureg.Quantity(v, u).m_as(par_units[n[:-4]]) for v in arrays[n]])
        _check_columns(par_units, feat_units, arrays, lambda i: f"{where}, line {line_of[i + 1]}", FileFormatError)
        return cls(par_units, feat_units, arrays)

    # -- access ------------------------------------------------------------------------------

    def __len__(self) -> int:
        return len(self.columns[next(iter(self.parameters))])

    @property
    def n_rows(self) -> int:
        """Number of rows (identified joints)."""
        return len(self)

    def values(self, parameter: str) -> np.ndarray:
        """The column of ``parameter`` in its unit (``parameters``).

        Parameters
        ----------
        parameter : str
            A parameter of the table, e.g. ``"k_yf"``.

        Returns
        -------
        ndarray
            One value per row, in the parameter's unit.
        """
        self._check_parameter(parameter)
        return np.asarray(self.columns[parameter], dtype=float)

    def stds(self, parameter: str) -> np.ndarray:
        """Standard deviations of ``parameter`` (NaN where unknown).

        Parameters
        ----------
        parameter : str
            A parameter of the table.

        Returns
        -------
        ndarray
            One value per row, in the parameter's unit.
        """
        self._check_parameter(parameter)
        return np.asarray(self.columns[parameter + "_std"], dtype=float)

    def feature(self, name: str) -> np.ndarray:
        """The column of feature ``name`` (numbers in its unit, or strings).

        Parameters
        ----------
        name : str
            A feature of the table.

        Returns
        -------
        ndarray
            One value per row: numbers in the feature's unit, or names for a categorical feature.
        """
        if name not in self.features:
            raise InvalidValueError(
                f"feature {name!r} is not in the table; it has {', '.join(self.features) or 'none'}")
        return self.columns[name]

    def feature_groups(self) -> list[list[int]]:
        """Rows with the same features, grouped: one group per tool (repeated tests of it together).

        Returns
        -------
        list of list of int
            Row indices (0-based) of each distinct feature set, in the order they first appear.
        """
        groups: dict[tuple, list[int]] = {}
        keys = zip(*(np.asarray(self.columns[f]).tolist() for f in self.features)) if self.features else ()
        for i, key in enumerate(keys):
            groups.setdefault(key, []).append(i)
        return list(groups.values()) if self.features else [list(range(len(self)))]

    def check_distinct_features(self, minimum: int, purpose: str) -> None:
        """Raise :class:`InvalidValueError` when fewer than ``minimum`` rows have distinct features.

        Repeated tests of one tool (rows with the same features) count once:
        they measure its scatter, not how the joint changes with the features.

        Parameters
        ----------
        minimum : int
            The distinct feature sets needed.
        purpose : str
            What needs them, for the message (e.g. ``"a surrogate"``).
        """
        self.check_not_empty(minimum, purpose)
        distinct = len(self.feature_groups())
        if distinct < minimum:
            raise InvalidValueError(
                f"the joint table has {len(self)} rows but {distinct} distinct tools (feature sets; rows with the "
                f"same features are repeated tests of one tool); {purpose} needs at least {minimum}")

    def _check_parameter(self, parameter: str) -> None:
        if parameter not in self.parameters:
            raise InvalidValueError(
                f"parameter {parameter!r} is not in the table; it has {', '.join(self.parameters)}"
            )

    def check_not_empty(self, minimum: int = 1, purpose: str = "") -> None:
        """Raise :class:`InvalidValueError` for a table with fewer than ``minimum`` rows.

        Parameters
        ----------
        minimum : int, default 1
            The rows needed.
        purpose : str
            What needs them, for the message (e.g. ``"a surrogate"``).
        """
        if len(self) == 0:
            raise InvalidValueError("the joint table is empty: identify some joints and append them first")
        if len(self) < minimum:
            rows = "1 row" if len(self) == 1 else f"{len(self)} rows"
            raise InvalidValueError(f"the joint table has {rows}; {purpose or 'this'} needs at least {minimum}")

    def feature_values(self, features: Mapping[str, Any], field: str = "features") -> dict[str, Any]:
        """Check one set of features against the table: every feature, in matching units.

        Parameters
        ----------
        features : mapping
            ``{feature: quantity, string with a unit, or name}`` with every feature of the table.
        field : str
            Name of the argument, for error messages.

        Returns
        -------
        dict
            Numbers in the table's units, strings for categorical features.
        """
        missing = [f for f in self.features if f not in features]
        if missing:
            raise InvalidValueError(
                f"{field}: {', '.join(missing)} missing; the table's features are "
                + ", ".join(f"{f} [{u}]" if u else f"{f} (categorical)" for f, u in self.features.items())
            )
        unknown = [f for f in features if f not in self.features]
        if unknown:
            raise InvalidValueError(
                f"{field}: {', '.join(unknown)} not in the table; its features are {', '.join(self.features)}"
            )
        out = {}
        for name, unit in self.features.items():
            value = features[name]
            if unit is None:
                if not isinstance(value, str):
                    raise InvalidValueError(f"{name}: got {value!r}; this feature is categorical (a name)")
                out[name] = value.strip()
            else:
                out[name] = _to_unit(value, unit, name)
                if _is_size(unit) and out[name] <= 0:
                    raise InvalidValueError(f"{field}: {name} is {value!s}; expected a size > 0 ({name} is a length, "
                                            f"in {unit} in the table)")
        return out

    # -- changes -----------------------------------------------------------------------------

    def append(self, row: Mapping[str, Any]) -> "JointTable":
        """A new table with one more row (quantities for parameters and unit features).

        Parameters
        ----------
        row : mapping
            Every parameter and feature, values with units (``"1.4e7 N/m"``, ``"12 mm"``);
            optional ``NAME_std`` standard deviations.

        Returns
        -------
        JointTable
            A new table; this one is unchanged.
        """
        feats = self.feature_values({k: v for k, v in row.items() if k in self.features
                                     or not (k in self.parameters or k.endswith("_std") and k[:-4] in self.parameters)},
                                    field="row")
        missing = [p for p in self.parameters if p not in row]
        if missing:
            raise InvalidValueError(f"row: parameter {', '.join(missing)} missing")
        cols = {k: list(v) for k, v in self.columns.items()}
        for p, unit in self.parameters.items():
            cols[p].append(_to_unit(row[p], unit, p))
            std = row.get(p + "_std")
            cols[p + "_std"].append(math.nan if std is None else _to_unit(std, unit, p + "_std"))
        for f, v in feats.items():
            cols[f].append(v)
        arrays = {k: np.array(v, dtype=object if (k in self.features and self.features[k] is None) else float)
                  for k, v in cols.items()}
        return JointTable(self.parameters, self.features, arrays)

    def append_report(self, report, features: Mapping[str, Any]) -> "JointTable":
        """A new table with the joint identified in ``report`` (an IdentificationReport).

        The report's values are SI (``k_yf`` in N/m, ...); every parameter of
        the table is taken from it, with its standard deviation when fitted.

        Parameters
        ----------
        report : IdentificationReport
            The identification of the joint.
        features : mapping
            The joint's features, with units (``{"tool_diameter": "12 mm", ...}``).

        Returns
        -------
        JointTable
            A new table; this one is unchanged.
        """
        row = dict(features)
        for p in self.parameters:
            kind, entry = p.split("_", 1)
            values = report.k if kind == "k" else report.c
            stds = report.k_std if kind == "k" else report.c_std
            if entry not in values:
                raise InvalidValueError(f"report of joint {report.joint!r} has no {p}")
            unit = PARAMETER_UNITS[p]
            row[p] = ureg.Quantity(float(values[entry]), unit)
            std = float(stds.get(entry, 0.0))
            row[p + "_std"] = ureg.Quantity(std, unit) if std > 0 else None
        return self.append(row)

    # -- output ------------------------------------------------------------------------------

    def to_csv(self, path: str | Path | None = None, overwrite: bool = False) -> str:
        """Write the table as CSV (units in the header); returns the text.

        Parameters
        ----------
        path : str or os.PathLike, optional
            Where to write it; None only returns the text.
        overwrite : bool, default False
            Whether an existing file may be replaced (else ``OutputExistsError``, naming it).

        Returns
        -------
        str
            The CSV text.
        """
        header, keys = [], []
        for f, u in self.features.items():
            header.append(f"{f} [{u}]" if u else f)
            keys.append(f)
        for p, u in self.parameters.items():
            header += [f"{p} [{u}]", f"{p}_std [{u}]"]
            keys += [p, p + "_std"]
        buf = io.StringIO()
        w = csv.writer(buf, lineterminator="\n")
        w.writerow(header)
        for i in range(len(self)):
            cells = []
            for k in keys:
                v = self.columns[k][i]
                if isinstance(v, str):
                    cells.append(v)
                elif isinstance(v, float) and math.isnan(v):
                    cells.append("")
                else:
                    cells.append(repr(float(v)))
            w.writerow(cells)
        return _written(buf.getvalue(), path, overwrite)

    def to_toml(self, path: str | Path | None = None, overwrite: bool = False) -> str:
        """Write the table as TOML: a ``[[joints]]`` table per row, every value with its unit.

        :meth:`from_toml` reads it back to an equal table (units and values).

        Parameters
        ----------
        path : str or os.PathLike, optional
            Where to write it; None only returns the text.
        overwrite : bool, default False
            Whether an existing file may be replaced (else ``OutputExistsError``, naming it).

        Returns
        -------
        str
            The TOML text.
        """
        import tomli_w

        rows = []
        for i in range(len(self)):
            row = {}
            for f, u in self.features.items():
                v = self.columns[f][i]
                row[f] = str(v) if u is None else f"{float(v)!r} {u}"
            for p, u in self.parameters.items():
                row[p] = f"{float(self.columns[p][i])!r} {u}"
                std = float(self.columns[p + "_std"][i])
                if not math.isnan(std):
                    row[p + "_std"] = f"{std!r} {u}"
            rows.append(row)
        header = {"parameters": dict(self.parameters),
                  "features": {f: (u if u is not None else "categorical") for f, u in self.features.items()}}
        return _written(tomli_w.dumps({**header, "joints": rows}), path, overwrite)

    @classmethod
    def from_toml(cls, path: str | Path) -> "JointTable":
        """Read a table written by :meth:`to_toml` (or by hand in that form).

        Parameters
        ----------
        path : str or os.PathLike
            The TOML file.

        Returns
        -------
        JointTable
            The table.
        """
        from .._toml import read_toml

        doc = read_toml(path, "joint table")
        data = doc.data
        doc.table(data, [], ("parameters", "features", "joints"))
        for key in ("parameters", "features", "joints"):
            if key not in data:
                raise doc.error([], f"missing [{key}]")
        for key in ("parameters", "features"):
            if not isinstance(data[key], dict) or not all(isinstance(u, str) for u in data[key].values()):
                raise doc.error([key], "expected NAME = \"unit\" entries")
        if not isinstance(data["joints"], list) or not all(isinstance(r, dict) for r in data["joints"]):
            raise doc.error(["joints"], "expected [[joints]] tables")
        features = {f: (None if u == "categorical" else u) for f, u in data["features"].items()}
        try:
            table = cls.empty(data["parameters"], features)
        except (InvalidValueError, UnitError) as exc:
            raise doc.error([], str(exc)) from None
        for i, row in enumerate(data["joints"]):
            try:
                table = table.append(row)
            except (InvalidValueError, UnitError) as exc:
                raise doc.error(["joints", i], str(exc)) from None
        return table

    def describe(self) -> str:
        """One line: rows, parameters and features.

        Returns
        -------
        str
            The description, with units.
        """
        feats = ", ".join(f"{f} [{u}]" if u else f"{f} (categorical)" for f, u in self.features.items())
        tools = len(self.feature_groups())
        rows = f"{len(self)} joints" + (f" of {tools} distinct tools" if tools < len(self) else "")
        return f"{rows}; parameters {', '.join(self.parameters)}; features {feats}"


def _written(text: str, path: str | Path | None, overwrite: bool) -> str:
    """``text``, written to ``path`` first unless it is None (an existing file only with ``overwrite``)."""
    if path is not None:
        from ..io import write_text

        write_text(path, text, overwrite=overwrite)
    return text


def thesis_table_4_2() -> JointTable:
    """Thesis Table 4.2 as a joint table: 13 holder-tool ``k_yf`` over diameter and gauge length.

    Returns
    -------
    JointTable
        Features ``tool_diameter`` and ``gauge_length`` in mm, parameter ``k_yf`` in N/m.
    """
    from ..datasets import thesis_table

    rows = [
        {"tool_diameter": f"{r['tool_diameter_mm']} mm", "gauge_length": f"{r['gauge_length_mm']} mm",
         "k_yf": f"{float(r['k_yf_identified_1e7_N_per_m']) * 1e7!r} N/m"}
        for r in thesis_table("4.2")
    ]
    return JointTable.from_rows(rows)
