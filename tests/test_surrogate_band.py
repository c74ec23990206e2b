"""The tool point FRF band of a predicted joint contains the FRF of the true joint."""

import numpy as np
import pytest

from substructure import Frequency, default_assembly
from substructure.surrogate import GPSurrogate, JointTable, predict_frf_band

GRID = Frequency.from_range("500 Hz", "5000 Hz", "5 Hz")


def _law(d, L):
    return 1.0e7 * (d / 12.0) ** 2 * (80.0 / L) ** 1.5


@pytest.fixture(scope="module")
def table():
    rng = np.random.default_rng(11)
    rows = []
    for d in (10.0, 12.0, 16.0, 20.0):
        for L in np.linspace(60.0, 110.0, 11):
            rows.append({"tool_diameter": f"{d} mm", "gauge_length": f"{L} mm",
                         "k_yf": f"{float(_law(d, L) * (1 + 0.05 * rng.standard_normal()))!r} N/m"})
    return JointTable.from_rows(rows)


def test_band_contains_the_true_parameter_frf(table):
    surrogate = GPSurrogate().fit(table, ["k_yf"])
    prediction = surrogate.predict({"tool_diameter": "14 mm", "gauge_length": "76 mm"})  # not in the table
    asm = default_assembly()
    band = predict_frf_band(asm, "holder-tool", prediction, frequency=GRID, n_samples=64)
    truth = asm.with_joint(asm.joint("holder-tool").with_parameters(k={"yf": f"{_law(14.0, 76.0)!r} N/m"}))
    h_true = truth.receptance("tool.tip:y", frequency=GRID)
    assert band.contains(h_true).all()
    # the band is not trivially wide (it opens up only where a resonance or
    # antiresonance moves with the joint)
    assert np.median(band.upper / band.lower) < 3.0
    # and the median-parameter FRF lies inside it too
    assert band.contains(band.nominal).all()
    j = band.to_json()
    assert len(j["frequency_hz"]) == len(GRID) and j["n_samples"] == 64


def test_band_errors(table):
    prediction = GPSurrogate().fit(table, ["k_yf"]).predict({"tool_diameter": "14 mm", "gauge_length": "76 mm"})
    with pytest.raises(Exception, match="n_samples"):
        predict_frf_band(default_assembly(), "holder-tool", prediction, frequency=GRID, n_samples=1)
    with pytest.raises(Exception, match="no joint"):
        predict_frf_band(default_assembly(), "nope", prediction, frequency=GRID)
