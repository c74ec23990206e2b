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
(and, as a plain check, its RMS error within ``explained_error_factor``,
1.5, times the noise floor, each line as the noise model scores it, or
within what the noise allows when the floor lives on a few lines:
:func:`~substructure.updating.error_check`).
When it is not, the report says so first, with where the remaining error
lives and what kind of effect has that signature
(:mod:`substructure.diagnose.report`).  Explanations the data cannot tell
apart are reported together, with the measurement that would separate them;
when they change different parts of the model (``sites``) and a
measurement would tell them apart, neither is claimed and the data are not
explained.  The search runs within a budget of model evaluations
(``budget``), so that the same data give the same answer on any machine.
Every threshold, grid and budget is a field of
:class:`~substructure.diagnose.settings.DiagnoseSettings`, given as
``settings``; the sentences of the verdict are written by
:mod:`substructure.diagnose.words`.
"""

from __future__ import annotations

import sys
from typing import Callable, Sequence

import attrs
import numpy as np

from .._kernels import one_blas_thread
from ..assembly import Assembly
from ..errors import InvalidValueError, SubstructureError
from ..frf import FRF
from ..measurements.measurement import Measurement
from ..measurements.measurement_set import measurements_given
from ..updating.likelihood import Likelihood, measured_frfs
from ..updating.structure import assembly_checked
from ..updating.selection import INDIFFERENCE, consistency, error_check, outlying_runs
from .compare import METRIC, Comparison, _pairs, frac, error_bands
from .effects import Effect, registry, tested_at, written_back
from .refine import refine as refine_model, trim_partial
from . import words
from .claims import bound_hits, bound_text, counted, explains, passive
from .result import Alternatives, Candidate, Changes, Diagnosis, Found, Measures, Step, Verdict, _finite, strict
from .search import Budget, candidates, free_tip_hits
from .tip import tip_fallback, tip_rival
from .settings import DEFAULT_SETTINGS, FROM_SETTINGS, DiagnoseSettings, _FromSettings, _real

__all__ = ["Found", "Candidate", "Step", "Diagnosis", "diagnose", "strict", "sites"]


def _catalogue(effects) -> dict:
    """The effects of a call: a snapshot of the registry, or the names or classes given."""
    known = registry()
    if isinstance(effects, str):
        if effects == "all":
            return known
        effects = [e.strip() for e in effects.split(",") if e.strip()]
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


def _comparisons(lik: Likelihood, ratios, floors, settings: DiagnoseSettings = DEFAULT_SETTINGS
                 ) -> tuple[Comparison, ...]:
    out = []
    for m, r, floor, alive in zip(lik.measured, ratios, floors, lik.alive):
        measured = m.frf
        model = FRF(measured.frequency, (measured.data[:, 0, 0] * np.exp(r))[:, None, None], measured.outputs,
                    measured.inputs)
        out.append(Comparison(model=model, measured=measured, error=float(np.sqrt(np.mean(np.abs(r[alive]) ** 2))),
                              noise_floor=floor, frac=frac(model, measured),
                              modes=_pairs(model, measured, floor, settings),
                              bands=error_bands(model, measured, settings.error_bands_share, floor=floor,
                                                width_share=settings.error_bands_width,
                                                floor_factor=settings.error_bands_floors)))
    return tuple(out)


def _peak_lines(baseline, settings: DiagnoseSettings = DEFAULT_SETTINGS) -> np.ndarray:
    """Positions of the lines within ``settings.peak_lines`` of every measured resonance the model as given lacks
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
            keep += range(max(0, i - settings.peak_lines), min(hz.size, i + settings.peak_lines + 1))
    return np.unique(np.array(keep, dtype=int))


def _main_shift(comparison: Comparison, share: float) -> float:
    pairs = [m for m in comparison.modes if m.model_hz is not None]
    if not pairs:
        return 0.0
    top = max(m.measured_amplitude for m in pairs)
    strong = [m for m in pairs if m.measured_amplitude >= share * top] or pairs
    best = max(strong, key=lambda m: abs(m.model_hz / m.measured_hz - 1))
    return float(best.model_hz / best.measured_hz - 1)


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
             refine: bool = True, max_steps: int | _FromSettings = FROM_SETTINGS,
             progress: bool | Callable[[str], None] = False, open_world: bool = True,
             budget: float | None | _FromSettings = FROM_SETTINGS,
             time_limit: float | None | _FromSettings = FROM_SETTINGS,
             settings: DiagnoseSettings | None = None) -> Diagnosis:
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
        Most changes the refinement adds (default: ``settings.max_steps``, 4).
    progress : bool or callable
        Report progress (to standard error when True).
    open_world : bool
        Consider every model parameter and the elements at fitted
        positions besides the catalogue (default True).
    budget : float or None
        Budget of the search in model evaluations of all lines (default
        ``settings.budget``, 3000; None: no limit): the same data give the
        same answer on any machine.  When it cuts the search,
        ``Diagnosis.search["cut"]`` is true and, unless the data are
        explained, the report says so.
    time_limit : float or None
        A limit in wall-clock seconds as well (default ``settings.time_limit``,
        None; with one, the answer may depend on the machine's speed).
    settings : DiagnoseSettings, optional
        Every threshold, grid and budget of the search and the report
        (default :data:`~substructure.diagnose.settings.DEFAULT_SETTINGS`);
        ``max_steps``, ``budget`` and ``time_limit`` given here win over its
        fields of the same names.

    Returns
    -------
    Diagnosis
        The verdict, the candidates, the refinement and the refined model.

    Notes
    -----
    When the data are not explained and a measurement that declares no
    window shows its noise correlated as through an exponential window
    (``NoiseModel.seen_tau``), the data are diagnosed again with each such
    measurement read as through that window (an analyser's window on the
    response adds the damping ``1/(tau omega)`` to every mode).  If that
    explains them, that diagnosis is returned, its report's first line says
    so and ``Diagnosis.assumed_windows`` lists the windows; otherwise the
    first, with a line that the window was tried
    (``DiagnoseSettings.seen_window``).
    """
    assembly_checked(assembly)
    if isinstance(measurements, FRF):  # one FRF is one measurement (iterated, it was read as FRF[0])
        measurements = [measurements]
    measurements = measurements_given(measurements)
    if settings is None:
        settings = DEFAULT_SETTINGS
    elif not isinstance(settings, DiagnoseSettings):
        raise InvalidValueError(f"settings: got {settings!r}; expected a DiagnoseSettings (or None: the defaults)")
    for name, value, what in (("budget", budget, "model evaluations"), ("time_limit", time_limit, "seconds")):
        if value is not None and value is not FROM_SETTINGS and not (_real(value) and value > 0):
            raise InvalidValueError(f"{name}: got {value!r}; expected a positive number of {what} (or None: no limit)")
    if max_steps is not FROM_SETTINGS and not (isinstance(max_steps, int) and not isinstance(max_steps, bool)
                                               and max_steps >= 1):
        raise InvalidValueError(f"max_steps: got {max_steps!r}; expected a whole number >= 1")
    budget = settings.budget if isinstance(budget, _FromSettings) else budget
    time_limit = settings.time_limit if isinstance(time_limit, _FromSettings) else time_limit
    max_steps = settings.max_steps if isinstance(max_steps, _FromSettings) else max_steps
    catalogue = _catalogue(effects)
    if progress is True:
        def progress(text):  # noqa: F811 - a printer when asked for
            print(f"diagnose: {text}", file=sys.stderr, flush=True)
    say = progress or None
    if hasattr(measurements, "validate"):
        measurements.validate(assembly)
    _refuse_rotations(measurements)
    first, seen = _diagnose(assembly, measurements, catalogue, band, refine, max_steps, say, open_world,
                            Budget(budget, time_limit, settings.budget_lines), settings)
    left = None if time_limit is None else time_limit - first.search["seconds"]
    if first.explained or not seen or not settings.seen_window or (left is not None and left <= 0):
        return first
    # noise correlated as through a window the data do not declare: the response through it too, as an analyser
    # that windows it makes it (the damping 1/(tau omega) on every mode, which no change of the structure makes)
    if say:
        say("the noise reads as through an exponential window the data do not declare; diagnosing again through it")
    entries = [(_one_entry(m), tau) for m, tau in seen]
    through, _ = _diagnose(assembly, [m.through_window(tau) if tau else m for m, tau in entries], catalogue, band,
                           refine, max_steps, say, open_world, Budget(budget, left, settings.budget_lines),
                           settings)
    windows = tuple((m.describe(), tau) for m, tau in entries if tau)
    if not through.explained:
        return attrs.evolve(first, verdict=attrs.evolve(first.verdict, report=first.report + (
            words.window_not_enough(windows),)))
    line = words.window_assumed(windows, first.final_error, first.noise_floor)
    return attrs.evolve(through, verdict=attrs.evolve(through.verdict, report=(line,) + through.report,
                                                      assumed_windows=windows),
                        search={**through.search, "without_window": first.search})


def _diagnose(assembly, measurements, catalogue, band, refine, max_steps, say, open_world, meter, settings
              ) -> tuple[Diagnosis, list]:
    """One diagnosis of :func:`diagnose`'s checked arguments, and the measured FRF entries (``Measured``), each
    with the window its noise shows (``seen_tau``) where it declares none (an empty list where none shows one)."""
    from .report import Explanation, level_signature, separation, unexplained_report, values_text

    measured, band = measured_frfs(measurements, band)
    lik = Likelihood(assembly, measured, calibration=settings.calibration)
    floor, floors = lik.floors()
    base_ratios = lik.log_ratios([])
    e0 = lik.rms(base_ratios)
    chi2_now = float(lik.whiten(base_ratios) @ lik.whiten(base_ratios))
    n = lik.n
    cons = consistency(lik, base_ratios, 0)
    baseline = _comparisons(lik, base_ratios, floors, settings)
    if say:
        say(f"baseline error {e0:.4g} (noise floor {floor:.4g}), chi^2/n = {chi2_now / n:.4g}"
            f"{': consistent with the noise' if cons.consistent else ''}")
    points = [lbl for m in measured for lbl in (m.frf.outputs[0], m.frf.inputs[0])]
    cands = candidates(assembly, points, catalogue, open_world, _main_shift(baseline[0], settings.main_mode_share),
                       say, settings)
    # where the hammer hit a free tip apart from the sensor: tried with the tip's position, not in the search
    tip_cands = cands + free_tip_hits(assembly, [(m.frf.outputs[0], m.frf.inputs[0]) for m in measured],
                                      settings.point_reach)
    lacking = _peak_lines(baseline, settings)
    screen_lik = lik.subsample(max(1, lik.lines.size // settings.screen_lines), keep=lacking)
    limit = 0 if cons.consistent else (max_steps if refine else 1)
    scaled = bool(limit) and bool(level_signature(baseline, floor, settings)[0])
    if scaled:
        # every FRF a constant factor times the model with every mode in place: a calibration or unit error, which
        # no change of the structure makes (changes fitted to it would only be stacked on the wrong level)
        limit = 0
        if say:
            say("every measured FRF is a constant factor times the model with every mode in place: a calibration "
                "or unit error; no change of the structure is fitted")
    with one_blas_thread():  # small, narrow linear algebra throughout the search (``_kernels.one_blas_thread``)
        outcome = refine_model(lik, screen_lik, cands, limit, lambda changes: passive(lik, changes), say, meter,
                               lacking=bool(len(lacking)), settings=settings)
    tip_note = None
    if limit and not explains(lik, outcome, settings):
        outcome, tip_note = tip_fallback(lik, screen_lik, assembly, points, tip_cands, outcome, say, settings,
                                         floor)
    current = outcome.current
    p_now = sum(len(c.specs) for c, _ in current)
    steps = [Step(0, None, e0, chi2_now / n)]
    for k, (result, added, stat, threshold) in enumerate(outcome.history, start=1):
        values = next(v for c, v in result.changes if c is added)
        steps.append(Step(k, Found(added, values, _std_of(result, added)), lik.rms(lik.log_ratios(result.changes)),
                          result.chi2_reduced, stat, threshold))
    first = [Candidate(Found(s.change, s.values, s.fit.std[-1]), lik.rms(lik.log_ratios(s.fit.changes)), s.chi2, True,
                       s.fit.nfev) for s in outcome.first_fitted]
    done = {s.change.key for s in outcome.first_fitted}
    for s in outcome.first_scored:
        if s.change.key not in done:
            r = lik.log_ratios([(s.change, s.values)])
            w = lik.whiten(r)
            first.append(Candidate(Found(s.change, s.values), lik.rms(r), float(w @ w), False))
    final_fit = outcome.fit
    final_ratios = lik.log_ratios(current)
    cons = consistency(lik, final_ratios, p_now)
    final_error = lik.rms(final_ratios)
    check = error_check(lik, final_ratios, settings.explained_error_factor)
    explained = bool(cons.consistent and check.passed)
    left: list = []
    if not explained and len(current) > 1:  # a partial explanation without the changes worth little error
        current, final_fit, left = trim_partial(lik, current, final_fit, floor, settings.partial_gain)
        if left:
            p_now = sum(len(c.specs) for c, _ in current)
            final_ratios = lik.log_ratios(current)
            cons, final_error = consistency(lik, final_ratios, p_now), lik.rms(final_ratios)
            check = error_check(lik, final_ratios, settings.explained_error_factor)
    hits = bound_hits(current, final_fit)
    final_effects = tuple(Found(c, v, {k: x for k, x in (final_fit.std[i] if final_fit else {}).items()
                                       if (i, k) not in {(h[0], h[1]) for h in hits}})
                          for i, (c, v) in enumerate(current))
    refined = written_back(assembly, current)
    missing = steps[1].added if len(steps) > 1 else None
    def instead(change) -> list:  # a kept change's alternatives of its step, each with the error in its place
        out = []
        for c, v, _ in outcome.alternatives.get(change.key, []):
            try:
                error = lik.rms(lik.log_ratios([(c, v) if x is change else (x, y) for x, y in current]))
            except SubstructureError:  # no place beside the other changes (a point beyond a tool they shortened)
                continue
            out.append((Found(c, v), error))
        return out

    ambiguous = instead(missing.change) if missing is not None else []
    # the other kept changes' alternatives inside the indifference region (the first's are ``ambiguous``)
    equivalents = [(i, alt, err) for i, found in enumerate(final_effects)
                   if missing is None or found.change.key != missing.change.key
                   for alt, err in instead(found.change)]
    names = tuple(dict.fromkeys(a.name for a, _ in ambiguous))
    sep = None
    if missing is not None and ambiguous:
        sep = separation(assembly, measured, missing, ambiguous[0][0], say, settings=settings)
    correlation = {}
    if final_fit is not None and final_fit.p > 1:
        labels = [f"{current[i][0].effect}@{current[i][0].where}:{name}" for i, name in final_fit.names]
        correlation = {"parameters": labels, "matrix": [[_finite(x) for x in row] for row in final_fit.correlation]}
    rivals = _distinct_rivals(assembly, measured, final_effects, outcome, say, settings) if explained else []
    if explained and limit and not rivals:
        rivals = _tip_rival(lik, screen_lik, assembly, measured, points, tip_cands, outcome, final_effects, say,
                            settings)
    # a same-part rival's replacement of one kept change, not listed yet
    for i, found, rival in _same_part_replacements(assembly, final_effects, outcome, settings):
        if (i, found.change.key) not in {(j, a.change.key) for j, a, _ in equivalents} and not (
                missing is not None and final_effects[i].change.key == missing.change.key
                and found.change.key in {a.change.key for a, _ in ambiguous}):
            try:
                equivalents.append((i, found, lik.rms(lik.log_ratios([(f.change, f.values) for f in rival]))))
            except SubstructureError:  # no place beside the other changes
                continue
    final = _comparisons(lik, final_ratios, floors, settings)
    report = unexplained_report(lik, assembly, current, baseline, cons, final_error, floor, explained, say,
                                settings, check) if not explained else ()
    if left:
        report = list(report) + [words.left_out([(c.effect, c.place(v), w) for c, v, w in left],
                                                settings.partial_gain, floor)]
    if explained and counted(current) > settings.most_changes:  # a composite that only just reaches the noise
        explained = False
        report = [words.too_many_changes(settings.most_changes, [f"{c.effect} at {c.place(v)}" for c, v in current],
                                         [s.statistic / s.threshold for s in steps if s.statistic and s.threshold]),
                  words.partial("composite", final_effects)]
    if hits:  # a value on the bound of its search is not a measurement: never an explanation
        texts = [bound_text(current, hit) for hit in hits]
        if explained:
            explained = False
            report = [words.bounded(texts), words.partial("bounded", final_effects)]
        else:
            report = list(report) + [words.on_bound(texts)]
    if rivals:  # consistent with the noise, but not uniquely: claim neither
        explained = False
        kept = Explanation(final_effects)
        keys = sorted(f.change.key for f in final_effects)
        report = [words.not_unique(kept.name, kept.where, rival.name, rival.where, INDIFFERENCE,
                                   [values_text(f.change, f.values) for f in rival.founds]
                                   if sorted(f.change.key for f in rival.founds) == keys else None)
                  for rival, _ in rivals[:1]]
        report += [words.tell_apart(sep["text"]) for rival, sep in rivals]
        report.append(words.partial("ambiguous", final_effects))
        sep = sep or rivals[0][1]
        names = tuple(dict.fromkeys(list(names) + [r.name for r, _ in rivals]))
    search = {**outcome.search, "evaluations": round(meter.used(), 1), "budget": meter.evaluations,
              "time_limit_s": meter.seconds, "seconds": round(meter.elapsed(), 3)}
    if not explained:  # the changes the cross-validation dropped, said where the verdict is read
        report = list(report) + [words.held_back(r["effect"], r["where"], r["chi2_with"], r["chi2_without"])
                                 for r in search.get("held_back", []) if not r["predicts"]]
        if tip_note is not None:
            report.append(tip_note)
    if search["cut"] and not explained:
        report = list(report) + [words.budget_cut(search["cut_at"])]
    # facts of the data, whatever the verdict
    level = lik.level(current)
    if settings.calibration is not None:
        report = list(report) + [words.calibrated(level, settings.calibration)]
    elif not (explained or scaled) and min(hint := settings.calibration_hint) <= abs(level - 1) <= max(hint):
        report = list(report) + [words.level_hint(level)]
    runs = outlying_runs(lik, final_ratios) if cons.consistent else []  # else the failing bands say where
    for item, (m, alive, (_, lacking)) in enumerate(zip(lik.measured, lik.alive, lik.windows())):
        which, hz = getattr(m.measurement, "describe", lambda: m.label)(), m.frf.frequency.hz
        report = list(report) + [words.outlying(which, lo, hi, count) for i, lo, hi, count in runs if i == item]
        tau = getattr(m.measurement, "window_tau", None)
        if tau is not None:
            report = list(report) + [words.windowed(which, tau, float(hz[0]), float(hz[-1]), m.noise.correlation,
                                                    lacking)]
        elif m.noise.seen_tau is not None:
            report = list(report) + [words.correlated(which, m.noise, float(hz[0]), float(hz[-1]))]
        cut = getattr(m.measurement, "truncation", None)
        if cut is not None:  # on the measurement's own lines: those of the band
            full = m.measurement.frf.frequency.hz
            inside = (full >= hz[0]) & (full <= hz[-1]) & np.isfinite(cut)
            if inside.any() and cut[inside].max() > 0:
                k = int(np.argmax(np.where(inside, cut, -1.0)))
                report = list(report) + [words.truncated(which, float(np.sqrt(cut[k])), float(full[k]))]
        held = m.noise.held
        if m.noise.interpolated is not None and held is not None:
            report = list(report) + [words.interpolated(which, *m.noise.interpolated, int(held.sum()), held.size)]
        empty = ~alive if held is None else held & ~alive
        if empty.any():
            report = list(report) + [words.empty_lines(which, hz[empty])]
        if getattr(m.measurement, "estimator", None) == "H2":
            corrected = getattr(m.measurement, "coherence", None) is not None
            report = list(report) + [words.estimated_as_h2(which, corrected)]
    if missing is not None:  # where it acts as kept (a point's place at its final value, not its first step's)
        missing = next((f for f in final_effects if f.change.key == missing.change.key), missing)
    seen = [(m, m.noise.seen_tau if getattr(m.measurement, "window_tau", None) is None else None) for m in measured]
    diagnosis = Diagnosis(
        verdict=Verdict(explained=explained, report=tuple(report),
                        missing_effect=None if missing is None else missing.name,
                        missing_where=None if missing is None else missing.where),
        measures=Measures(metric=METRIC, band=band, noise_floor=floor, baseline_error=e0, final_error=final_error,
                          consistency=cons, correlation=correlation, baseline=baseline, final=final,
                          error_check=check, level=level if settings.calibration is not None else None),
        changes=Changes(final_effects=final_effects, refined_assembly=refined, candidates=tuple(first),
                        refinement=tuple(steps)),
        alternatives=Alternatives(ambiguous=tuple(ambiguous), ambiguous_with=names,
                                  suggestion=None if sep is None else sep["text"], separation=sep,
                                  rivals=tuple(rivals), equivalents=tuple(equivalents)),
        search=search, settings=settings,
    )
    return diagnosis, seen if any(tau for _, tau in seen) else []


def _one_entry(item) -> Measurement:
    """The measurement of one FRF entry of the data (a plain FRF's entry, or one of what holds it as ``frf``,
    made one, on all its lines)."""
    if isinstance(item.measurement, Measurement):
        return item.measurement
    out, inp = item.frf.outputs[0], item.frf.inputs[0]
    whole = item.measurement if isinstance(item.measurement, FRF) else getattr(item.measurement, "frf", item.frf)
    return Measurement.from_frf(whole if whole.shape[1:] == (1, 1) else whole.select([out], [inp]), out, inp)


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


def _rival_pool(assembly, final_effects, outcome, settings: DiagnoseSettings = DEFAULT_SETTINGS) -> list:
    """The rivals to check, best first: ``(founds, same_parts)`` for at most ``settings.rivals_checked``.

    A rival is a whole explanation of the parsimony check
    (:func:`substructure.diagnose.refine.refine`), the kept one with one
    change replaced by an alternative of its step, or the kept changes at
    other values that fit as well (a second minimum); one that holds every
    kept change and more is not (the data do not decide the extra).
    ``same_parts``: it is other changes acting on the same parts
    (components and joints by name, :func:`sites`) as the kept ones.
    """
    pool = [(chi2, [Found(c, v) for c, v in changes]) for changes, chi2, _ in outcome.rivals]
    for i, found in enumerate(final_effects):
        for c, v, chi2 in outcome.alternatives.get(found.change.key, []):
            pool.append((chi2, [Found(c, v) if j == i else f for j, f in enumerate(final_effects)]))
    pool.sort(key=lambda t: t[0])
    keys = {f.change.key for f in final_effects}
    # a rival that holds every kept change plus more is not another explanation: the data do not decide the extra
    # (the same changes at other values are another explanation: a second minimum of the same changes)
    pool = [(chi2, founds) for chi2, founds in pool if not keys < {f.change.key for f in founds}]
    kept_sites = frozenset().union(*(sites(assembly, f.change, f.values) for f in final_effects))
    return [(founds, {f.change.key for f in founds} != keys
             and frozenset().union(*(sites(assembly, f.change, f.values) for f in founds)) == kept_sites)
            for _, founds in pool[:settings.rivals_checked]]


def _distinct_rivals(assembly, measured, final_effects, outcome, say,
                     settings: DiagnoseSettings = DEFAULT_SETTINGS) -> list:
    """Rival explanations inside the indifference region that are different structures.

    A rival (:func:`_rival_pool`) is a *different structure* when some
    measurement with the test's sensors on (a point or cross FRF at the
    ends, quarter points and middles of the components) would tell the two
    apart (``chi^2 > INDIFFERENCE`` over the band); otherwise it is an
    equivalent description (a joint's stiffness as a named effect or as its
    matrix entry) and the preferred one stands.  One that changes the same
    parts is an equivalent description too (:func:`_same_part_replacements`
    says what it replaces).

    Returns
    -------
    list of (Explanation, dict)
        The distinct rivals with their separating measurement.
    """
    from .report import Explanation, separation

    kept = Explanation(final_effects)
    out = []
    for founds, same_parts in _rival_pool(assembly, final_effects, outcome, settings):
        if same_parts:
            continue
        rival = Explanation(founds)
        sep = separation(assembly, measured, kept, rival, say, contact_only=True, settings=settings)
        if sep is not None and sep["chi2"] > INDIFFERENCE:
            if say:
                say(f"rival explanation {rival.name} at {rival.where}: {sep['text']}")
            out.append((rival, sep))
    return out


def _tip_rival(lik, screen_lik, assembly, measured, points, cands, outcome, final_effects, say,
               settings: DiagnoseSettings) -> list:
    """The test taken below a free tip as a rival of an explanation that changed the structure there
    (:func:`~substructure.diagnose.tip.tip_rival`), with the measurement that tells the two apart."""
    from .report import Explanation, separation

    found = tip_rival(lik, screen_lik, assembly, points, cands, outcome, settings)
    if found is None:
        return []
    rival = Explanation(tuple(Found(c, v, sd) for c, v, sd in found))
    sep = separation(assembly, measured, Explanation(final_effects), rival, say, contact_only=True, settings=settings)
    kept = [(c, v) for c, v, _ in found]
    (point, place), *_ = (tested_at(kept) or tested_at(kept, hits=True)).items()  # the sensor's, else the hit's
    ruler = words.taken_below(point, place)  # what tells them apart without a test
    if sep is None or sep["chi2"] <= INDIFFERENCE:  # no FRF with the test's sensors on does
        sep = {**(sep or {"response": None, "excitation": None, "non_contact": False, "chi2": None}), "text": ruler}
    else:
        sep = {**sep, "text": f"{sep['text']}; or {ruler}"}
    if say:
        say(f"rival explanation {rival.name} at {rival.where}: {sep['text']}")
    return [(rival, sep)]


def _same_part_replacements(assembly, final_effects, outcome, settings: DiagnoseSettings = DEFAULT_SETTINGS) -> list:
    """The rivals on the same parts that replace one kept change by another: what the data allow as well.

    Returns
    -------
    list of (int, Found, list of Found)
        The index of the kept change, the change that fits as well in its
        place, and the whole rival.
    """
    keys = {f.change.key for f in final_effects}
    out = []
    for founds, same_parts in _rival_pool(assembly, final_effects, outcome, settings):
        new = [f for f in founds if f.change.key not in keys]
        gone = [i for i, f in enumerate(final_effects) if f.change.key not in {g.change.key for g in founds}]
        if same_parts and len(new) == 1 and len(gone) == 1:
            out.append((gone[0], new[0], founds))
    return out


def _std_of(result, change) -> dict:
    return next((result.std[i] for i, (c, _) in enumerate(result.changes) if c is change), {})
