"""Identification on data from the independent FE model, with 2 % multiplicative noise.

The "measurements" come from tests/fe_reference.py (its own elements, joints
and assembly), not from the library's forward model that the identification
uses.  Translational FRFs at three points on the tool, 5 mm apart, are
measured; rotations only from finite differences of those three points.
"""

import numpy as np
import pytest

import fe_reference as fe
from substructure import FRF, Assembly, Flutes, Frequency, Holder, Insert, Joint, Segment, Spindle, Tool
from substructure.identify import JointIdentifier, identify_joint
from substructure.measurements import Measurement, MeasurementSet

GRID = Frequency.from_range("100 Hz", "5000 Hz", "4 Hz")
TRUE = {"k_yf": 1.43e7, "k_tm": 8e4, "c_yf": 12.0, "c_tm": 4.0}
TIP, S = 0.076, 0.005  # tool length and point spacing [m]


def _fe_measurements():
    st = fe.Material(210e9, 0.29, 7850.0, 0.002)
    cb = fe.Material(580e9, 0.22, 14500.0, 0.002)
    m = fe.Model()
    s = m.add_beam([(0.12, fe.section(0.07, 0.04, st)), (0.15, fe.section(0.09, 0.04, st)),
                    (0.06, fe.section(0.11, 0.04, st))])
    h = m.add_beam([(0.016, fe.section(0.063, 0, st)), (0.010, fe.section(0.04, 0, st)),
                    (0.040, fe.section(0.04, 0.012, st, insert=cb))])
    t = m.add_beam([(0.046, fe.section(0.012, 0, cb)), (0.030, fe.fluted(0.012, 0.8, cb))],
                   points=[TIP - S, TIP - 2 * S])
    m.add_joint((s, 0.33), (h, 0.0), k=[[4.1e7, 0], [0, 3.5e6]], c=[[400, 0], [0, 7]])
    m.add_joint((h, 0.066), (t, 0.0), k=[[TRUE["k_yf"], 0], [0, TRUE["k_tm"]]],
                c=[[TRUE["c_yf"], 0], [0, TRUE["c_tm"]]])
    pts = [(t, TIP, "y"), (t, TIP - S, "y"), (t, TIP - 2 * S, "y")]
    return m.receptance(GRID.hz, pts, pts)  # (n, 3, 3): point and cross FRFs


@pytest.fixture(scope="module")
def fe_data():
    return _fe_measurements()


def _model(start):
    spindle = Spindle("spindle", [Segment("120 mm", "70 mm", "40 mm"), Segment("150 mm", "90 mm", "40 mm"),
                                  Segment("60 mm", "110 mm", "40 mm")])
    holder = Holder("holder", [Segment("16 mm", "63 mm"), Segment("10 mm", "40 mm"),
                               Segment("40 mm", "40 mm", "12 mm", insert=Insert("12 mm", "carbide"))])
    tool = Tool("tool", [Segment("46 mm", "12 mm", material="carbide"),
                         Segment("30 mm", "12 mm", material="carbide", flutes=Flutes(0.8))])
    return Assembly("fe twin", components=(spindle, holder, tool), joints=(
        Joint("spindle-holder", ("spindle.tip", "holder.base"), k={"yf": "4.1e7 N/m", "tm": "3.5e6 N*m/rad"},
              c={"yf": "400 N*s/m", "tm": "7 N*m*s/rad"}),
        Joint("holder-tool", ("holder.tip", "tool.base"),
              k={"yf": f"{start['k_yf']} N/m", "tm": f"{start['k_tm']} N*m/rad"},
              c={"yf": f"{start['c_yf']} N*s/m", "tm": f"{start['c_tm']} N*m*s/rad"}),
    ))


def test_band_fit_on_fe_data_with_noise_has_honest_uncertainty(fe_data):
    labels = ("tool.tip:y", "tool.tip-5 mm:y", "tool.tip-10 mm:y")
    start = _model({"k_yf": 0.7e7, "k_tm": 1.5e5, "c_yf": 25.0, "c_tm": 2.0})
    k_err, c_err, within_k, within_c = [], [], 0, 0
    for seed in range(20):
        rng = np.random.default_rng(seed)
        noise = (rng.standard_normal(fe_data.shape) + 1j * rng.standard_normal(fe_data.shape)) / np.sqrt(2)
        measured = FRF(GRID, fe_data * (1 + 0.02 * noise), labels, labels)
        entries = [measured.select([o], [i])
                   for o, i in ((labels[0], labels[0]), (labels[1], labels[0]), (labels[2], labels[0]))]
        ident = JointIdentifier("holder-tool").fit(start, entries)
        k, c = ident.values_["k_yf"], ident.values_["c_yf"]
        k_err.append(abs(k / TRUE["k_yf"] - 1))
        c_err.append(abs(c / TRUE["c_yf"] - 1))
        within_k += abs(k - TRUE["k_yf"]) <= 3 * ident.std_["k_yf"]
        within_c += abs(c - TRUE["c_yf"]) <= 3 * ident.std_["c_yf"]
    print(f"k_yf errors max {max(k_err):.3%}, c_yf max {max(c_err):.3%}, within 3 sigma: {within_k}, {within_c}")
    assert max(k_err) < 0.10
    assert max(c_err) < 0.30
    assert within_k >= 18 and within_c >= 18


def test_identify_joint_on_fe_data_uses_finite_differences_of_three_points(fe_data):
    """The whole workflow on a measurement set of FE data: six FRFs of three points 5 mm
    apart (rotations for the closed form only from finite differences), 2 % noise."""
    labels = ("tool.tip:y", "tool.tip-5 mm:y", "tool.tip-10 mm:y")
    start = _model({"k_yf": 0.7e7, "k_tm": 1.5e5, "c_yf": 25.0, "c_tm": 2.0})
    rng = np.random.default_rng(7)
    noise = (rng.standard_normal(fe_data.shape) + 1j * rng.standard_normal(fe_data.shape)) / np.sqrt(2)
    data = fe_data * (1 + 0.02 * noise)
    pairs = [(0, 0), (1, 0), (2, 0), (1, 1), (2, 1), (2, 2)]
    measured = tuple(
        Measurement.from_frf(FRF(GRID, data[:, i:i + 1, j:j + 1], (labels[i],), (labels[j],)), labels[i], labels[j])
        for i, j in pairs
    )
    report = identify_joint(start, MeasurementSet("fe", measured), "holder-tool")
    assert report.k["yf"] == pytest.approx(TRUE["k_yf"], rel=0.10)
    assert report.c["yf"] == pytest.approx(TRUE["c_yf"], rel=0.30)
    assert report.closed_form is not None  # built from the finite-difference rotations
    band = report.closed_form.frequency.band_mask(*report.band)
    assert np.median(report.closed_form.parameter("k_yf")[band]) == pytest.approx(TRUE["k_yf"], rel=0.1)
