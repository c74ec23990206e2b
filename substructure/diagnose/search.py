"""The open-world search: candidates, cheap screening, full fits, forward selection.

The candidates of one diagnosis are

(a) every parameter of the model and the linked ones
    (:func:`substructure.updating.parameters.model_parameters`), each a
    ``model-parameter`` correction;
(b) elements the model may lack, on every plain beam component, at a fitted
    position: ``added-mass``, ``ground-spring``, ``section-change``
    (:mod:`substructure.updating.elements`);
(c) every registered effect of the catalogue at every place it proposes
    (:mod:`substructure.diagnose.effects`).

Each step of the forward selection screens every candidate on a subsample
of the lines (every ``k``-th, about 250 per FRF): a coarse scan of its main
parameter (with its position, for elements) and a short local fit with the
effects already added held; then every candidate whose screened improvement
is at least a quarter of the best one is fitted on all lines together with
the effects already added (all refitted).  The best by BIC is added when it
passes the significance test of :mod:`substructure.updating.selection`;
the search stops when the model is consistent with the noise, when nothing
passes, or after ``max_steps``.  Which candidates get full fits depends on
each one's own screened improvement, never on a count, so a registered
effect can only add a candidate, not push a built-in one out.  The numbers
(lines of the subsample, the share, the polish's budget) are fields of
:class:`~substructure.diagnose.settings.DiagnoseSettings`.
"""

from __future__ import annotations

import math
import time
from typing import Callable, Sequence

import attrs
import numpy as np
from scipy.optimize import minimize_scalar

from ..components import Beam, is_plain_beam
from ..errors import SubstructureError
from ..points import parse_point
from ..updating.elements import (AddedMass, GroundSpring, HitPosition, PointPosition, SectionChange, body_bounds,
                                 rear_bounds)
from ..updating.fit import Fit, fit, from_u, to_u
from ..updating.parameters import Change, ParameterChange, material_changes, model_parameters, parameter_change
from ..updating.structure import uniform_beam
from ..updating.selection import INDIFFERENCE, bic, significance
from .effects import EffectChange, effect_change
from .scan import finer, sharpen
from .scan import trials as _trials
from .settings import DEFAULT_SETTINGS, DiagnoseSettings

__all__ = ["Scored", "Budget", "candidates", "screen", "full_fits"]


class Budget:
    """The work a search may do: model evaluations, and optionally seconds.

    Evaluations are counted in evaluations of all lines of all measured
    FRFs (one on the screening subsample of a tenth of the lines counts a
    tenth), and of at least ``lines`` lines (data of fewer lines count
    each evaluation as its share of that), so that the same data and model
    give the same search on any machine; a limit in seconds is there for
    users who want one (it makes the result depend on the machine's speed).

    Parameters
    ----------
    evaluations : float or None
        Most evaluations (None: no limit).
    seconds : float or None
        Most wall-clock seconds (None: no limit).
    lines : int
        The fewest lines an evaluation of all lines counts as
        (``DiagnoseSettings.budget_lines``).
    """

    def __init__(self, evaluations: float | None = None, seconds: float | None = None, lines: int = 1):
        self.evaluations = evaluations
        self.seconds = seconds
        self.started = time.monotonic()
        self.likelihoods: list = []
        self.lines = max(int(lines), 1)
        self.full = self.lines

    def watch(self, *likelihoods) -> None:
        """Count the evaluations of these likelihoods (the first one's lines are "all lines").

        Parameters
        ----------
        *likelihoods : Likelihood
            The likelihoods the search evaluates.
        """
        if not self.likelihoods and likelihoods:
            self.full = max(likelihoods[0].n, self.lines)
        self.likelihoods += [x for x in likelihoods if all(x is not y for y in self.likelihoods)]

    def used(self) -> float:
        """Evaluations so far, in evaluations of all lines.

        Returns
        -------
        float
            The work done.
        """
        return sum(x.evaluations * x.n for x in self.likelihoods) / self.full

    def elapsed(self) -> float:
        """Seconds since the budget was made.

        Returns
        -------
        float
            Wall-clock seconds.
        """
        return time.monotonic() - self.started

    def spent(self) -> bool:
        """Whether either limit is reached.

        Returns
        -------
        bool
            True once the search must stop adding work.
        """
        return bool((self.evaluations is not None and self.used() > self.evaluations)
                    or (self.seconds is not None and self.elapsed() > self.seconds))


def _p(changes) -> int:
    """Parameters of ``(Change, values)`` pairs."""
    return sum(len(c.specs) for c, _ in changes)


def candidates(assembly, measured_points: Sequence[str], effects: dict, open_world: bool = True,
               shift: float = 0.0, progress: Callable | None = None,
               settings: DiagnoseSettings = DEFAULT_SETTINGS) -> list[Change]:
    """Every candidate change of a diagnosis (see the module docstring).

    Parameters
    ----------
    assembly : Assembly
        The model.
    measured_points : sequence of str
        The measured DOF labels (places of ``sensor-mass``).
    effects : dict of str to type
        The effects of the catalogue to consider.
    open_world : bool
        Include the model's parameters and the elements.
    shift : float
        Relative shift of the main mode (starting values of effects).
    progress : callable, optional
        Told about effects that cannot act at a place.
    settings : DiagnoseSettings
        The diagnosis's settings (``inertia_floor``).

    Returns
    -------
    list of Change
        The candidates.
    """
    out: list[Change] = []
    if open_world:
        out += [parameter_change(p) for p in model_parameters(assembly)]
        out += material_changes(assembly)
        for comp in assembly.components:
            if not isinstance(comp, Beam):  # bodies and springs sit along a beam, of any type
                continue
            lo, hi, mass_max = body_bounds(assembly, comp)
            # the largest rotary inertia: that mass at the radius of twice the widest section (at least the floor)
            widest = max(float(s.od.m_as("m")) for s in comp.segments)
            inertia_max = max(settings.inertia_floor, mass_max * widest**2)
            out.append(AddedMass(comp.name, comp.length_m, mass_max, (lo, hi), inertia_max))
            rear = rear_bounds(assembly, comp)
            if rear is not None:  # a spindle's rear end: a pulley, a rotary union
                out.append(AddedMass(comp.name, comp.length_m, mass_max, rear, inertia_max, f"{comp.name} rear end"))
            out.append(GroundSpring(comp.name, comp.length_m))
            if uniform_beam(comp):  # a section changed in the arrays of a plain beam
                out.append(SectionChange(comp.name, comp.length_m))
        out += _point_positions(assembly, measured_points, settings.point_reach)
    for name, cls in effects.items():
        try:
            places = cls.places(assembly, list(measured_points))
        except SubstructureError as exc:
            if progress:
                progress(f"  {name}: no places ({exc})")
            continue
        for where in places:
            try:
                out.append(effect_change(cls, where, assembly, shift))
            except (SubstructureError, ValueError) as exc:
                if progress:
                    progress(f"  skipped {name} at {where}: {exc}")
    empty = [c for c in out if any(not spec.upper > spec.lower for spec in c.specs)]
    for c in empty:  # a search of no width (a cross term bounded by the diagonal terms of a joint with k_yf = 0)
        if progress:
            progress(f"  skipped {c.effect} at {c.where}: a parameter's search range is empty")
    return [c for c in out if c not in empty]


def _measured_beams(assembly, measured_points: Sequence[str]):
    """``(point, component)`` of each measured point on a plain beam, once each."""
    for label in dict.fromkeys(measured_points):
        try:
            ref = parse_point(label)
            comp = assembly.component(ref.component)
        except SubstructureError:
            continue
        if isinstance(comp, Beam) and is_plain_beam(comp):
            yield ref, comp


def _point_positions(assembly, measured_points: Sequence[str], reach: float) -> list[Change]:
    """A measured point given at a distance along a beam (``tool.tip-20 mm``, ``holder@30 mm``: measured with a
    ruler) may be a few millimetres off: its position, a candidate (a free tip is tried alone after the search:
    :func:`free_tips`)."""
    out = [PointPosition(str(ref.point), comp.name, comp.position(ref.point), comp.length_m, reach)
           for ref, comp in _measured_beams(assembly, measured_points) if reach > 0 and ref.where in ("at", "from_tip")]
    return list({c.where: c for c in out}.values())


def free_tips(assembly, measured_points: Sequence[str], reach: float) -> list[Change]:
    """A measured free tip (``tool.tip``, nothing joined or supported there): a sensor cannot sit on the very edge,
    nor a hammer strike it, so where the test was taken, up to ``reach`` towards the base, is a candidate.  Not one
    of the search's: :func:`~substructure.diagnose.diagnose` tries these alone when the search explains nothing."""
    held = {p for j in assembly.joints for p in j.between} | {s.at for s in assembly.supports}
    out = [PointPosition(str(ref.point), comp.name, comp.length_m, comp.length_m, reach)
           for ref, comp in _measured_beams(assembly, measured_points)
           if reach > 0 and ref.where == "tip" and str(ref.point) not in held]
    return list({c.where: c for c in out}.values())


def free_tip_hits(assembly, pairs: Sequence[tuple[str, str]], reach: float) -> list[Change]:
    """Where the hammer hit a measured free tip apart from the sensor there (at another height beside it): a
    candidate where the tip is hit and takes part in an FRF with another point too, as the hit (a roving sensor)
    or as the response (a roving hammer): on the driving point alone the hit's place and the sensor's are one
    (reciprocity).  Like the free tip's position, not one of the search's: tried with it
    (:mod:`~substructure.diagnose.tip`).

    Parameters
    ----------
    assembly : Assembly
        The model.
    pairs : sequence of (str, str)
        ``(response, excitation)`` labels of the measurements.
    reach : float
        How far from the tip [m] (``point_reach``).
    """
    ends = [(parse_point(r).point, parse_point(e).point) for r, e in pairs]
    crossed = {p for r, e in ends if r != e for p in (r, e)}
    tips = free_tips(assembly, [e for _, e in pairs], reach)
    # a free tip is at its component's end: its place and the component's length are one (t.distance)
    return [HitPosition(t.where, t.component, t.distance, t.distance, reach) for t in tips
            if parse_point(t.where).point in crossed]


@attrs.frozen
class Scored:
    """A candidate after screening (and possibly a full fit).

    Attributes
    ----------
    change : Change
        The candidate.
    values : dict
        Its values (screened, or fitted on all lines).
    chi2 : float
        ``chi^2`` of the model with it (on the lines of the fit).
    fit : Fit or None
        The full fit (the effects already added refitted with it).
    """

    change: Change = attrs.field(eq=False)
    values: dict = attrs.field(eq=False)
    chi2: float
    fit: Fit | None = attrs.field(default=None, eq=False)
    start: list | None = attrs.field(default=None, eq=False)

    @property
    def k(self) -> int:
        """Parameters the candidate adds."""
        return len(self.change.specs)


def screen(likelihood, current: Sequence[tuple], changes: Sequence[Change], chi2_now: float, n_full: int,
           progress: Callable | None = None, extra: dict | None = None, cross: bool = False,
           settings: DiagnoseSettings = DEFAULT_SETTINGS, narrow: dict | None = None) -> list[Scored]:
    """Screen candidates on a subsample: a scan with the changes already added held, then local fits.

    Every candidate's main parameter is scanned over its range (at each
    place, for elements); the changes already added are refitted to first
    order at every trial (the residual is projected out of the span of
    their Jacobian, computed once), since their values may compensate for
    the candidate.  The candidates that pass :func:`shortlist` get a short
    local fit on the subsample with the current changes refitted too; their
    values (and the current changes' moved values) start the full fits.

    Parameters
    ----------
    likelihood : Likelihood
        Usually a subsample of the lines.
    current : sequence of (Change, dict)
        The changes already added.
    changes : sequence of Change
        The candidates.
    chi2_now : float
        ``chi^2`` of the current model on these lines.
    n_full : int
        Residuals of the full data (to scale improvements for the tests).
    progress : callable, optional
        Progress lines.
    extra : dict, optional
        More trials per candidate key (from :func:`substructure.diagnose.modes.mode_starts`).
    cross : bool
        Cross the sizes and positions of springs (:func:`substructure.diagnose.scan.trials`).
    narrow : dict, optional
        Groups of more trials per candidate key; each group's best have their main parameter searched close to each
        (:func:`substructure.diagnose.modes.rigid_starts`, :func:`substructure.diagnose.scan.sharpen`).
    settings : DiagnoseSettings
        The grids, the polish and the shortlist's numbers.

    Returns
    -------
    list of Scored
        The candidates that improve the model, best first (local fits first).
    """
    basis = _basis(likelihood, current, settings)

    def projected(w) -> float:
        if basis is not None:  # the changes already added, refitted to first order
            w = w - basis @ (basis.T @ w)
        return float(w @ w)

    def chi2_of(models, none_held_raises: bool = False) -> list[float]:
        # several models evaluated together (the same numbers as one by one); one that cannot be held costs inf
        # (a trial of the scan beyond what the model holds: a shorter overhang than a section change leaves);
        # none held: the first one's error, when asked
        try:
            return [projected(w) for w in likelihood.residuals(models)]
        except (SubstructureError, ValueError, FloatingPointError) as exc:
            first = exc
        costs = []
        for model in models:
            try:
                costs.append(projected(likelihood.residual(model)))
            except (SubstructureError, ValueError, FloatingPointError):
                costs.append(math.inf)
        if none_held_raises and not np.isfinite(costs).any():
            raise first
        return costs

    scanned = []
    for n, change in enumerate(changes, start=1):
        if progress and (n % 25 == 0 or n == len(changes)):
            progress(f"scanned {n}/{len(changes)} candidates")
        best_chi2, best = math.inf, None
        try:
            tried = _trials(change, first=cross, settings=settings) + list((extra or {}).get(change.key, ()))
            # evaluated together (the same numbers as one by one), then an element's size searched at each of
            # its places
            def evaluate(batch, change=change) -> list[float]:
                return chi2_of([list(current) + [(change, t)] for t in batch], none_held_raises=True)

            costs = evaluate(tried)
            try:
                more, more_costs = finer(change, tried, costs, evaluate, settings, below=chi2_now)
            except (SubstructureError, ValueError, FloatingPointError):
                more, more_costs = [], []  # a size between the grid's that cannot be evaluated: the grid's stand
            tried, costs = tried + more, costs + more_costs
            for starts in (narrow or {}).get(change.key, ()):
                start_costs = evaluate(list(starts))
                sharper, sharper_costs = sharpen(change, list(starts), start_costs, evaluate, settings)
                tried, costs = tried + list(starts) + sharper, costs + start_costs + sharper_costs
            for trial, chi2 in zip(tried, costs):
                if chi2 < best_chi2:
                    best_chi2, best = chi2, trial
        except (SubstructureError, ValueError, FloatingPointError) as exc:
            if progress:
                progress(f"  skipped {change.effect} at {change.where}: {exc}")
            continue
        if best is not None and best_chi2 <= chi2_now * (1 + 1e-9):  # at its nominal value: the polish may still gain
            scanned.append(Scored(change, dict(best), float(best_chi2), start=list(current)))
    scanned.sort(key=lambda s: s.chi2)
    scanned = [s for s in _polish(scanned, chi2_of, current, settings) if s.chi2 < chi2_now]
    local = []
    p_now = _p(current)
    for s in shortlist(scanned, chi2_now, likelihood.n, n_full, p_now, settings):
        try:
            result = fit(likelihood, list(current) + [(s.change, s.values)],
                         max_nfev=settings.short_fit_evaluations * (p_now + s.k + 1))
        except (SubstructureError, ValueError, FloatingPointError):
            continue
        if result.chi2 < s.chi2:
            s = Scored(s.change, dict(result.changes[-1][1]), float(result.chi2),
                       start=[(c, dict(v)) for c, v in result.changes[:-1]])
        local.append(s)
    local.sort(key=lambda s: s.chi2)
    done = {s.change.key for s in local}
    return [s for s in local + [s for s in scanned if s.change.key not in done] if s.chi2 < chi2_now]


def _polish(scanned: list, chi2_of, current, settings: DiagnoseSettings = DEFAULT_SETTINGS) -> list:
    """Every scanned candidate's main parameter refined around its best trial (on its fitted scale).

    A grid of nine values over decades misses minima narrower than its
    step (a bearing pair half as stiff sits between 0.32 and 1 on a factor
    grid, and moves the modes by many bandwidths on the way), and a change
    smaller than a step scans no better than the model as it is.  So every
    candidate (those whose scan found nothing better too) is refined, the
    other values held: the ``settings.brent_candidates`` best by evaluations
    at points between their best trial and the grid's neighbours
    (``settings.polish_points`` per step) and a bounded scalar minimisation
    (Brent's, at most ``settings.brent_evaluations`` evaluations) around the
    best of those; the others by the slope at their best trial and Brent's
    down it, when it descends.  The order is then by the refined ``chi^2``.
    """
    out = [_refined(s, chi2_of, current, k < settings.brent_candidates, settings) for k, s in enumerate(scanned)]
    out.sort(key=lambda x: x.chi2)
    return out


def _refined(s: Scored, chi2_of, current, thorough: bool, settings: DiagnoseSettings) -> Scored:
    """One candidate of :func:`_polish` refined."""
    main = s.change.specs[0]
    u0 = to_u(main, s.values[main.name])
    lo_u, hi_u = to_u(main, main.lower), to_u(main, main.upper)
    step = (hi_u - lo_u) / float(settings.scan_values - 1)  # a step of the scan's grid
    lo, hi = max(lo_u, u0 - step), min(hi_u, u0 + step)
    if not hi > lo:
        return s

    def costs_at(us) -> list[float]:
        return chi2_of([list(current) + [(s.change, {**s.values, main.name: from_u(main, u)})] for u in us])

    def cost(u) -> float:
        return costs_at([u])[0]

    best_u, best_c = u0, float(s.chi2)
    bracket = None
    if thorough:
        # points between the scan's best and the grid's neighbours (scanned already) first: the landscape can
        # hold several minima where a model peak crosses the lines; Brent's around the best of them
        sub = step / settings.polish_points
        pts = [u for u in u0 + sub * np.arange(-settings.polish_points + 1, settings.polish_points)
               if lo < u < hi and u != u0]
        costs = costs_at(pts)
        if costs and min(costs) < best_c:
            j = int(np.argmin(costs))
            best_u, best_c = float(pts[j]), float(costs[j])
        bracket = (max(lo, best_u - sub), min(hi, best_u + sub))
    else:
        # the slope at the scan's best, then Brent's down it (a change smaller than a grid step scans no
        # better than the model, but the slope shows it)
        tiny = step / float(settings.slope_divisions)
        near = [u for u in (u0 - tiny, u0 + tiny) if lo <= u <= hi]
        down = [(c, u) for c, u in zip(costs_at(near), near) if c < best_c]
        if down:
            best_c, best_u = min(down)
            bracket = (lo, u0) if best_u < u0 else (u0, hi)
    if bracket is not None and bracket[1] > bracket[0]:
        with np.errstate(invalid="ignore", over="ignore"):  # a model refused inside the bracket costs inf
            r = minimize_scalar(cost, bounds=bracket, method="bounded",
                                options={"maxiter": settings.brent_evaluations, "xatol": settings.brent_tolerance})
        if np.isfinite(r.fun) and r.fun < best_c:
            best_u, best_c = float(r.x), float(r.fun)
    if np.isfinite(best_c) and best_c < s.chi2:
        return Scored(s.change, {**s.values, main.name: from_u(main, best_u)}, best_c, start=s.start)
    return s


def _basis(likelihood, current, settings: DiagnoseSettings = DEFAULT_SETTINGS) -> np.ndarray | None:
    """An orthonormal basis of the Jacobian of the changes already added (None without any)."""
    if not current:
        return None
    w0 = likelihood.residual(current)
    cols = []
    for i, (c, v) in enumerate(current):
        for spec in c.specs:
            u = to_u(spec, v[spec.name])
            h = settings.jacobian_step * max(1.0, abs(u))
            moved = [(x, dict(y)) for x, y in current]
            moved[i][1][spec.name] = from_u(spec, u + h)
            if moved[i][1][spec.name] == v[spec.name]:
                moved[i][1][spec.name] = from_u(spec, u - h)
            cols.append(likelihood.residual(moved) - w0)
    q, r = np.linalg.qr(np.array(cols).T)
    keep = np.abs(np.diag(r)) > 1e-12 * max(np.abs(np.diag(r)).max(), 1e-300)
    return q[:, keep]


def shortlist(scored: Sequence[Scored], chi2_now: float, n_lines: int, n_full: int, p_now: int,
              settings: DiagnoseSettings = DEFAULT_SETTINGS) -> list[Scored]:
    """The screened candidates worth fitting further.

    A candidate qualifies when its improvement is at least
    ``settings.shortlist_share`` of the best one and, less the ``k`` that
    fitting its ``k`` parameters to noise gains and scaled to all lines, could
    pass the significance test; of those, at most ``settings.shortlist_max``
    of each kind: the model's parameters and elements, the catalogue's
    effects, and users' registered effects (so that registering effects
    never pushes a built-in candidate out).

    Parameters
    ----------
    scored : sequence of Scored
        Screened candidates, best first.
    chi2_now : float
        ``chi^2`` of the current model on the screening lines.
    n_lines : int
        Residuals on the screening lines.
    n_full : int
        Residuals on all lines.
    p_now : int
        Parameters of the current model.
    settings : DiagnoseSettings
        ``shortlist_share``, ``shortlist_max`` and ``tie_chi2``.

    Returns
    -------
    list of Scored
        The candidates to fit further, best first.
    """
    if not scored:
        return []
    scale = n_full / max(n_lines, 1)
    gain = chi2_now - scored[0].chi2
    out, counts = [], {"model": 0, "catalogue": 0, "user": 0}
    for s in _ties_by_preference(scored, settings.tie_chi2):
        own = chi2_now - s.chi2
        if own < settings.shortlist_share * gain:
            continue
        # scaled to all lines, less what fitting k parameters to noise gains on the subsample
        if not significance((chi2_now - s.k) * scale, s.chi2 * scale, s.k, n_full, p_now + s.k).significant:
            continue
        kind = _kind(s.change)
        if counts[kind] >= settings.shortlist_max:
            continue
        counts[kind] += 1
        out.append(s)
    return out


def _ties_by_preference(scored: Sequence[Scored], tie: float) -> list[Scored]:
    """Best first; candidates that screened alike (within ``tie`` of chi^2) in order of preference."""
    ordered = sorted(scored, key=lambda s: s.chi2)
    out, i = [], 0
    while i < len(ordered):
        j = i + 1
        while j < len(ordered) and ordered[j].chi2 - ordered[i].chi2 <= tie:
            j += 1
        out += sorted(ordered[i:j], key=lambda s: (preference(s.change), s.chi2))
        i = j
    return out


def _kind(change: Change) -> str:
    """A candidate's kind in the shortlist: ``model`` (a parameter or an element), ``catalogue`` (an effect of
    this package) or ``user`` (an effect registered from elsewhere)."""
    if not isinstance(change, EffectChange):
        return "model"
    return "catalogue" if change.cls.__module__.startswith(__name__.split(".")[0] + ".") else "user"


def full_fits(likelihood, current: Sequence[tuple], chosen: Sequence[Scored],
              progress: Callable | None = None, budget: Budget | None = None) -> list[Scored]:
    """Fit each chosen candidate on all lines with the effects already added refitted.

    Parameters
    ----------
    likelihood : Likelihood
        All lines.
    current : sequence of (Change, dict)
        The effects already added (refitted with each candidate).
    chosen : sequence of Scored
        Candidates with their screened values as the start.
    progress : callable, optional
        Progress lines.
    budget : Budget, optional
        Once it is spent no more candidates are fitted (the first one always
        is; the shortlist is best first).

    Returns
    -------
    list of Scored
        With ``fit`` set, best ``chi^2`` first.
    """
    out = []
    for k, s in enumerate(chosen):
        if k and budget is not None and budget.spent():
            break
        if progress:
            progress(f"fitting {s.change.effect} at {s.change.where} with {len(current)} effect(s) added")
        held = list(s.start if s.start is not None else current)
        try:
            result = fit(likelihood, held + [(s.change, s.values)])
        except (SubstructureError, ValueError, FloatingPointError) as exc:
            if progress:
                progress(f"  skipped {s.change.effect} at {s.change.where}: {exc}")
            continue
        result = _from_own_start(likelihood, held, s, result)
        out.append(Scored(s.change, dict(result.changes[-1][1]), result.chi2, result))
    out.sort(key=lambda s: s.chi2)
    return out


def _from_own_start(likelihood, held: list, s: Scored, result):
    """The fit again from the candidate's own start when it ended with its main parameter on a bound.

    The scan's grid is coarse (half a decade for a factor over four) and a
    minimum can be narrower: both rear bearings of a machine spindle half as
    stiff sit between the grid's 0.32 and 1, both far off, while the far end
    of the range (100) fits fairly, and the fit that starts there stays on
    the bound.  The start of a change is the model as given (or the effect's
    own starting values), nearest the basin a drawing's error lies in; the
    better of the two fits is kept.
    """
    main = s.change.specs[0]
    index = len(result.changes) - 1
    on = dict(zip(result.names, result.at_bound)).get((index, main.name), False)
    own = {spec.name: spec.start for spec in s.change.specs}
    if not on or np.isclose(s.values.get(main.name, np.nan), own[main.name], rtol=1e-9, atol=0.0):
        return result
    try:
        again = fit(likelihood, held + [(s.change, own)])
    except (SubstructureError, ValueError, FloatingPointError):
        return result
    return again if again.chi2 < result.chi2 else result


def rank(fitted: Sequence[Scored], n: int, p_now: int) -> list[Scored]:
    """Candidates ordered by BIC (``chi^2`` plus ``k ln n``), best first.

    Parameters
    ----------
    fitted : sequence of Scored
        Fully fitted candidates.
    n : int
        Number of residuals.
    p_now : int
        Parameters of the model without the candidate.

    Returns
    -------
    list of Scored
        Best first.
    """
    return sorted(fitted, key=lambda s: bic(s.chi2, p_now + s.k, n))


MEASURED = ("length", "od", "id", "od_tip", "id_tip", "insert.od", "insert.id")
"""A segment's dimensions: what a user measures on the part with a caliper, and so trusts more than a number
of the model (a flutes' ratio, a joint entry, a material constant) that gives the same FRF."""


def preference(change: Change) -> float:
    """Which of explanations the data cannot tell apart is reported first (lower first).

    0: an effect of the catalogue (a named physical effect); 1: a linked
    model parameter (an overhang, a component's material, a joint's whole
    stiffness); 2: a single model parameter, 2.5 when it is a dimension
    the user measures on the part (:data:`MEASURED`: a fluted segment's
    ``od`` and its flutes' ``diameter_ratio`` set the same equivalent
    section, and the ratio is the model's guess); 3: an element at a
    fitted place; 3.5: a number known to a few per cent
    (``ModelParameter.known``: a holder's steel, whose density 12 % higher
    fits as well as the nut on it that the model lacks).

    Parameters
    ----------
    change : Change
        The candidate.

    Returns
    -------
    float
        Its class.
    """
    if isinstance(change, EffectChange):
        return 0
    if isinstance(change, ParameterChange):
        if getattr(change.parameter, "known", False):
            return ELEMENT + 0.5
        if change.parameter.linked:
            return 1
        parts = change.parameter.path.split(".")
        measured = parts[0] == "components" and parts[2:3] == ["segments"] and ".".join(parts[4:]) in MEASURED
        return 2.5 if measured else 2
    if getattr(change, "linked", False):
        return 1
    return ELEMENT


ELEMENT = 3
"""The :func:`preference` of an element at a fitted place (a body, a spring, a section change)."""


def choose(ranked: Sequence[Scored], n: int, p_now: int) -> tuple[Scored, list[Scored], float]:
    """The explanation to add among fitted candidates, and those indifferent to it.

    The best by BIC sets the misfit scale ``s^2``; every candidate whose
    ``chi^2`` is within :data:`~substructure.updating.selection.INDIFFERENCE`
    of it (scaled) is indifferent; among those the one of lowest
    :func:`preference`, then lowest BIC, is chosen.

    Parameters
    ----------
    ranked : sequence of Scored
        Fully fitted candidates, best BIC first.
    n : int
        Number of residuals.
    p_now : int
        Parameters of the current model.

    Returns
    -------
    (Scored, list of Scored, float)
        The choice, the others inside the indifference region, and ``s^2``.
    """
    best = ranked[0]
    s2 = max(1.0, best.chi2 / max(n - p_now - best.k, 1))
    inside = [s for s in ranked if abs(s.chi2 - best.chi2) / s2 <= INDIFFERENCE]
    chosen = min(inside, key=lambda s: (preference(s.change), bic(s.chi2, p_now + s.k, n, s2)))
    return chosen, [s for s in inside if s is not chosen], s2


def physical(change: Change, values: dict) -> bool:
    """A fitted candidate is physical: its values finite and inside their physical bounds.

    Parameters
    ----------
    change : Change
        The candidate.
    values : dict
        Its fitted values.

    Returns
    -------
    bool
        Whether every value is allowed.
    """
    for spec in change.specs:
        v = values.get(spec.name)
        if (v is None or not np.isfinite(v) or v < spec.lower - 1e-12 * abs(spec.lower)
                or v > spec.upper * (1 + 1e-12) + 1e-300):
            return False
    return True


__all__ += ["shortlist", "rank", "physical", "preference", "choose", "free_tips", "free_tip_hits", "MEASURED",
            "ELEMENT"]
