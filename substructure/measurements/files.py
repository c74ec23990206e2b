"""Measurement files (internal): the reading of a measurement set file (TOML) into the class it is given.

The public readers are :func:`substructure.io.measurements.load_measurements` (its documentation
describes the format and the checks) and :meth:`MeasurementSet.from_file`; the reading is here, in
the ``measurements`` layer, so that ``MeasurementSet.from_file`` reads without importing ``io``.
"""

from __future__ import annotations

import math
import os
import re
import warnings
from pathlib import Path
from typing import Any

import attrs
import numpy as np

from .._files import MAX_DATA_BYTES, file_name, read_text, relative_path
from .._files import check_file as check_readable_file
from .._toml import TomlDocument, loads_toml
from ..errors import FileFormatError, InvalidValueError, SubstructureError, SubstructureWarning, WindowedFRFWarning
from ..frf import FRF, QUANTITIES, Frequency
from ..frf.axis import ROUNDED_STEP_SHARE, rounded_uniform
from ..frf.files._common import _beyond_physical
from ..frf.files._common import QuantityContradiction
from ..frf.files.csv_files import _read_csv
from ..frf.files.mat_reader import read_mat, read_mat_coherence
from ..frf.files.uff_reader import read_uff, read_uff_coherence
from ..points import check_name
from ..tap import ESTIMATORS
from .measurement import Measurement, _optional_force_window, _optional_tau, dof_label

__all__ = ["read_measurements", "reads_measurements"]

_TOP_KEYS = ("name", "frf")
_FRF_KEYS = ("response", "excitation", "file", "record", "quantity", "sensors", "removed", "averages", "window_tau_s",
             "force_window_s", "estimator", "coherence_record")
_REQUIRED = ("response", "excitation", "file")
_CSV = (".csv",)
_FOREIGN_LABEL = re.compile(r"^node(?P<node>-?\d+):(?:(?P<dof>y|theta)|dir(?P<code>\d+))$")  # uff_units._label
_UFF = (".uff", ".unv")
_MAT = (".mat",)  # MATLAB files of signal structures (Simcenter Testlab exports)


def _uniform_grid(hz: np.ndarray) -> tuple[np.ndarray | None, tuple[int, str] | None]:
    """A data file's frequencies as the uniform grid they stand for, or the first line that breaks it, in words.

    Identification and diagnosis estimate each line's noise from its neighbours (Savitzky-Golay smoothing), which
    needs equally spaced lines.  Frequencies within ``ROUNDED_STEP_SHARE`` of a step of the uniform grid
    fitted to them (``substructure.frf.axis.rounded_uniform``; a leading 0 Hz line, dropped later, aside) are that
    grid, written rounded.
    """
    first = 1 if hz.size > 1 and hz[0] == 0.0 else 0
    n = hz.size - first
    if n < 3:
        return hz, None
    steps = np.diff(hz[first:])
    if not np.ptp(steps) > 1e-6 * steps.mean():  # uniform as written (the smoother's tolerance): kept
        return hz, None
    grid = rounded_uniform(hz[first:])
    if grid is not None:
        return np.concatenate([hz[:first], grid]), None
    index = np.arange(n)
    off = np.abs(hz[first:] - np.polyval(np.polyfit(index, hz[first:], 1), index))
    jump = np.abs(steps - steps[0]) > 2 * ROUNDED_STEP_SHARE * steps[0]  # where the step changes, else the drift
    k = int(np.argmax(jump)) if jump.any() else max(int(np.argmax(off)) - 1, 0)
    return None, (first + k + 1, f"{steps[k]:.6g} Hz after the line before, where the grid's step is {steps[0]:.6g} "
                  "Hz: identify and diagnose estimate each line's noise from its neighbours and need equally spaced "
                  "lines; write the data on one frequency step (as `substructure tap` writes them; frequencies "
                  f"rounded within {ROUNDED_STEP_SHARE:g} of a step are read as their grid)")


class _LocatedError(FileFormatError):
    """An error already naming the measurement file and the key path."""


class _Reader:
    def __init__(self, doc: TomlDocument, base_dir: Path):
        self.base_dir, self.source, self.doc = base_dir, doc.source, doc
        self.nodes: dict[int, tuple[tuple[int, int], tuple[int, int]]] = {}  # frf index: (node, direction) x 2

    @staticmethod
    def parts(index: int | None, key: str | None) -> list:
        return ([] if index is None else ["frf", index]) + ([] if key is None else [key])

    def error(self, index: int | None, key: str | None, message: str) -> FileFormatError:
        return self.doc.error(self.parts(index, key), message, _LocatedError)

    # -- values ------------------------------------------------------------
    def string(self, table: dict, index: int, key: str) -> str:
        value = table[key]
        if not isinstance(value, str) or not value.strip():
            raise self.error(index, key, f"got {value!r}; expected a non-empty string")
        return value

    def point(self, table: dict, index: int, key: str) -> str:
        value = self.string(table, index, key)
        try:
            return dof_label(value, key)
        except SubstructureError as exc:
            message = str(exc)
            raise self.error(index, key, message.split(": ", 1)[1] if message.startswith(key) else message) from None

    def names(self, table: dict, index: int, key: str) -> tuple[str, ...]:
        value = table.get(key, [])
        what = "sensor names declared in the assembly" if key == "sensors" else "component names"
        if not isinstance(value, list):
            raise self.error(index, key, f"got {value!r}; expected an array of {what}, e.g. [\"accelerometer\"]")
        for name in value:
            try:
                check_name(name, key)
            except SubstructureError as exc:
                raise self.error(index, key, str(exc).split(": ", 1)[1]) from None
        twice = sorted({n for n in value if value.count(n) > 1})
        if twice:
            raise self.error(index, key, f"{', '.join(map(repr, twice))} given more than once")
        return tuple(value)

    def choice(self, table: dict, index: int, key: str, options: tuple[str, ...]) -> str | None:
        if key not in table:
            return None
        value = table[key]
        if value not in options:
            raise self.error(index, key, f"got {value!r}; expected one of {', '.join(options)}")
        return value

    def integer(self, table: dict, index: int, key: str, minimum: int, expected: str) -> int | None:
        if key not in table:
            return None
        value = table[key]
        if isinstance(value, bool) or not isinstance(value, int) or value < minimum:
            raise self.error(index, key, f"got {value!r}; expected {expected}")
        return value

    def seconds(self, table: dict, index: int, key: str, convert, expected: str) -> float | None:
        if key not in table:
            return None
        value = table[key]
        try:
            return convert(value)  # what a measurement takes, said with the file's key
        except InvalidValueError:
            raise self.error(index, key, f"got {value!r}; expected {expected} (a number > 0)") from None

    # -- data files -----------------------------------------------------------
    def data(self, index: int, file: str, record: int | None, quantity: str | None,
             response: str, excitation: str) -> tuple[FRF, dict[str, Any], float | None]:
        path = relative_path(self.base_dir, file)
        suffix = path.suffix.lower()
        if suffix not in _CSV + _UFF + _MAT:
            raise self.error(index, "file", f"{file!r}: unknown kind of file; expected .csv, .uff, .unv or .mat")
        if not path.exists():
            raise self.error(index, "file", f"{path}: no such file (paths are relative to the measurement file)")
        try:
            check_readable_file(path, "data file", MAX_DATA_BYTES)
            if suffix in _CSV:
                if record is not None:
                    raise self.error(index, "record", f"a CSV file ({file}) holds one FRF; record is for UFF and "
                                                      "MATLAB files")
                frf, lines_of, columns, window = _read_csv(path, output=response, input=excitation,
                                                           quantity=quantity)
            elif suffix in _MAT:
                try:
                    frf = read_mat(path, record=record, quantity=quantity, output=response, input=excitation)
                except InvalidValueError as exc:  # an index beyond the file's channels
                    if not str(exc).startswith("record:"):
                        raise
                    raise self.error(index, "record", f"{path}: {str(exc)[len('record: '):]}") from None
                lines_of, columns, window = None, {}, None
            else:
                frf = self.uff(index, path, record, quantity, response, excitation)
                lines_of, columns, window = None, {}, None
            beyond = _beyond_physical(frf.frequency.hz, frf.data, frf.quantity)  # a measured FRF's range
            if beyond is not None:
                k, what = beyond
                where = (f"line {lines_of[k]}" if lines_of is not None else
                         f"{'channel' if suffix in _MAT else 'type-58 record'} {record or 0}, value {k + 1} of "
                         f"{frf.frequency.n}")
                raise FileFormatError(f"{path}, {where}: at {frf.frequency.hz[k]:g} Hz: {what}")
            grid, irregular = _uniform_grid(frf.frequency.hz)
            if grid is not None and not np.array_equal(grid, frf.frequency.hz):
                frf = attrs.evolve(frf, frequency=Frequency(grid))
            if irregular is not None:
                k, what = irregular
                where = (f"line {lines_of[k]}" if lines_of is not None else
                         f"{'channel' if suffix in _MAT else 'type-58 record'} {record or 0}, value {k + 1} of "
                         f"{frf.frequency.n}")
                raise FileFormatError(f"{path}, {where}: at {frf.frequency.hz[k]:g} Hz: {what}")
            return frf, columns, window
        except _LocatedError:
            raise
        except QuantityContradiction as exc:  # the file says another quantity than the key
            raise self.error(index, "quantity", f"{quantity!r} contradicts the data file: {exc}; leave the key out "
                             "or correct it") from None
        except FileFormatError as exc:  # names the data file (and its line)
            raise self.error(index, "file", str(exc)) from None
        except SubstructureError as exc:
            raise self.error(index, "file", f"{path}: {exc}") from None

    def uff_coherence(self, index: int, file: str, record: int, frf: FRF) -> Any:
        path = relative_path(self.base_dir, file)
        if path.suffix.lower() not in _UFF + _MAT:
            raise self.error(index, "coherence_record", f"a CSV file ({file}) has no records; its coherence is its "
                                                        "fourth column")
        try:
            read = read_mat_coherence if path.suffix.lower() in _MAT else read_uff_coherence
            hz, values = read(path, record)
        except FileFormatError as exc:
            raise self.error(index, "coherence_record", str(exc)) from None
        if hz.size != frf.frequency.n or not np.allclose(hz, frf.frequency.hz, rtol=1e-6, atol=0.0):
            raise self.error(index, "coherence_record",
                             f"{path}, {'channel' if path.suffix.lower() in _MAT else 'type-58 record'} {record}: "
                             f"the coherence's {hz.size} lines from {hz[0]:g} to "
                             f"{hz[-1]:g} Hz are not the FRF's {frf.frequency!r}")
        return values

    def uff(self, index: int, path: Path, record: int | None, quantity: str | None,
            response: str, excitation: str) -> FRF:
        try:
            frf = read_uff(path, record=record, quantity=quantity)
        except SubstructureError as exc:
            if str(exc).startswith("record:"):  # an index beyond the file's records
                raise self.error(index, "record", f"{path}: {str(exc)[len('record: '):]}") from None
            raise
        if frf.shape[1:] != (1, 1):
            raise self.error(
                index, "record", f"missing; {path} holds {frf.shape[1] * frf.shape[2]} type-58 records: "
                "give the 0-based index of this FRF's record, record = N"
            )
        stored = []
        for label in (frf.outputs[0], frf.inputs[0]):
            try:
                stored.append(dof_label(label))
            except SubstructureError:  # labels of another program: their nodes are not the set's points
                self.check_directions(index, path, record, frf, response, excitation)
                found = [_FOREIGN_LABEL.match(label) for label in (frf.outputs[0], frf.inputs[0])]
                if found[0] and found[1]:
                    self.nodes[index] = tuple(  # type: ignore[assignment]
                        (int(m["node"]), 2 if m["dof"] == "y" else 6 if m["dof"] == "theta" else int(m["code"]))
                        for m in found)
                return frf.with_labels((response,), (excitation,))
        if stored != [response, excitation]:
            raise self.error(
                index, "record" if record is not None else "file",
                f"{path}, record {record if record is not None else 0} holds response {stored[0]} / excitation "
                f"{stored[1]}, not {response} / {excitation} as this table says; check the record index (0-based)",
            )
        return frf.with_labels((response,), (excitation,))

    def check_directions(self, index: int, path: Path, record: int | None, frf: FRF, response: str,
                         excitation: str) -> None:
        """A record of another program (``node<N>:<dof>``) is taken for the table's points, but its direction
        codes must be of the same kind as the table's DOFs: a translation (1-3) for ``y``, a rotation (4-6) for
        ``theta``; direction 0 (a scalar) says nothing."""
        for key, label, point in (("response", frf.outputs[0], response), ("excitation", frf.inputs[0], excitation)):
            match = _FOREIGN_LABEL.match(label)
            if match is None:
                continue
            code = 2 if match["dof"] == "y" else 6 if match["dof"] == "theta" else int(match["code"])
            if code not in range(1, 7):
                continue
            kind, wanted = ("a rotation" if code > 3 else "a translation",
                            "a rotation" if point.endswith(":theta") else "a translation")
            if kind != wanted:
                raise self.error(
                    index, "record" if record is not None else key,
                    f"{path}, type-58 record {record or 0}: its {'reference' if key == 'excitation' else key} is "
                    f"{kind} (direction code {code}) at node {match['node']}, but this table's {key} {point} is "
                    f"{wanted}; check the record index (0-based) or the {key}'s DOF (:y or :theta)")

    # -- the file, top down ----------------------------------------------------
    def measurement_set(self, data: dict, cls: Any) -> Any:
        for key in data:
            if key not in _TOP_KEYS:
                raise self.error(None, key, f"unknown key; allowed keys: {', '.join(_TOP_KEYS)}")
        name = data.get("name", Path(self.source).stem if self.source != "<string>" else "measurements")
        if not isinstance(name, str) or not name.strip():
            raise self.error(None, "name", f"got {name!r}; expected a non-empty string")
        tables = data.get("frf")
        if tables is None:
            raise self.error(None, "frf", "missing; a measurement set needs at least one [[frf]] table")
        if not isinstance(tables, list) or not tables:
            raise self.error(None, "frf", f"got {tables!r}; expected [[frf]] tables")
        measurements = [self.measurement(table, index) for index, table in enumerate(tables)]
        self.check_set(measurements)
        try:
            return cls(name, measurements, source=self.source)
        except SubstructureError as exc:  # pragma: no cover - check_set found these first
            raise FileFormatError(f"{self.source}: {exc}") from None

    def measurement(self, table: Any, index: int) -> Measurement:
        if not isinstance(table, dict):
            raise self.error(index, None, f"got {table!r}; expected a table")
        for key in table:
            if key not in _FRF_KEYS:
                raise self.error(index, key, f"unknown key; allowed keys: {', '.join(_FRF_KEYS)}")
        for key in _REQUIRED:
            if key not in table:
                raise self.error(index, key, "missing; this value is required")
        response, excitation = self.point(table, index, "response"), self.point(table, index, "excitation")
        file = self.string(table, index, "file")
        quantity = self.choice(table, index, "quantity", QUANTITIES)
        record = self.integer(table, index, "record", 0, "the 0-based index of a type-58 record (of a channel "
                              "on a frequency axis in a .mat file)")
        sensors, removed = self.names(table, index, "sensors"), self.names(table, index, "removed")
        averages = self.integer(table, index, "averages", 1, "the number of averages (an integer >= 1)")
        tau = self.seconds(table, index, "window_tau_s", _optional_tau, "the exponential window's time constant in s")
        force_window = self.seconds(table, index, "force_window_s", _optional_force_window,
                                    "the force window's length in s")
        estimator = self.choice(table, index, "estimator", ESTIMATORS)
        coherence_record = self.integer(table, index, "coherence_record", 0,
                                        "the 0-based index of the type-58 coherence record")
        with warnings.catch_warnings(record=True) as caught:  # a file's window the entry gives is said no more
            warnings.simplefilter("always", WindowedFRFWarning)
            raw, columns, window = self.data(index, file, record, quantity, response, excitation)
        for item in caught:
            if tau is None or not issubclass(item.category, WindowedFRFWarning):
                warnings.warn_explicit(item.message, item.category, item.filename, item.lineno)
        if window is not None:  # the data file says it was measured through the window: it travels with the data
            if tau is None:
                tau = window
            elif not math.isclose(tau, window, rel_tol=1e-9):
                raise self.error(index, "window_tau_s", f"got {tau!r} s, but {file} says it was measured through "
                                                        f"a window of {window!r} s (its '# window_tau_s' line); "
                                                        "give the file's value or leave the key out")
        if coherence_record is not None:
            columns["coherence"] = self.uff_coherence(index, file, coherence_record, raw)
        if "force_noise" in columns and force_window is None:
            raise self.error(index, "force_window_s", f"missing; {file} has a force_noise column, correlated over "
                                                      "1 / force_window_s hertz (the force window's length in s)")
        if raw.frequency.hz[0] == 0.0:
            if raw.frequency.n < 3:
                raise self.error(index, "file", f"{relative_path(self.base_dir, file)}: {raw.frequency.n} "
                                 "frequency lines, the first at 0 Hz, which is dropped (no receptance there); an FRF "
                                 "needs at least 2 lines besides it")
            why = ("the model has no receptance at 0 Hz (its free-free components have no static receptance), so "
                   "identify and diagnose cannot compare it" if raw.quantity == "receptance" else
                   f"{'an' if raw.quantity[0] in 'aeiou' else 'a'} {raw.quantity} has no receptance at 0 Hz")
            warnings.warn(
                f"{self.doc.where(self.parts(index, 'file'))}: frf[{index}].file: {file}: dropped the 0 Hz "
                f"line: {why}",
                SubstructureWarning, stacklevel=2,
            )
            raw = raw.crop(lo=raw.frequency.hz[1])
            columns = {key: value[1:] for key, value in columns.items()}
        try:
            receptance = raw.to_receptance(1.0 / tau if tau else 0.0)
        except SubstructureError as exc:
            raise self.error(index, "file", f"{relative_path(self.base_dir, file)}: {exc}") from None
        try:
            return Measurement(response, excitation, receptance, raw.quantity, sensors, removed, file, record,
                               columns.get("coherence"), averages, tau, columns.get("force_noise"), force_window,
                               estimator, columns.get("truncation"))
        except SubstructureError as exc:  # pragma: no cover - every field was checked above
            raise self.error(index, None, str(exc)) from None

    def check_set(self, measurements: list[Measurement]) -> None:
        first = measurements[0]
        seen: dict[tuple, int] = {}
        sources: dict[tuple, int] = {}
        for i, m in enumerate(measurements):
            if m.frf.frequency != first.frf.frequency:
                raise self.error(
                    i, "file",
                    f"{m.file} and {first.file} (frf[0].file) have different frequency axes "
                    f"({m.frf.frequency!r} and {first.frf.frequency!r}); all FRFs of a measurement set "
                    "must share one grid: interpolate them to a common grid (FRF.interpolate) and write "
                    "them again",
                )
            key = (m.response, m.excitation, m.configuration)
            if key in seen:
                raise self.error(
                    i, None,
                    f"measures {m.response} / {m.excitation} in the same configuration as frf[{seen[key]}] "
                    "(same sensors and removed components); keep one",
                )
            seen[key] = i
            # the file itself: links, hard links, a name in other case
            found = os.stat(relative_path(self.base_dir, m.file))
            source = (found.st_dev, found.st_ino, m.record or 0)
            if source in sources:
                j = sources[source]
                raise self.error(
                    i, "record" if m.record is not None else "file",
                    f"reads the same data as frf[{j}] ({m.file}{f', record {m.record}' if m.record else ''}); "
                    "each [[frf]] table is a measurement of its own: check the file name and the record index",
                )
            sources[source] = i
        self.check_nodes(measurements)

    def check_nodes(self, measurements: list[Measurement]) -> None:
        """Records of another program name their points by node number: warn where the tables and the nodes
        disagree (a record index off by one, most often), not refuse, since a laboratory may number a point's
        hammer side and sensor side apart.  A driving point's record has one node in one direction; within one
        file and configuration a node is one point of the tables and a point one node."""
        points: dict[tuple, tuple[str, int]] = {}
        numbers: dict[tuple, tuple[int, int]] = {}
        for i, m in enumerate(measurements):
            if i not in self.nodes:
                continue
            found = os.stat(relative_path(self.base_dir, m.file))
            key = (found.st_dev, found.st_ino, m.configuration)  # one file's nodes, in one configuration
            where = f"{m.file}, type-58 record {m.record or 0}"
            (out_node, out_dir), (in_node, in_dir) = self.nodes[i]
            turned = 0 not in (out_dir, in_dir) and out_dir != in_dir  # direction 0, a scalar, says nothing
            if m.response == m.excitation and (out_node != in_node or turned):
                self.warn(i, f"{where} has its response at node {out_node} (direction {out_dir}) and its "
                             f"reference at node {in_node} (direction {in_dir}), but this table measures the driving "
                             f"point {m.response}; check the record index (0-based)")
            for role, label, node in (("response", m.response, out_node), ("excitation", m.excitation, in_node)):
                point = label.rsplit(":", 1)[0]
                other, j = points.setdefault(key + (node,), (point, i))
                if other != point:
                    there = ("its response is that node too, read as" if j == i else
                             f"frf[{j}] reads node {node} of this file as")
                    self.warn(i, f"{where}: its {role} is node {node}, read as {point}, but {there} {other}; a node "
                                 "is one point: check the record indices (0-based), and write one point the same "
                                 "way in every table")
                    continue
                number, j = numbers.setdefault(key + (point,), (node, i))
                if number != node:
                    self.warn(i, f"{where}: its {role} {point} is node {node}, but in frf[{j}] {point} is node "
                                 f"{number} of this file; check the record indices (0-based)")

    def warn(self, index: int, message: str) -> None:
        warnings.warn(f"{self.doc.where(self.parts(index, 'record'))}: frf[{index}]: {message}", SubstructureWarning,
                      stacklevel=2)


def reads_measurements(cls: Any, text: str, base_dir: str | os.PathLike = ".", source: str = "<string>") -> Any:
    """A measurement set of class ``cls`` from TOML text (:func:`substructure.io.measurements.loads_measurements`)."""
    doc = loads_toml(text, source, "measurement set")
    try:
        return _Reader(doc, Path(base_dir)).measurement_set(doc.data, cls)
    except _LocatedError as exc:  # the public class, without the internal marker
        raise FileFormatError(str(exc)) from None


def read_measurements(cls: Any, path: str | os.PathLike) -> Any:
    """A measurement set of class ``cls`` from a file (:func:`substructure.io.measurements.load_measurements`)."""
    name = file_name(path, "measurement set")
    text = read_text(path, "measurement set file")
    return reads_measurements(cls, text, base_dir=Path(name).parent, source=name)
