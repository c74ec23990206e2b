"""Diagnosis: which physical effect is the model missing, and the refinement that adds it.

For every registered effect at every place it proposes, its few parameters
are fitted to the measurements by bounded least squares on the complex log
ratio of model to measurement (the error measure of
:mod:`substructure.diagnose.compare`), starting from a scan of the main
parameter; the candidates are ranked by their error after the fit.  The best
is declared the ``missing_effect`` only when

* the model is not already as good as the data (baseline error above 1.5
  times the noise floor), and
* the fit improves the error clearly beyond what noise allows: by more than
  half the noise floor and by more than a tenth of the excess over the floor.

Effects whose fitted error is nearly as low (within 0.3 times the noise
floor, plus a tenth of the best error's excess over the floor) are
``ambiguous_with`` it, with a suggestion of a measurement that would tell
them apart.

The refinement adds the best effect, fits all added effects together, and
diagnoses again, until nothing beats the noise floor; its history is the
"watch the error fall" table.
"""

from __future__ import annotations

import sys
from typing import Callable, Sequence

import attrs
import numpy as np
from scipy.optimize import least_squares

from ..assembly import Assembly
from ..errors import InvalidValueError, UnknownPointError
from ..frf import FRF
from ..identify.band_fit import model_of_measurement
from .compare import METRIC, Comparison, compare, noise_floor
from .effects import EFFECTS, Effect, get_effect

__all__ = ["Candidate", "Step", "Diagnosis", "diagnose", "SUGGESTIONS", "REFIT_TOP"]

REFIT_TOP = 3
"""In refinement steps after the first, the best this many candidates are refitted together with
the effects already added (the others keep their fit with those effects held)."""

SUGGESTIONS = {
    frozenset({"sensor-mass", "joint-stiffness"}): "measure once more with a laser vibrometer (or with a "
    "second, different sensor mass): a sensor's effect changes with its mass, a joint's does not",
    frozenset({"joint-stiffness", "joint-cross-coupling"}): "measure cross FRFs at a second point on the tool "
    "(finite-difference rotations): cross-coupling changes the tool's rotation, a stiffness change "
    "mostly its translation",
    frozenset({"sensor-mass", "fluted-section"}): "measure with a laser vibrometer: flutes stay, a sensor's "
    "mass goes",
    frozenset({"fluted-section", "joint-stiffness"}): "measure a second tool overhang: the joint stays, the "
    "fluted length moves with the tool",
    frozenset({"support-springs", "joint-stiffness"}): "extend the measurement down to a few Hz, or soften "
    "the suspension: support modes move with the suspension, joint modes do not",
}


def _suggestion(a: str, b: str) -> str:
    return SUGGESTIONS.get(frozenset({a, b}), "measure at another point, or in another configuration "
                           f"(with a component removed), where {a} and {b} act differently")


@attrs.frozen
class Candidate:
    """One effect at one place, fitted: its error after the fit.

    Parameters
    ----------
    effect : Effect
        The effect with its fitted values (SI units of its parameters).
    error : float
        The error measure after the fit (dimensionless, :data:`METRIC`).
    nfev : int
        Model evaluations the fit took.
    added : tuple of Effect
        Effects added earlier in the refinement, refitted with this one.
    """

    effect: Effect = attrs.field(eq=False)
    error: float
    nfev: int = 0
    added: tuple = attrs.field(default=(), eq=False)  # earlier effects, refitted with this one

    @property
    def name(self) -> str:
        """The effect's name (``"sensor_mass"``)."""
        return self.effect.name

    @property
    def where(self) -> str:
        """Where the effect acts: a point or a joint name."""
        return self.effect.where

    def to_json(self) -> dict:
        """The candidate as in ``substructure diagnose --json``.

        Returns
        -------
        dict
            ``effect``, ``where``, ``parameters`` (values with their SI units), ``error``,
            ``explanation``.
        """
        return {"effect": self.name, "where": self.where, "parameters": self.effect.parameters_json(),
                "error": self.error, "explanation": self.effect.explanation}


@attrs.frozen
class Step:
    """One step of the refinement: the effect added (None at step 0), with its values as fitted at
    that step, and the error after it (earlier effects refitted with it).

    Parameters
    ----------
    step : int
        The step number, 0 for the model as given.
    added : Effect or None
        The effect added at this step, with its values then (None at step 0).
    error : float
        The error measure after the step (dimensionless).
    """

    step: int
    added: Effect | None = attrs.field(eq=False)
    error: float

    def to_json(self) -> dict:
        """The step as in ``substructure diagnose --json``.

        Returns
        -------
        dict
            ``step``, ``added`` (a name or None), ``error``; ``where`` and ``parameters``
            (values with their SI units) when an effect was added.
        """
        out = {"step": self.step, "added": None if self.added is None else self.added.name, "error": self.error}
        if self.added is not None:
            out["where"] = self.added.where
            out["parameters"] = self.added.parameters_json()
        return out


@attrs.frozen
class Diagnosis:
    """What :func:`diagnose` found.  ``to_json`` gives the JSON of ``substructure diagnose --json``.

    Parameters
    ----------
    metric : str
        The error measure's name, :data:`METRIC`.
    baseline_error : float
        The error of the model as given (dimensionless).
    noise_floor : float
        The error a perfect model would show, estimated from the data.
    missing_effect : str or None
        The name of the effect found missing; None when nothing beats the noise floor.
    missing_where : str or None
        Where it acts (a point or a joint name).
    ambiguous_with : tuple of str
        Other effects that fit as well (the data cannot tell them apart).
    suggestion : str or None
        How to tell the ambiguous effects apart.
    candidates : tuple of Candidate
        Every effect at every place, fitted, the best first.
    refinement : tuple of Step
        The refinement's steps: the error falling as effects are added.
    band : tuple of float
        The frequency band compared, ``(lo, hi)`` in Hz.
    baseline : tuple of Comparison
        The model as given against each measurement.
    final : tuple of Comparison
        The refined model against each measurement.
    refined_assembly : Assembly
        The model with the effects added.
    final_effects : tuple of Effect
        The effects added, with their final (jointly refitted) values.
    """

    metric: str
    baseline_error: float
    noise_floor: float
    missing_effect: str | None
    missing_where: str | None
    ambiguous_with: tuple[str, ...]
    suggestion: str | None
    candidates: tuple[Candidate, ...]
    refinement: tuple[Step, ...]
    band: tuple[float, float]
    baseline: tuple[Comparison, ...] = attrs.field(eq=False)
    final: tuple[Comparison, ...] = attrs.field(eq=False)
    refined_assembly: Assembly = attrs.field(eq=False)
    final_effects: tuple = attrs.field(default=(), eq=False)

    @property
    def effects(self) -> list[Effect]:
        """The effects the refinement added, in order, with their final values (refitted together)."""
        return list(self.final_effects)

    def to_json(self) -> dict:
        """The JSON object of ``substructure diagnose --json`` (SI units, frequencies in Hz).

        Returns
        -------
        dict
            The diagnosis: errors, candidates, refinement, modes and error bands.
        """
        return {
            "metric": self.metric,
            "baseline_error": self.baseline_error,
            "noise_floor": self.noise_floor,
            "missing_effect": self.missing_effect,
            "ambiguous_with": list(self.ambiguous_with),
            "candidates": [c.to_json() for c in self.candidates],
            "refinement": [s.to_json() for s in self.refinement],
            "missing_where": self.missing_where,
            "suggestion": self.suggestion,
            "band_hz": list(self.band),
            "final_error": self.refinement[-1].error,
            "final_effects": [{"effect": e.name, "where": e.where, "parameters": e.parameters_json()}
                              for e in self.final_effects],
            "modes": [
                {"measured_hz": m.measured_hz, "model_hz": m.model_hz, "shift_hz": m.shift_hz,
                 "amplitude_ratio": m.amplitude_ratio}
                for m in self.baseline[0].modes
            ],
            "error_bands_hz": [[lo, hi, share] for lo, hi, share in self.baseline[0].bands],
        }

    def plot_where(self, ax=None):
        """The baseline comparison: FRFs overlaid, residual, error bands, mode shifts.

        Parameters
        ----------
        ax : Axes or sequence of Axes, optional
            Where to draw; a new figure when None.

        Returns
        -------
        Figure
            The figure (never shown by the library).
        """
        return self.baseline[0].plot(ax=ax)

    def plot_history(self, ax=None):
        """The error falling step by step, against the noise floor.

        Parameters
        ----------
        ax : Axes or sequence of Axes, optional
            Where to draw; a new figure when None.

        Returns
        -------
        Figure
            The figure (never shown by the library).
        """
        from .plots import plot_history

        return plot_history(self, ax=ax)


# ---------------------------------------------------------------------------
# The data and the model


@attrs.frozen
class _Data:
    """Measured FRFs (cropped to the band) and the configuration of each."""

    items: tuple  # of (measurement, FRF cropped)

    def residual(self, models: Sequence[np.ndarray]) -> np.ndarray:
        parts = []
        for (_, frf), model in zip(self.items, models):
            with np.errstate(divide="ignore", invalid="ignore"):
                r = np.log(model / frf.data)
            parts.append(r.real.ravel())
            parts.append(r.imag.ravel())
        out = np.concatenate(parts)
        return np.where(np.isfinite(out), out, 10.0)

    def error(self, models) -> float:
        r = self.residual(models)
        return float(np.sqrt(np.mean(r**2) * 2))


def _measurements(measurements, band) -> tuple[_Data, tuple[float, float]]:
    items = []
    for m in measurements:
        frf = m if isinstance(m, FRF) else m.frf
        if not isinstance(frf, FRF):
            raise InvalidValueError(f"measurements: got {m!r}; expected FRFs or measurements")
        items.append((m, frf.to_receptance()))
    if not items:
        raise InvalidValueError("measurements: got none")
    f0 = items[0][1].frequency
    full = (float(f0.hz[0]), float(f0.hz[-1]))
    if band is None:
        band = full
    lo, hi = (float(x) for x in band)
    if not lo < hi:
        raise InvalidValueError(f"band: got {band!r}; expected lo < hi")
    if hi < full[0] or lo > full[1] or lo < full[0] - 1e-9 * full[1] or hi > full[1] * (1 + 1e-12):
        raise InvalidValueError(
            f"band: {lo:g}-{hi:g} Hz is outside the measured data ({full[0]:g}-{full[1]:g} Hz)"
        )
    cropped = []
    for m, frf in items:
        c = frf.crop(lo, hi)
        if len(c.frequency) < 10:
            raise InvalidValueError(f"band: {lo:g}-{hi:g} Hz holds {len(c.frequency)} lines; too few")
        cropped.append((m, c))
    return _Data(tuple(cropped)), (lo, hi)


def _diff(old: Assembly, new: Assembly) -> dict:
    """What a modification changed, as replacements by name (for PreparedFRF.evaluate)."""
    changes: dict = {"joints": {}, "sensors": {}, "supports": {}, "components": {}}
    for kind, attr in (("joints", "joints"), ("sensors", "sensors"), ("supports", "supports")):
        before = {getattr(o, "name", None) or f"support at {o.at}": o for o in getattr(old, attr)}
        for o in getattr(new, attr):
            key = getattr(o, "name", None) or f"support at {o.at}"
            if key not in before or before[key] is not o:
                changes[kind][key] = o
    before = {c.name: c for c in old.components}
    for c in new.components:
        if before.get(c.name) is not c:
            changes["components"][c.name] = c
    return changes


def _apply_all(model: Assembly, effects: Sequence[Effect]) -> Assembly:
    """Apply effects in order; one whose place is not in this configuration is skipped."""
    for e in effects:
        try:
            model = e.apply(model)
        except UnknownPointError:
            continue
    return model


class _Model:
    """Fast evaluation of the assembly with a list of effects applied, per measurement.

    Each measurement's configuration (its sensors on, its components off) is
    set first, then the effects are applied: a diagnosed effect acts in every
    test where its place exists.
    """

    def __init__(self, assembly: Assembly, effects: Sequence[Effect], data: _Data):
        self.data = data
        self.configurations = [model_of_measurement(assembly, m) for m, _ in data.items]
        self.references = [_apply_all(c, effects) for c in self.configurations]
        self.prepared = [
            ref.prepare(list(frf.outputs), list(frf.inputs), frf.frequency)
            for ref, (_, frf) in zip(self.references, data.items)
        ]

    def evaluate(self, effects: Sequence[Effect]) -> list[np.ndarray]:
        out = []
        for config, ref, prepared, (_, frf) in zip(self.configurations, self.references, self.prepared,
                                                   self.data.items):
            modified = _apply_all(config, effects)
            changes = _diff(ref, modified)
            try:
                out.append(prepared.evaluate(joints=changes["joints"], sensors=changes["sensors"],
                                             supports=changes["supports"], components=changes["components"]).data)
            except InvalidValueError:  # the effect moved a point (e.g. a spring's position): compute anew
                out.append(modified.frf(list(frf.outputs), list(frf.inputs), frf.frequency).data)
        return out


def _fit(assembly: Assembly, data: _Data, fixed: Sequence[Effect], free: Sequence[tuple[type, str, dict]],
         scan: bool = True) -> tuple[list[Effect], float, int]:
    """Fit the parameters of the ``free`` effects (class, where, start) with ``fixed`` applied first."""
    specs = []  # (effect index, parameter, lower, upper)
    for i, (cls, where, start) in enumerate(free):
        bounds = cls.bounds(assembly, where)
        for p in cls.parameters:
            lo, hi = max(bounds[p.name][0], p.lower), min(bounds[p.name][1], p.upper)
            specs.append((i, p, lo, hi, float(np.clip(start[p.name], lo, hi))))
    starts = [cls(where, **start) for cls, where, start in free]
    model = _Model(assembly, list(fixed) + starts, data)

    def to_values(x):
        values = [dict(s) for _, _, s in free]
        for (i, p, lo, hi, s0), xi in zip(specs, x):
            values[i][p.name] = float(np.clip(np.exp(xi) if p.log else xi, lo, hi))
        return values

    def effects_of(x):
        return [cls(where, **v) for (cls, where, _), v in zip(free, to_values(x))]

    def residual(x):
        return data.residual(model.evaluate(list(fixed) + effects_of(x)))

    x0 = np.array([np.log(s0) if p.log else s0 for (_, p, _, _, s0) in specs])
    lower = np.array([np.log(lo) if p.log else lo for (_, p, lo, _, _) in specs])
    upper = np.array([np.log(hi) if p.log else hi for (_, p, _, hi, _) in specs])
    nfev = 0
    if scan and specs:
        best = (float(np.sum(residual(x0) ** 2)), x0)
        for v in np.linspace(lower[0], upper[0], 13)[1:-1]:
            x = x0.copy()
            x[0] = v
            cost = float(np.sum(residual(x) ** 2))
            nfev += 1
            if cost < best[0]:
                best = (cost, x)
        x0 = best[1]
    x0 = np.clip(x0, lower + 1e-12 * np.abs(lower), upper - 1e-12 * np.abs(upper))
    scale = np.where([p.log for (_, p, _, _, _) in specs], 1.0, np.maximum(upper - lower, 1e-30) / 10)
    fit = least_squares(residual, x0, bounds=(lower, upper), x_scale=scale, method="trf",
                        max_nfev=25 * len(x0) + 20)
    nfev += fit.nfev
    err = float(np.sqrt(np.mean(fit.fun**2) * 2))
    return effects_of(fit.x), err, nfev


def _main_shift(comparison: Comparison) -> float:
    """Relative shift (model / measured - 1) of the strongest paired mode that moved most."""
    pairs = [m for m in comparison.modes if m.model_hz is not None]
    if not pairs:
        return 0.0
    top = max(m.measured_amplitude for m in pairs)
    strong = [m for m in pairs if m.measured_amplitude >= 0.1 * top] or pairs
    best = max(strong, key=lambda m: abs(m.model_hz / m.measured_hz - 1))
    return float(best.model_hz / best.measured_hz - 1)


def _significant(e0: float, e1: float, floor: float) -> bool:
    return e0 > 1.5 * floor and (e0 - e1) > 0.5 * floor and (e0 - e1) > 0.1 * (e0 - floor)


def _candidates(assembly, data, added, names, exclude, progress, shift: float = 0.0) -> list[Candidate]:
    """Every effect at every place, fitted; with ``added`` effects refitted together with it."""
    points = []
    for m, frf in data.items:
        points += list(frf.outputs) + list(frf.inputs)
    todo = []
    for name in names:
        cls = get_effect(name)
        for where in cls.places(assembly, points):
            if (name, where) not in exclude:
                todo.append((cls, where))
    out = []
    for n, (cls, where) in enumerate(todo, start=1):
        if progress:
            progress(f"fitting {cls.name} at {where} ({n}/{len(todo)})")
        start = cls.starting_values(assembly, where, shift)
        try:
            effects, err, nfev = _fit(assembly, data, list(added), [(cls, where, start)])
        except InvalidValueError as exc:  # the effect cannot act here (e.g. out of its bounds)
            if progress:
                progress(f"  skipped {cls.name} at {where}: {exc}")
            continue
        out.append(Candidate(effects[0], err, nfev, tuple(added)))
    out.sort(key=lambda c: c.error)
    if added:
        # The earlier effects were fitted without this one and may be biased by
        # it: refit them together with each of the best few candidates.
        refined = []
        for c in out[:REFIT_TOP]:
            if progress:
                progress(f"refitting {c.name} at {c.where} with the effects added so far")
            free = [(type(c.effect), c.where, c.effect.values)] + [(type(e), e.where, e.values) for e in added]
            effects, err, nfev = _fit(assembly, data, [], free, scan=False)
            refined.append(Candidate(effects[0], err, c.nfev + nfev, tuple(effects[1:])))
        out = sorted(refined, key=lambda c: c.error) + out[REFIT_TOP:]
    return out


def _comparisons(assembly, effects, data) -> tuple[Comparison, ...]:
    model = _Model(assembly, effects, data)
    values = model.evaluate(list(effects))
    return tuple(compare(FRF(frf.frequency, v, frf.outputs, frf.inputs), frf) for (m, frf), v in zip(data.items, values))


def diagnose(assembly: Assembly, measurements, effects: str | Sequence[str] = "all", band=None,
             refine: bool = True, max_steps: int = 3,
             progress: bool | Callable[[str], None] = False) -> Diagnosis:
    """Diagnose which physical effect an assembly model is missing against measurements.

    Parameters
    ----------
    assembly : Assembly
        The model (sensors declared in it are applied as each measurement says).
    measurements : MeasurementSet, or sequence of measurements or FRFs
        The tap tests (receptances in m/N).
    effects : "all" or sequence of str
        Names of registered effects to consider.
    band : (lo, hi), optional
        Frequency band in Hz (default: all measured lines).
    refine : bool
        Run the greedy refinement after the first diagnosis.
    max_steps : int
        Most effects the refinement adds.
    progress : bool or callable
        Report progress (to standard error when True).

    Returns
    -------
    Diagnosis
        The missing effect with its fitted values (SI), the candidates, and the refinement.
    """
    if effects == "all":
        names = list(EFFECTS)
    else:
        names = [effects] if isinstance(effects, str) else list(effects)
        for n in names:
            get_effect(n)
    if progress is True:
        def progress(text):  # noqa: F811 - a printer when asked for
            print(f"diagnose: {text}", file=sys.stderr, flush=True)
    if hasattr(measurements, "validate"):
        measurements.validate(assembly)
    data, band = _measurements(measurements, band)
    floor = float(np.sqrt(np.mean([noise_floor(frf) ** 2 for _, frf in data.items])))
    base_model = _Model(assembly, [], data)
    e0 = data.error(base_model.evaluate([]))
    baseline = _comparisons(assembly, [], data)
    shift = _main_shift(baseline[0])
    first = _candidates(assembly, data, [], names, set(), progress, shift)
    best = first[0] if first else None
    missing = best is not None and _significant(e0, best.error, floor)
    ambiguous, suggestion = [], None
    if missing:
        margin = 0.3 * floor + 0.1 * max(best.error - floor, 0.0)
        for c in first[1:]:
            if c.error <= best.error + margin and c.name != best.name and c.name not in ambiguous:
                ambiguous.append(c.name)
        if ambiguous:
            suggestion = _suggestion(best.name, ambiguous[0])
    steps = [Step(0, None, e0)]
    added: list[Effect] = []
    current_error = e0
    if refine and missing:
        candidates = first
        while len(added) < max_steps:
            choice = candidates[0] if candidates else None
            if choice is None or not _significant(current_error, choice.error, floor):
                break
            added = list(choice.added) + [choice.effect]
            current_error = choice.error
            if progress:
                progress(f"step {len(added)}: added {choice.name} at {choice.where}, error {current_error:.4g}")
            steps.append(Step(len(added), choice.effect, current_error))
            if current_error <= 1.5 * floor:
                break
            exclude = {(e.name, e.where) for e in added}
            candidates = _candidates(assembly, data, added, names, exclude, progress, shift)
    refined = assembly
    for e in added:
        refined = e.apply(refined)
    return Diagnosis(
        metric=METRIC,
        baseline_error=e0,
        noise_floor=floor,
        missing_effect=best.name if missing else None,
        missing_where=best.where if missing else None,
        ambiguous_with=tuple(ambiguous),
        suggestion=suggestion,
        candidates=tuple(first),
        refinement=tuple(steps),
        band=band,
        baseline=baseline,
        final=_comparisons(assembly, added, data),
        refined_assembly=refined,
        final_effects=tuple(added),
    )
