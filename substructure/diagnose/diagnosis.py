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
apart are reported together, with the measurement that would separate them;
when they change different parts of the model (``sites``) and a
measurement would tell them apart, neither is claimed and the data are not
explained.  The search runs within a budget of model evaluations
(``BUDGET``), so that the same data give the same answer on any machine.
"""


from __future__ import annotations

import math
import sys
from typing import Callable, Sequence

import numpy as np

from ..assembly import Assembly
from ..errors import InvalidValueError
from ..frf import FRF
from ..updating.likelihood import Likelihood, measured_frfs
from ..updating.selection import INDIFFERENCE, consistency
from .compare import METRIC, Comparison, frac, pair_modes, error_bands
from .effects import Effect, registry
from .refine import refine as refine_model
from .result import Candidate, Diagnosis, Found, Step, _finite, strict
from .search import SCREEN_LINES, Budget, candidates

__all__ = ["Found", "Candidate", "Step", "Diagnosis", "diagnose", "strict", "sites", "BUDGET"]


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


PEAK_LINES = 2
"""Lines either side of every measured resonance the model lacks kept in the screening subsample."""


def _peak_lines(baseline) -> np.ndarray:
    """Positions of the lines within :data:`PEAK_LINES` of every measured resonance the model as given lacks
    (no model mode paired with it): a subsample of every k-th line can step over such a narrow peak (a
    suspension mode between two of its lines), and there a candidate's fit on the subsample says nothing about
    all lines.  Paired modes are left to the mode starts (:mod:`substructure.diagnose.modes`): their lines
    make the scan's landscape rugged where a model peak crosses them."""
    keep: list[int] = []
    for c in baseline:
        hz = c.measured.frequency.hz
        for p in c.modes:
            if p.model_hz is not None:  # a paired mode: its shift is followed by the mode starts
                continue
            i = int(np.argmin(np.abs(hz - p.measured_hz)))
            keep += range(max(0, i - PEAK_LINES), min(hz.size, i + PEAK_LINES + 1))
    return np.unique(np.array(keep, dtype=int))


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


BUDGET = 3000
"""Default budget of the search, in model evaluations of all lines (about 30 s for 3 FRFs of 2,500 lines on one
core of a 2-core machine): once spent no step is added and a step fits only its best candidate on all lines (the
checks after the forward search always run); the result and the JSON say so (``search``)."""


def _refuse_rotations(measurements) -> None:
    """A measured rotation (``:theta`` response or excitation) is refused, with the reason.

    A tap test measures translations per force (a hammer and an
    accelerometer or a vibrometer); rotational receptances are estimated
    from several translations (:mod:`substructure.rdof`), with their noise
    amplified, and a diagnosis built on them would weigh noise as data.
    """
    where = getattr(measurements, "_where", lambda: "measurements")()
    for m in measurements:
        frf = m if isinstance(m, FRF) else getattr(m, "frf", None)
        if not isinstance(frf, FRF):
            continue  # measured_frfs names what is not a measurement
        for label in (*frf.outputs, *frf.inputs):
            if str(label).rsplit(":", 1)[-1] == "theta":
                what = getattr(m, "describe", lambda: f"{frf.outputs[0]} / {frf.inputs[0]}")()
                raise InvalidValueError(
                    f"{where}: measured FRF {what}: {label} is a rotation; diagnose compares translational FRFs "
                    "as tap tests measure them (a hammer's force, an accelerometer's or a vibrometer's motion "
                    "along y); rotations are estimated from translations (substructure.rdof), not measured: "
                    "leave this FRF out of the measurement set")


def diagnose(assembly: Assembly, measurements, effects: str | Sequence = "all", band=None,
             refine: bool = True, max_steps: int = 4, progress: bool | Callable[[str], None] = False,
             open_world: bool = True, budget: float | None = BUDGET, time_limit: float | None = None) -> Diagnosis:
    """Diagnose what an assembly model is missing against measurements.

    Parameters
    ----------
    assembly : Assembly
        The model (sensors declared in it are applied as each measurement
        says; ``always_on`` sensors and permanent masses in every test).
    measurements : MeasurementSet, or sequence of measurements or FRFs
        The data: translational FRFs (``:y``); a rotation (``:theta``) is
        refused, as tap tests do not measure it.
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
        Budget of the search in model evaluations of all lines (default
        ``BUDGET``; None: no limit): the same data give the same answer
        on any machine.  When it cuts the search, ``Diagnosis.search["cut"]``
        is true and, unless the data are explained, the report says so.
    time_limit : float or None
        A limit in wall-clock seconds as well (default None; with one, the
        answer may depend on the machine's speed).

    Returns
    -------
    Diagnosis
        The verdict, the candidates, the refinement and the refined model.
    """
    from .report import Explanation, separation, unexplained_report, values_text

    for name, value, what in (("budget", budget, "model evaluations"), ("time_limit", time_limit, "seconds")):
        if value is not None and not (isinstance(value, (int, float)) and not isinstance(value, bool)
                                      and math.isfinite(value) and value > 0):
            raise InvalidValueError(f"{name}: got {value!r}; expected a positive number of {what} (or None: no limit)")
    meter = Budget(budget, time_limit)
    catalogue = _catalogue(effects)
    if progress is True:
        def progress(text):  # noqa: F811 - a printer when asked for
            print(f"diagnose: {text}", file=sys.stderr, flush=True)
    say = progress or None
    if hasattr(measurements, "validate"):
        measurements.validate(assembly)
    _refuse_rotations(measurements)
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
    lacking = _peak_lines(baseline)
    screen_lik = lik.subsample(max(1, lik.lines.size // SCREEN_LINES), keep=lacking)
    limit = 0 if cons.consistent else (max_steps if refine else 1)
    outcome = refine_model(lik, screen_lik, cands, limit, lambda changes: _passive(lik, changes), say, meter,
                           lacking=bool(len(lacking)))
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
    hits = bound_hits(current, final_fit)
    final_effects = tuple(Found(c, v, {k: x for k, x in (final_fit.std[i] if final_fit else {}).items()
                                       if (i, k) not in {(h[0], h[1]) for h in hits}})
                          for i, (c, v) in enumerate(current))
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
    if explained and len(current) > MOST_CHANGES:  # a composite that only just reaches the noise
        explained = False
        names = ", ".join(f"{c.effect} at {c.place(v)}" for c, v in current)
        report = [f"unexplained: no candidate explains the data with at most {MOST_CHANGES} changes; "
                  f"{len(current)} together reach the noise ({names}): several changes that each buy a small "
                  "improvement are the mark of one effect the search lacks, not of several effects",
                  "the best (composite) explanation is reported as partial: "
                  + ", ".join(repr(e) for e in final_effects)]
    if hits:  # a value on the bound of its search is not a measurement: never an explanation
        words = "; ".join(bound_text(current, hit) for hit in hits)
        if explained:
            explained = False
            report = [f"unexplained: no candidate explains the data within the bounds of its search: {words}; "
                      "a value on its bound is not a measurement (the data ask for more than the change "
                      "allows: the mark of another effect, missing)",
                      "the best (bounded) explanation is reported as partial: "
                      + ", ".join(repr(e) for e in final_effects)]
        else:
            report = list(report) + [f"on the bound of its search (not a measurement): {words}"]
    if rivals:  # consistent with the noise, but not uniquely: claim neither
        explained = False
        kept = Explanation(final_effects)
        keys = sorted(f.change.key for f in final_effects)
        report = [f"unexplained: no candidate explains the data uniquely: {kept.name} at {kept.where} and "
                  f"{rival.name} at {rival.where} both leave a residual consistent with the noise (their BIC "
                  f"differ by at most {INDIFFERENCE:g}) but "
                  + ("are the same change at other values ("
                     + "; ".join(values_text(f.change, f.values) for f in rival.founds) + ")"
                     if sorted(f.change.key for f in rival.founds) == keys else "change different parts")
                  for rival, _ in rivals[:1]]
        report += [f"to tell them apart: {sep['text']}" for rival, sep in rivals]
        report.append("the best (ambiguous) explanation is reported as partial: "
                      + ", ".join(repr(e) for e in final_effects))
        sep = sep or rivals[0][1]
        names = tuple(dict.fromkeys(list(names) + [r.name for r, _ in rivals]))
    search = {**outcome.search, "evaluations": round(meter.used(), 1), "budget": budget,
              "time_limit_s": time_limit, "seconds": round(meter.elapsed(), 3)}
    if not explained:  # the changes the cross-validation dropped, said where the verdict is read
        report = list(report) + [f"dropped {r['effect']} at {r['where']}: did not predict held-back lines "
                                 f"(their chi^2 {r['chi2_with']:.1f} with it, {r['chi2_without']:.1f} without)"
                                 for r in search.get("held_back", []) if not r["predicts"]]
    if search["cut"] and not explained:
        report = list(report) + [f"the search was cut by its budget ({search['cut_at']}); a larger budget "
                                 "(--budget, --time-limit) may find more"]
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
    (:func:`substructure.diagnose.refine.refine`), the kept one with one
    change replaced by an alternative of its step, or the kept changes at
    other values that fit as well (a second minimum); one that holds every
    kept change and more is not (the data do not decide the extra).  It is a *different
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
    keys = {f.change.key for f in final_effects}
    # a rival that holds every kept change plus more is not another explanation: the data do not decide the extra
    # (the same changes at other values are another explanation: a second minimum of the same changes)
    pool = [(chi2, founds) for chi2, founds in pool if not keys < {f.change.key for f in founds}]
    kept = Explanation(final_effects)
    kept_sites = frozenset().union(*(sites(assembly, f.change, f.values) for f in final_effects))
    out = []
    for _, founds in pool[:RIVALS_CHECKED]:
        rival = Explanation(founds)
        same_changes = {f.change.key for f in founds} == keys
        if not same_changes and frozenset().union(*(sites(assembly, f.change, f.values) for f in founds)) == kept_sites:
            continue  # the same parts changed: an equivalent description
        rival = Explanation(founds)
        sep = separation(assembly, measured, kept, rival, say, contact_only=True)
        if sep is not None and sep["chi2"] > INDIFFERENCE:
            if say:
                say(f"rival explanation {rival.name} at {rival.where}: {sep['text']}")
            out.append((rival, sep))
    return out


MOST_CHANGES = 2
"""Most changes an explanation may hold: two effects at once (a reground tool and a forgotten sensor) are
found together; three or more that together only just reach the noise are the mark of one effect the search
lacks, and the verdict says so."""

PHYSICAL_ENDS = ("position", "start", "inset", "inset_tip", "length", "end")
"""Parameters whose bounds are the ends of a component (a body at the tip, a section over the whole tool):
places, not limits of a search, so that a value on them is a finding."""


def bound_hits(current, fit) -> list[tuple[int, str, float, float, str]]:
    """The fitted parameters of the kept changes that ended on a bound of their search.

    Parameters
    ----------
    current : sequence of (Change, dict)
        The kept changes with their values.
    fit : Fit or None
        Their joint fit (``at_bound`` per fitted parameter).

    Returns
    -------
    list of (change index, parameter name, value, bound, "lower" or "upper")
        One entry per parameter on a bound.
    """
    if fit is None:
        return []
    out = []
    for (i, name), on in zip(fit.names, fit.at_bound):
        if not on or i >= len(current):
            continue
        change, values = current[i]
        spec = next((sp for sp in change.specs if sp.name == name), None)
        if spec is None or name not in values or name in PHYSICAL_ENDS:
            continue
        value = float(values[name])
        side = "lower" if abs(value - spec.lower) <= abs(value - spec.upper) else "upper"
        if side == "lower" and spec.log and spec is not change.specs[0]:
            continue  # a secondary size at its floor: none detectable (a sensor's rotary inertia), not a limit
        out.append((i, name, value, float(spec.lower if side == "lower" else spec.upper), side))
    return out


def bound_text(current, hit) -> str:
    """One bound hit in words: the change, the parameter, its value and the bound.

    Parameters
    ----------
    current : sequence of (Change, dict)
        The kept changes.
    hit : tuple
        An entry of :func:`bound_hits`.

    Returns
    -------
    str
        E.g. ``"joint-damping at holder-tool: c_yf = 240 N*s/m, the upper bound of its search"``.
    """
    i, name, value, bound, side = hit
    change = current[i][0]
    unit = next((sp.unit for sp in change.specs if sp.name == name), "")
    return (f"{change.effect} at {change.where}: {name} = {value:.4g} {unit}, "
            f"the {side} bound of its search ({bound:.4g} {unit})")


def _std_of(result, change) -> dict:
    for i, (c, _) in enumerate(result.changes):
        if c is change:
            return result.std[i]
    return {}
