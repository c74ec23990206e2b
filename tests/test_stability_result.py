"""Lobes results (substructure.stability.result, plotting): reading, JSON, comparisons on one plot, bands."""

from __future__ import annotations

import json

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pytest  # noqa: E402
from matplotlib.collections import PolyCollection  # noqa: E402

from substructure import InvalidValueError  # noqa: E402
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
