"""The refinement of a diagnosis: forward selection, backward elimination, review, the history.

:func:`refine` runs the steps of :mod:`substructure.diagnose.search` until
no candidate passes the significance test (or ``max_steps``), refitting
every change added at every step; a model consistent with the noise before
any change is left alone, and one that a step made consistent with the
noise gets no further step (what is left is at the noise's level: a change
found in it would be fitted to the noise, stacked on the explanation).  Then

* backward elimination drops a change whose removal (the others refitted)
  is not significant: an early change that a later one made redundant;
* the review tries, for each change kept, the other candidates fitted at
  the step it was added and the changes dropped, in place of it with the
  others refitted: one
  inside the indifference region is an alternative explanation (reported
  as ambiguous), and replaces it when it is preferred (a named effect of
  the catalogue before a linked parameter, before a single parameter,
  before an element; :func:`~substructure.diagnose.search.preference`),
  and for an element the catalogue's effects on the same component too,
  from their starts (flutes for a section change over a tool's tip);
* the parsimony check compares an explanation of two or more changes by
  BIC with every single candidate of the first step and the best pairs
  fitted from the values of the best singles that change the model in
  different ways, not only extensions of the greedy path; the lowest BIC
  is kept, those within the indifference region are its rivals; when the
  forward path did not reach the noise with two changes, pairs found by
  second steps from other singles join them
  (:mod:`substructure.diagnose.pairs`), and where it did, those from the
  best other single and, for a first change that is an element at a
  fitted place, from the catalogue's effects on its component
  (:func:`_named_firsts`); a single such element that reached the noise
  is checked against the pairs from those alone;
* the cross-validation drops a kept change whose explanation does not
  predict held-back lines better than the one without it
  (:mod:`substructure.diagnose.crossval`);
* the history is rebuilt from the changes kept, in the order that lowers
  ``chi^2`` most at each step, so that the "error fall" shows the final
  explanation.

A :class:`~substructure.diagnose.search.Budget` of model evaluations bounds
the forward search: once spent, no step is added and a step fits only its
best candidate on all lines.  The checks after it always run (the parsimony
check costs a few dozen evaluations: at most six short fits on the
screening lines and two on all lines); a forward path that the budget cut
short is exactly when a pair from fair starts is most likely to explain
better.  The sizes of the pools and the budgets of the short fits are fields
of :class:`~substructure.diagnose.settings.DiagnoseSettings`.
"""

from __future__ import annotations

import itertools
from types import SimpleNamespace
from typing import Callable

import attrs
import numpy as np

from ..errors import SubstructureError
from ..updating.fit import Fit, fit, to_u
from ..updating.selection import INDIFFERENCE, bic, consistency, significance
from .crossval import cross_validate
from .effects import EffectChange
from .modes import mode_starts, rigid_starts
from .pairs import other_paths
from .scan import places, trials
from .search import (ELEMENT, Budget, Scored, _p, choose, full_fits, physical, preference, rank, screen,
                     shortlist)
from .settings import DEFAULT_SETTINGS, DiagnoseSettings

__all__ = ["Outcome", "refine"]


@attrs.define
class Outcome:
    """What :func:`refine` gives the diagnosis.

    Attributes
    ----------
    current : list of (Change, dict)
        The changes kept, with their final values.
    fit : Fit or None
        The final joint fit of those changes.
    history : list of tuple
        Per step ``(fit of the changes so far, the change added, statistic, threshold)``.
    first_scored, first_fitted : list of Scored
        The first step's screened and fully fitted candidates.
    alternatives : dict
        Per kept change's key, the alternatives inside the indifference
        region: ``[(change, values, chi2), ...]``.
    rivals : list
        Whole explanations (a single or a pair of changes fitted from fair
        starts, or the forward path's) inside the indifference region of the
        one kept: ``[(changes, chi2, bic), ...]``.
    search : dict
        ``candidates``, ``steps_screened``, ``full_fits``, ``cut`` (the time
        budget stopped part of the search) and ``cut_at`` (where).
    """

    current: list
    fit: Fit | None
    history: list
    first_scored: list
    first_fitted: list
    alternatives: dict
    rivals: list = attrs.field(factory=list)
    search: dict = attrs.field(factory=dict)


def _prune(lik, current, chi2_now, say, refits: dict | None = None):
    n = lik.n
    dropped: list = []
    while len(current) > 1:
        p = _p(current)
        worst = None
        for i in range(len(current)):
            refit = fit(lik, current[:i] + current[i + 1:])
            if refits is not None:  # kept for the cross-validation: the explanation without change i
                refits[frozenset(c.key for c, _ in refit.changes)] = refit
            sig = significance(refit.chi2, chi2_now, len(current[i][0].specs), n, p, 1)
            if not sig.significant and (worst is None or sig.statistic < worst[0]):
                worst = (sig.statistic, i, refit)
        if worst is None:
            break
        _, i, refit = worst
        if say:
            say(f"dropped {current[i][0].effect} at {current[i][0].where}: no longer significant")
        dropped.append(Scored(current[i][0], dict(current[i][1]), chi2_now, start=None))
        current, chi2_now = [(c, dict(v)) for c, v in refit.changes], refit.chi2
    return current, chi2_now, dropped


def trim_partial(lik, current: list, final: Fit | None, floor: float, gain: float) -> tuple[list, Fit | None, list]:
    """An unexplained model's changes, less those worth under ``gain`` noise floors of error (``partial_gain``).

    The least worth first, each judged refitted without it, until every change left is worth more (or one is left).
    Returns the changes kept, their joint fit and ``[(change, values, error it was worth), ...]`` left out.
    """
    left: list = []
    error = lik.rms(lik.log_ratios(current))
    while len(current) > 1:
        refits = [fit(lik, current[:i] + current[i + 1:]) for i in range(len(current))]
        worth = [lik.rms(lik.log_ratios(r.changes)) - error for r in refits]
        i = int(np.argmin(worth))
        if worth[i] >= gain * floor:
            break
        left.append((current[i][0], dict(current[i][1]), worth[i]))
        current, final = [(c, dict(v)) for c, v in refits[i].changes], refits[i]
        error += worth[i]
    return current, final, left


def _review(lik, current, chi2_now, steps_fitted, steps_inside, dropped, passive, say,
            settings: DiagnoseSettings = DEFAULT_SETTINGS, cands=()):
    """Alternatives of each kept change; preferred ones replace it (see the module docstring)."""
    n = lik.n
    alternatives: dict = {}
    for i in range(len(current)):
        change = current[i][0]
        keys = {c.key for c, _ in current}
        # the candidates fitted when it was added that the report would prefer (refitting costs)
        pool = [s for s in steps_fitted.get(change.key, []) + dropped if s.change.key not in keys
                and preference(s.change) < preference(change)]
        pool.sort(key=lambda s: (preference(s.change), s.chi2))
        pool = pool[:settings.review_pool]
        if preference(change) >= ELEMENT:
            # an element at a fitted place may be a named effect of the same component under another name (a
            # section change over a tool's last 30 mm at 0.8 is flutes there): those effects, from their starts
            pool = [Scored(c, {spec.name: spec.start for spec in c.specs}, np.inf) for c in cands
                    if isinstance(c, EffectChange) and c.where == change.where and c.key not in keys] + pool
        found = []
        for s in pool:
            trial = current[:i] + [(s.change, s.values)] + current[i + 1:]
            if s.fit is None and s.start is not None:  # screened only: with the values it screened at
                trial = [(c, dict(v)) for c, v in s.start[:i]] + [(s.change, s.values)] + current[i + 1:]
            try:
                result = fit(lik, trial)
            except (ValueError, ArithmeticError):
                continue
            if not (physical(s.change, result.changes[i][1]) and passive(result.changes)):
                continue
            s2 = max(1.0, min(result.chi2, chi2_now) / max(n - _p(current), 1))
            if abs(result.chi2 - chi2_now) / s2 <= INDIFFERENCE:
                found.append((result, s))
        best = min(found, key=lambda t: t[0].chi2, default=None)  # every one of the pool is preferred
        if best is not None:
            result, s = best
            if say:
                say(f"review: {s.change.effect} at {s.change.where} explains as well as {change.effect} at "
                    f"{change.where} and is preferred")
            old = (change, current[i][1], chi2_now)
            current, chi2_now = [(c, dict(v)) for c, v in result.changes], result.chi2
            found = [(r, t) for r, t in found if t is not s]
            alternatives[current[i][0].key] = [old] + [(t.change, r.changes[i][1], r.chi2) for r, t in found]
        else:
            alternatives[change.key] = [(t.change, r.changes[i][1], r.chi2) for r, t in found]
        # and those that were inside the indifference region when it was added
        alts = alternatives[current[i][0].key]
        for s in steps_inside.get(current[i][0].key, []):
            if s.change.key not in {c.key for c, _ in current} and s.change.key not in {a[0].key for a in alts}:
                alts.append((s.change, s.fit.changes[-1][1], s.fit.chi2))
    return current, chi2_now, alternatives


def _history(lik, current, final: Fit, tried: int):
    """The steps rebuilt from the kept changes: at each step the one that lowers chi^2 most."""
    n = lik.n
    order, rest, history = [], list(current), []
    chi2_prev = lik.chi2([])
    while rest:
        if len(rest) == 1:
            result, pick = final, rest[0]
        else:
            chosen = {id(x) for x in order}
            result, pick = min([(fit(lik, [x for x in current if id(x) in chosen or x is c]), c) for c in rest],
                               key=lambda t: t[0].chi2)
        order.append(pick)
        rest = [c for c in rest if c is not pick]
        sig = significance(chi2_prev, result.chi2, len(pick[0].specs), n, _p(order), tried)
        history.append((result, pick[0], sig.statistic, sig.threshold))
        chi2_prev = result.chi2
    return history


def _distinct(screen_lik, singles, count: int, settings: DiagnoseSettings = DEFAULT_SETTINGS) -> list:
    """The best ``count`` singles that change the model in different ways.

    Two singles whose changes of the residual (on the screening lines) have
    a cosine above ``settings.same_direction`` are one explanation under
    two names (a joint's stiffness and its ``k.yf`` entry; an overhang and
    its free segment's length): only one enters the pool, under the name
    :func:`~substructure.diagnose.search.preference` puts first, also when
    that name ranks after the pool is full (a flutes' ratio behind the
    fluted segment's ``od``, equal to the last digit).
    """
    try:
        r0 = screen_lik.residual([])
    except (ValueError, ArithmeticError, SubstructureError):
        return list(singles[:count])
    pool, directions = [], []
    for s in singles:
        if len(pool) == count and all(preference(s.change) >= preference(p.change) for p in pool):
            continue  # full, and this one cannot stand for one of the pool under a preferred name
        try:
            d = screen_lik.residual(s.fit.changes) - r0
        except (ValueError, ArithmeticError, SubstructureError):
            continue
        norm = float(np.linalg.norm(d))
        if not np.isfinite(norm) or norm == 0.0:
            continue
        d = d / norm
        same = [k for k, e in enumerate(directions) if abs(float(d @ e)) > settings.same_direction]
        if same:  # one explanation under two names: the preferred name stands for it (an overhang, not a length)
            k = same[0]
            if preference(s.change) < preference(pool[k].change):
                pool[k] = s
            continue
        if len(pool) < count:
            pool.append(s)
            directions.append(d)
    return pool


def _parsimony(lik, screen_lik, current, chi2_now, first_fitted, passive, say,
               settings: DiagnoseSettings = DEFAULT_SETTINGS, more=()):
    """The kept explanation against the best single and best pair ones fitted from fair starts.

    Forward selection extends its first choice; when that choice was wrong,
    later steps compensate and the path ends at several changes that a
    single or a pair of other changes explains as well.  Here every single
    of the first step (fitted from its own scan on all lines) and every pair
    of the ``settings.pair_pool`` best of them that change the model in
    different ways and of the changes the path kept (:func:`_distinct`;
    fitted from the two changes' values, first on the screening lines, the
    best ``settings.pairs_fitted`` on all lines) is
    compared with the kept explanation by BIC (``chi^2 / s^2 + p ln n``,
    ``s^2`` the misfit scale of the best of them).  Of those within
    :data:`~substructure.updating.selection.INDIFFERENCE` of the lowest BIC
    (the data do not decide between them) the one with the fewest changes
    is kept, then the one whose names :func:`preference` puts first, then
    the fewest parameters and the lowest BIC; the others are its rivals.

    Returns
    -------
    (list, float, list)
        The explanation kept, its ``chi^2``, and the rivals ``[(changes, chi2, bic), ...]``.
    """
    n = lik.n
    options = [([(c, dict(v)) for c, v in current], chi2_now)]
    keys_now = sorted(c.key for c, _ in current)
    singles = [s for s in first_fitted if s.fit is not None]
    options += [([(c, dict(v)) for c, v in s.fit.changes], s.fit.chi2) for s in singles if [s.change.key] != keys_now]
    if len(current) >= 2:
        # the pool: the best singles of the first step, and the changes the path kept (a change the
        # first step ranked too low to fit, found later once another had taken its share, pairs too)
        kept_path = [SimpleNamespace(change=c, values=dict(v), fit=SimpleNamespace(changes=[(c, dict(v))]))
                     for c, v in current]
        pool = _distinct(screen_lik, singles, settings.pair_pool, settings)
        keys = {s.change.key for s in pool}
        pool += [k for k in _distinct(screen_lik, kept_path, len(kept_path), settings) if k.change.key not in keys]
        trials = []
        for a, b in itertools.combinations(pool, 2):
            if sorted([a.change.key, b.change.key]) == keys_now:
                continue
            pair = [(a.change, dict(a.values)), (b.change, dict(b.values))]
            try:
                trials.append((fit(screen_lik, pair, max_nfev=settings.pair_screen_evaluations).chi2, pair))
            except (ValueError, ArithmeticError, SubstructureError):
                continue
        trials.sort(key=lambda t: t[0])
        for _, pair in trials[:settings.pairs_fitted]:
            try:
                result = fit(lik, pair)
            except (ValueError, ArithmeticError, SubstructureError):
                continue
            if all(physical(c, v) for c, v in result.changes) and passive(result.changes):
                options.append(([(c, dict(v)) for c, v in result.changes], result.chi2))
    options += [(pair, chi2) for pair, chi2 in more if sorted(c.key for c, _ in pair) != keys_now]
    best_chi2 = min(chi2 for _, chi2 in options)
    p_best = next(_p(ch) for ch, chi2 in options if chi2 == best_chi2)
    s2 = max(1.0, best_chi2 / max(n - p_best, 1))
    scored = sorted(((ch, chi2, bic(chi2, _p(ch), n, s2)) for ch, chi2 in options), key=lambda t: (t[2], _p(t[0])))
    inside = [t for t in scored if t[2] - scored[0][2] <= INDIFFERENCE]
    # the data do not decide between these: the one with the fewest changes is kept, then the preferred names
    # (flutes over the same equivalent diameter written as a segment's od), then the fewest parameters and
    # the lowest BIC
    kept, kept_chi2, kept_bic = min(inside, key=lambda t: (len(t[0]), sum(preference(c) for c, _ in t[0]),
                                                           _p(t[0]), t[2]))
    if say and sorted(c.key for c, _ in kept) != keys_now:
        say(f"parsimony: {', '.join(f'{c.effect} at {c.place(v)}' for c, v in kept)} explains as well with "
            f"{_p(kept)} parameter(s) instead of {_p(current)} (BIC {kept_bic:.1f})")
    rivals = [t for t in inside if t[0] is not kept]
    return kept, kept_chi2, rivals


def _named_firsts(lik, first, first_scored, firsts, passive, settings: DiagnoseSettings = DEFAULT_SETTINGS,
                  cands=()) -> list:
    """Where the path's first change is an element at a fitted place (a section change, the generic stand-in),
    the catalogue's effects on the same component (those that improved the model in the first step best first
    from their screened values, then the others of ``cands`` from their starts; at most
    ``settings.confirm_named``, those not among ``firsts``), each fitted on all lines: the other firsts of the
    confirming step besides.

    A tapered tool with a 3 g sensor came back as a section change over most of the tool and a 0.9 mm bore:
    the taper alone screened too far behind the section change to be fitted in the first step, so no pair
    started from it; with it, the taper and the sensor describe the data better with fewer parameters.  Under
    three times the real noise the taper alone screened no better than the model at all (the sensor hides it),
    so an effect that did not improve the model alone starts the step too.
    """
    if preference(first) < ELEMENT or not settings.confirm_named:
        return []
    taken = {s.change.key for s in firsts} | {first.key}

    def same(change) -> bool:
        return isinstance(change, EffectChange) and change.where == first.where and change.key not in taken

    named = [s for s in first_scored if same(s.change)]
    screened = {s.change.key for s in named}
    named += [Scored(c, {spec.name: spec.start for spec in c.specs}, np.inf) for c in cands
              if same(c) and c.key not in screened]
    named = named[:settings.confirm_named]
    return [s for s in full_fits(lik, [], named) if physical(s.change, s.values) and passive(s.fit.changes)]


PLACING = ("position", "start", "inset", "inset_tip")
"""Parameters that place a change along a component: where a second minimum lives (a body either side of a
symmetric point, springs further in at another stiffness)."""


def _other_values(lik, screen_lik, current, final: Fit, passive, say,
                  settings: DiagnoseSettings = DEFAULT_SETTINGS) -> list:
    """The same changes at other values that explain the data as well: a second minimum.

    A fit finds the minimum its start leads to; springs that hold a body
    whose modes sit below the band, say, fit as well at another stiffness
    with other positions.  For each change kept, its screening trials
    (with the other changes at their final values) are evaluated on the
    subsample; the ``settings.other_starts`` best that lie away from the
    kept values start fits of every change on all lines (changes with a
    place among their parameters, :data:`PLACING`, only).  A result inside
    the indifference region whose values of that change lie apart (some
    parameter by more than ``settings.other_apart_std`` standard deviations
    and ``settings.other_apart`` of its range on its fitted scale) is the
    same explanation at other values: a rival.

    Returns
    -------
    list of (changes, chi2, bic)
        The rivals found (as the parsimony check gives them).
    """
    n = lik.n
    chi2_now = final.chi2
    s2 = max(1.0, chi2_now / max(n - _p(current), 1))
    out = []
    for i, (change, values) in enumerate(current):
        if not any(spec.name in PLACING for spec in change.specs[1:]):
            continue  # without a place, its scan and refinement have seen its range; a place can mirror
        kept_u = {spec.name: to_u(spec, values[spec.name]) for spec in change.specs}
        span = {spec.name: max(to_u(spec, spec.upper) - to_u(spec, spec.lower), 1e-300) for spec in change.specs}
        std = final.std[i] if i < len(final.std) else {}

        def apart(vals) -> bool:
            for spec in change.specs:
                u = to_u(spec, vals[spec.name])
                sd = std.get(spec.name)
                sd_u = abs(to_u(spec, values[spec.name] + sd) - kept_u[spec.name]) if sd and np.isfinite(sd) and \
                    spec.lower <= values[spec.name] + sd <= spec.upper else 0.0
                if abs(u - kept_u[spec.name]) > max(settings.other_apart_std * sd_u,
                                                    settings.other_apart * span[spec.name]):
                    return True
            return False

        scored = []
        for trial in trials(change, settings=settings):
            vals = {**values, **{k: v for k, v in trial.items() if k in values}}
            if not apart(vals):
                continue
            try:
                chi2 = screen_lik.chi2(current[:i] + [(change, vals)] + current[i + 1:])
            except (ValueError, ArithmeticError, SubstructureError):
                continue
            if np.isfinite(chi2):
                scored.append((chi2, vals))
        scored.sort(key=lambda t: t[0])
        for _, vals in scored[:settings.other_starts]:
            try:
                result = fit(lik, current[:i] + [(change, vals)] + current[i + 1:])
            except (ValueError, ArithmeticError, SubstructureError):
                continue
            got = result.changes[i][1]
            if (result.chi2 - chi2_now > INDIFFERENCE * s2 or not apart(got)
                    or not (all(physical(c, v) for c, v in result.changes) and passive(result.changes))):
                continue
            if say:
                say(f"{change.effect} at {change.where} fits as well at other values: "
                    + ", ".join(f"{k} = {v:.4g}" for k, v in got.items()))
            out.append(([(c, dict(v)) for c, v in result.changes], result.chi2,
                        bic(result.chi2, _p(current), n, s2)))
            break
    return out


def refine(lik, screen_lik, cands, max_steps: int, passive: Callable, say=None,
           budget: Budget | None = None, lacking: bool = False,
           settings: DiagnoseSettings = DEFAULT_SETTINGS) -> Outcome:
    """Forward selection, then elimination, review and history (see the module docstring).

    Parameters
    ----------
    lik : Likelihood
        All lines.
    screen_lik : Likelihood
        The screening subsample.
    cands : list of Change
        The candidates.
    max_steps : int
        Most forward steps.
    passive : callable
        ``passive(changes) -> bool``: the changed model is passive.
    say : callable, optional
        Progress.
    budget : Budget, optional
        Once it is spent the search adds no step and fits no more candidates
        in a step than the first (recorded in ``Outcome.search``).
    lacking : bool
        The data hold a resonance the model lacks (a suspension mode): the
        first step crosses the sizes and positions of springs.
    settings : DiagnoseSettings
        The grids, pools and budgets of the search.

    Returns
    -------
    Outcome
        The changes kept and what the report needs.
    """
    n = lik.n
    search = {"candidates": len(cands), "steps_screened": 0, "full_fits": 0, "cut": False, "cut_at": None,
              "held_back": []}
    lik0 = lik.same(measured=lik.measured[:1])
    if budget is not None:
        budget.watch(lik, screen_lik, lik0)

    def spent() -> bool:
        return budget is not None and budget.spent()

    def cut(where: str) -> None:
        if not search["cut"]:
            search["cut"], search["cut_at"] = True, where
            if say:
                say(f"budget spent: {where}")

    current: list = []
    chi2_now = lik.chi2([])
    first_scored, first_fitted = [], []
    steps_fitted: dict = {}
    steps_inside: dict = {}
    path: list = []
    tried = len(cands)
    while len(current) < max_steps:
        if spent():
            cut(f"no step {len(current) + 1} screened")
            break
        if current and consistency(lik, lik.log_ratios(current), _p(current)).consistent:
            if say:
                say(f"step {len(current) + 1}: the model is consistent with the noise: no further step")
            break
        search["steps_screened"] += 1
        keys = {c.key for c, _ in current}
        remaining = [c for c in cands if c.key not in keys]
        if say:
            say(f"step {len(current) + 1}: screening {len(remaining)} candidates on "
                f"{screen_lik.lines.size} of {lik.lines.size} lines")
        # the current changes refitted on the subsample too: candidates are compared with that
        chi2_s = fit(screen_lik, current).chi2 if current else screen_lik.chi2([])
        extra = mode_starts(lik0, current, remaining, lambda change: places(change, settings), settings)
        narrow = rigid_starts(lik, current, remaining, settings)
        scored = screen(screen_lik, current, remaining, chi2_s, n, say, extra, cross=lacking and not current,
                        settings=settings, narrow=narrow)
        chosen = []
        for s in shortlist(scored, chi2_s, screen_lik.n, n, _p(current), settings):
            # the screened values checked on all lines (noise fitted on the subsample does not carry over)
            start = list(s.start if s.start is not None else current)
            chi2_all = lik.chi2(start + [(s.change, s.values)])
            if significance(chi2_now, chi2_all, s.k, n, _p(current) + s.k).significant:
                chosen.append(s)
            elif lacking and not spent():
                # data with a resonance the model lacks can hold a minimum narrower than the subsample's
                # spacing (a mode just below the first line moves the lowest lines only): a short fit on all
                # lines from the screened values decides
                try:
                    short = fit(lik, start + [(s.change, s.values)],
                                max_nfev=settings.short_fit_evaluations * (_p(current) + s.k + 1))
                except (ValueError, ArithmeticError, SubstructureError):
                    continue
                if significance(chi2_now, short.chi2, s.k, n, _p(current) + s.k).significant:
                    chosen.append(Scored(s.change, dict(short.changes[-1][1]), short.chi2,
                                         start=[(c, dict(v)) for c, v in short.changes[:-1]]))
        done = full_fits(lik, current, chosen, say, budget)
        search["full_fits"] += len(done)
        if len(done) < len(chosen):
            cut(f"step {len(current) + 1}: {len(done)} of {len(chosen)} shortlisted candidates fitted on all lines")
        fitted = [s for s in done if physical(s.change, s.values) and passive(s.fit.changes)]
        ranked = rank(fitted, n, _p(current))
        if not first_scored:
            first_scored, first_fitted = scored, ranked
        if not ranked:
            break
        best, inside, _ = choose(ranked, n, _p(current))
        sig = significance(chi2_now, best.chi2, best.k, n, _p(current) + best.k, len(remaining))
        if not sig.significant:
            if say:
                say(f"best candidate {best.change.effect} at {best.change.where} is not significant "
                    f"({sig.statistic:.4g} <= {sig.threshold:.4g}): stop")
            break
        # the review's pool: what was fitted, and what screened nearly as well as the choice
        winner = next((x for x in scored if x.change.key == best.change.key), None)
        near = [x for x in scored if winner is not None and x.change.key not in {r.change.key for r in ranked}
                and chi2_s - x.chi2 >= settings.review_near_share * (chi2_s - winner.chi2)]
        steps_fitted[best.change.key] = [s for s in ranked if s is not best] + near
        steps_inside[best.change.key] = inside
        path.append((best.fit, best.change, sig.statistic, sig.threshold))
        current, chi2_now = [(c, dict(v)) for c, v in best.fit.changes], best.chi2
        if say:
            say(f"step {len(current)}: added {best.change.effect} at {best.change.place(best.values)}, "
                f"chi^2/nu = {chi2_now / max(n - _p(current), 1):.4g}")
    refits = {frozenset(c.key for c, _ in f.changes): f for f, _, _, _ in path}  # fits of subsets, all lines
    current, chi2_now, dropped = _prune(lik, current, chi2_now, say, refits)  # nothing to drop from one change
    pruned = sorted(c.key for c, _ in current)
    current, chi2_now, alternatives = _review(lik, current, chi2_now, steps_fitted, steps_inside, dropped,
                                              passive, say, settings, cands)
    rivals: list = []

    def confirming(firsts: list) -> list:  # a cheaper screening: one second change per first, fitted on all lines
        return other_paths(lik, screen_lik.subsample(settings.confirm_screen_step), lik0, firsts, cands, passive,
                           say, settings, seconds=1, with_mode_starts=False)

    # a single element at a fitted place that reached the noise (a section change) may stand in for a named effect
    # of its component with a change it hides (a taper with a sensor): the pairs from those, cheaply screened
    named = _named_firsts(lik, current[0][0], first_scored, [], passive, settings, cands) if len(current) == 1 else []
    if named:
        more = confirming(named)
        before = [c.key for c, _ in current]
        current, chi2_now, rivals = _parsimony(lik, screen_lik, current, chi2_now, [], passive, say, settings, more)
        if [c.key for c, _ in current] != before:  # a pair: each must still earn its place
            current, chi2_now, late = _prune(lik, current, chi2_now, say, refits)
            dropped += late
            alternatives = {c.key: [] for c, _ in current}
    if len(current) >= 2 and not named:
        before = [c.key for c, _ in current]
        more = []
        failed = len(current) > settings.most_changes or not consistency(lik, lik.log_ratios(current),
                                                                          _p(current)).consistent
        # its first choice may be the wrong one: where the path did not reach the noise with two changes, and where
        # it did (a stand-in completed by an invented second change), from fewer other firsts
        # the path's own first change (or the same change under another name) is not started from again
        starts = settings.other_firsts if failed else settings.confirm_firsts
        singles = [s for s in first_fitted if s.fit is not None]
        firsts = [s for s in _distinct(screen_lik, singles, starts + 1, settings)
                  if s.change.key != path[0][1].key][:starts] if starts else []
        if failed:
            more = other_paths(lik, screen_lik, lik0, firsts, cands, passive, say, settings) if firsts else []
        else:  # the named effects of a first change that is an element too (even with confirm_firsts 0)
            firsts += _named_firsts(lik, path[0][1], first_scored, firsts, passive, settings, cands)
            more = confirming(firsts) if firsts else []
        current, chi2_now, rivals = _parsimony(lik, screen_lik, current, chi2_now, first_fitted, passive, say,
                                               settings, more)
        if len(current) > 1 and sorted(c.key for c, _ in current) != pruned:
            # what the review and the parsimony check put in must each still earn its place
            current, chi2_now, late = _prune(lik, current, chi2_now, say, refits)
            dropped += late
        if sorted(c.key for c, _ in current) != sorted(before):  # the same changes in another order keep theirs
            alternatives = {c.key: [] for c, _ in current}
    kept = [c.key for c, _ in current]
    unchanged = kept == [change.key for _, change, _, _ in path]
    final = path[-1][0] if unchanged and path else (fit(lik, current) if current else None)
    if final is not None:
        current = [(c, dict(v)) for c, v in final.changes]
        current, final, search["held_back"] = cross_validate(lik, current, final, refits, say)
        gone = set(kept) - {c.key for c, _ in current}
        if gone:  # a change that did not predict held-back lines: the history and the rivals without it
            unchanged = False
            alternatives = {k: v for k, v in alternatives.items() if k not in gone}
            rivals = [r for r in rivals if not gone & {c.key for c, _ in r[0]}]
    history = path if unchanged else (_history(lik, current, final, tried) if current else [])
    if final is not None:
        rivals = list(rivals) + _other_values(lik, screen_lik, current, final, passive, say, settings)
    return Outcome(current, final, history, first_scored, first_fitted, alternatives, rivals, search)
