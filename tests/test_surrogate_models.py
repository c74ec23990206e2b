"""Surrogates of joint parameters: Table 4.2 leave-one-out, a synthetic law, bad input."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from substructure.errors import InvalidValueError, UnitError
from substructure.surrogate import (ExtrapolationWarning, GPSurrogate, JointTable, MLPSurrogate, cross_validate,
                                    thesis_table_4_2)


@pytest.fixture(scope="module")
def table42():
    return thesis_table_4_2()


@pytest.mark.parametrize("surrogate", [MLPSurrogate(), GPSurrogate()], ids=["mlp", "gp"])
def test_table_4_2_leave_one_out(table42, surrogate):
    cv = cross_validate(surrogate, table42, "k_yf", "loo")
    assert len(cv.folds) == 13 and all(len(f["held_out"]) == 1 for f in cv.folds)
    assert np.isfinite(cv.mean_abs_percent_error) and cv.mean_abs_percent_error < 40
    js = cv.to_json()
    assert set(js) >= {"model", "folds", "mean_abs_percent_error", "coverage_68", "coverage_95"}
    if isinstance(surrogate, GPSurrogate):
        assert round(cv.coverage(0.95) * 13) >= 11


def _law(d, L):
    """A smooth known law: stiffer with diameter, softer with gauge length (N/m)."""
    return 1.0e7 * (d / 12.0) ** 2 * (80.0 / L) ** 1.5


@pytest.fixture(scope="module")
def synthetic():
    rng = np.random.default_rng(3)
    rows, true = [], []
    for d in (10.0, 12.0, 16.0, 20.0):
        for L in np.linspace(60.0, 110.0, 11):
            k = _law(d, L)
            true.append(k)
            rows.append({"tool_diameter": f"{d} mm", "gauge_length": f"{L} mm",
                         "k_yf": f"{float(k * (1 + 0.05 * rng.standard_normal()))!r} N/m"})
    return JointTable.from_rows(rows), np.array(true)


@pytest.mark.parametrize("surrogate", [MLPSurrogate(), GPSurrogate()], ids=["mlp", "gp"])
def test_synthetic_law_with_5_percent_noise(synthetic, surrogate):
    table, true = synthetic
    assert len(table) >= 40
    cv = cross_validate(surrogate, table, "k_yf", "loo")
    held = np.concatenate([f["held_out"] for f in cv.folds])
    pred = np.concatenate([f["predicted"] for f in cv.folds])
    # error against the noisy held-out values: within 1.5 x the noise level (5 %, mean |e| of N(0, 5 %) = 4 %)
    assert cv.mean_abs_percent_error <= 1.5 * 5.0
    # and against the law itself it is below the noise
    assert np.mean(np.abs(pred / true[held] - 1)) * 100 < 5.0
    assert abs(cv.coverage(0.68) - 0.68) <= 0.10
    assert abs(cv.coverage(0.95) - 0.95) <= 0.10


def test_leave_one_group_out(synthetic):
    table, _ = synthetic
    cv = cross_validate(GPSurrogate(), table, "k_yf", "group:tool_diameter")
    assert len(cv.folds) == 4 and sorted(len(f["held_out"]) for f in cv.folds) == [11, 11, 11, 11]


def test_fit_returns_self_and_fitted_attributes(table42):
    model = GPSurrogate()
    assert model.fit(table42) is model
    assert model.targets_ == ("k_yf",) and list(model.feature_names_in_) == ["tool_diameter", "gauge_length"]
    pred = model.predict({"tool_diameter": "14 mm", "gauge_length": "90 mm"})
    js = pred.to_json()
    assert js["k_yf"]["unit"] == "N/m" and 0.5e7 < js["k_yf"]["value"] < 4e7 and js["k_yf"]["std"] > 0


def test_bad_input(table42):
    model = GPSurrogate().fit(table42)
    with pytest.raises(InvalidValueError, match="gauge_length"):
        model.predict({"tool_diameter": "14 mm"})
    with pytest.raises(UnitError, match="do not match"):
        model.predict({"tool_diameter": "14 N", "gauge_length": "90 mm"})
    with pytest.raises(UnitError, match="bare number"):
        model.predict({"tool_diameter": 14, "gauge_length": "90 mm"})
    with pytest.raises(ExtrapolationWarning, match=r"tool_diameter = 50 mm is 30 mm \(3.0 times"):
        model.predict({"tool_diameter": "50 mm", "gauge_length": "90 mm"})
    empty = JointTable.empty({"k_yf": "N/m"}, {"tool_diameter": "mm"})
    with pytest.raises(InvalidValueError, match="empty"):
        GPSurrogate().fit(empty)
    with pytest.raises(InvalidValueError, match="not fitted"):
        MLPSurrogate().predict({"tool_diameter": "14 mm", "gauge_length": "90 mm"})


def test_categorical_feature():
    rows = []
    for holder, f in (("collet", 1.0), ("shrink-fit", 1.6)):
        for d in (10, 12, 16, 20):
            rows.append({"tool_diameter": f"{d} mm", "holder_type": holder, "k_yf": f"{f * d * 1e6} N/m"})
    table = JointTable.from_rows(rows)
    assert table.features == {"tool_diameter": "mm", "holder_type": None}
    model = GPSurrogate().fit(table)
    a = model.predict({"tool_diameter": "14 mm", "holder_type": "collet"}).value("k_yf")[0]
    b = model.predict({"tool_diameter": "14 mm", "holder_type": "shrink-fit"}).value("k_yf")[0]
    assert b > 1.3 * a
    with pytest.raises(InvalidValueError, match="hydraulic"):
        model.predict({"tool_diameter": "14 mm", "holder_type": "hydraulic"})


def test_prediction_refuses_what_it_cannot_answer(table42):
    model = GPSurrogate().fit(table42)
    with pytest.raises(InvalidValueError, match="features: got None; expected a mapping.*tool_diameter, gauge_length"):
        model.predict(None)
    with pytest.raises(InvalidValueError, match="features: got 14; expected a mapping"):
        model.predict([14])
    pred = model.predict({"tool_diameter": "14 mm", "gauge_length": "90 mm"})
    for call in (pred.value, pred.std, lambda p: pred.interval(p, 0.95)):
        with pytest.raises(InvalidValueError, match="'k_tm', which was not predicted; the prediction has k_yf"):
            call("k_tm")
    for level in (1.5, 0, 1, -0.2, float("nan"), "0.95"):
        with pytest.raises(InvalidValueError, match="level: got .*strictly between 0 and 1"):
            pred.interval("k_yf", level)
    lo, hi = pred.interval("k_yf", 0.5)
    assert 0 < lo[0] < pred.value("k_yf")[0] < hi[0]
    for n in (0, -3, 2.5, True):
        with pytest.raises(InvalidValueError, match="n: got .*whole number of samples >= 1"):
            pred.sample(n)
    assert pred.sample(1)["k_yf"].shape == (1,) and pred.sample(np.int64(3))["k_yf"].shape == (3,)


def _repeated_tests():
    """Four tools, each tested three times (measured values scattering by a few %)."""
    rows = []
    for d, L, k in ((10, 70, 0.9e7), (12, 76, 1.43e7), (16, 83, 2.2e7), (20, 95, 3.4e7)):
        for f in (0.97, 1.0, 1.04):
            rows.append({"tool_diameter": f"{d} mm", "gauge_length": f"{L} mm", "k_yf": f"{k * f!r} N/m"})
    return JointTable.from_rows(rows)


def test_repeated_tests_count_once_and_are_held_out_together():
    table = _repeated_tests()
    assert len(table) == 12 and len(table.feature_groups()) == 4
    cv = cross_validate(GPSurrogate(), table, "k_yf", "loo")
    assert [list(f["held_out"]) for f in cv.folds] == [[0, 1, 2], [3, 4, 5], [6, 7, 8], [9, 10, 11]]
    # the held-out tool is not in the training set: its error is that of a tool never seen, not ~0
    assert cv.mean_abs_percent_error > 5.0
    first_three = JointTable(table.parameters, table.features, {k: v[:9] for k, v in table.columns.items()})
    with pytest.raises(InvalidValueError, match="9 rows of 3 distinct tools .* leaves 2 to fit"):
        cross_validate(GPSurrogate(), first_three, "k_yf", "loo")
    two_tools = JointTable(table.parameters, table.features, {k: v[:6] for k, v in table.columns.items()})
    with pytest.raises(InvalidValueError, match="6 rows but 2 distinct tools .*a surrogate needs at least 3"):
        GPSurrogate().fit(two_tools)
    assert GPSurrogate().fit(first_three).predict({"tool_diameter": "12 mm", "gauge_length": "76 mm"}).std("k_yf") > 0


def test_prediction_records_extrapolation(table42):
    model = GPSurrogate().fit(table42)
    inside = model.predict({"tool_diameter": "14 mm", "gauge_length": "90 mm"})
    assert inside.outside() == [] and inside.to_json()["k_yf"]["extrapolation"] == []
    # a little outside: no warning (within 0.25 times the range), but recorded
    with warnings.catch_warnings():
        warnings.simplefilter("error", ExtrapolationWarning)
        near = model.predict({"tool_diameter": "21 mm", "gauge_length": "90 mm"})
    assert near.outside() == [{"feature": "tool_diameter", "value": 21.0, "unit": "mm", "table_min": 10.0,
                               "table_max": 20.0, "side": "above", "distance": 1.0, "times_range": 0.1}]
    with pytest.warns(ExtrapolationWarning):
        far = model.predict([{"tool_diameter": "14 mm", "gauge_length": "90 mm"},
                             {"tool_diameter": "5 mm", "gauge_length": "146 mm"}])
    assert far.outside(0) == []
    entries = far.to_json(1)["k_yf"]["extrapolation"]
    assert [(e["feature"], e["side"]) for e in entries] == [("tool_diameter", "below"), ("gauge_length", "above")]
    assert entries[0]["distance"] == pytest.approx(5.0) and entries[0]["times_range"] == pytest.approx(0.5)
    assert entries[1]["distance"] == pytest.approx(40.0) and entries[1]["times_range"] == pytest.approx(40 / 41)
    # a prediction built by hand knows of no extrapolation
    from substructure.surrogate import Prediction

    assert Prediction({"k_yf": np.zeros(1)}, {"k_yf": np.ones(1)}, {"k_yf": "N/m"}).outside() == []
