"""Lobes results (substructure.stability.result, plotting): reading, JSON, comparisons on one plot, bands."""

from __future__ import annotations

import json

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pytest  # noqa: E402
from matplotlib.collections import PolyCollection  # noqa: E402

from substructure import InvalidValueError, UnitError  # noqa: E402
from substructure.stability import (Lobes, LobesBand, MillingCut, ModalModel, Mode, lobes_band,  # noqa: E402
                                    spindle_speeds, zoa)
from substructure.units import Q_  # noqa: E402

SPEEDS = spindle_speeds("4000 rpm", "20000 rpm", "20 rpm")
CUT = MillingCut(4, "12 mm", "3 mm", kt="625 MPa", kn="100 MPa", milling="up")


def model(stiffness="1e7 N/m", frequency="1000 Hz") -> ModalModel:
    return ModalModel([Mode("x", frequency, 0.02, stiffness), Mode("y", frequency, 0.02, stiffness)])


def test_json_has_the_command_keys_and_null_for_no_limit():
    lobes = zoa(model(), CUT, SPEEDS)
    out = json.loads(json.dumps(lobes.to_json()))
    assert out["method"] == "zoa"
    assert len(out["spindle_speed_rpm"]) == len(out["depth_limit_m"]) == len(out["chatter_frequency_hz"]) == SPEEDS.size
    assert out["absolute_limit_m"] == pytest.approx(lobes.absolute_limit_m)
    none = Lobes("sdm", [1000.0, 2000.0], [np.inf, 1e-3], [np.nan, 900.0])
    out = json.loads(json.dumps(none.to_json()))
    assert out["depth_limit_m"] == [None, 1e-3] and out["chatter_frequency_hz"] == [None, 900.0]
    assert "absolute_limit_m" not in out


def test_reading_the_diagram():
    lobes = zoa(model(), CUT, SPEEDS)
    best = lobes.best_speeds(3)
    assert len(best) == 3 and best[0][1] >= best[1][1] >= best[2][1]
    n, a = best[0]
    assert lobes.limit_at(n) == pytest.approx(a)
    assert lobes.is_stable(n, 0.9 * a) and not lobes.is_stable(n, 1.1 * a)
    assert lobes.min_limit_m >= lobes.absolute_limit_m * (1 - 1e-9)
    with pytest.raises(InvalidValueError, match="one per spindle speed"):
        Lobes("zoa", [1.0, 2.0], [1.0], [1.0, 2.0])


def test_several_results_on_one_plot():
    a = zoa(model(), CUT, SPEEDS, label="measured")
    b = zoa(model(stiffness="1.2e7 N/m"), CUT, SPEEDS, label="model")
    fig = a.plot(lobes=True)
    b.plot(ax=fig.axes[0], ls="--")
    ax = fig.axes[0]
    labels = [line.get_label() for line in ax.lines if not line.get_label().startswith("_")]
    assert labels == ["measured", "stable at every speed", "model"]  # plain words for the absolute limit
    assert ax.get_xlabel() == "spindle speed [rpm]" and "mm" in ax.get_ylabel()
    assert len(ax.lines) > 2 + len(a.lobes) - 1  # individual lobes drawn faintly
    plt.close(fig)


def test_band_from_an_frf_uncertainty_band():
    members = [zoa(model(stiffness=f"{k} N/m"), CUT, SPEEDS) for k in (0.9e7, 1.0e7, 1.1e7)]
    band = lobes_band(members, nominal=members[1], label="k +-10 %")
    assert isinstance(band, LobesBand)
    assert np.all(band.lower_m <= members[1].depth_limit_m) and np.all(band.upper_m >= members[1].depth_limit_m)
    assert np.all(band.upper_m - band.lower_m >= 0) and np.any(band.upper_m > band.lower_m)
    fig = band.plot()
    ax = fig.axes[0]
    assert any(isinstance(c, PolyCollection) for c in ax.collections)
    assert [t.get_text() for t in ax.get_legend().get_texts()][0] == "k +-10 %"
    plt.close(fig)
    other = zoa(model(), CUT, spindle_speeds("4000 rpm", "20000 rpm", "40 rpm"))
    with pytest.raises(InvalidValueError, match="same spindle speeds"):
        lobes_band([members[0], other])
    with pytest.raises(InvalidValueError, match="one or more"):
        lobes_band([])


def test_plot_rejects_what_is_not_axes():
    with pytest.raises(InvalidValueError, match="Axes"):
        zoa(model(), CUT, SPEEDS).plot(ax="left")


def test_results_compare_as_values():
    a = zoa(model(), CUT, SPEEDS)
    assert a == zoa(model(), CUT, SPEEDS)
    assert a.with_label("x") != a and a.with_label("x").label == "x"
    assert Q_(a.depth_limit_m, "m").check("[length]")


def test_reading_outside_the_computed_range_is_refused_naming_the_speed_and_the_range():
    lobes = zoa(model(), CUT, SPEEDS)
    with pytest.raises(InvalidValueError, match=r"speed_rpm: expected speeds within the computed range "
                                                 r"4000\.\.20000 rpm; got 100000 rpm"):
        lobes.limit_at(100000.0)  # it gave the limit at 20,000 rpm
    with pytest.raises(InvalidValueError, match=r"range 4000\.\.20000 rpm; got 1000 rpm \(and 1 more\)"):
        lobes.limit_at([1000.0, 5000.0, 30000.0])
    with pytest.raises(InvalidValueError, match=r"speed_rpm: expected speeds within .*; got 3000 rpm"):
        lobes.is_stable(3000.0, 1e-4)
    with pytest.raises(InvalidValueError, match="speed_rpm: got nan; expected finite speeds"):
        lobes.limit_at(np.nan)
    with pytest.raises(InvalidValueError, match="speed_rpm: got inf; expected finite speeds"):
        lobes.is_stable([np.inf], [1e-4])
    assert lobes.limit_at(20000.0) == lobes.depth_limit_m[-1]  # the ends themselves are in range
    assert lobes.limit_at([]).shape == (0,)


def test_speeds_with_a_unit_read_as_the_same_speed_in_rpm():
    lobes = zoa(model(), CUT, SPEEDS)
    rad_s = np.array([1000.0, 1500.0, 2000.0])
    by_hand = rad_s * 60.0 / (2.0 * np.pi)  # 1 rad/s = 60 / (2 pi) rpm
    np.testing.assert_allclose(lobes.limit_at(Q_(rad_s, "rad/s")), lobes.limit_at(by_hand), rtol=1e-12)
    assert lobes.limit_at(Q_(1200.0, "rad/s")) == pytest.approx(lobes.limit_at(1200.0 * 60.0 / (2.0 * np.pi)))
    assert lobes.limit_at("11459 rpm") == lobes.limit_at(11459.0)
    assert lobes.limit_at(Q_(11459.0, "turn/min")) == pytest.approx(lobes.limit_at(11459.0), rel=1e-12)
    a = lobes.limit_at(11459.0)
    np.testing.assert_array_equal(lobes.is_stable(Q_([11459.0, 11459.0], "rpm"), [0.9 * a, 1.1 * a]), [True, False])
    with pytest.raises(UnitError, match="speed_rpm: got a speed in Hz; a spindle speed is in rpm"):
        lobes.limit_at(Q_(200.0, "Hz"))  # documented: Hz is ambiguous, refused
    with pytest.raises(UnitError, match="speed_rpm: got a speed in Hz"):
        lobes.is_stable("200 Hz", 1e-4)
    with pytest.raises(UnitError, match="speed_rpm: got 3 meter"):
        lobes.limit_at(Q_(3.0, "m"))
    with pytest.raises(InvalidValueError, match=r"speed_rpm: got \['fast'\]; expected spindle speeds in rpm"):
        lobes.limit_at(["fast"])
    with pytest.raises(InvalidValueError, match="speed_rpm: expected speeds within the computed range"):
        lobes.limit_on(Q_(100.0, "rad/s"))  # 955 rpm
    depth, _ = lobes.limit_on(Q_(1200.0, "rad/s"))
    assert depth[0] == pytest.approx(lobes.limit_on([1200.0 * 60.0 / (2.0 * np.pi)])[0][0], rel=1e-12)


def test_speed_windows_that_are_not_windows_are_refused_naming_the_parameter():
    lobes = zoa(model(), CUT, SPEEDS)
    with pytest.raises(InvalidValueError, match="lo_rpm: got nan; expected finite speeds"):
        lobes.window_minimum(np.nan, 8000.0)  # it was sampled from 8000 alone
    with pytest.raises(InvalidValueError, match="lo_rpm: got nan; expected finite speeds"):
        lobes.window_minimum(np.nan, np.nan)  # it said inf: stable at any depth
    with pytest.raises(InvalidValueError, match="hi_rpm: got inf; expected finite speeds"):
        lobes.window_minimum([6000.0], [np.inf])
    with pytest.raises(InvalidValueError, match="lo_rpm: got no values; expected one or more window ends"):
        lobes.window_minimum([], [])
    with pytest.raises(InvalidValueError, match=r"hi_rpm: got shape \(1, 1\); expected one number or a 1-D array"):
        lobes.window_minimum([6000.0], [[8000.0]])
    with pytest.raises(InvalidValueError, match="lo_rpm, hi_rpm: got 2 and 1 ends; expected as many"):
        lobes.window_minimum([6000.0, 7000.0], [8000.0])
    with pytest.raises(InvalidValueError, match=r"lo_rpm, hi_rpm: got the window 9000\.\.8000 rpm \(index 1\); "
                                                 r"expected lo <= hi"):
        lobes.window_minimum([6000.0, 9000.0], [7000.0, 8000.0])
    with pytest.raises(UnitError, match="lo_rpm: got a speed in Hz"):
        lobes.window_minimum("100 Hz", 8000.0)


def test_speed_windows_with_a_unit_give_the_plain_rpm_windows_minimum():
    lobes = zoa(model(), CUT, SPEEDS)
    plain = lobes.window_minimum([6000.0], [8000.0])
    for lo, hi in (("6000 rpm", "8000 rpm"), (Q_([6000.0], "rpm"), [8000.0]), (6000.0, Q_(8000.0, "turn/min"))):
        for a, b in zip(lobes.window_minimum(lo, hi), plain):
            np.testing.assert_allclose(a, b, rtol=1e-12)
    rad_s = Q_([700.0, 900.0], "rad/s")
    by_hand = np.array([700.0, 900.0]) * 60.0 / (2.0 * np.pi)  # 6685 and 8594 rpm
    for a, b in zip(lobes.window_minimum(rad_s[:1], rad_s[1:]), lobes.window_minimum(by_hand[:1], by_hand[1:])):
        np.testing.assert_allclose(a, b, rtol=1e-12)


def test_best_speeds_take_a_whole_number_of_speeds():
    lobes = zoa(model(), CUT, SPEEDS)
    for count in (0, -1, 2.5, 3.0, "3", True, None):
        with pytest.raises(InvalidValueError, match=r"count: got .*; expected a whole number >= 1"):
            lobes.best_speeds(count)  # -1 gave three speeds, 2.5 a TypeError
    assert lobes.best_speeds(np.int64(2)) == lobes.best_speeds(2) == lobes.best_speeds(3)[:2]
    assert len(lobes.best_speeds(1)) == 1
