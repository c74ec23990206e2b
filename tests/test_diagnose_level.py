"""A measurement that is a constant factor times the model: a calibration or unit error, not the structure.

The data come from the independent FE rig of hidden_data.py; a miscalibrated hammer or sensor scales every
line of an FRF by one factor and leaves the modes where they are.  No candidate of the diagnosis does that
(it would have to scale every mass and stiffness alike), so the data are not explained, and the report says
which kind of error has this signature.  Beside it, the verdict's first line for an error that is local
(within the noise over the whole band, not band by band).
"""

import re

import numpy as np
import pytest

import hidden_data as hd
from substructure import FRF
from substructure.diagnose import diagnose
from substructure.diagnose.compare import compare
from substructure.diagnose.report import level_signature


def _scaled(frfs, factor):
    return [FRF(f.frequency, f.data * factor, f.outputs, f.inputs) for f in frfs]


def _comparisons(model, frfs):
    return [compare(model.frf(list(f.outputs), list(f.inputs), f.frequency), f) for f in frfs]


@pytest.mark.parametrize("factor", [1.1, 0.9, 1.0 / 9.81])
def test_a_scaled_measurement_is_recognised_with_its_factor(factor):
    model = hd.nominal_model()
    frfs = _scaled(hd.measure(seed=31, points=("tool.tip", "tool.tip-30 mm")), factor)
    baseline = _comparisons(model, frfs)
    lines, info = level_signature(baseline, max(c.noise_floor for c in baseline))
    assert len(lines) == 1 and "calibration" in lines[0]
    assert [x["factor"] for x in info["level"]] == pytest.approx([factor, factor], rel=0.01)


@pytest.mark.parametrize("hidden", [dict(), dict(sensor_kg=0.003), dict(nut=(0.12, 5e-5, 0.045)),
                                    dict(ht_damping=3.0), dict(tool_length=0.080), dict(ht_loss=0.05)],
                         ids=["nothing", "sensor", "nut", "damping", "overhang", "joint loss"])
def test_changes_of_the_structure_do_not_look_like_a_calibration(hidden):
    model = hd.nominal_model()
    baseline = _comparisons(model, hd.measure(seed=32, **hidden))
    assert level_signature(baseline, baseline[0].noise_floor) == ([], {})


def test_a_miscalibrated_test_is_unexplained_and_the_report_says_why():
    d = diagnose(hd.nominal_model(), _scaled(hd.measure(seed=33), 1.1))
    assert not d.explained
    assert d.report[0].startswith("unexplained: no candidate explains the data")
    (line,) = [x for x in d.report if "calibration" in x]
    assert "1.1 times" in line and "no change of the structure is fitted" in line
    assert np.isfinite(d.final_error)
    # nothing stacked on the wrong level: no change fitted, no partial explanation, no claim that none improves
    assert not d.effects and len(d.refinement) == 1
    assert not any("partial" in x or "no candidate improves" in x for x in d.report), d.report


def _bumped(frf, height):
    """The data with a bump of ``height`` (relative) in magnitude around 150 Hz: a local error no change makes."""
    hz = frf.frequency.hz
    bump = 1 + height * np.exp(-((hz - 150.0) / 25.0) ** 2)
    return FRF(frf.frequency, frf.data * bump[:, None, None], frf.outputs, frf.inputs)


@pytest.mark.parametrize("seed", [0, 1])
def test_an_error_within_the_noise_overall_but_not_band_by_band_is_said_to_be_local(seed):
    """The first line gives the whole band's numbers; when those pass and only a band fails, it says so (else
    an error of 1 noise floor, chi^2/nu under what the noise allows, would read as a pass)."""
    d = diagnose(hd.nominal_model(), [_bumped(hd.measure(seed=seed)[0], 0.06)])
    assert not d.explained
    first = d.report[0]
    assert first.startswith("unexplained: no candidate explains the data")
    found = re.search(r"chi\^2/nu = (\S+) where the noise allows (\S+?)[;,]", first)
    chi2, allowed = (float(x) for x in found.groups())
    assert chi2 <= allowed
    assert "not band by band: the error is local" in first
    assert "110-208 Hz" in d.report[1]
    # scaled by 1.1, the data fail over the whole band: not called local (one candidate, to be quick)
    worse = diagnose(hd.nominal_model(), _scaled(hd.measure(seed=seed), 1.1), effects=["sensor-mass"],
                     open_world=False)
    assert not worse.explained and "the error is local" not in worse.report[0]
