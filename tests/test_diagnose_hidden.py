"""Diagnosis on data with hidden effects, from the independent FE rig of hidden_data.py.

Each case hides one effect (or two, or none) in the FE "test rig"; the
library's nominal model lacks it.  The diagnosis must name it, fit it, and
the refinement must bring the error down to the noise floor.
"""

import pytest

import hidden_data as hd
from substructure.diagnose import diagnose

CASES = {
    "sensor": dict(sensor_kg=0.002),
    "flutes": dict(flutes=(0.03, 0.8)),
    "springs": dict(springs=(1.0e5, 0.05, 0.28)),  # bands ~16 and ~26 Hz
    "soft-joint": dict(ht_scale=1 / 3),
    "cross-coupling": dict(ht_cross=0.8e6),  # passive: 0.8e6^2 < 1.43e7 * 8e4
    "sensor+flutes": dict(sensor_kg=0.002, flutes=(0.03, 0.8)),
    "none": dict(),
}


@pytest.fixture(scope="module")
def results():
    model = hd.nominal_model()
    return {name: diagnose(model, hd.measure(seed=i, **kw)) for i, (name, kw) in enumerate(CASES.items())}


def _params(diagnosis, effect):
    step = next(s for s in diagnosis.refinement if s.added is not None and s.added.name == effect)
    return step.added.values


def test_accelerometer(results):
    d = results["sensor"]
    assert d.missing_effect == "sensor-mass" and d.missing_where == "tool.tip"
    assert _params(d, "sensor-mass")["mass"] == pytest.approx(0.002, rel=0.15)


def test_flutes(results):
    d = results["flutes"]
    assert d.missing_effect == "fluted-section"
    assert _params(d, "fluted-section")["diameter_ratio"] == pytest.approx(0.8, abs=0.05)


def test_suspension_springs(results):
    assert results["springs"].missing_effect == "support-springs"


def test_soft_joint(results):
    d = results["soft-joint"]
    assert d.missing_effect == "joint-stiffness" and d.missing_where == "holder-tool"
    assert _params(d, "joint-stiffness")["k_yf"] == pytest.approx(1.43e7 / 3, rel=0.2)


def test_cross_coupling(results):
    d = results["cross-coupling"]
    assert d.missing_effect == "joint-cross-coupling" or "joint-cross-coupling" in d.ambiguous_with


def test_two_effects_in_the_first_two_steps(results):
    d = results["sensor+flutes"]
    added = {s.added.name for s in d.refinement[1:3]}
    assert added == {"sensor-mass", "fluted-section"}


def test_no_hidden_effect(results):
    d = results["none"]
    assert d.missing_effect is None
    assert d.baseline_error <= 1.5 * d.noise_floor
    assert len(d.refinement) == 1


@pytest.mark.parametrize("case", [c for c in CASES if c != "none"])
def test_the_error_falls_to_the_noise_floor(results, case):
    d = results[case]
    final = d.refinement[-1].error
    assert final <= d.baseline_error / 5
    assert final <= 1.5 * d.noise_floor
    # the JSON of formats.md
    j = d.to_json()
    assert {"metric", "baseline_error", "noise_floor", "missing_effect", "ambiguous_with", "candidates",
            "refinement"} <= set(j)
    assert j["refinement"][0] == {"step": 0, "added": None, "error": d.baseline_error}
    assert all({"effect", "where", "parameters", "error", "explanation"} <= set(c) for c in j["candidates"])
