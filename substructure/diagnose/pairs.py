"""Pairs of changes found from other first changes than the forward path's.

The parsimony check (:func:`substructure.diagnose.refine.refine`) pairs the
best singles of the first step.  A pair whose members are each weak alone
is missed that way: a holder-tool joint 0.6 times as stiff with flutes at the
tip, where a section change over the whole tool explains more alone than
either, and the flutes (one effect of the two) are not among the best
singles at all; or a reground tool with a forgotten sensor fitted below 2 kHz,
where the sensor alone explains little.  Forward selection then extends the
wrong first choice, and later steps compensate with changes that do not
exist.

So when the forward path did not reach the noise with at most
two changes (``DiagnoseSettings.most_changes``),
:func:`other_paths` repeats its second step from each of the
``DiagnoseSettings.other_firsts`` best other singles of the first step that change the
model in different ways: every candidate is screened with that single held
(and refitted to first order, as the forward step does), the
``DiagnoseSettings.pair_seconds`` best of the shortlist are fitted on all lines with it (and any later one of
a preferred name that the screening cannot tell from one of them), and
the one :func:`~substructure.diagnose.search.choose` takes (the preferred
name among those the data cannot tell apart) makes a pair.  Where the path
did reach the noise with two changes, its first choice may still have stood
in for another effect, the second change inventing the rest (a tapered tool
with a sensor came back as flutes and a bore): the second step is repeated
from the ``DiagnoseSettings.confirm_firsts`` best other singles (screened on
every ``confirm_screen_step``-th line of the screening subsample, from the
scan's own starts), the best second change of each fitted on all lines.  The pairs join
the parsimony check's explanations, where the fewest changes, then the
preferred names, are kept among those the data do not decide between.
"""

from __future__ import annotations

from typing import Callable

from ..errors import SubstructureError
from ..updating.selection import indifferent
from .modes import mode_starts
from .scan import places
from .search import _p, choose, full_fits, physical, preference, rank, screen, shortlist
from .settings import DEFAULT_SETTINGS, DiagnoseSettings

__all__ = ["other_paths"]


def other_paths(lik, screen_lik, lik0, firsts: list, cands: list, passive: Callable, say=None,
                settings: DiagnoseSettings = DEFAULT_SETTINGS, seconds: int | None = None,
                with_mode_starts: bool = True) -> list:
    """Pairs of changes from other first changes (see the module docstring).

    Parameters
    ----------
    lik : Likelihood
        All lines.
    screen_lik : Likelihood
        The screening subsample.
    lik0 : Likelihood
        The first measured FRF on all lines (for the starts from mode shifts).
    firsts : list of Scored
        Fitted singles of the first step to start from, best first.
    cands : list of Change
        Every candidate.
    passive : callable
        ``passive(changes) -> bool``.
    say : callable, optional
        Progress.
    settings : DiagnoseSettings
        The diagnosis's settings.
    seconds : int, optional
        Shortlisted second changes fitted on all lines with each single
        (default ``settings.pair_seconds``).
    with_mode_starts : bool, default True
        Screen from the starts the mode shifts predict as well as from the
        scan's own.

    Returns
    -------
    list of (list of (Change, dict), float)
        Each pair with its values and ``chi^2`` on all lines.
    """
    n = lik.n
    out = []
    for first in firsts:
        held = [(c, dict(v)) for c, v in first.fit.changes]
        keys = {c.key for c, _ in held}
        remaining = [c for c in cands if c.key not in keys]
        if say:
            say(f"pairs: a second change screened with {first.change.effect} at {first.change.place(first.values)}")
        try:
            chi2_s = screen_lik.chi2(held)
            starts = mode_starts(lik0, held, remaining, lambda change: places(change, settings), settings) \
                if with_mode_starts else {}
            scored = screen(screen_lik, held, remaining, chi2_s, n, None, starts, settings=settings)
        except (ValueError, ArithmeticError, SubstructureError):
            continue
        count = settings.pair_seconds if seconds is None else seconds
        chosen = _with_preferred(shortlist(scored, chi2_s, screen_lik.n, n, _p(held), settings), count,
                                 screen_lik.n, _p(held))
        done = [s for s in full_fits(lik, held, chosen) if physical(s.change, s.values) and passive(s.fit.changes)]
        if not done:
            continue
        best, _, _ = choose(rank(done, n, _p(held)), n, _p(held))
        pair = [(c, dict(v)) for c, v in best.fit.changes]
        if all(physical(c, v) for c, v in pair):
            out.append((pair, best.chi2))
    return out


def _with_preferred(shortlisted: list, count: int, n_lines: int, p_now: int) -> list:
    """The ``count`` best of the shortlist, and every later one of a preferred name that the screening cannot
    tell from one of those (``indifferent`` on the screening lines, parameters counted).

    Only the first ``count`` are fitted on all lines, and :func:`~substructure.diagnose.search.choose` prefers
    names only among what was fitted: a body 0.2 mm from the tool's tip screens a little better than a sensor
    at the tip (its position fits some noise too), yet on all lines the two are alike and the sensor is the
    name to give.
    """
    first = list(shortlisted[:count])
    if not first:
        return first
    s2 = max(1.0, min(s.chi2 for s in shortlisted) / max(n_lines - p_now - max(s.k for s in shortlisted), 1))
    return first + [s for s in shortlisted[count:]
                    if any(preference(s.change) < preference(t.change)
                           and indifferent(s.chi2, p_now + s.k, t.chi2, p_now + t.k, n_lines, s2) for t in first)]
