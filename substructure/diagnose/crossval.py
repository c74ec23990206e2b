"""Cross-validation of the changes kept: each must predict lines that were not fitted.

Significance says a change lowers ``chi^2`` by more than its parameters
buy; it does not say that the change describes the structure rather than
the lines it was fitted to.  Here each kept change is tested on data that
were held back: the lines of the band are cut into :data:`CV_BLOCKS`
contiguous blocks, and block ``b`` goes to fold ``b mod`` :data:`CV_FOLDS`,
so that each fold holds back a few contiguous stretches spread across the
band (the same lines of every measured FRF).  Contiguous blocks, because
neighbouring lines of a tap test are correlated (windows, smoothing, a
resonance spans many lines): a model fitted to every other line would
"predict" the lines between from their neighbours.

For each fold the explanation with the change and the one without it (the
others refitted on all lines) are refitted on the lines kept, starting from
their values fitted on all lines, by one Gauss-Newton step on the Jacobian
of all lines (computed once and restricted to the lines kept), halved until
it lowers ``chi^2`` on those lines (:data:`CV_HALVINGS`); the refitted model
then predicts the held-back lines and is scored by their ``chi^2`` with the
same likelihood and noise model as every other decision.  The sums over the
folds are compared.  A single change is compared with the model as given
(nothing to refit).

The one-step refits are the classical first-order approximation of
cross-validation: where a quarter of the lines moves the optimum by a
fraction of its standard deviation, one Gauss-Newton step follows it to
second order (the test suite checks it against full refits).  Where the
lines kept determine a change weakly (springs whose suspension modes lie in
one block), the refit may move far, which one step does not follow; so a
change the steps find not predicting is checked again with full refits of
both explanations on the lines kept of every fold, and dropped only when
those do not predict the held-back lines better either.
"""

from __future__ import annotations

from typing import Sequence

import numpy as np

from ..errors import SubstructureError
from ..updating.fit import fit, from_u, to_u

__all__ = ["CV_FOLDS", "CV_BLOCKS", "fold_masks", "held_back_chi2", "cross_validate"]

CV_FOLDS = 4
"""Folds of the cross-validation: each holds back about a quarter of the lines."""
CV_BLOCKS = 20
"""Contiguous blocks of lines the band is cut into (5 % of the band each); block ``b`` is held back in fold
``b mod CV_FOLDS``, so that every fold holds back stretches spread across the band."""
CV_RESOLVED = 1.0
"""Smallest singular value of the whitened Jacobian (on the fitted scale: a log, or a tenth of the range) whose
direction a fold's refit moves; below it the data fix the direction to worse than a factor e (or a tenth of the
range), and the refit keeps the value fitted on all lines."""
CV_HALVINGS = 3
"""Halvings of a fold's Gauss-Newton step before the refit keeps the values fitted on all lines."""


def fold_masks(likelihood, folds: int = CV_FOLDS, blocks: int = CV_BLOCKS) -> list[np.ndarray]:
    """Which residuals each fold holds back (see the module docstring).

    Parameters
    ----------
    likelihood : Likelihood
        The data (its residual vector: real parts, then imaginary parts, per measured FRF).
    folds : int
        Number of folds.
    blocks : int
        Contiguous blocks of lines, dealt to the folds in turn.

    Returns
    -------
    list of ndarray of bool
        One mask over the residual vector per fold; every residual is held back in exactly one fold.
    """
    n_lines = likelihood.lines.size
    blocks = max(folds, min(blocks, n_lines))
    block = np.minimum(np.arange(n_lines) * blocks // n_lines, blocks - 1)
    per_residual = np.tile(block % folds, 2 * len(likelihood.measured))
    return [per_residual == k for k in range(folds)]


def _slots(changes) -> list:
    return [(i, spec) for i, (c, _) in enumerate(changes) for spec in c.specs]


def _model(changes, slots, u) -> list:
    out = [(c, dict(v)) for c, v in changes]
    for (i, spec), ui in zip(slots, u):
        out[i][1][spec.name] = from_u(spec, ui)
    return out


def _refitted(likelihood, changes: list, masks: Sequence[np.ndarray]) -> np.ndarray:
    """Held-back ``chi^2`` per fold with full refits on the lines kept (from the values fitted on all lines)."""
    n_lines = likelihood.lines.size
    out = []
    for held in masks:
        per_line = held[:n_lines]
        kept = likelihood.same(lines=likelihood.lines[~per_line])
        back = likelihood.same(lines=likelihood.lines[per_line])
        try:
            values = fit(kept, changes).changes
        except (SubstructureError, ValueError, FloatingPointError):
            values = changes
        out.append(back.chi2(values))
    return np.array(out)


def held_back_chi2(likelihood, changes: Sequence[tuple], masks: Sequence[np.ndarray],
                   refit: bool = False) -> np.ndarray:
    """``chi^2`` of each fold's held-back lines, predicted by the explanation refitted without them.

    Parameters
    ----------
    likelihood : Likelihood
        All lines.
    changes : sequence of (Change, dict)
        The explanation, with its values fitted on all lines (SI).
    masks : sequence of ndarray of bool
        The folds (:func:`fold_masks`).
    refit : bool
        Full refits on the lines kept (:func:`substructure.updating.fit.fit`, from the values fitted on all
        lines) in place of one Gauss-Newton step: what a change is dropped on.

    Returns
    -------
    ndarray
        Per fold, the held-back ``chi^2`` [-] (for the model as given, with no changes, the ``chi^2`` of
        those lines: there is nothing to refit).
    """
    changes = [(c, dict(v)) for c, v in changes]
    slots = _slots(changes)
    if slots and refit:
        return _refitted(likelihood, changes, masks)
    r0 = likelihood.residual(changes)
    if not slots:
        return np.array([float(r0[m] @ r0[m]) for m in masks])
    u0 = np.array([to_u(spec, changes[i][1][spec.name]) for i, spec in slots])
    lo = np.array([to_u(spec, spec.lower) for _, spec in slots])
    hi = np.array([to_u(spec, spec.upper) for _, spec in slots])
    jac = np.empty((r0.size, u0.size))
    for j in range(u0.size):  # forward differences, as the fits take them; backwards at an upper bound
        h = 1e-6 * max(1.0, abs(u0[j]))
        if u0[j] + h > hi[j]:
            h = -h
        u = u0.copy()
        u[j] += h
        jac[:, j] = (likelihood.residual(_model(changes, slots, u)) - r0) / h
    out = []
    for held in masks:
        kept = ~held
        chi2_kept = float(r0[kept] @ r0[kept])
        # directions the lines kept do not determine (a standard deviation above one unit of the fitted
        # scale) stay where all lines put them: they carry no information on the held-back lines either
        left, sv, right = np.linalg.svd(jac[kept], full_matrices=False)
        resolved = sv >= CV_RESOLVED
        step = right[resolved].T @ ((left[:, resolved].T @ -r0[kept]) / sv[resolved])
        best = r0
        for _ in range(CV_HALVINGS + 1):
            u = np.clip(u0 + step, lo, hi)
            try:
                r = likelihood.residual(_model(changes, slots, u))
            except (SubstructureError, ValueError, FloatingPointError):
                r = None
            if r is not None and np.all(np.isfinite(r)) and float(r[kept] @ r[kept]) < chi2_kept:
                best = r
                break
            step = step / 2.0
        out.append(float(best[held] @ best[held]))
    return np.array(out)


def cross_validate(lik, current: list, final, refits: dict, say=None):
    """Drop the kept changes that do not predict held-back lines (:mod:`substructure.diagnose.crossval`).

    Each change's explanation is compared with the one without it (the others refitted on all lines, from the
    elimination's fits when it made them; a single change against the model as given) on the held-back
    ``chi^2`` summed over the folds; of the changes that do not predict better, the one that predicts worst is
    dropped and the rest checked again.

    Parameters
    ----------
    lik : Likelihood
        All lines.
    current : list of (Change, dict)
        The changes kept, with their values fitted on all lines (SI).
    final : Fit
        Their joint fit.
    refits : dict
        Fits on all lines of subsets of the changes, by the frozenset of their keys (filled as needed).
    say : callable, optional
        Progress.

    Returns
    -------
    (list, Fit or None, list of dict)
        The changes kept, their fit, and per change checked ``effect``, ``where``, ``chi2_with``,
        ``chi2_without`` (held-back ``chi^2`` summed over the folds), ``predicts`` and ``refitted`` (the
        sums are those of full refits, made before a change is dropped).
    """
    masks = fold_masks(lik)
    records: list = []
    while current:
        with_it = float(held_back_chi2(lik, current, masks).sum())
        rounds, worst = [], None
        full = None  # the explanation's held-back chi^2 with full refits, once one change needs it
        for i, (change, values) in enumerate(current):
            rest = current[:i] + current[i + 1:]
            key = frozenset(c.key for c, _ in rest)
            if rest and key not in refits:
                refits[key] = fit(lik, rest)
            refit = refits[key] if rest else None
            others = refit.changes if refit is not None else []
            without = float(held_back_chi2(lik, others, masks).sum())
            record = {"effect": change.effect, "where": change.place(values), "chi2_with": with_it,
                      "chi2_without": without, "predicts": bool(with_it < without), "refitted": False}
            if not record["predicts"]:
                # never dropped on one step: a change the lines kept determine weakly (springs whose modes lie
                # in one block) may move far when a block is held back, which a step does not follow
                if full is None:
                    full = float(held_back_chi2(lik, current, masks, refit=True).sum())
                without = float(held_back_chi2(lik, others, masks, refit=True).sum())
                record.update(chi2_with=full, chi2_without=without, predicts=bool(full < without), refitted=True)
            rounds.append(record)
            if not record["predicts"] and (worst is None or record["chi2_with"] - without > worst[0]):
                worst = (record["chi2_with"] - without, i, refit, record)
        if worst is None:
            records += rounds
            break
        _, i, refit, record = worst
        if say:
            say(f"dropped {record['effect']} at {record['where']}: did not predict held-back lines (chi^2 of "
                f"the held-back lines {record['chi2_with']:.1f} with it, {record['chi2_without']:.1f} without)")
        records.append(record)
        current = [(c, dict(v)) for c, v in refit.changes] if refit is not None else []
        final = refit
    return current, final, records
