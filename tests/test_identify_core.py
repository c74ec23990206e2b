"""Identification on the model-updating core: the joint model chosen by significance, honest uncertainty.

The data come from the independent FE rig of hidden_data.py (its own
elements and joints), with 1.5 % relative noise, 0.5 degree of phase noise
and an additive floor, in repeated trials with fixed seeds.
"""

import numpy as np
import pytest

import hidden_data as hd
from substructure import FRF
from substructure.identify import identify_joint
from substructure.measurements import Measurement, MeasurementSet

POINTS = ("tool.tip", "tool.tip-20 mm")


def _noisy(frf: FRF, seed: int) -> FRF:
    rng = np.random.default_rng(seed)
    h = frf.data
    n = h.shape
    level = 1e-3 * np.median(np.abs(h))
    data = (h * (1 + 0.015 * rng.standard_normal(n)) * np.exp(1j * np.radians(0.5) * rng.standard_normal(n))
            + level * (rng.standard_normal(n) + 1j * rng.standard_normal(n)) / np.sqrt(2))
    return FRF(frf.frequency, data, frf.outputs, frf.inputs)


def _set(clean, seed) -> MeasurementSet:
    return MeasurementSet("FE rig", tuple(Measurement.from_frf(_noisy(frf, 10 * seed + i), p, "tool.tip")
                                          for i, (frf, p) in enumerate(zip(clean, POINTS))))


@pytest.fixture(scope="module")
def cross_coupled():
    return hd.measure(ht_cross=0.8e6, points=POINTS, noise=0.0, phase_deg=0.0, floor=0.0)


def test_a_cross_coupled_joint_is_found_by_default_with_honest_uncertainty(cross_coupled):
    model = hd.nominal_model()  # diagonal holder-tool joint: the cross term is not in the model
    covered = {"k_ym": 0, "k_yf": 0, "k_tm": 0}
    for seed in range(8):
        report = identify_joint(model, _set(cross_coupled, seed), "holder-tool")
        assert report.model == "full" and "k_ym" in report.fitted
        assert report.k["ym"] == pytest.approx(0.8e6, rel=0.3)
        assert report.consistent
        for name, true in (("k_ym", 0.8e6), ("k_yf", 1.43e7), ("k_tm", 8e4)):
            entry = name.split("_")[1]
            covered[name] += abs(report.k[entry] - true) <= 3 * report.k_std[entry]
    assert all(count >= 7 for count in covered.values()), covered


def test_a_diagonal_joint_stays_diagonal():
    clean = hd.measure(points=POINTS, noise=0.0, phase_deg=0.0, floor=0.0)
    models = [identify_joint(hd.nominal_model(), _set(clean, seed), "holder-tool").model for seed in range(4)]
    assert models.count("diagonal") >= 3


def test_a_model_that_misses_something_says_so_instead_of_reporting_tight_values():
    """The tap test had a 2 g accelerometer on the tip that the record does not mention."""
    clean = hd.measure(sensor_kg=0.002, points=POINTS, noise=0.0, phase_deg=0.0, floor=0.0)
    report = identify_joint(hd.nominal_model(), _set(clean, 0), "holder-tool")
    assert not report.consistent and report.chi2_reduced > 2
    assert any("misses something" in w and "substructure diagnose" in w for w in report.warnings)
    # the standard deviations carry the misfit: about sqrt(chi^2/nu) times those of the model with the sensor
    from substructure import Sensor

    with_sensor = hd.nominal_model().attach(Sensor("accelerometer", "tool.tip", "2 g", always_on=True))
    right = identify_joint(with_sensor, _set(clean, 0), "holder-tool")
    assert right.consistent
    ratio = report.k_std["yf"] / right.k_std["yf"]
    assert ratio == pytest.approx(np.sqrt(report.chi2_reduced), rel=0.5)
    assert abs(right.k["yf"] - 1.43e7) <= 3 * right.k_std["yf"]
