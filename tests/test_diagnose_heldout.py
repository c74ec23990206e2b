"""Held-out cases of kinds the other diagnosis tests do not hold, judged as a user who acts on the answer would.

Each case hides something in the independent FE rig (hidden_data.py); the rule: the
changes named are the truth's and no more, the verdict is right, and the model the
diagnosis writes predicts what was not fitted, outside the fitted band and at the
rotations of the tool tip that no tap test measures, better than the model as given.
The truth for those predictions is the library's model with the hidden changes made
by hand (the FE rig and the library agree far below the noise; test_fe_validation).
"""

from __future__ import annotations

import numpy as np
import pytest

import hidden_data as hd
from substructure import Frequency, Mass
from substructure.diagnose import DiagnoseSettings, diagnose
from substructure.updating import set_parameters

ALL = Frequency.from_range("20 Hz", "5000 Hz", "4 Hz")
BEYOND = Frequency.from_range("5000 Hz", "8000 Hz", "4 Hz")  # above the measured band (10 Hz - 5 kHz)
ABOVE_2K = Frequency.from_range("2000 Hz", "5000 Hz", "4 Hz")  # measured, above a band fitted to 2 kHz


def _error(model, truth, entry, grid) -> float:
    """RMS log ratio of one tool tip receptance of a model against the truth's."""
    a = model.frf([entry[0]], [entry[1]], grid).data[:, 0, 0]
    b = truth.frf([entry[0]], [entry[1]], grid).data[:, 0, 0]
    return float(np.sqrt(np.mean(np.abs(np.log(a / b)) ** 2)))


@pytest.fixture(scope="module")
def reground():
    """A tool reground 4 mm shorter, and a 3 g accelerometer the test record forgot."""
    frfs = hd.measure(seed=21, tool_length=0.072, sensor_kg=0.003)
    truth = hd.nominal_model(tool_length=0.072).attach(Mass("accelerometer", "tool.tip", "3 g"))
    return diagnose(hd.nominal_model(), frfs), truth


def test_a_reground_tool_with_a_forgotten_sensor_is_two_changes_and_no_more(reground):
    d, _ = reground
    assert d.explained, d.report
    names = sorted(e.name for e in d.effects)
    assert names == ["model-parameter", "sensor-mass"], [repr(e) for e in d.effects]
    (length,) = [e for e in d.effects if e.name == "model-parameter"]
    assert length.where in ("components.tool.overhang", "components.tool.segments.0.length",
                            "components.tool.segments.1.length")
    (sensor,) = [e for e in d.effects if e.name == "sensor-mass"]
    assert sensor.values["mass"] == pytest.approx(0.003, rel=0.1)


def test_the_saved_model_predicts_what_was_not_fitted(reground):
    """Above the measured band, at the tip's rotation and at a point never measured, the written model is the
    truth's, the given one is not."""
    d, truth = reground
    nominal = hd.nominal_model()
    for entry, grid in ((("tool.tip:y", "tool.tip:y"), BEYOND), (("tool.tip:theta", "tool.tip:theta"), ALL),
                        (("tool.tip:y", "tool.tip:theta"), ALL), (("holder.tip:y", "tool.tip:y"), ALL)):
        saved = _error(d.refined_assembly, truth, entry, grid)
        given = _error(nominal, truth, entry, grid)
        assert saved < 0.1 * given, (entry, saved, given)
        assert saved < 0.02, (entry, saved)


@pytest.fixture(scope="module")
def bored():
    """A 3 mm coolant bore through the whole tool, its shank in the holder too."""
    frfs = hd.measure(seed=4, tool_bore=0.003)
    truth = set_parameters(hd.nominal_model(), {"components.tool.bore": 0.003})
    return diagnose(hd.nominal_model(), frfs), truth


def test_a_coolant_bore_is_named_as_one_bore_not_as_the_carbide_lighter(bored):
    """Before the bore was a candidate: carbide density -6 % and the tool's E -0.7 %, explained."""
    d, _ = bored
    assert d.explained, d.report
    (found,) = d.effects
    assert (found.name, found.where) == ("model-parameter", "components.tool.bore")
    assert found.values["value"] == pytest.approx(0.003, rel=0.05)


def test_the_bored_tools_saved_model_predicts_what_was_not_fitted(bored):
    d, truth = bored
    nominal = hd.nominal_model()
    for entry, grid in ((("tool.tip:y", "tool.tip:y"), BEYOND), (("tool.tip:theta", "tool.tip:theta"), ALL),
                        (("holder.tip:y", "tool.tip:y"), ALL)):
        saved = _error(d.refined_assembly, truth, entry, grid)
        given = _error(nominal, truth, entry, grid)
        assert saved < 0.1 * given, (entry, saved, given)


def test_a_rear_bearing_mounted_50_mm_forward_is_placed_to_the_precision_the_data_allow():
    """Before: stopped at the 15 % window (79.5 mm), with a softer bearing set and a spring that does not exist."""
    frfs = hd.measure(seed=6, bearings=(1.0, 1.0), bearing_moved=(0, 0.08))
    d = diagnose(hd.nominal_model(bearings=True), frfs)
    assert d.explained, d.report
    (found,) = d.effects
    assert (found.name, found.where) == ("model-parameter", "supports.0.at")
    assert found.values["value"] == pytest.approx(0.08, abs=1e-3)
    std = found.std["value"]
    assert 0 < std < 1e-3 and abs(found.values["value"] - 0.08) < 4 * std + 2e-4


def test_a_body_at_the_spindles_rear_end_is_one_body_not_three_geometry_changes():
    """A 1.5 kg pulley at the rear end: before, three changes of the spindle's geometry, or two, 'explained'."""
    d = diagnose(hd.nominal_model(), hd.measure(seed=7, spindle_body=(1.5, 2e-3, 0.0)))
    assert d.explained, d.report
    (found,) = d.effects
    assert found.name == "added-mass" and found.change.where == "spindle rear end"
    assert found.values["mass"] == pytest.approx(1.5, rel=0.05)
    assert found.values["position"] < 0.01


def test_the_same_tool_fitted_below_3_khz_is_the_truths_two_changes():
    """Below 3 kHz the data hold less: the forward path reaches the noise only with four changes (a joint, a
    section change, a cross term, a length); a second step from the overhang finds the sensor (before: the
    composite, called explained, then unexplained)."""
    frfs = hd.measure(seed=21, tool_length=0.072, sensor_kg=0.003)
    d = diagnose(hd.nominal_model(), frfs, band=(20.0, 3000.0))
    assert d.explained, d.report
    assert sorted(e.name for e in d.effects) == ["model-parameter", "sensor-mass"], [repr(e) for e in d.effects]
    (length,) = [e for e in d.effects if e.name == "model-parameter"]
    assert (length.where, length.values["value"]) == ("components.tool.overhang", pytest.approx(0.072, abs=5e-4))
    (sensor,) = [e for e in d.effects if e.name == "sensor-mass"]
    assert sensor.values["mass"] == pytest.approx(0.003, rel=0.1)


def test_without_pairs_from_other_first_changes_a_composite_is_not_claimed():
    """The same data without the pairs from other first changes (nor the search of an element's size at each
    place, which finds a section at the tool's tip as heavy as the sensor: ``place_search=0``): the search ends
    with three or more changes (one a joint at its nominal values), close to the noise, and the verdict does not
    claim them."""
    frfs = hd.measure(seed=21, tool_length=0.072, sensor_kg=0.003)
    d = diagnose(hd.nominal_model(), frfs, band=(20.0, 3000.0), settings=DiagnoseSettings(place_search=0,
                                                                                         other_firsts=0))
    assert not d.explained
    assert d.report[0].startswith("unexplained: no candidate explains the data"), d.report
    assert len(d.final_effects) >= 3

def _predicts(d, truth, cases) -> None:
    """The saved model is the truth's where nothing was fitted, the given one is not."""
    nominal = hd.nominal_model()
    for entry, grid in cases:
        saved = _error(d.refined_assembly, truth, entry, grid)
        given = _error(nominal, truth, entry, grid)
        assert saved < 0.1 * given, (entry, saved, given)
        assert saved < 0.02, (entry, saved)


@pytest.fixture(scope="module")
def joint_and_flutes():
    """The holder-tool joint 0.6 times as stiff (k_yf) and flutes over the last 30 mm (ratio 0.8): two effects of
    different kinds, the flutes weak alone (a section change over the tool explains more than either)."""
    frfs = hd.measure(seed=5, ht_scale=0.6, flutes=(0.030, 0.8))
    truth = set_parameters(hd.nominal_model(flutes=(0.030, 0.8)), {"joints.holder-tool.k.yf": 0.6 * 1.43e7})
    return diagnose(hd.nominal_model(), frfs), truth


def test_a_softer_joint_with_flutes_is_the_joint_and_the_flutes_and_no_more(joint_and_flutes):
    """Before: a section change on its bound, the tool's material and its loss factor, unexplained."""
    d, _ = joint_and_flutes
    assert d.explained, d.report
    assert len(d.effects) == 2, [repr(e) for e in d.effects]
    (flutes,) = [e for e in d.effects if e.name == "fluted-section"]
    assert flutes.values["diameter_ratio"] == pytest.approx(0.8, abs=0.02)
    assert flutes.values["length"] == pytest.approx(0.030, abs=1e-3)
    (joint,) = [e for e in d.effects if e is not flutes]
    assert (joint.name, joint.where) in (("joint-stiffness", "holder-tool"),
                                         ("model-parameter", "joints.holder-tool.k.yf"))
    k_yf = joint.values.get("k_yf", joint.values.get("value"))
    assert k_yf == pytest.approx(0.6 * 1.43e7, rel=0.05)
    assert joint.values.get("k_tm", 8e4) == pytest.approx(8e4, rel=0.05)
    assert all(r["predicts"] for r in d.search["held_back"])


def test_the_softer_joint_with_flutes_saved_model_predicts_what_was_not_fitted(joint_and_flutes):
    d, truth = joint_and_flutes
    _predicts(d, truth, ((("tool.tip:y", "tool.tip:y"), BEYOND), (("tool.tip:theta", "tool.tip:theta"), ALL),
                         (("tool.tip:y", "tool.tip:theta"), ALL)))


@pytest.fixture(scope="module")
def reground_below_2khz():
    """The reground tool and the forgotten sensor of :func:`reground`, fitted on 10 Hz - 2 kHz only."""
    frfs = hd.measure(seed=21, tool_length=0.072, sensor_kg=0.003)
    truth = hd.nominal_model(tool_length=0.072).attach(Mass("accelerometer", "tool.tip", "3 g"))
    return diagnose(hd.nominal_model(), frfs, band=(10.0, 2000.0)), truth


def test_a_reground_tool_with_a_sensor_below_2_khz_is_two_changes_and_no_more(reground_below_2khz):
    """Before: a 1.5 mm collar at the tip on the bound of its search (the sensor's 3 g) with the tool's length,
    after three changes of the forward path (the tool's material and two cross terms)."""
    d, _ = reground_below_2khz
    assert d.explained, d.report
    names = sorted(e.name for e in d.effects)
    assert names == ["model-parameter", "sensor-mass"], [repr(e) for e in d.effects]
    (length,) = [e for e in d.effects if e.name == "model-parameter"]
    assert length.where in ("components.tool.overhang", "components.tool.segments.0.length")
    assert length.values["value"] == pytest.approx(0.072 if "overhang" in length.where else 0.042, abs=5e-4)
    (sensor,) = [e for e in d.effects if e.name == "sensor-mass"]
    assert sensor.values["mass"] == pytest.approx(0.003, rel=0.1)


def test_the_reground_tool_fitted_below_2_khz_predicts_above_it(reground_below_2khz):
    d, truth = reground_below_2khz
    _predicts(d, truth, ((("tool.tip:y", "tool.tip:y"), ABOVE_2K), (("tool.tip:y", "tool.tip:y"), BEYOND),
                         (("tool.tip:theta", "tool.tip:theta"), ALL), (("tool.tip:y", "tool.tip:theta"), ALL)))


@pytest.fixture(scope="module")
def stiffer_joint():
    """The holder-tool joint 1.6 times as stiff in translation as the model says (a shrink-fit where the model
    has a collet's value): a joint stiffer than given, not softer."""
    frfs = hd.measure(seed=12, ht_scale=1.6)
    truth = set_parameters(hd.nominal_model(), {"joints.holder-tool.k.yf": 1.6 * 1.43e7})
    return diagnose(hd.nominal_model(), frfs), truth


def test_a_stiffer_joint_is_the_joint_and_no_more(stiffer_joint):
    d, truth = stiffer_joint
    assert d.explained, d.report
    (joint,) = d.effects
    assert (joint.name, joint.where) in (("joint-stiffness", "holder-tool"),
                                         ("model-parameter", "joints.holder-tool.k.yf"))
    assert joint.values.get("k_yf", joint.values.get("value")) == pytest.approx(1.6 * 1.43e7, rel=0.05)
    _predicts(d, truth, ((("tool.tip:y", "tool.tip:y"), BEYOND), (("tool.tip:theta", "tool.tip:theta"), ALL),
                         (("holder.tip:y", "tool.tip:y"), ALL)))
