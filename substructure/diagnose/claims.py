"""What a diagnosis may claim of a set of fitted changes.

A changed model must stay passive (:func:`passive`); a fitted value on the
bound of its search is not a measurement (:func:`bound_hits`); and changes
explain the data when they reach the noise with at most
``DiagnoseSettings.most_changes`` of them (:func:`counted`: where the test
was taken and where its hammer hit, at one point, are one fact) and none on
a bound (:func:`explains`).
"""

from __future__ import annotations

import numpy as np

from ..updating.likelihood import Likelihood
from ..updating.selection import consistency, error_check
from . import words
from .settings import DiagnoseSettings

__all__ = ["PHYSICAL_ENDS", "passive", "bound_hits", "bound_text", "explains", "counted"]


def passive(lik: Likelihood, changes) -> bool:
    """Every joint, support and body of the changed model is passive (PSD matrices, masses >= 0).

    Parameters
    ----------
    lik : Likelihood
        The model and the data's configurations.
    changes : sequence of (Change, dict)
        The changes with their values.

    Returns
    -------
    bool
        True when every link's matrices are positive semi-definite.
    """
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
    return words.bound_text(change.effect, change.where, name, value, unit, side, bound)


def counted(current) -> int:
    """How many changes an explanation holds, against ``most_changes``: a point's ``point-position`` and its
    ``hit-position`` together count once (where the sensor sat and where the hammer hit beside it: how one test
    was taken, not two things found).

    Parameters
    ----------
    current : sequence of (Change, dict)
        The changes with their values.

    Returns
    -------
    int
    """
    placed = {c.where for c, _ in current if c.effect == "point-position"}
    return len(current) - sum(1 for c, _ in current if c.effect == "hit-position" and c.where in placed)


def explains(lik: Likelihood, outcome, settings: DiagnoseSettings) -> bool:
    """The outcome's changes could be claimed: within the noise (consistent, the error within the explained
    factor), at most ``settings.most_changes`` of them (:func:`counted`), none on the bound of its search.

    Parameters
    ----------
    lik : Likelihood
        All lines.
    outcome : Outcome
        A search's outcome (its ``current`` changes and their joint ``fit``).
    settings : DiagnoseSettings
        ``most_changes`` and ``explained_error_factor``.

    Returns
    -------
    bool
        Whether the changes explain the data.
    """
    current = outcome.current
    if not current or counted(current) > settings.most_changes or bound_hits(current, outcome.fit):
        return False
    ratios = lik.log_ratios(current)
    p = sum(len(c.specs) for c, _ in current)
    return bool(consistency(lik, ratios, p).consistent
                and error_check(lik, ratios, settings.explained_error_factor).passed)
