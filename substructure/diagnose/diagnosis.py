"""Diagnosis: what the model is missing, decided by statistics, and an honest verdict.

:func:`diagnose` compares an assembly with measured FRFs through the
likelihood of :mod:`substructure.updating.likelihood` (complex log ratios
weighted by the noise of each line, estimated from the data), searches the
open world of candidates of :mod:`substructure.diagnose.search` (every model
parameter, bodies, springs and section changes at fitted positions, the
catalogue of effects) by forward selection with the significance test of
:mod:`substructure.updating.selection`, refits everything added at every
step, drops at the end what no longer earns its parameters, and says
``explained`` only when the final residual is consistent with the noise
(and, as a plain check, its RMS error within 1.5 times the noise floor).
When it is not, the report says so first, with where the remaining error
lives and what kind of effect has that signature
(:mod:`substructure.diagnose.report`).  Explanations the data cannot tell
apart are reported together, with the measurement that would separate them.
"""

from __future__ import annotations

import math
import sys
import time
from typing import Callable, Sequence

import attrs
import numpy as np

from ..assembly import Assembly
from ..errors import InvalidValueError
from ..frf import FRF
from ..updating.likelihood import Likelihood, measured_frfs
from ..updating.selection import INDIFFERENCE, consistency
from .compare import METRIC, Comparison, frac, pair_modes, error_bands
from .effects import Effect, registry
from .refine import refine as refine_model
from .search import SCREEN_LINES, candidates

__all__ = ["Found", "Candidate", "Step", "Diagnosis", "diagnose", "strict"]


def _finite(x):
    """A JSON-safe number: None for NaN and infinities."""
    if x is None:
        return None
    x = float(x)
    return x if math.isfinite(x) else None


def strict(value):
    """A JSON-ready copy with every NaN or infinity replaced by None (numpy numbers made plain).

    Parameters
    ----------
    value : object
        Dicts, lists, tuples, numbers, strings.

    Returns
    -------
    object
        The same structure, safe for ``json.dumps(..., allow_nan=False)``.
    """
    if isinstance(value, dict):
        return {str(k): strict(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [strict(v) for v in value]
    if isinstance(value, (bool, np.bool_)):
        return bool(value)
    if isinstance(value, (int, np.integer)):
        return int(value)
    if isinstance(value, (float, np.floating)):
        return _finite(value)
    return value


class Found:
    """A change with fitted values: what a candidate or a refinement step reports.

    It has the interface of an :class:`~substructure.diagnose.effects.Effect`
    instance (``name``, ``where``, ``values``, ``explanation``,
    ``parameters_json()``, ``apply(assembly)``), so that
    ``assembly.with_effect(found)`` works, plus ``std`` and ``nominal``.

    Parameters
    ----------
    change : Change
        The change.
    values : dict
        Fitted values (SI).
    std : dict, optional
        Standard deviations (SI).
    """

    def __init__(self, change, values: dict, std: dict | None = None):
        self.change = change
        self.values = {k: float(v) for k, v in values.items()}
        self.std = {k: float(v) for k, v in (std or {}).items()}

    @property
    def name(self) -> str:
        """The effect's name (``model-parameter``, ``added-mass``, ``sensor-mass``, ...)."""
        return self.change.effect

    @property
    def where(self) -> str:
        """Where it acts (a path, a point, a joint, a component)."""
        return self.change.place(self.values)

    @property
    def explanation(self) -> str:
        """Its signature in the FRF, in words."""
        return self.change.explanation

    @property
    def nominal(self) -> dict:
        """The model's values before a correction (parameters that have one)."""
        return {s.name: s.nominal for s in self.change.specs if s.nominal is not None}

    def parameters_json(self) -> dict:
        """``{name: {"value", "unit", "std"[, "nominal"]}}`` (SI, strict JSON).

        Returns
        -------
        dict
            One entry per parameter.
        """
        out = {}
        for s in self.change.specs:
            entry = {"value": _finite(self.values.get(s.name)), "unit": s.unit,
                     "std": _finite(self.std.get(s.name)) if s.name in self.std else None}
            if s.nominal is not None:
                entry["nominal"] = _finite(s.nominal)
            out[s.name] = entry
        return out

    def apply(self, assembly: Assembly) -> Assembly:
        """The assembly with this change (a normal assembly that saves as usual).

        Parameters
        ----------
        assembly : Assembly
            The model.

        Returns
        -------
        Assembly
            The changed model.
        """
        return self.change.apply(assembly, self.values)

    def __repr__(self) -> str:
        vals = ", ".join(f"{k}={v:.4g}" for k, v in self.values.items())
        return f"{self.name}(where={self.where!r}, {vals})"


@attrs.frozen
class Candidate:
    """One candidate of the first round, fitted: its error and ``chi^2`` after the fit.

    Parameters
    ----------
    effect : Found
        The change with its values.
    error : float
        The error measure after the fit (dimensionless).
    chi2 : float
        ``chi^2`` after the fit.
    fitted : bool
        Fitted on all lines (else its values are the screening's).
    nfev : int
        Model evaluations of its fit.
    """

    effect: Found = attrs.field(eq=False)
    error: float
    chi2: float = 0.0
    fitted: bool = True
    nfev: int = 0

    @property
    def name(self) -> str:
        """The effect's name."""
        return self.effect.name

    @property
    def where(self) -> str:
        """Where it acts."""
        return self.effect.where

    def to_json(self) -> dict:
        """The candidate's JSON object.

        Returns
        -------
        dict
            ``effect``, ``where``, ``parameters``, ``error``, ``chi2``, ``fitted``, ``explanation``.
        """
        return {"effect": self.name, "where": self.where, "parameters": self.effect.parameters_json(),
                "error": _finite(self.error), "chi2": _finite(self.chi2), "fitted": self.fitted,
                "explanation": self.effect.explanation}


@attrs.frozen
class Step:
    """One refinement step: the change added (None at step 0), its values when added, the error after.

    Parameters
    ----------
    step : int
        Its number (0: the model as given).
    added : Found or None
        The change added, with its values at this step.
    error : float
        The error measure after the step.
    chi2_reduced : float
        ``chi^2 / nu`` after the step.
    statistic : float or None
        The significance test's likelihood ratio that admitted it.
    threshold : float or None
        The test's threshold.
    """

    step: int
    added: Found | None = attrs.field(eq=False)
    error: float
    chi2_reduced: float = float("nan")
    statistic: float | None = None
    threshold: float | None = None

    def to_json(self) -> dict:
        """The step's JSON object.

        Returns
        -------
        dict
            ``step``, ``added``, ``error``, ``chi2_reduced`` and, for a change, ``where``, ``parameters``,
            ``significance``.
        """
        out = {"step": self.step, "added": None if self.added is None else self.added.name, "error": self.error}
        if self.added is not None:
            out["where"] = self.added.where
            out["parameters"] = self.added.parameters_json()
            out["significance"] = {"statistic": _finite(self.statistic), "threshold": _finite(self.threshold)}
        out["chi2_reduced"] = _finite(self.chi2_reduced)
        return out


@attrs.frozen
class Diagnosis:
    """What :func:`diagnose` found.  ``to_json`` gives the JSON of docs/file-formats.md.

    Parameters
    ----------
    metric : str
        ``"rms_log_ratio"``.
    baseline_error : float
        The error of the model as given (dimensionless).
    noise_floor : float
        The error a perfect model would show, from the data's own noise.
    explained : bool
        The final residual is consistent with the noise (and within 1.5 floors).
    missing_effect : str or None
        The first change of the refinement.
    missing_where : str or None
        Where it acts.
    ambiguous_with : tuple of str
        Names of the alternatives inside the indifference region.
    suggestion : str or None
        The measurement that would tell the first change from its first alternative.
    candidates : tuple of Candidate
        The first step's candidates, best first.
    refinement : tuple of Step
        Step 0 (the model as given), then one per change kept.
    band : tuple of float
        The band used ``(lo, hi)`` [Hz].
    baseline : tuple of Comparison
        Every measurement against the model as given.
    final : tuple of Comparison
        Every measurement against the final model.
    refined_assembly : Assembly
        The model with the changes kept.
    final_effects : tuple of Found
        The changes kept, with their final values and standard deviations.
    consistency : Consistency
        The test of the final model.
    ambiguous : tuple of (Found, float)
        The alternatives with their errors.
    separation : dict or None
        ``response``, ``excitation``, ``non_contact``, ``chi2``, ``text``.
    report : tuple of str
        The verdict's lines when the data are not explained.
    correlation : dict
        ``parameters`` and ``matrix`` of the final fit's correlations.
    final_error : float
        The error of the final model.
    rivals : tuple of (Explanation, dict)
        Whole explanations as good as the one reported (inside the
        indifference region) that are different structures, each with the
        measurement that separates it; when there are any, ``explained`` is
        false.
    search : dict
        What the search did: ``candidates``, ``steps_screened``,
        ``full_fits``, ``seconds``, ``budget_s``, ``cut`` (the time budget
        stopped part of it) and ``cut_at`` (where).
    """

    metric: str
    baseline_error: float
    noise_floor: float
    explained: bool
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
    consistency: object = attrs.field(default=None, eq=False)
    ambiguous: tuple = attrs.field(default=(), eq=False)
    separation: dict | None = attrs.field(default=None, eq=False)
    report: tuple[str, ...] = ()
    correlation: dict = attrs.field(factory=dict, eq=False)
    final_error: float = float("nan")
    rivals: tuple = attrs.field(default=(), eq=False)
    search: dict = attrs.field(factory=dict, eq=False)

    @property
    def effects(self) -> list[Found]:
        """The changes the refinement kept, with their final values (refitted together)."""
        return list(self.final_effects)

    def to_json(self) -> dict:
        """One JSON object (strict JSON: no NaN or infinities); see docs/file-formats.md.

        Returns
        -------
        dict
            The keys of the contract and the added ones.
        """
        return strict(self._json())

    def _json(self) -> dict:
        cons = self.consistency
        return {
            "metric": self.metric,
            "baseline_error": _finite(self.baseline_error),
            "noise_floor": _finite(self.noise_floor),
            "explained": bool(self.explained),
            "missing_effect": self.missing_effect,
            "ambiguous_with": list(self.ambiguous_with),
            "candidates": [c.to_json() for c in self.candidates],
            "refinement": [s.to_json() for s in self.refinement],
            "missing_where": self.missing_where,
            "suggestion": self.suggestion,
            "band_hz": list(self.band),
            "final_error": _finite(self.final_error),
            "final_effects": [{"effect": e.name, "where": e.where, "parameters": e.parameters_json()}
                              for e in self.final_effects],
            "correlation": self.correlation,
            "consistency": None if cons is None else {
                "chi2_reduced": _finite(cons.chi2_reduced), "threshold": _finite(cons.threshold),
                "bands_hz": [{"frf": self.final[b.item].measured.outputs[0] + " / " + self.final[b.item].measured.inputs[0],
                              "lo": b.lo_hz, "hi": b.hi_hz, "ratio": _finite(b.ratio), "share": _finite(b.share)}
                             for b in cons.bands]},
            "ambiguous": [{"effect": a.name, "where": a.where, "parameters": a.parameters_json(),
                           "error": _finite(err)} for a, err in self.ambiguous],
            "separation": self.separation,
            "rivals": [{"effects": [{"effect": f.name, "where": f.where, "parameters": f.parameters_json()}
                                    for f in r.founds], "separation": sep} for r, sep in self.rivals],
            "search": dict(self.search),
            "report": list(self.report),
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
        ax : sequence of three Axes, optional
            Where to draw.

        Returns
        -------
        matplotlib.figure.Figure
            The figure.
        """
        return self.baseline[0].plot(ax=ax)

    def plot_history(self, ax=None):
        """The error falling step by step, against the noise floor.

        Parameters
        ----------
        ax : Axes, optional
            Where to draw.

        Returns
        -------
        matplotlib.figure.Figure
            The figure.
        """
        from .plots import plot_history

        return plot_history(self, ax=ax)


def _catalogue(effects) -> dict:
    """The effects of a call: a snapshot of the registry, or the names or classes given."""
    known = registry()
    if isinstance(effects, str):
        if effects == "all":
            return known
        effects = [e.strip() for e in effects.split(",") if e.strip()]
        if not effects:
            raise InvalidValueError("effects: got an empty list; give 'all' or effect names "
                                    f"({', '.join(known)})")
    effects = list(effects)
    if not effects:
        raise InvalidValueError("effects: got an empty list; give 'all' or effect names "
                                f"({', '.join(known)})")
    out = {}
    for e in effects:
        if isinstance(e, type) and issubclass(e, Effect):
            out[e.name] = e
        elif isinstance(e, str) and e in known:
            out[e] = known[e]
        else:
            raise InvalidValueError(f"effect: unknown effect {e!r}; known: {', '.join(known)}")
    return out


def _comparisons(lik: Likelihood, ratios, floors) -> tuple[Comparison, ...]:
    out = []
    for m, r, floor in zip(lik.measured, ratios, floors):
        measured = m.frf
        model = FRF(measured.frequency, (measured.data[:, 0, 0] * np.exp(r))[:, None, None], measured.outputs,
                    measured.inputs)
        out.append(Comparison(model=model, measured=measured, error=float(np.sqrt(np.mean(np.abs(r) ** 2))),
                              noise_floor=floor, frac=frac(model, measured),
                              modes=pair_modes(model, measured, noise=floor),
                              bands=error_bands(model, measured, floor=floor)))
    return tuple(out)


def _rms(ratios) -> float:
    return float(np.sqrt(np.mean(np.concatenate([np.abs(r) ** 2 for r in ratios]))))


def _passive(lik: Likelihood, changes) -> bool:
    """Every joint, support and body of the changed model is passive (PSD matrices, masses >= 0)."""
    for g in lik.groups:
        s = g.structure_with(changes)
        for link in s.links:
            if link.rigid or link.custom is not None:
                continue
            for m in (link.K, link.C, link.M):
                sym = 0.5 * (m + m.T)
                scale = max(abs(sym).max(), 1e-300)
                if np.linalg.eigvalsh(sym).min() < -1e-9 * scale:
                    return False
    return True


def _main_shift(comparison: Comparison) -> float:
    pairs = [m for m in comparison.modes if m.model_hz is not None]
    if not pairs:
        return 0.0
    top = max(m.measured_amplitude for m in pairs)
    strong = [m for m in pairs if m.measured_amplitude >= 0.1 * top] or pairs
    best = max(strong, key=lambda m: abs(m.model_hz / m.measured_hz - 1))
    return float(best.model_hz / best.measured_hz - 1)


BUDGET_S = 30.0
"""Default time budget of the search [s]: past it no step is added, a step fits only its best candidate on all
lines, and the parsimony check compares singles only; the JSON says so (``search.cut``)."""


def diagnose(assembly: Assembly, measurements, effects: str | Sequence = "all", band=None,
             refine: bool = True, max_steps: int = 4, progress: bool | Callable[[str], None] = False,
             open_world: bool = True, budget: float | None = BUDGET_S) -> Diagnosis:
    """Diagnose what an assembly model is missing against measurements.

    Parameters
    ----------
    assembly : Assembly
        The model (sensors declared in it are applied as each measurement
        says; ``always_on`` sensors and permanent masses in every test).
    measurements : MeasurementSet, or sequence of measurements or FRFs
        The data.
    effects : "all", or sequence of names or Effect classes
        The catalogue effects to consider (default: a snapshot of every
        registered effect); classes given here need no registration.
    band : (lo, hi), optional
        Frequency band in Hz (default: all measured lines).
    refine : bool
        Run the forward selection to the end (else one step).
    max_steps : int
        Most changes the refinement adds.
    progress : bool or callable
        Report progress (to standard error when True).
    open_world : bool
        Consider every model parameter and the elements at fitted
        positions besides the catalogue (default True).
    budget : float or None
        Time budget of the search [s] (default :data:`BUDGET_S`; None: no
        limit).  When it cuts the search, ``Diagnosis.search["cut"]`` is
        true and, unless the data are explained, the report says so.

    Returns
    -------
    Diagnosis
        The verdict, the candidates, the refinement and the refined model.
    """
    from .report import Explanation, separation, unexplained_report

    started = time.monotonic()
    if budget is not None and not (isinstance(budget, (int, float)) and math.isfinite(budget) and budget > 0):
        raise InvalidValueError(f"budget: got {budget!r}; expected a positive number of seconds (or None: no limit)")
    catalogue = _catalogue(effects)
    if progress is True:
        def progress(text):  # noqa: F811 - a printer when asked for
            print(f"diagnose: {text}", file=sys.stderr, flush=True)
    say = progress or None
    if hasattr(measurements, "validate"):
        measurements.validate(assembly)
    measured, band = measured_frfs(measurements, band)
    lik = Likelihood(assembly, measured)
    floors = [m.noise.floor for m in measured]
    floor = float(np.sqrt(np.mean(np.concatenate([m.noise.var_re + m.noise.var_im for m in measured]))))
    base_ratios = lik.log_ratios([])
    e0 = _rms(base_ratios)
    chi2_now = float(lik.whiten(base_ratios) @ lik.whiten(base_ratios))
    n = lik.n
    cons = consistency(lik, base_ratios, 0)
    baseline = _comparisons(lik, base_ratios, floors)
    if say:
        say(f"baseline error {e0:.4g} (noise floor {floor:.4g}), chi^2/n = {chi2_now / n:.4g}"
            f"{': consistent with the noise' if cons.consistent else ''}")
    points = [lbl for m in measured for lbl in (m.frf.outputs[0], m.frf.inputs[0])]
    cands = candidates(assembly, points, catalogue, open_world, _main_shift(baseline[0]), say)
    screen_lik = lik.subsample(max(1, lik.lines.size // SCREEN_LINES))
    limit = 0 if cons.consistent else (max_steps if refine else 1)
    outcome = refine_model(lik, screen_lik, cands, limit, lambda changes: _passive(lik, changes), say,
                           None if budget is None else started + float(budget))
    current = outcome.current
    p_now = sum(len(c.specs) for c, _ in current)
    steps = [Step(0, None, e0, chi2_now / n)]
    for k, (result, added, stat, threshold) in enumerate(outcome.history, start=1):
        values = next(v for c, v in result.changes if c is added)
        steps.append(Step(k, Found(added, values, _std_of(result, added)), _rms(lik.log_ratios(result.changes)),
                          result.chi2_reduced, stat, threshold))
    first = [Candidate(Found(s.change, s.values, s.fit.std[-1]), _rms(lik.log_ratios(s.fit.changes)), s.chi2, True,
                       s.fit.nfev) for s in outcome.first_fitted]
    done = {s.change.key for s in outcome.first_fitted}
    for s in outcome.first_scored:
        if s.change.key not in done:
            r = lik.log_ratios([(s.change, s.values)])
            w = lik.whiten(r)
            first.append(Candidate(Found(s.change, s.values), _rms(r), float(w @ w), False))
    final_fit = outcome.fit
    final_ratios = lik.log_ratios(current)
    cons = consistency(lik, final_ratios, p_now)
    final_error = _rms(final_ratios)
    explained = bool(cons.consistent and final_error <= 1.5 * floor)
    final_effects = tuple(Found(c, v, final_fit.std[i] if final_fit else {}) for i, (c, v) in enumerate(current))
    refined = assembly
    for c, v in current:
        refined = c.apply(refined, v)
    missing = steps[1].added if len(steps) > 1 else None
    ambiguous = []
    if missing is not None:
        for c, v, chi2 in outcome.alternatives.get(missing.change.key, []):
            alt = [(c, v) if x is missing.change else (x, y) for x, y in current]
            ambiguous.append((Found(c, v), _rms(lik.log_ratios(alt))))
    names = tuple(dict.fromkeys(a.name for a, _ in ambiguous))
    sep = None
    if missing is not None and ambiguous:
        sep = separation(assembly, measured, missing, ambiguous[0][0], say)
    correlation = {}
    if final_fit is not None and final_fit.p > 1:
        labels = [f"{current[i][0].effect}@{current[i][0].where}:{name}" for i, name in final_fit.names]
        correlation = {"parameters": labels, "matrix": [[_finite(x) for x in row] for row in final_fit.correlation]}
    rivals = _distinct_rivals(assembly, measured, final_effects, outcome, say) if explained else []
    final = _comparisons(lik, final_ratios, floors)
    report = unexplained_report(lik, assembly, current, baseline, cons, final_error, floor, explained, say) \
        if not explained else ()
    if rivals:  # consistent with the noise, but not uniquely: claim neither
        explained = False
        kept = Explanation(final_effects)
        report = [f"unexplained: no candidate explains the data uniquely: {kept.name} at {kept.where} and "
                  f"{rival.name} at {rival.where} both leave a residual consistent with the noise (their BIC "
                  f"differ by at most {INDIFFERENCE:g}) but change different parts" for rival, _ in rivals[:1]]
        report += [f"to tell them apart: {sep['text']}" for rival, sep in rivals]
        report.append("the best (ambiguous) explanation is reported as partial: "
                      + ", ".join(repr(e) for e in final_effects))
        sep = sep or rivals[0][1]
        names = tuple(dict.fromkeys(list(names) + [r.name for r, _ in rivals]))
    search = {**outcome.search, "budget_s": budget, "seconds": round(time.monotonic() - started, 3)}
    if search["cut"] and not explained:
        report = list(report) + [f"the search was cut by its time budget ({budget:g} s): {search['cut_at']}; "
                                 "a larger budget (--budget) may find more"]
    return Diagnosis(
        metric=METRIC, baseline_error=e0, noise_floor=floor, explained=explained,
        missing_effect=None if missing is None else missing.name,
        missing_where=None if missing is None else missing.where,
        ambiguous_with=names, suggestion=None if sep is None else sep["text"],
        candidates=tuple(first), refinement=tuple(steps), band=band, baseline=baseline, final=final,
        refined_assembly=refined, final_effects=final_effects, consistency=cons, ambiguous=tuple(ambiguous),
        separation=sep, report=tuple(report), correlation=correlation, final_error=final_error,
        rivals=tuple(rivals), search=search,
    )


def sites(assembly, change, values) -> frozenset:
    """The parts of the model a change acts on: joints by name, components by name.

    A model parameter acts on the component, joint, support's component,
    sensor's or body's component its path names (a material on every
    component made of it); an element or an effect on the component or
    joint its place names.

    Parameters
    ----------
    assembly : Assembly
        The model.
    change : Change
        The change.
    values : dict
        Its values (for places that depend on them).

    Returns
    -------
    frozenset of str
        ``"joint:NAME"`` and ``"component:NAME"`` entries.
    """
    joints = {j.name for j in assembly.joints}
    comps = set(assembly.component_names)
    where = change.where
    parts = where.split(".")
    if change.effect == "model-parameter":
        head = parts[0]
        if head == "components":
            return frozenset({f"component:{parts[1]}"})
        if head == "joints":
            return frozenset({f"joint:{parts[1]}"})
        if head == "materials":
            name = ".".join(parts[1:-1])
            return frozenset(f"component:{c.name}" for c in assembly.components
                             if any(getattr(getattr(seg, "material", None), "name", None) == name
                                    for seg in getattr(c, "segments", ())))
        if head == "supports":
            return frozenset(f"component:{assembly.supports[int(i)].at.split('.')[0].split('@')[0]}"
                             for i in parts[1].split("+") if i.isdigit() and int(i) < len(assembly.supports))
        if head in ("sensors", "masses"):
            items = {x.name: x for x in getattr(assembly, head)}
            if parts[1] in items:
                return frozenset({f"component:{items[parts[1]].at.split('.')[0].split('@')[0]}"})
        return frozenset({where})
    if where in joints:
        return frozenset({f"joint:{where}"})
    out = set()
    for piece in where.replace("+", ",").split(","):
        name = piece.strip().split("@")[0].split(".")[0]
        out.add(f"component:{name}" if name in comps else piece.strip())
    return frozenset(out)


RIVALS_CHECKED = 3
"""Most rival explanations whose separation is computed for the verdict."""


def _distinct_rivals(assembly, measured, final_effects, outcome, say) -> list:
    """Rival explanations inside the indifference region that are different structures.

    A rival is a whole explanation of the parsimony check
    (:func:`substructure.diagnose.refine.refine`) or the kept one with one
    change replaced by an alternative of its step.  It is a *different
    structure* when some measurement with the test's sensors on (a point or
    cross FRF at the ends, quarter points and middles of the components)
    would tell the two apart (``chi^2 > INDIFFERENCE`` over the band);
    otherwise it is an equivalent description (a joint's stiffness as a
    named effect or as its matrix entry) and the preferred one stands.

    Returns
    -------
    list of (Explanation, dict)
        The distinct rivals with their separating measurement.
    """
    from .report import Explanation, separation

    pool = [(chi2, [Found(c, v) for c, v in changes]) for changes, chi2, _ in outcome.rivals]
    for i, found in enumerate(final_effects):
        for c, v, chi2 in outcome.alternatives.get(found.change.key, []):
            pool.append((chi2, [Found(c, v) if j == i else f for j, f in enumerate(final_effects)]))
    pool.sort(key=lambda t: t[0])
    kept = Explanation(final_effects)
    kept_sites = frozenset().union(*(sites(assembly, f.change, f.values) for f in final_effects))
    out = []
    for _, founds in pool[:RIVALS_CHECKED]:
        rival = Explanation(founds)
        if frozenset().union(*(sites(assembly, f.change, f.values) for f in founds)) == kept_sites:
            continue  # the same parts changed: an equivalent description
        rival = Explanation(founds)
        sep = separation(assembly, measured, kept, rival, say, contact_only=True)
        if sep is not None and sep["chi2"] > INDIFFERENCE:
            if say:
                say(f"rival explanation {rival.name} at {rival.where}: {sep['text']}")
            out.append((rival, sep))
    return out


def _std_of(result, change) -> dict:
    for i, (c, _) in enumerate(result.changes):
        if c is change:
            return result.std[i]
    return {}
