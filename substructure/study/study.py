"""A study: every tool/holder combination on its machines, for every cut, as independent tasks.

:class:`Study` holds the definition (machines, combinations, cuts, what to
compute, grids, the surrogate), makes the tasks (:meth:`Study.tasks`: one
per combination and machine, plain data with a fingerprint and a seed
derived from the names) and runs them (:meth:`Study.run`, on Dask or in
this process; :mod:`substructure.study.runner`).
"""

from __future__ import annotations

import hashlib
import json
import re
import warnings
from typing import Any

import attrs

from ..errors import InvalidValueError
from .settings import Compute, Grid
from .spec import Combination, Cut, Machine, SurrogateSpec

__all__ = ["Study", "task_key", "task_seed"]


def _tuple_of(cls, field: str):
    def convert(value: Any) -> tuple:
        items = tuple(value or ())
        for i, item in enumerate(items):
            if not isinstance(item, cls):
                raise InvalidValueError(f"{field}[{i}]: got {type(item).__name__}; expected {cls.__name__}")
        seen: dict[str, int] = {}
        for i, item in enumerate(items):
            if item.name in seen:
                first = items[seen[item.name]]
                raise InvalidValueError(f"{item.where or f'{field}[{i}]'}: name: {item.name!r} is already the name of "
                                        f"{first.where or f'{field}[{seen[item.name]}]'}; names must be unique")
            seen[item.name] = i
        return items

    return convert


def task_seed(combination: str, machine: str) -> int:
    """The seed of a combination on a machine: from their names, not from the order tasks run in.

    Parameters
    ----------
    combination : str
        The combination's name.
    machine : str
        The machine's name.

    Returns
    -------
    int
        The first 32 bits of the SHA-256 of the two names.
    """
    digest = hashlib.sha256(f"{machine}\x00{combination}".encode()).digest()
    return int.from_bytes(digest[:4], "big")


def task_key(combination: str, machine: str) -> str:
    """The name of a combination's files in a study's output directory.

    Parameters
    ----------
    combination : str
        The combination's name.
    machine : str
        The machine's name.

    Returns
    -------
    str
        ``MACHINE__COMBINATION-HASH``: the names with anything but letters,
        digits, ``.``, ``_`` and ``-`` made ``_`` (cut to 40 characters
        each), and 8 hexadecimal digits of their hash, so that names that
        read alike never share a file.
    """
    def slug(text: str) -> str:
        return re.sub(r"[^A-Za-z0-9._-]", "_", text)[:40].strip(".") or "_"

    digest = hashlib.sha256(f"{machine}\x00{combination}".encode()).hexdigest()[:8]
    return f"{slug(machine)}__{slug(combination)}-{digest}"


@attrs.frozen
class Study:
    """Tool/holder combinations on machines, evaluated for cuts: FRFs, bands, lobes, recommendations.

    Parameters
    ----------
    name : str
        The study's name (titles, messages).
    machines : sequence of Machine
        At least one.
    combinations : sequence of Combination
        At least one; each runs on its machines (default all).
    cuts : sequence of Cut, optional
        The cuts; none: the FRF and the tool mode only.
    compute : Compute, optional
        What to compute (default: FRF, zero-order lobes, recommendation,
        band with a surrogate, figures).
    grid : Grid, optional
        Frequency lines (default the machines') and spindle speeds.
    surrogate : SurrogateSpec, optional
        Predicts the holder-tool joint of combinations without an explicit one.
    joint : str, default "holder-tool"
        The name of the holder-tool joint in the machines' assemblies.
    plugins : sequence of str, optional
        Modules every worker imports first (registered component types).
    source : str, optional
        The study file, for messages.
    inputs : sequence of str, optional
        Every file the study was read from (the output checks of the command).

    Examples
    --------
    >>> from substructure.study import Combination, Cut, Machine, Study
    >>> study = Study("two tools", [Machine("bench")],
    ...               [Combination("12 mm, 76 mm", tool={"diameter": "12 mm", "overhang": "76 mm", "teeth": 4},
    ...                            joint={"k": {"yf": "1.43e7 N/m"}}),
    ...                Combination("12 mm, 85 mm", tool={"diameter": "12 mm", "overhang": "85 mm", "teeth": 4},
    ...                            joint={"k": {"yf": "1.20e7 N/m"}})],
    ...               [Cut("aluminium", workpiece="aluminium-7075", radial_depth="3 mm")])
    >>> len(study.tasks())
    2
    """

    name: str
    machines: tuple = attrs.field(converter=_tuple_of(Machine, "machines"))
    combinations: tuple = attrs.field(converter=_tuple_of(Combination, "combinations"))
    cuts: tuple = attrs.field(default=(), converter=_tuple_of(Cut, "cuts"))
    compute: Compute = attrs.field(factory=Compute)
    grid: Grid = attrs.field(factory=Grid)
    surrogate: SurrogateSpec | None = None
    joint: str = "holder-tool"
    plugins: tuple = attrs.field(default=(), converter=tuple)
    source: str | None = attrs.field(default=None, eq=False)
    inputs: tuple = attrs.field(default=(), converter=tuple, eq=False)
    _fitted: dict = attrs.field(factory=dict, init=False, eq=False, repr=False)

    def __attrs_post_init__(self) -> None:
        if not isinstance(self.name, str) or not self.name.strip():
            raise InvalidValueError(f"name: got {self.name!r}; expected the study's name")
        if not self.machines:
            raise InvalidValueError("machines: none; a study needs at least one machine")
        if not self.combinations:
            raise InvalidValueError("combinations: none; a study needs at least one combination")
        for field, cls in (("compute", Compute), ("grid", Grid)):
            if not isinstance(getattr(self, field), cls):
                raise InvalidValueError(f"{field}: got {type(getattr(self, field)).__name__}; expected {cls.__name__}")
        if self.surrogate is not None and not isinstance(self.surrogate, SurrogateSpec):
            raise InvalidValueError(f"surrogate: got {type(self.surrogate).__name__}; expected SurrogateSpec")
        machines = {m.name for m in self.machines}
        cuts = {c.name for c in self.cuts}
        for i, combo in enumerate(self.combinations):
            where = combo.where or f"combinations[{i}]"
            for m in combo.machines or ():
                if m not in machines:
                    raise InvalidValueError(f"{where}: machines: {m!r} is not a machine of the study "
                                            f"({', '.join(sorted(machines))})")
            for c in combo.cuts or ():
                if c not in cuts:
                    raise InvalidValueError(f"{where}: cuts: {c!r} is not a cut of the study "
                                            f"({', '.join(sorted(cuts)) or 'none'})")
        powered = {m.name for m in self.machines if m.limits is not None
                   and (m.limits.power is not None or m.limits.torque is not None)}
        if self.compute.recommend and self.compute.lobes:
            for combo, machine in self.pairs():
                for cut in self.cuts:
                    if (machine.name in powered and cut.feed_per_tooth is None
                            and (combo.cuts is None or cut.name in combo.cuts)):
                        raise InvalidValueError(
                            f"{cut.where or f'cut {cut.name!r}'}: feed_per_tooth: missing; machine {machine.name!r} "
                            "has a power or torque limit, and checking it needs the cut's feed per tooth")
        for machine in self.machines:
            assembly = machine.build()
            missing = [n for n in ("holder", "tool") if n not in assembly.component_names]
            names = {j.name for j in assembly.joints}
            where = machine.where or f"machine {machine.name!r}"
            if missing:
                raise InvalidValueError(f"{where}: the assembly {machine.source} has no component "
                                        f"{' or '.join(map(repr, missing))}; a machine's assembly holds the holder "
                                        "and tool that combinations replace")
            if self.joint not in names:
                raise InvalidValueError(f"{where}: the assembly {machine.source} has no joint {self.joint!r} (its "
                                        f"joints: {', '.join(sorted(names)) or 'none'}); set the study's joint")
        for module in self.plugins:
            if not isinstance(module, str) or not module:
                raise InvalidValueError(f"plugins: got {module!r}; expected module names")

    # -- construction ------------------------------------------------------------------
    @classmethod
    def from_file(cls, path: Any) -> Study:
        """Read a study file (TOML; its combinations may be in a CSV file).

        Parameters
        ----------
        path : str or path-like
            The study file (docs/file-formats.md, "substructure study").

        Returns
        -------
        Study
            The study; paths in the file are relative to it.

        Raises
        ------
        FileFormatError
            Naming the file, the line and the key.
        """
        from ._reader import read_study

        return read_study(cls, path)

    # -- tasks -------------------------------------------------------------------------
    def pairs(self) -> list[tuple[Combination, Machine]]:
        """Every combination with each of its machines, in the study's order.

        Returns
        -------
        list of (Combination, Machine)
            Combinations in order, each with its machines in the study's order.
        """
        return [(combo, machine) for combo in self.combinations for machine in self.machines
                if combo.machines is None or machine.name in combo.machines]

    def _model(self):
        if "model" not in self._fitted:
            from ..surrogate import make_surrogate

            spec = self.surrogate
            targets = list(spec.targets) if spec.targets else None
            self._fitted["model"] = make_surrogate(spec.model).fit(spec.joint_table, targets)
        return self._fitted["model"]

    def _prediction(self, combo: Combination, machine: Machine) -> dict | None:
        if combo.joint is not None or self.surrogate is None:
            return None
        table = self.surrogate.joint_table
        features: dict[str, Any] = {}
        try:
            for feature in table.features:
                if combo.features and feature in combo.features:
                    features[feature] = combo.features[feature]
                elif feature in self.surrogate.features:
                    source = self.surrogate.features[feature]
                    value = machine.name if source == "machine" else combo.feature_source(source)
                    if value is None:
                        raise InvalidValueError(f"{feature}: the combination has no {source} (the study maps the "
                                                "feature to it)")
                    features[feature] = value
            extra = [f for f in (combo.features or {}) if f not in table.features]
            if extra:
                raise InvalidValueError(f"{extra[0]}: not a feature of the joint table ({', '.join(table.features)})")
            with warnings.catch_warnings(record=True) as record:
                warnings.simplefilter("always")
                prediction = self._model().predict(features)
        except Exception as exc:  # this combination's rows fail, the others go on
            return {"error": " ".join(str(exc).split())}
        return {"log_mean": {p: float(v[0]) for p, v in prediction.log_mean.items()},
                "log_std": {p: float(v[0]) for p, v in prediction.log_std.items()},
                "units": dict(prediction.units), "features": {k: str(v) for k, v in features.items()},
                "warnings": list(dict.fromkeys(" ".join(str(w.message).split()) for w in record))}

    def tasks(self) -> list[dict]:
        """The tasks: one per combination and machine, plain data a worker anywhere can compute.

        Joints predicted by the surrogate are predicted here (the surrogate
        is fitted once, in this process); a combination whose prediction
        fails carries the message and fails its rows.

        Returns
        -------
        list of dict
            In the study's order; each with ``key``, ``fingerprint`` (SHA-256
            of everything the result depends on, the package's version
            included) and ``seed`` (from the names).
        """
        from .. import __version__

        compute = attrs.asdict(self.compute)
        compute.update(point=self.compute.point, recommend_method=self.compute.recommend_method,
                       lobes=list(self.compute.lobes), quantiles=list(self.compute.quantiles))
        grid = {k: None if v is None else list(v) for k, v in attrs.asdict(self.grid).items()}
        cuts = {c.name: c.spec() for c in self.cuts}
        tasks = []
        for combo, machine in self.pairs():
            where = (f"{combo.where} " if combo.where else "") + f"(combination {combo.name!r} on {machine.name!r})"
            task = {
                "combination": combo.name, "where": where, "seed": task_seed(combo.name, machine.name),
                "key": task_key(combo.name, machine.name), "machine": machine.spec(), "tool": combo.tool,
                "holder": combo.holder, "joint": combo.joint, "joint_name": self.joint,
                "prediction": self._prediction(combo, machine),
                "cuts": [cuts[n] for n in (combo.cuts if combo.cuts is not None else cuts)],
                "compute": compute, "grid": grid, "plugins": list(self.plugins),
            }
            text = json.dumps(task, sort_keys=True) + f"\x00substructure {__version__}"  # inf as a bad value says it
            task["fingerprint"] = hashlib.sha256(text.encode()).hexdigest()
            tasks.append(task)
        return tasks

    # -- running -----------------------------------------------------------------------
    def run(self, client: Any = None, out: Any = None, *, scheduler: str | None = None, resume: bool = False,
            overwrite: bool = False, progress: Any = True):
        """Compute every combination and return the table.

        Parameters
        ----------
        client : dask.distributed.Client, optional
            Run on this client's cluster (a notebook's).  Without it: the
            ``scheduler``, else the current default client, else a local
            cluster of one worker thread per CPU in this process (worker
            processes, ``scheduler="processes:N"``, need the ``if __name__
            == "__main__":`` guard in a script).
        out : str or path, optional
            Output directory: each finished combination is written there as
            it completes (``results/``, ``figures/``, ``frf/``), then the
            table (``table.parquet``, ``table.csv``) and ``summary.png``.
            Without it nothing is written.
        scheduler : str, optional
            ``"processes:N"`` (a local cluster of N worker processes),
            ``"local:N"`` (N worker threads in this process), a scheduler's
            address (``"tcp://host:8786"``) or ``"serial"`` (this process,
            no Dask).
        resume : bool, default False
            Keep the finished combinations found in ``out`` (same inputs:
            same fingerprint) and compute the rest.
        overwrite : bool, default False
            Compute everything anew, replacing the files of a study in ``out``.
        progress : bool or file, default True
            Progress lines (done / total, rate, time left; the dashboard's
            address) on standard error, on a file-like object, or none.

        Returns
        -------
        pandas.DataFrame
            One row per combination, machine and cut, in the study's order
            (:data:`~substructure.study.table.COLUMNS`).
        """
        from .runner import run_study

        return run_study(self, client=client, out=out, scheduler=scheduler, resume=resume, overwrite=overwrite,
                         progress=progress)
