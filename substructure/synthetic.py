"""Synthetic tap tests: measurement sets made from a model, with realistic noise.

For teaching, examples, the demo and tests: :func:`simulate` computes the
FRFs a tap test would give on an assembly (with the sensors that were on and
the components that were off), adds multiplicative complex noise of a given
level with a fixed seed, and returns a
:class:`~substructure.measurements.MeasurementSet`; :func:`write_measurement_set`
saves it as CSV files plus the measurement TOML of docs/file-formats.md.
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import NamedTuple, Sequence

import numpy as np
import tomli_w

from .assembly import Assembly
from .errors import InvalidValueError
from .frf import FRF
from .measurements import Measurement, MeasurementSet, model_of_measurement
from .points import parse_point
from .units import finite_real, items_of, whole_number

__all__ = ["simulate", "write_measurement_set"]


class _Configuration(NamedTuple):
    sensors: tuple
    removed: tuple


def simulate(assembly: Assembly, points: Sequence[str], excitation: str | None = None, *, frequency=None,
             noise: float = 0.0, seed: int = 0, sensors: Sequence[str] = (), removed: Sequence[str] = (),
             name: str = "synthetic tap test") -> MeasurementSet:
    """Tap-test FRFs of a model: the response at each point for a hammer at ``excitation``.

    Parameters
    ----------
    assembly : Assembly
        The structure (its declared sensors are put on as listed in ``sensors``).
    points : sequence of str
        Response points (translational DOF ``y``).
    excitation : str, optional
        Where the hammer hits; default the first point.
    frequency : Frequency or array_like, optional
        Frequency lines (plain numbers in Hz); default the assembly's grid.
    noise : float
        Relative level of complex Gaussian multiplicative noise (0.02 for 2 %).
    seed : int
        Seed of the noise.
    sensors, removed : sequence of str
        Sensors (names declared in the assembly) on the structure, components off.
    name : str
        Name of the measurement set.

    Returns
    -------
    MeasurementSet
        One receptance (m/N) per point, recorded with the sensors and removed components.
    """
    if not (finite_real(noise) and noise >= 0):
        raise InvalidValueError(f"noise: got {noise!r}; expected a level >= 0")
    whole_number(seed, "seed", 0, "a seed, an integer")
    points = [points] if isinstance(points, str) else items_of(points, "points", "point names")
    if not points:
        raise InvalidValueError("points: got none; expected at least one response point")
    sensors, removed = (items_of(v, f, "names") for v, f in ((sensors, "sensors"), (removed, "removed")))
    model = model_of_measurement(assembly, _Configuration(tuple(sensors), tuple(removed)))
    excitation = excitation or points[0]
    rng = np.random.default_rng(seed)
    out = []
    ex = f"{parse_point(excitation).point}:y"
    for p in points:
        resp = f"{parse_point(p).point}:y"
        frf = model.frf([resp], [ex], frequency)
        if noise:
            z = (rng.standard_normal(frf.data.shape) + 1j * rng.standard_normal(frf.data.shape)) / np.sqrt(2)
            frf = FRF(frf.frequency, frf.data * (1 + noise * z), frf.outputs, frf.inputs)
        out.append(Measurement.from_frf(frf, resp, ex, sensors=sensors, removed=removed))
    return MeasurementSet(name, tuple(out))


def _file_name(m: Measurement, i: int) -> str:
    def clean(label: str) -> str:
        return label.replace(":y", "").replace(" ", "").replace("@", "_at_").replace(".", "_")

    tag = "__".join(filter(None, ["+".join(m.sensors), "-".join(f"no_{r}" for r in m.removed)]))
    return f"{i:02d}_{clean(m.response)}__{clean(m.excitation)}{'__' + tag if tag else ''}.csv"


def write_measurement_set(measurements: MeasurementSet | Sequence[Measurement], directory, name: str | None = None,
                          file_name: str = "measurements.toml", overwrite: bool = False) -> Path:
    """Write measurements as CSV files and a measurement TOML (docs/file-formats.md) into ``directory``.

    Parameters
    ----------
    measurements : MeasurementSet or sequence of Measurement
        The measurements (receptances on one grid).
    directory : str or path-like
        Where the files go; created if missing.
    name : str, optional
        The set's name in the file (default: the set's own, else "measurements").
    file_name : str, default "measurements.toml"
        The measurement file's name.
    overwrite : bool, default False
        Replace existing files; without it any existing file is an error
        before anything is written.

    Returns
    -------
    pathlib.Path
        The path of the TOML file.  Every file is written through a
        temporary file and an atomic rename (:func:`substructure.io.write_text`).
    """
    from .io import write_text
    from .io.frf_files import write_csv

    from ._files import file_name as _path_text

    directory = Path(_path_text(directory, "directory"))
    directory.mkdir(parents=True, exist_ok=True)
    items = list(measurements)
    toml_path = directory / file_name
    files = [directory / _file_name(m, i) for i, m in enumerate(items)]
    if not overwrite:
        existing = [str(p) for p in [toml_path, *files] if p.exists()]
        if existing:
            from .errors import OutputExistsError

            raise OutputExistsError(f"{existing[0]} exists; pass overwrite=True to replace it")
    tables = []
    for m, path in zip(items, files):
        write_csv(m.frf, path, overwrite=overwrite)
        table = {"response": m.response, "excitation": m.excitation, "file": os.path.basename(path)}
        if m.sensors:
            table["sensors"] = list(m.sensors)
        if m.removed:
            table["removed"] = list(m.removed)
        tables.append(table)
    title = name or getattr(measurements, "name", None) or "measurements"
    write_text(toml_path, tomli_w.dumps({"name": title, "frf": tables}), overwrite=overwrite)
    return toml_path
