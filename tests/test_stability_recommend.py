"""The machinist's recommendation: right structure band, margin over a speed window, machine limits, data."""

from __future__ import annotations

import json
import warnings

import attrs
import numpy as np
import pytest
from scipy.integrate import quad

from substructure import FRF, Frequency, InvalidValueError, default_assembly
from substructure.errors import FileFormatError, UnitError
from substructure.stability import (MachineLimits, MillingCut, ModalModel, Mode, Recommendation, assembly_structure,
                                    cut_power, flexible_band, lobes_band, recommend, removal_rate, sdm,
                                    spindle_speeds, workpiece, workpieces, load_workpieces, xy_frf, zoa)
from substructure.stability.cutting import MAX_SPEEDS
from substructure.stability.result import Lobes, sampled_window_minimum
from substructure.units import Q_

SPEEDS = spindle_speeds("3000 rpm", "24000 rpm", "25 rpm")
JSON_KEYS = {"spindle_speed_rpm", "depth_m", "limit_depth_m", "margin", "mrr_m3_per_s", "chatter_frequency_hz"}


def thesis_cut(**kw):
    return MillingCut(4, "12 mm", "3 mm", kt="625 MPa", kn="100 MPa", milling="up", **kw)


def on_bearings(assembly, k="1e8 N/m", c="200 N*s/m"):
    return (assembly.support("spindle@30 mm", k={"yf": k}, c={"yf": c})
            .support("spindle@250 mm", k={"yf": k}, c={"yf": c}))


def first_antiresonance(assembly, step=0.5):
    """Independently: the first sign change of Re H from - to + of the tool point receptance."""
    f = np.arange(5.0, 1000.0, step)
    h = assembly.receptance("tool.tip:y", frequency=f).data[:, 0, 0]
    i = np.flatnonzero((h.real[:-1] < 0) & (h.real[1:] >= 0))[0]
    return f[i]


def rigid_body_apparent_mass(assembly):
    """1 / (1/m + d^2/J) at the tool tip of the chain spindle-holder-tool laid end to end."""
    x0, parts = 0.0, []
    for comp in assembly.components:
        for seg in comp.segments:
            length = seg.length_m
            m = seg.mass()
            od = seg.od.m_as("m") * (seg.flutes.diameter_ratio if seg.flutes else 1.0)
            rho_i = seg.material.rho.m_as("kg/m^3") * np.pi * (od ** 4 - seg.id.m_as("m") ** 4) / 64 * length
            if seg.insert is not None:
                rho_i += seg.insert.material.rho.m_as("kg/m^3") * np.pi * seg.insert.od.m_as("m") ** 4 / 64 * length
            parts.append((m, x0 + length / 2, length, rho_i))
            x0 += length
    mass = sum(p[0] for p in parts)
    xc = sum(p[0] * p[1] for p in parts) / mass
    inertia = sum(p[0] * ((p[1] - xc) ** 2 + p[2] ** 2 / 12) + p[3] for p in parts)
    return 1.0 / (1.0 / mass + (x0 - xc) ** 2 / inertia)


# -- 1. right by default -------------------------------------------------------------------------


def test_the_rigid_body_band_of_a_free_free_model_is_found_and_checked_independently():
    assembly = default_assembly()
    frf, band = assembly_structure(assembly, "tool.tip:y")
    assert band.kind == "free-free"
    assert band.lo_hz == pytest.approx(first_antiresonance(assembly), abs=2.0)
    assert band.apparent_mass_kg == pytest.approx(rigid_body_apparent_mass(assembly), rel=0.03)
    assert frf.frequency.hz[0] == band.lo_hz
    # the same from the data alone
    data = flexible_band(assembly.receptance("tool.tip:y", frequency=assembly.frequency))
    assert (data.kind, data.lo_hz) == ("free-free", band.lo_hz)


@pytest.mark.parametrize("k, kind", [("1e6 N/m", "suspended"), ("1e5 N/m", "suspended"), ("1e8 N/m", "supported"),
                                     ("5e8 N/m", "supported")])
def test_suspension_or_bearings_are_told_apart(k, kind):
    free = default_assembly()
    model = on_bearings(free, k=k)
    frf, band = assembly_structure(model, "tool.tip:y")
    assert band.kind == kind
    fa = first_antiresonance(free)
    if kind == "suspended":
        assert fa <= band.lo_hz <= 1.2 * fa and all(f < fa for f in band.suspension_hz)
        assert band.excluded_hz == (model.frequency.hz[0], band.lo_hz)
    else:
        assert band.lo_hz == model.frequency.hz[0] and band.excluded_hz is None


@pytest.mark.parametrize("variant", ["free-free", "bearings", "suspended"])
def test_recommendations_never_sit_on_rigid_body_or_suspension_lines(variant):
    free = default_assembly()
    model = {"free-free": free, "bearings": on_bearings(free), "suspended": on_bearings(free, k="1e6 N/m")}[variant]
    frf, band = assembly_structure(model, "tool.tip:y")
    cut = thesis_cut(feed_per_tooth="0.05 mm")
    lobes = zoa(xy_frf(frf), cut, SPEEDS, band=band)
    best = recommend(lobes, cut)
    rigid_top = first_antiresonance(free)  # the free-free model's rigid-body band ends here
    for r in (best, *best.runners_up):
        assert r.chatter_frequency_hz >= max(rigid_top, band.lo_hz) - 2.0
        assert r.chatter_frequency_hz >= band.lo_hz
    finite = np.isfinite(lobes.chatter_frequency_hz)
    assert np.all(lobes.chatter_frequency_hz[finite] >= band.lo_hz)
    # without the band (the old behaviour) the limit is set by rigid-body lines far below
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        everything = zoa(xy_frf(model.receptance("tool.tip:y", frequency=model.frequency)), cut, SPEEDS, band="all")
    if variant != "bearings":
        assert everything.absolute_limit_frequency_hz < rigid_top
        assert everything.absolute_limit_m < 0.5 * lobes.absolute_limit_m


def test_a_mass_line_over_the_whole_band_is_refused():
    f = Frequency.from_range("10 Hz", "100 Hz", "1 Hz")
    h = FRF.single(f, -1.0 / (2.0 * (2 * np.pi * f.hz) ** 2), output="x", input="x")
    with pytest.raises(InvalidValueError, match="mass line"):
        zoa(h, thesis_cut(), SPEEDS)


# -- 2. the recommendation and its margin ------------------------------------------------------


def lobes_and_cut(**cut_kw):
    frf, band = assembly_structure(default_assembly(), "tool.tip:y")
    cut = thesis_cut(**cut_kw)
    return zoa(xy_frf(frf), cut, SPEEDS, band=band), cut, frf, band


@pytest.mark.parametrize("margin, tolerance", [(0.2, 0.03), (0.1, 0.05), (0.35, 0.01)])
def test_the_margin_holds_at_every_speed_of_the_window_on_a_finer_grid(margin, tolerance):
    lobes, cut, frf, band = lobes_and_cut()
    best = recommend(lobes, cut, margin=margin, speed_tolerance=tolerance)
    assert isinstance(best, Recommendation) and best.margin == margin and len(best.runners_up) == 2
    for r in (best, *best.runners_up):
        lo, hi = r.window_rpm
        assert lo == pytest.approx(r.spindle_speed_rpm * (1 - tolerance))
        assert hi == pytest.approx(r.spindle_speed_rpm * (1 + tolerance))
        fine = zoa(xy_frf(frf), cut, Q_(np.linspace(lo, hi, 3001), "rpm"), band=band)  # computed anew
        assert np.all(r.depth_m <= (1 - margin) * fine.depth_limit_m * (1 + 1e-9))
        # and the margin is not wasted: the window's lowest limit is what the recommendation says
        assert fine.depth_limit_m.min() == pytest.approx(r.limit_depth_m, rel=2e-3)
        assert r.limit_depth_m <= fine.depth_limit_m.min() * (1 + 1e-9)
    # the choice: the largest removal rate a*n among the computed speeds whose window fits
    speeds = lobes.spindle_speed_rpm
    ok = (speeds * (1 - tolerance) >= speeds[0]) & (speeds * (1 + tolerance) <= speeds[-1])
    window_min, _, _ = lobes.window_minimum(speeds[ok] * (1 - tolerance), speeds[ok] * (1 + tolerance))
    score = (1 - margin) * window_min * speeds[ok]
    assert best.depth_m * best.spindle_speed_rpm == pytest.approx(score.max(), rel=1e-9)
    # runners-up come from other pockets, worse than the best
    assert all(abs(r.spindle_speed_rpm - best.spindle_speed_rpm) > 2 * tolerance * best.spindle_speed_rpm
               for r in best.runners_up)
    assert all(r.depth_m * r.spindle_speed_rpm <= best.depth_m * best.spindle_speed_rpm for r in best.runners_up)


def test_the_tip_of_a_lobe_is_not_recommended_when_its_flanks_fall():
    lobes, cut, _, _ = lobes_and_cut()
    tip_speed, tip_depth = lobes.best_speeds(1)[0]
    best = recommend(lobes, cut, margin=0.0, speed_tolerance=0.03)
    assert best.limit_depth_m < tip_depth  # the window sees the flanks
    assert best.depth_m < 0.95 * tip_depth


def test_with_an_frf_band_the_margin_holds_for_every_member():
    from substructure.sweep import sweep

    assembly = default_assembly()
    joint = assembly.joint("holder-tool")
    variants = [assembly.with_joint(joint.with_parameters(k={"yf": f"{k} N/m"})) for k in (1.2e7, 1.43e7, 1.7e7)]
    grid = Frequency.from_range("180 Hz", "5000 Hz", "2 Hz")
    result = sweep(variants, "tool.tip:y", frequency=grid)
    cut = thesis_cut()
    members = [zoa(xy_frf(result[i]), cut, SPEEDS, band="all") for i in range(3)]
    band = lobes_band(members, nominal=members[1])
    best = recommend(members[1], cut, band=band)
    assert best.band_members == 3
    lo, hi = best.window_rpm
    fine = Q_(np.linspace(lo, hi, 2001), "rpm")
    for i in range(3):
        check = zoa(xy_frf(result[i]), cut, fine, band="all")
        assert np.all(best.depth_m <= (1 - best.margin) * check.depth_limit_m * (1 + 1e-9))
    alone = recommend(members[1], cut)
    assert best.depth_m * best.spindle_speed_rpm <= alone.depth_m * alone.spindle_speed_rpm * (1 + 1e-12)


def test_semi_discretization_lobes_are_checked_by_new_runs():
    k = 0.03993 * (2 * np.pi * 922) ** 2
    model = ModalModel([Mode("x", "922 Hz", 0.011, Q_(k, "N/m")), Mode("y", "922 Hz", 0.011, Q_(k, "N/m"))])
    cut = MillingCut(2, "10 mm", "5 mm", kt="6e8 Pa", kn="2e8 Pa", milling="down")
    lobes = sdm(model, cut, spindle_speeds("9000 rpm", "16000 rpm", "250 rpm"))
    best = recommend(lobes, cut, speed_tolerance=0.02, count=1)
    lo, hi = best.window_rpm
    fine = sdm(model, cut, Q_(np.linspace(lo, hi, 41), "rpm"))
    assert np.all(best.depth_m <= (1 - best.margin) * fine.depth_limit_m * (1 + 0.01))  # bracket rtol 0.5 %


def test_power_torque_and_removal_rate_against_a_hand_calculation():
    cut = MillingCut(3, "16 mm", "4 mm", kt="800 MPa", kn="200 MPa", milling="down", feed_per_tooth="0.1 mm",
                     kte="25 N/mm", kne="20 N/mm")
    a, n = 2e-3, 12000.0
    mrr = a * 4e-3 * 3 * 0.1e-3 * n / 60.0
    assert removal_rate(cut, a, n) == pytest.approx(mrr, rel=1e-12)
    st, ex = cut.angles
    edge = 25e3 * a * 8e-3 * 3 * n / 60.0 * (ex - st)
    assert cut_power(cut, a, n) == pytest.approx(800e6 * mrr + edge, rel=1e-10)
    # power limits the depth: the recommended cut uses exactly what the spindle gives
    lobes = zoa(xy_frf(assembly_structure(default_assembly(), "tool.tip:y")[0]), cut, SPEEDS)
    limits = MachineLimits(power="1.5 kW", max_speed="20000 rpm")
    best = recommend(lobes, cut, limits)
    assert best.spindle_speed_rpm <= 20000
    if best.limited_by == "power":
        assert best.power_w == pytest.approx(1500.0, rel=1e-9)
    assert best.power_w <= 1500.0 * (1 + 1e-9)
    assert best.power_w == pytest.approx(float(cut_power(cut, best.depth_m, best.spindle_speed_rpm)))
    assert best.mrr_m3_per_s == pytest.approx(float(removal_rate(cut, best.depth_m, best.spindle_speed_rpm)))
    small = recommend(lobes, cut, MachineLimits(power="0.2 kW"))
    assert small.limited_by == "power" and small.power_w == pytest.approx(200.0, rel=1e-9)
    # a torque limit: P = T omega
    torque = recommend(lobes, cut, MachineLimits(torque="0.1 N*m"))
    assert torque.limited_by in ("torque", "power")
    assert torque.torque_n_m <= 0.1 * (1 + 1e-9)
    assert torque.power_w == pytest.approx(torque.torque_n_m * 2 * np.pi * torque.spindle_speed_rpm / 60)
    # the largest depth
    capped = recommend(lobes, cut, MachineLimits(max_depth="0.5 mm"))
    assert capped.depth_m == pytest.approx(0.5e-3) and capped.limited_by == "max depth"
    # a power curve that is zero outside its speeds: the recommendation stays inside
    curve = MachineLimits(power=[("3000 rpm", "1 kW"), ("10000 rpm", "3 kW")])
    inside = recommend(lobes, cut, curve)
    assert 3000 <= inside.spindle_speed_rpm <= 10000
    assert inside.power_w <= curve.power_w(inside.spindle_speed_rpm) * (1 + 1e-9)


def test_kienzle_power_against_an_independent_integral():
    entry = workpiece("steel-1045")
    cut = MillingCut.for_workpiece(4, "20 mm", entry, radial_depth="5 mm", feed_per_tooth="0.12 mm", kr=0.3)
    st, ex = cut.angles
    c = 0.12e-3

    def force(phi):  # N per m of depth: kc11 * h^(1 - mc), h in mm
        h_mm = c * np.sin(phi) * 1e3
        return 1500.0 * h_mm ** (1 - 0.22) * 1e3

    integral, _ = quad(force, st, ex)
    a, n = 1e-3, 3000.0
    assert cut_power(cut, a, n) == pytest.approx(a * n * 4 / 60 * 0.01 * integral, rel=1e-6)
    # stability uses the slope at the mean chip thickness
    hm = c * (np.cos(st) - np.cos(ex)) / (ex - st) * 1e3
    assert cut.kt_pa == pytest.approx((1 - 0.22) * 1500e6 * hm ** -0.22, rel=1e-12)


def test_recommendation_json_and_errors():
    lobes, cut, _, _ = lobes_and_cut(feed_per_tooth="0.05 mm")
    best = recommend(lobes, cut)
    out = best.to_json()
    assert JSON_KEYS <= set(out) and len(out["runners_up"]) == 2
    json.dumps(out, allow_nan=False)
    assert out["depth_m"] == pytest.approx((1 - out["margin"]) * out["limit_depth_m"])
    with pytest.raises(InvalidValueError, match="margin"):
        recommend(lobes, cut, margin=1.0)
    with pytest.raises(InvalidValueError, match="speed_tolerance"):
        recommend(lobes, cut, speed_tolerance=-0.1)
    with pytest.raises(InvalidValueError, match="not the cut"):
        recommend(lobes, attrs.evolve(cut, teeth=3))
    with pytest.raises(InvalidValueError, match="feed"):
        recommend(lobes, thesis_cut(), MachineLimits(power="5 kW"))
    narrow = zoa(xy_frf(assembly_structure(default_assembly(), "tool.tip:y")[0]), cut,
                 spindle_speeds("10000 rpm", "10500 rpm", "50 rpm"))
    with pytest.raises(InvalidValueError, match="window"):
        recommend(narrow, cut, speed_tolerance=0.1)
    with pytest.raises(UnitError):
        MachineLimits(max_speed="400 Hz")


# -- 3. the coefficient table -----------------------------------------------------------------


def test_the_table_loads_with_units_and_sources():
    table = workpieces()
    names = {w.name for w in table}
    assert {"aluminium-6061", "aluminium-7075", "steel-1045", "stainless-304", "titanium-ti6al4v",
            "grey-cast-iron"} <= names
    for w in table:
        assert len(w.source) > 40 and any(year in w.source for year in ("2017", "2021"))
        if w.model == "linear":
            assert w.kt.check("[pressure]") and w.kt.m_as("MPa") > 100
            assert w.kte is None or w.kte.check("[force] / [length]")
        else:
            assert w.kc11.check("[pressure]") and 0 < w.mc < 1 and w.kr is None
    assert workpiece("AL7075").kt.m_as("N/mm^2") == pytest.approx(767.01)
    assert workpiece("c45").kc11.m_as("MPa") == pytest.approx(1500)
    with pytest.raises(InvalidValueError, match="known"):
        workpiece("unobtainium")
    with pytest.raises(InvalidValueError, match="radial"):
        MillingCut.for_workpiece(4, "12 mm", "titanium", radial_depth="3 mm", feed_per_tooth="0.05 mm")
    with pytest.raises(InvalidValueError, match="feed"):
        MillingCut.for_workpiece(4, "12 mm", "titanium", radial_depth="3 mm", kr=0.3)


def test_a_user_table_is_searched_first_and_checked(tmp_path):
    path = tmp_path / "mine.toml"
    path.write_text('[[workpiece]]\nname = "my-7075"\naliases = ["7075"]\nmodel = "linear"\nkt = "700 MPa"\n'
                    'kr = "210 MPa"\nsource = "our own calibration cuts, 2024"\n', encoding="utf-8")
    assert workpiece("7075", path).kt.m_as("MPa") == 700
    bad = tmp_path / "bad.toml"
    bad.write_text('[[workpiece]]\nname = "x"\nmodel = "linear"\nkt = "700"\nsource = "s"\n', encoding="utf-8")
    with pytest.raises(FileFormatError, match="kt"):
        load_workpieces(bad)
    bad.write_text('[[workpiece]]\nname = "x"\nmodel = "linear"\nkt = "700 MPa"\n', encoding="utf-8")
    with pytest.raises(FileFormatError, match="source"):
        load_workpieces(bad)


# -- 4. the plot ---------------------------------------------------------------------------------


def test_the_lobe_plot_shows_the_recommendation_and_says_things_plainly():
    import matplotlib.pyplot as plt

    lobes, cut, _, _ = lobes_and_cut()
    best = recommend(lobes, cut)
    for factor in (3.0, 0.1):  # even with an axis meant to clip far below the recommendation
        fig = lobes.plot(lobes=True, recommendation=best, ylim_factor=factor, title="a long title " * 20)
        ax = fig.axes[0]
        y0, y1 = ax.get_ylim()
        x0, x1 = ax.get_xlim()
        assert y0 <= best.depth_m * 1e3 <= y1 and best.limit_depth_m * 1e3 < y1
        assert x0 <= best.window_rpm[0] and best.window_rpm[1] <= x1
        labels = [t.get_text() for t in ax.get_legend().get_texts()]
        assert any("zero-order" in t for t in labels) and not any("zoa" in t for t in labels)
        assert any("recommended" in t for t in labels) and any("safe window" in t for t in labels)
        assert "\n" in ax.get_title() and "mm" in ax.get_ylabel() and "rpm" in ax.get_xlabel()
        plt.close(fig)


# -- 5. size limits --------------------------------------------------------------------------------


def test_size_limits_are_named_before_anything_big_is_allocated():
    with pytest.raises(InvalidValueError, match="MAX_SPEEDS"):
        spindle_speeds("2000 rpm", "24000 rpm", "1e-4 rpm")
    assert MAX_SPEEDS >= 10_000
    model = ModalModel([Mode("x", "922 Hz", 1e-12, "1e7 N/m")])
    with pytest.raises(InvalidValueError, match="MAX_DEFAULT_LINES"):
        zoa(model, thesis_cut(), SPEEDS)
    k = 0.03993 * (2 * np.pi * 922) ** 2
    ok = ModalModel([Mode("x", "922 Hz", 0.011, Q_(k, "N/m"))])
    with pytest.raises(InvalidValueError, match="MAX_INTERVALS"):
        sdm(ok, thesis_cut(), SPEEDS, intervals=100000)
    f = Frequency(np.linspace(100.0, 5000.0, 1_000_000))
    h = FRF.single(f, 1.0 / (1e7 * (1 - (f.hz / 1500) ** 2 + 0.04j * f.hz / 1500)), output="x", input="x")
    with pytest.raises(InvalidValueError, match="MAX_LOBE_POINTS"):
        zoa(h, thesis_cut(), SPEEDS)


def test_window_samples_cover_each_window_and_windows_of_one_width_share_them():
    seen: list[np.ndarray] = []

    def evaluate(n):
        seen.append(np.array(n))
        return 1.0 + (n - 12000.0) ** 2 * 1e-6, np.zeros(n.size)  # lowest at 12,000 rpm

    x = 0.03
    centres = np.array([11000.0, 11050.0, 13000.0])
    depth, at, _ = sampled_window_minimum(evaluate, centres * (1 - x), centres * (1 + x))
    first = seen[0]
    for lo, hi in zip(centres * (1 - x), centres * (1 + x)):
        inside = first[(first >= lo) & (first <= hi)]
        assert inside.size >= 33 and lo in inside and hi in inside
        assert np.diff(np.log(np.unique(inside))).max() <= np.log(hi / lo) / 32 * (1 + 1e-9)
    assert at[0] == pytest.approx(11000.0 * (1 + x)) and at[2] == pytest.approx(13000.0 * (1 - x))
    assert at[1] == pytest.approx(11050.0 * (1 + x))
    assert depth[0] == pytest.approx(1.0 + (11330.0 - 12000.0) ** 2 * 1e-6)
    sampled_window_minimum(evaluate, np.array([11025.0]) * (1 - x), np.array([11025.0]) * (1 + x))
    ladder = lambda s: set(s[(s > 11050.0 * (1 - x)) & (s < 11000.0 * (1 + x))].tolist())  # noqa: E731
    assert ladder(seen[1]) - {11025.0 * (1 - x), 11025.0 * (1 + x)} <= ladder(first)  # the same speeds again


def test_semi_discretization_windows_evaluate_a_speed_once():
    k = 0.03993 * (2 * np.pi * 922) ** 2
    model = ModalModel([Mode("x", "922 Hz", 0.011, Q_(k, "N/m"))])
    cut = MillingCut(2, "10 mm", "5 mm", kt="6e8 Pa", kn="2e8 Pa", milling="down")
    lines: list[str] = []
    lobes = sdm(model, cut, spindle_speeds("9000 rpm", "16000 rpm", "250 rpm"), progress=lines.append)
    before = len(lines)
    lo, hi = np.array([11000.0, 11100.0]) * 0.97, np.array([11000.0, 11100.0]) * 1.03
    first = lobes.window_minimum(lo, hi)
    runs = lines[before:]
    assert len(runs) == 1 and runs[0].startswith("semi-discretization: a new run on ")
    assert int(runs[0].split("a new run on ")[1].split()[0]) < 2 * 33  # the two windows share most samples
    again = lobes.window_minimum(lo, hi)
    assert len(lines) == before + 1  # nothing new to compute
    for a, b in zip(first, again):
        np.testing.assert_array_equal(a, b)
    depth, chatter = lobes.limit_on(lobes.spindle_speed_rpm)  # the lobes' own speeds keep their limits
    np.testing.assert_array_equal(depth, lobes.depth_limit_m)
    assert len(lines) == before + 1
    fine = sdm(model, cut, Q_(np.linspace(lo[0], hi[0], 41), "rpm"))
    assert first[0][0] <= fine.depth_limit_m.min() * (1 + 0.01)  # bracket rtol 0.5 %


def test_semi_discretization_lobes_pickle_without_their_progress_lines():
    import pickle

    model = ModalModel([Mode("x", "922 Hz", 0.011, "1.34e6 N/m")])
    cut = MillingCut(2, "10 mm", "5 mm", kt="6e8 Pa", kn="2e8 Pa", milling="down")
    lines: list[str] = []
    lobes = sdm(model, cut, spindle_speeds("10000 rpm", "11000 rpm", "500 rpm"), progress=lambda t: lines.append(t))
    again = pickle.loads(pickle.dumps(lobes))  # a lambda does not pickle: it is left behind
    np.testing.assert_array_equal(again.limit_on([10250.0])[0], lobes.limit_on([10250.0])[0])


def test_speeds_outside_the_computed_range_are_refused_by_name():
    lobes = Lobes("sdm", np.array([1000.0, 2000.0, 3000.0]), np.array([1e-3, 2e-3, 1.5e-3]), np.full(3, 900.0))
    with pytest.raises(InvalidValueError, match=r"lo_rpm, hi_rpm: expected speeds within the computed range 1000"):
        lobes.window_minimum([500.0], [1500.0])
    with pytest.raises(InvalidValueError, match="speed_rpm: expected speeds within"):
        lobes.limit_on([3500.0])
    depth, at, _ = lobes.window_minimum([1500.0, 1000.0], [1500.0, 3000.0])  # a window of no width is its speed
    np.testing.assert_allclose(depth, [1.5e-3, 1e-3])
    np.testing.assert_allclose(at, [1500.0, 1000.0])


def test_a_narrow_window_beside_a_wide_one_samples_each_by_its_own_width():
    seen: list[int] = []

    def evaluate(n):
        seen.append(n.size)
        return np.ones(n.size), np.zeros(n.size)

    sampled_window_minimum(evaluate, np.array([1000.0, 2000.0]), np.array([3000.0, 2001.0]))
    assert 66 <= seen[0] <= 2 * 37  # about 33 each, not the narrow window's spacing over the wide one


def test_sampled_window_minima_refuse_windows_and_counts_they_cannot_sample():
    def evaluate(n):
        return np.abs(np.sin(n / 700.0)) + 0.1, n / 60.0

    with warnings.catch_warnings():
        warnings.simplefilter("error")  # no numpy warnings on the way to the message
        for lo, hi, message in (
                ([-5.0], [8000.0], "lo: got -5; expected positive speeds"),
                ([0.0], [8000.0], "lo: got 0; expected positive speeds"),
                ([], [], "lo: got no values; expected one or more window ends"),
                ([6000.0], [np.nan], "hi: got nan; expected finite speeds"),
                ([9000.0], [8000.0], r"lo, hi: got the window 9000\.\.8000 rpm \(index 0\); expected lo <= hi"),
                ([6000.0, 7000.0], [8000.0], "lo, hi: got 2 and 1 ends"),
                ([[6000.0]], [[8000.0]], r"lo: got shape \(1, 1\)"),
                (["6000 rpm"], [8000.0], r"lo: got \['6000 rpm'\]; expected speeds in rpm as plain numbers")):
            with pytest.raises(InvalidValueError, match=message):
                sampled_window_minimum(evaluate, lo, hi)
        for count in (0, 1, 2.5, True):
            with pytest.raises(InvalidValueError, match=f"count: got {count!r}; expected a whole number >= 2"):
                sampled_window_minimum(evaluate, np.array([6000.0]), np.array([8000.0]), count=count)
        depth, at, _ = sampled_window_minimum(evaluate, 6000.0, 8000.0, count=2)  # the ends and a ladder point
        assert 6000.0 <= at[0] <= 8000.0 and depth[0] == pytest.approx(evaluate(at)[0][0])
