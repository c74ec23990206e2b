"""A test labelled ``tool.tip`` but taken a few millimetres below it (a sensor cannot sit on the cutting edge, nor a
hammer strike it), under a real test's noise.

The search of the model's changes explained nothing (1 mm: a 1.7 g sensor, a point 20 mm back moved by 5 um and a
shorter segment; 3 mm: a 10.7 g sensor and another tool material), so a measured free tip is tried alone after it:
where it explains the data, that is the answer.  The data are the independent FE rig (hidden_data.py) measured at
``tool.tip-N mm`` and relabelled ``tool.tip``; the model is the rig's nominal one.
"""

from __future__ import annotations

import numpy as np
import pytest

import hidden_data as hd
from real_noise import with_real_noise
from substructure.diagnose import diagnose
from substructure.diagnose.refine import refine
from substructure.diagnose.report import Explanation
from substructure.diagnose.search import free_tips
from substructure.diagnose.settings import DEFAULT_SETTINGS
from substructure.measurements import Measurement, MeasurementSet
from substructure.updating import Likelihood, measured_frfs
from substructure.updating.selection import consistency


def _tested_below(mm: float, offset: int = 11, **hidden) -> MeasurementSet:
    """The rig's tip FRFs taken ``mm`` below the tip (hit and sensor), labelled ``tool.tip``, with real noise."""
    where = f"tool.tip-{mm:g} mm" if mm else "tool.tip"
    exact = hd.measure(points=(where, "tool.tip-20 mm", "holder.tip"), excitation=where, noise=0.0, phase_deg=0.0,
                       floor=0.0, **hidden)
    out = []
    for frf in with_real_noise(exact, offset, 1.0):
        response = "tool.tip:y" if frf.outputs[0] == f"{where}:y" else frf.outputs[0]
        out.append(Measurement(response, "tool.tip:y", frf.with_labels((response,), ("tool.tip:y",)), averages=5))
    return MeasurementSet("tip below", out)


def test_a_tip_tested_1_mm_below_it_is_found_where_it_was():
    result = diagnose(hd.nominal_model(), _tested_below(1.0))
    assert result.verdict.explained
    (found,) = result.changes.final_effects
    assert found.change.effect == "point-position" and found.change.where == "tool.tip"
    assert found.values["shift"] == pytest.approx(-0.001, abs=5e-5)
    assert found.change.place(found.values) == "tool.tip-1 mm"
    assert result.search["tip_alone"] == "tool.tip"
    # the search's own counts are kept; what was held back is that of the answer, not of the search's path
    assert result.search["candidates"] > 1
    assert [r["effect"] for r in result.search["held_back"]] in ([], ["point-position"])


@pytest.mark.parametrize("mm", [2.0, 3.0])
def test_after_a_short_search_the_tip_alone_is_tried(mm):
    """A search cut short by its budget explained nothing: the tip alone does, at 2 and 3 mm."""
    result = diagnose(hd.nominal_model(), _tested_below(mm), budget=150)
    assert result.verdict.explained
    (found,) = result.changes.final_effects
    assert found.change.place(found.values) == f"tool.tip-{mm:g} mm"


def test_beyond_the_reach_of_the_search_the_report_says_where_to_look():
    """At 5 mm, the reach of the search (point_reach), the tip's position ends on its bound: not claimed, but the
    report says that the tip taken there removes nearly all of the misfit."""
    assert DEFAULT_SETTINGS.point_reach == pytest.approx(0.005)
    result = diagnose(hd.nominal_model(), _tested_below(5.0), budget=150)
    assert not result.verdict.explained
    assert any(line.startswith("tool.tip taken at tool.tip-5 mm, as far as the search reaches") and
               "Give each point as measured" in line for line in result.verdict.report)


def test_a_sensor_below_the_tip_is_found_where_it_sat_and_predicts_the_cross_frfs():
    """The usual tap test: the model lacks the sensor, which sat 2 mm below the edge (1 g, where the hammer struck).
    The search alone explains nothing, nor does the tip's position alone (the sensor lowers the modes); the tip
    fitted together with the sensor on it explains the driving point, and the two predict, within the noise, the
    cross FRFs they were not fitted to (20 mm back and on the holder)."""
    measured, _ = measured_frfs(_tested_below(2.0, offset=1500, sensor_kg=0.001, sensor_below=0.002))
    driving = [m for m in measured if m.frf.outputs[0] == "tool.tip:y"]
    model = hd.nominal_model()
    result = diagnose(model, driving, progress=False, budget=150)  # the search cut short: the tip is tried after it
    assert result.verdict.explained, result.verdict.report
    found = {e.change.effect: e for e in result.changes.final_effects}
    assert set(found) == {"point-position", "sensor-mass"} and result.search["tip_alone"] == "tool.tip"
    tip, sensor = found["point-position"], found["sensor-mass"]
    assert tip.change.place(tip.values) == "tool.tip-2 mm" and sensor.change.where == "tool.tip"
    assert sensor.values["mass"] == pytest.approx(0.001, rel=0.05)
    held = Likelihood(model, [m for m in measured if m.frf.outputs[0] != "tool.tip:y"])
    kept = [(e.change, dict(e.values)) for e in result.changes.final_effects]
    assert consistency(held, held.log_ratios(kept), 0).consistent
    assert not consistency(held, held.log_ratios([]), 0).consistent
    # neither alone: the tip without the sensor, nor the sensor at the edge, predicts them
    for one in kept:
        assert not consistency(held, held.log_ratios([one]), 0).consistent, one[0].effect
    # written back, the sensor sits where the test was: with the point named as measured the model is consistent
    (sensor,) = result.changes.refined_assembly.sensors
    assert sensor.at == "tool.tip-2 mm" and sensor.always_on
    assert [s.at for s in Explanation(result.changes.final_effects).apply(model).sensors] == ["tool.tip-2 mm"]
    assert sensor.mass.m_as("kg") == pytest.approx(0.001, rel=0.05)
    as_measured = [Measurement("tool.tip-2 mm:y", "tool.tip-2 mm:y", m.frf.with_labels(
        ("tool.tip-2 mm:y",), ("tool.tip-2 mm:y",)), averages=5) for m in _tested_below(
            2.0, offset=1500, sensor_kg=0.001, sensor_below=0.002) if m.response == "tool.tip:y"]
    lik = Likelihood(result.changes.refined_assembly, measured_frfs(as_measured)[0])
    assert consistency(lik, lik.log_ratios([]), 0).consistent


@pytest.mark.parametrize("hidden", [dict(sensor_kg=0.003), dict(sensor_kg=0.0005), dict(ht_scale=0.8),
                                    dict(tool_length=0.074), dict(ht_damping=1.5), dict(insert_length=0.036),
                                    dict(taper=0.011), dict(tool_bore=0.003), dict(flutes=(0.03, 0.9))])
def test_the_tip_alone_explains_no_other_effect(hidden):
    """The criterion of the fallback: for effects of the structure at a tip tested where it is, the tip's position
    alone never reaches the noise (a shorter tool and a bored one come nearest: 2.1 and 2.4 mm, removing 34 % and
    41 % of the misfit)."""
    measured, _ = measured_frfs(_tested_below(0.0, **hidden))
    model = hd.nominal_model()
    lik = Likelihood(model, measured)
    tips = free_tips(model, [m.frf.outputs[0] for m in measured] + ["tool.tip:y"], DEFAULT_SETTINGS.point_reach)
    assert [t.where for t in tips] == ["tool.tip"]  # holder.tip holds the tool: not a free tip
    screen = lik.subsample(max(1, lik.lines.size // DEFAULT_SETTINGS.screen_lines))
    outcome = refine(lik, screen, tips, 1, lambda changes: True)
    p = sum(len(c.specs) for c, _ in outcome.current)
    assert not consistency(lik, lik.log_ratios(outcome.current), p).consistent
    # nor is it named as nearly the answer: it removes far less of the misfit than tip_share
    chi2_0 = lik.chi2([])
    assert (chi2_0 - lik.chi2(outcome.current)) / (chi2_0 - lik.n) < 0.5 < DEFAULT_SETTINGS.tip_share


@pytest.mark.parametrize("mm", [1.0, 3.0])
def test_the_tip_found_on_the_driving_point_predicts_the_cross_frfs(mm):
    """The tip's position fitted on the driving point alone predicts, within the noise, the FRFs it was not fitted
    to: the responses 20 mm back and on the holder to a hammer at the tip depend on where the hammer struck."""
    measured, _ = measured_frfs(_tested_below(mm))
    driving = [m for m in measured if m.frf.outputs[0] == "tool.tip:y"]
    others = [m for m in measured if m.frf.outputs[0] != "tool.tip:y"]
    model = hd.nominal_model()
    lik = Likelihood(model, driving)
    tips = free_tips(model, ["tool.tip:y"], DEFAULT_SETTINGS.point_reach)
    screen = lik.subsample(max(1, lik.lines.size // DEFAULT_SETTINGS.screen_lines))
    (found,) = refine(lik, screen, tips, 1, lambda changes: True).current
    assert found[0].place(found[1]) == f"tool.tip-{mm:g} mm"
    held = Likelihood(model, others)
    before = consistency(held, held.log_ratios([]), 0).consistent
    after = consistency(held, held.log_ratios([found]), 0).consistent
    assert after and not before


def _driving_point_below(mm: float, grams: float, offset: int, level: float) -> MeasurementSet:
    """The driving point alone, taken ``mm`` below the tip with a sensor of ``grams`` there, labelled ``tool.tip``."""
    where = f"tool.tip-{mm:g} mm"
    exact = hd.measure(points=(where,), excitation=where, noise=0.0, phase_deg=0.0, floor=0.0,
                       sensor_kg=grams / 1e3, sensor_below=mm / 1e3)
    (frf,) = with_real_noise(exact, offset, level)
    return MeasurementSet("driving point", [Measurement("tool.tip:y", "tool.tip:y", frf.with_labels(
        ("tool.tip:y",), ("tool.tip:y",)), averages=5)])


def _rms_log(h, truth) -> float:
    return float(np.sqrt(np.mean(np.abs(np.log(h.data.ravel() / truth.data.ravel())) ** 2)))


def test_a_shorter_tool_with_a_heavier_sensor_is_not_claimed_beside_the_tip_tested_below_it():
    """On the driving point alone a 5.3 g sensor 1.2 mm below the tip is nearly a tool 1.2 mm shorter with the stub
    beyond the sensor added to it (7.3 g): the search found that form (a random case of 16, the seed of the data
    fixed here).  The tip taken below with the sensor explains the data too, so neither is claimed, and the report
    names what tells them apart.  Checked against the FE rig: the cross FRF it names, at a point a quarter of the
    tool from the tip, is the rival's and far from the shorter tool's; a point measured from the tool's base would
    not have told them (both within a tenth of a per cent)."""
    measured = _driving_point_below(1.2, 5.3, 7410, 1.0)
    model = hd.nominal_model()
    result = diagnose(model, measured)
    assert not result.verdict.explained
    assert result.verdict.report[0].startswith("unexplained: no candidate explains the data uniquely")
    ((rival, sep),) = result.alternatives.rivals
    tip = next(f for f in rival.founds if f.change.effect == "point-position")
    sensor = next(f for f in rival.founds if f.change.effect == "sensor-mass")
    assert tip.change.place(tip.values) == "tool.tip-1.2 mm" and sensor.values["mass"] == pytest.approx(5.3e-3, 0.03)
    assert (sep["response"], sep["excitation"]) == ("tool.tip-19 mm:y", "tool.tip:y") and sep["chi2"] > 1e3
    assert "how far below the edge the sensor and the hammer sat" in sep["text"]
    assert any(line.startswith("to tell them apart: measure the cross FRF tool.tip-19 mm / tool.tip")
               for line in result.verdict.report)
    kept, taken = Explanation(result.changes.final_effects).apply(model), Explanation(rival.founds).apply(model)
    # the FE rig, the hammer where the test was: each explanation read where it says the test was taken
    truth = hd.measure(points=("tool.tip-19 mm", "tool@38 mm"), excitation="tool.tip-1.2 mm", noise=0.0,
                       phase_deg=0.0, floor=0.0, sensor_kg=5.3e-3, sensor_below=1.2e-3)
    hz = truth[0].frequency.hz
    assert _rms_log(taken.receptance("tool.tip-19 mm:y", "tool.tip-1.2 mm:y", hz), truth[0]) < 1e-3
    assert _rms_log(kept.receptance("tool.tip-19 mm:y", "tool.tip:y", hz), truth[0]) > 0.05
    assert _rms_log(taken.receptance("tool@38 mm:y", "tool.tip-1.2 mm:y", hz), truth[1]) < 2e-3
    assert _rms_log(kept.receptance("tool@38 mm:y", "tool.tip:y", hz), truth[1]) < 2e-3
