"""A tool tip tested below its edge: where a search of the model's changes explained nothing.

A sensor cannot sit on a tool's very edge, nor a hammer strike it: a test
labelled ``tool.tip`` was taken a few millimetres below it.  That moves no
mode, only the FRF's levels and antiresonances; tried among the search's
candidates it took places on the shortlist from the changes a search needs.
So where the search explained nothing and a measured point is a free tip
(:func:`~substructure.diagnose.search.free_tips`), :func:`tip_fallback` fits
the tip's position alone: where that alone explains the data, it is the
answer; where it removes at least ``settings.tip_share`` of the misfit, the
report says so without claiming it.
"""

from __future__ import annotations

import attrs

from ..updating.likelihood import Likelihood
from . import words
from .claims import bound_hits, explains, passive
from .refine import Outcome, refine
from .search import free_tips
from .settings import DiagnoseSettings

__all__ = ["tip_fallback"]


def tip_fallback(lik: Likelihood, screen_lik: Likelihood, assembly, points: list, outcome: Outcome, say,
                 settings: DiagnoseSettings, floor: float) -> tuple[Outcome, str | None]:
    """``(outcome, note)`` after a search that explained nothing (see the module docstring).

    Parameters
    ----------
    lik, screen_lik : Likelihood
        All lines and the screening subsample.
    assembly : Assembly
        The model.
    points : list of str
        The measured points (``component.point:dof``).
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
    if explains(lik, alone, settings):
        if say:
            say(f"the search explained nothing; {change.where} taken at {change.place(values)} alone explains "
                "the data")
        return attrs.evolve(alone, **firsts, search={**outcome.search, "held_back": alone.search.get("held_back", []),
                                                     "tip_alone": change.where}), None
    chi2_0 = lik.chi2([])
    excess = chi2_0 - lik.n  # the misfit above what the noise makes
    share = (chi2_0 - lik.chi2(alone.current)) / excess if excess > 0 else 0.0
    if share < settings.tip_share:
        return outcome, None
    error = lik.rms(lik.log_ratios(alone.current))
    return outcome, words.tip_nearly(change.where, change.place(values), share, error, floor,
                                     bool(bound_hits(alone.current, alone.fit)))
