"""An unexplained verdict's partial explanation: the changes that matter, not every correction that wins a little.

Effects beyond every candidate, hidden in the independent FE rig (hidden_data.py) under the noise of a real tap
test (real_noise.py): a hysteretic holder-tool joint (damping that does not grow with frequency) and a drawbar in
the spindle's bore.  Against their misfit every flexible change wins a little, significantly against the noise
alone; the forward search stacked a joint's cross-coupling, a stiffer carbide or a sensor on the holder on the
change that matters.  The rule (``partial_gain``) is checked here from outside: every change kept is worth at
least that share of the noise floor, refitted without it with the library's fit, and every change left out was
worth less.
"""

from __future__ import annotations

import pytest

import hidden_data as hd
from real_noise import free_free_residual, with_real_noise
from substructure.diagnose import diagnose
from substructure.updating import Likelihood, fit, measured_frfs

POINTS = ("tool.tip", "tool.tip-20 mm", "holder.tip")


def _taps(offset: int, level: float, residual=None, **hidden):
    exact = hd.measure(points=POINTS, noise=0.0, phase_deg=0.0, floor=0.0, **hidden)
    return with_real_noise(exact, offset, level, residual)


@pytest.fixture(scope="module")
def hysteretic():
    taps = _taps(11, 1.0, ht_loss=0.05)
    return taps, diagnose(hd.nominal_model(), taps, progress=False)


@pytest.fixture(scope="module")
def drawbar():
    taps = _taps(11, 1.0, drawbar=True)
    return taps, diagnose(hd.nominal_model(), taps, progress=False)


def _worth(taps, d) -> list[float]:
    """The error each kept change is worth: refitted without it, with the library's fit, on all lines."""
    lik = Likelihood(hd.nominal_model(), measured_frfs(taps)[0])
    kept = [(e.change, dict(e.values)) for e in d.effects]
    error = lik.rms(lik.log_ratios(kept))
    assert error == pytest.approx(d.final_error, rel=1e-6)
    return [lik.rms(lik.log_ratios(fit(lik, kept[:i] + kept[i + 1:]).changes)) - error if len(kept) > 1 else
            lik.rms(lik.log_ratios([])) - error for i in range(len(kept))]


def _left_out(d) -> str:
    (line,) = [x for x in d.report if x.startswith("left out of the partial explanation")]
    return line


def test_a_hysteretic_joint_is_partly_the_joints_damping_and_nothing_stacked_on_it(hysteretic):
    taps, d = hysteretic
    assert not d.explained and d.report[0].startswith("unexplained: no candidate explains the data")
    assert [(e.name, e.where) for e in d.effects] == [("joint-damping", "holder-tool")], [repr(e) for e in d.effects]
    line = _left_out(d)
    assert "joint-cross-coupling at holder-tool" in line and "0.05 times the noise floor" in line
    # the search's steps stay on record: it had stacked more than it keeps
    assert [s.added.name for s in d.refinement[1:]][:1] == ["joint-damping"]
    assert len(d.refinement) - 1 > len(d.effects)


def test_a_drawbar_is_partly_a_stiffer_spindle_and_nothing_stacked_on_it(drawbar):
    taps, d = drawbar
    assert not d.explained
    ((name, where),) = [(e.name, e.where) for e in d.effects]
    assert name == "section-change" and where.startswith("spindle@"), where
    assert "left out of the partial explanation" in _left_out(d)


def _rule_holds(taps, d) -> None:
    gain = d.settings.partial_gain * d.noise_floor
    assert all(w >= gain for w in _worth(taps, d))
    worths = [float(part.rsplit("(", 1)[1].rstrip(")")) for part in _left_out(d).split(": ", 1)[1].split("; ")[:-1]]
    assert worths and all(0.0 <= w < gain for w in worths), worths


def test_every_change_kept_is_worth_the_share_and_every_one_left_out_is_not(hysteretic):
    _rule_holds(*hysteretic)


def test_so_too_for_the_drawbar(drawbar):
    _rule_holds(*drawbar)


def test_under_another_real_tests_noise_the_hysteretic_joint_is_its_damping_too():
    """The free-free beam's residual, 1.5 times: a neighbouring case nobody tuned."""
    taps = _taps(333, 1.5, free_free_residual(), ht_loss=0.05)
    d = diagnose(hd.nominal_model(), taps, progress=False)
    assert not d.explained
    assert [(e.name, e.where) for e in d.effects][:1] == [("joint-damping", "holder-tool")]
    gain = d.settings.partial_gain * d.noise_floor
    assert all(w >= gain for w in _worth(taps, d)), [repr(e) for e in d.effects]
