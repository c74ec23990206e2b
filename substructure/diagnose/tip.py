"""A tool tip tested below its edge: where a search of the model's changes explained nothing.

A sensor cannot sit on a tool's very edge, nor a hammer strike it: a test
labelled ``tool.tip`` was taken a few millimetres below it.  That moves no
mode, only the FRF's levels and antiresonances; tried among the search's
candidates it took places on the shortlist from the changes a search needs.
So where the search explained nothing and a measured point is a free tip
(:func:`~substructure.diagnose.search.free_tips`), :func:`tip_fallback` fits
the tip's position alone: where that alone explains the data, it is the
answer (with the hammer's place apart from it, ``hit-position``, where a
cross FRF lets it be fitted and it is significant: one place for both is
then their compromise; likewise after the tip with a sensor).  Else the
tip's position is fitted together with what the test put at that point
(the search's test-only candidates there: a sensor the model lacks, for
the sensor sat where the test was, not on the edge): where the two
explain the data, they are the answer.  Else, where the tip alone removes at
least ``settings.tip_share`` of the misfit, the report says so without
claiming it.

The same pair is a rival of an explanation the search did find
(:func:`tip_rival`): a sensor on the tip beside a change of the structure
there (a tool that much shorter carrying the stub beyond the sensor) is
nearly the test taken below the tip with that sensor; where the pair
explains the data too, the diagnosis claims neither.  Without a sensor
there, the tip's position alone is the rival of changes of the structure.
"""

from __future__ import annotations

import attrs

from ..updating.fit import fit
from ..updating.likelihood import Likelihood
from ..updating.selection import significance
from . import words
from .claims import bound_hits, explains, passive
from .refine import Outcome, refine
from .search import free_tips
from .settings import DiagnoseSettings

__all__ = ["tip_fallback", "tip_rival"]


def tip_fallback(lik: Likelihood, screen_lik: Likelihood, assembly, points: list, cands: list, outcome: Outcome,
                 say, settings: DiagnoseSettings, floor: float) -> tuple[Outcome, str | None]:
    """``(outcome, note)`` after a search that explained nothing (see the module docstring).

    Parameters
    ----------
    lik, screen_lik : Likelihood
        All lines and the screening subsample.
    assembly : Assembly
        The model.
    points : list of str
        The measured points (``component.point:dof``).
    cands : list of Change
        The search's candidates (the test-only ones at the tip are fitted with it).
    outcome : Outcome
        What the search gave.
    say : callable or None
        Progress.
    settings : DiagnoseSettings
        ``point_reach``, ``tip_share`` and what a claim needs.
    floor : float
        The noise floor (for the note).

    Returns
    -------
    (Outcome, str or None)
        The tip's outcome where it explains the data (its ``search`` holds ``tip_alone``: the tip's point), else
        ``outcome``; and the note of the report when it alone nearly explains them.
    """
    tips = free_tips(assembly, points, settings.point_reach)
    if not tips:
        return outcome, None
    alone = refine(lik, screen_lik, tips, 1, lambda changes: passive(lik, changes), None, None, settings=settings)
    if not alone.current:
        return outcome, None
    change, values = alone.current[0]
    firsts = {"first_scored": alone.first_scored + outcome.first_scored,
              "first_fitted": alone.first_fitted + outcome.first_fitted}
    found = alone if explains(lik, alone, settings) else _with_test_only(lik, screen_lik, change, cands, settings)
    if found is not None:
        found = _apart(lik, change, found, cands, settings)
        if say:
            kept = " and ".join(f"{change.where} taken at {c.place(v)}" if c is change else
                                f"{c.effect} at {c.where}" + (f" ({c.place(v)})" if c.effect == "hit-position" else "")
                                for c, v in found.current)
            say(f"the search explained nothing; {kept} explains the data")
        return attrs.evolve(found, **firsts, search={**outcome.search, "held_back": found.search.get("held_back", []),
                                                     "tip_alone": change.where}), None
    chi2_0 = lik.chi2([])
    excess = chi2_0 - lik.n  # the misfit above what the noise makes
    share = (chi2_0 - lik.chi2(alone.current)) / excess if excess > 0 else 0.0
    if share < settings.tip_share:
        return outcome, None
    error = lik.rms(lik.log_ratios(alone.current))
    return outcome, words.tip_nearly(change.where, change.place(values), share, error, floor,
                                     bool(bound_hits(alone.current, alone.fit)))


def tip_rival(lik: Likelihood, screen_lik: Likelihood, assembly, points: list, cands: list, outcome: Outcome,
              settings: DiagnoseSettings) -> list | None:
    """Another explanation of an explained outcome: its test-only changes at a free tip, the tip taken below it.

    On a tool tested a few millimetres below its tip with a sensor the model lacks, a tool that much shorter with
    a heavier sensor (the stub beyond the sensor added to it) is nearly the same structure on a driving point:
    the search may explain the data that way.  Where the outcome holds a test-only change at a measured free tip
    beside a change of the structure, and not the tip's position, the tip's position is fitted with the same
    test-only candidates at that point alone (as :func:`tip_fallback` does); where they explain the data too,
    their changes are returned (the diagnosis weighs them as a rival explanation), else None.  Where the outcome
    changes the structure without a test-only change at the tip (a little less overhang and a little more flute
    standing in for the test taken below it), the tip's position alone is the rival where it explains the data.

    Parameters
    ----------
    lik, screen_lik, assembly, points, cands, outcome, settings
        As for :func:`tip_fallback`; ``outcome`` explains the data.

    Returns
    -------
    list of (Change, dict, dict) or None
        The rival's changes with their values and standard deviations.
    """
    kept = [c for c, _ in outcome.current]
    for tip in free_tips(assembly, points, settings.point_reach):
        if any(c.key == tip.key for c in kept) or all(c.test_only for c in kept):
            continue
        if not any(c.test_only and c.where == tip.where for c in kept):
            # no sensor there: changes of the structure that only stand in for the test taken below the tip (a
            # few millimetres' less overhang and a little more flute) are rivalled by the tip's place alone
            alone = refine(lik, screen_lik, [tip], 1, lambda changes: passive(lik, changes), None, None,
                           settings=settings)
            if alone.current and alone.fit is not None and explains(lik, alone, settings):
                alone = _apart(lik, tip, alone, cands, settings)  # the hammer's place too, where significant
                return [(c, dict(v), dict(sd)) for (c, v), sd in zip(alone.current, alone.fit.std)]
            continue
        both = _with_test_only(lik, screen_lik, tip, cands, settings)
        if both is not None:
            both = _apart(lik, tip, both, cands, settings)
        if both is not None and both.fit is not None:
            return [(c, dict(v), dict(sd)) for (c, v), sd in zip(both.current, both.fit.std)]
    return None


def _apart(lik: Likelihood, tip, found: Outcome, cands: list, settings: DiagnoseSettings) -> Outcome:
    """An outcome that explains the data with one of the tip's two places (where the test was, ``tip``, or where
    the hammer hit, ``hit-position``): the other added, fitted from the kept one's place, where it is significant
    (one place for both is then their compromise); else the outcome as it was.  The search stops at the noise, so
    it would not try it."""
    hit = next((c for c in cands if c.effect == "hit-position" and c.where == tip.where), None)
    kept = [c for c, _ in found.current]
    places = [c for c in (tip, hit) if c is not None and c in kept]
    other = next((c for c in (tip, hit) if c is not None and c not in kept), None)
    if len(places) != 1 or other is None or found.fit is None:
        return found
    start = dict(next(v for c, v in found.current if c is places[0]))  # both at one place: the kept fit's optimum
    try:
        both = fit(lik, [*found.current, (other, start)])
    except (ValueError, ArithmeticError):
        return found
    p = sum(len(c.specs) for c in kept) + len(other.specs)
    sig = significance(found.fit.chi2, both.chi2, len(other.specs), lik.n, p)
    if not sig.significant:
        return found
    apart = attrs.evolve(found, current=[(c, dict(v)) for c, v in both.changes], fit=both,
                         history=[*found.history, (both, both.changes[-1][0], sig.statistic, sig.threshold)])
    return apart if passive(lik, apart.current) and explains(lik, apart, settings) else found


def _with_test_only(lik: Likelihood, screen_lik: Likelihood, tip, cands: list,
                    settings: DiagnoseSettings) -> Outcome | None:
    """The tip's position searched with the test-only candidates at its point (a sensor there; the hammer's place
    apart from the sensor's where a cross FRF of that hit was measured), at most one change each; the outcome
    where it keeps the tip and explains the data, else None."""
    at_tip = [c for c in cands if c.test_only and c.where == tip.where and c.effect != tip.effect]
    if not at_tip:
        return None
    both = refine(lik, screen_lik, [tip, *at_tip], 1 + len({c.effect for c in at_tip}),
                  lambda changes: passive(lik, changes), None, None, settings=settings)
    # the tip's test: where it was taken, or where it was hit apart from the sensor (the sensor on the very edge)
    kept = any(c is tip or c.effect == "hit-position" for c, _ in both.current)
    return both if kept and explains(lik, both, settings) else None
