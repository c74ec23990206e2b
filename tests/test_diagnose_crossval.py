"""The cross-validation of the changes a diagnosis keeps: each must predict lines that were not fitted.

The one-step refits of substructure.diagnose.crossval are checked against full refits on the lines kept
(a second method written here), and the rule against a change that is significant on all lines yet fitted
to a stretch of the data no structure explains (a calibration jump of the analyser over 300 Hz).
"""

from __future__ import annotations

import numpy as np
import pytest

import hidden_data as hd
from substructure import FRF, Frequency
from substructure.diagnose import diagnose
from substructure.diagnose.crossval import CV_BLOCKS, CV_FOLDS, cross_validate, fold_masks, held_back_chi2
from substructure.updating import set_parameters
from substructure.updating.fit import fit
from substructure.updating.likelihood import Likelihood, measured_frfs
from substructure.updating.parameters import model_parameters, parameter_change
from substructure.updating.selection import significance

GRID = Frequency.from_range("20 Hz", "5000 Hz", "4 Hz")
MODEL = hd.nominal_model()


def _change(path):
    (p,) = [p for p in model_parameters(MODEL) if p.path == path]
    return parameter_change(p)


def _likelihood(truth, seed, jump=None) -> Likelihood:
    """A tool tip FRF of ``truth`` with 1.5 % complex noise; ``jump``: (lo Hz, hi Hz, factor) on those lines."""
    h = truth.frf(["tool.tip:y"], ["tool.tip:y"], GRID)
    rng = np.random.default_rng(seed)
    data = h.data * (1 + 0.015 * (rng.standard_normal(h.data.shape) + 1j * rng.standard_normal(h.data.shape))
                     / np.sqrt(2))
    if jump is not None:
        data[(GRID.hz >= jump[0]) & (GRID.hz <= jump[1])] *= jump[2]
    measured, _ = measured_frfs([FRF(GRID, data, h.outputs, h.inputs)])
    return Likelihood(MODEL, measured)


def test_every_line_is_held_back_once_in_contiguous_blocks_spread_across_the_band():
    lik = _likelihood(MODEL, seed=1)
    masks = fold_masks(lik)
    assert len(masks) == CV_FOLDS
    assert np.array_equal(np.sum(masks, axis=0), np.ones(lik.n, dtype=int))
    n_lines = lik.lines.size
    for m in masks:
        per_line = m[:n_lines]
        assert np.array_equal(m, np.tile(per_line, 2))  # a line's real and imaginary parts together
        starts = np.flatnonzero(np.diff(per_line.astype(int)) == 1) + 1
        assert len(starts) + per_line[0] == CV_BLOCKS // CV_FOLDS  # its blocks, each one stretch
        held = np.flatnonzero(per_line)
        assert held[0] < n_lines // 4 and held[-1] >= 3 * n_lines // 4 - 1  # from the low end to the high end


def test_one_step_refits_predict_as_full_refits_on_the_lines_kept():
    """A joint fitted alone to data with the tool's E 0.5 % off as well: the fit moves with the lines kept (the
    prediction without a refit is up to 40 % off), and the one-step refit follows the full refit."""
    truth = set_parameters(MODEL, {"joints.holder-tool.k.yf": 0.9 * 1.43e7, "components.tool.E": 0.995})
    lik = _likelihood(truth, seed=3)
    full = fit(lik, [(_change("joints.holder-tool.k.yf"), {"value": 0.9 * 1.43e7})])
    masks = fold_masks(lik)
    approx = held_back_chi2(lik, full.changes, masks)
    n_lines = lik.lines.size
    exact, no_refit = [], []
    for m in masks:
        kept = Likelihood(MODEL, lik.measured, lines=np.flatnonzero(~m[:n_lines]))
        held = Likelihood(MODEL, lik.measured, lines=np.flatnonzero(m[:n_lines]))
        exact.append(held.chi2(fit(kept, full.changes).changes))
        no_refit.append(held.chi2(full.changes))
    exact, no_refit = np.array(exact), np.array(no_refit)
    assert approx == pytest.approx(exact, rel=0.01)
    assert np.max(np.abs(no_refit - exact) / exact) > 0.2  # the refit matters here
    # the model as given: nothing to refit, the chi^2 of the lines held back
    r0 = lik.residual([])
    assert held_back_chi2(lik, [], masks) == pytest.approx([r0[m] @ r0[m] for m in masks])


def test_a_change_fitted_to_a_calibration_jump_is_significant_but_is_dropped():
    """5 % more on 1000-1300 Hz (an analyser's range change): the spindle-holder rotation stiffness fitted on all
    lines passes the significance test, but fitted without a stretch it does not predict it."""
    lik = _likelihood(MODEL, seed=4, jump=(1000.0, 1300.0, 1.05))
    change = _change("joints.spindle-holder.k.tm")
    result = fit(lik, [(change, {})])
    chi2_0 = lik.chi2([])
    assert significance(chi2_0, result.chi2, 1, lik.n, 1, 80).significant
    current, final, records = cross_validate(lik, list(result.changes), result, {}, None)
    assert current == [] and final is None
    (record,) = records
    assert not record["predicts"] and record["chi2_with"] > record["chi2_without"]
    assert record["refitted"]  # dropped on full refits, not on one step
    assert record["chi2_without"] == pytest.approx(chi2_0)  # the model as given predicts every fold as it is


def test_a_true_change_predicts_the_lines_held_back():
    truth = set_parameters(MODEL, {"joints.holder-tool.k.yf": 0.9 * 1.43e7})
    lik = _likelihood(truth, seed=5)
    result = fit(lik, [(_change("joints.holder-tool.k.yf"), {})])
    current, final, records = cross_validate(lik, list(result.changes), result, {}, None)
    assert [c.key for c, _ in current] == [c.key for c, _ in result.changes] and final is result
    (record,) = records
    assert record["predicts"] and record["chi2_with"] < 0.1 * record["chi2_without"]


def test_the_diagnosis_says_a_dropped_change_did_not_predict_held_back_lines():
    """12 % more on 1000-1300 Hz: the joint cross term the search adds (significant on all lines) is dropped, the
    verdict says why, and the JSON keeps the held-back chi^2 with and without it."""
    h = _likelihood(MODEL, seed=4, jump=(1000.0, 1300.0, 1.12)).measured[0].frf
    d = diagnose(MODEL, [h], effects=["joint-stiffness", "joint-cross-coupling", "joint-damping"], open_world=False)
    assert not d.explained and d.final_effects == ()
    assert d.refinement[-1].step == 0
    (record,) = d.search["held_back"]
    assert (record["effect"], record["predicts"]) == ("joint-cross-coupling", False)
    assert any(line.startswith("dropped joint-cross-coupling at spindle-holder: did not predict held-back lines")
               for line in d.report), d.report
    assert d.to_json()["search"]["held_back"][0]["chi2_with"] == pytest.approx(record["chi2_with"])
