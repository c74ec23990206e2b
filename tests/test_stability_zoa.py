"""Zero-order lobes (substructure.stability.zoa): closed form, the lobe equation, data vs modes, errors."""

from __future__ import annotations

import sys
import warnings

import numpy as np
import pytest

from substructure import FRF, Frequency, FrequencyAxisMismatchError, InvalidValueError, UnitError, default_assembly
from substructure.stability import (MillingCut, ModalModel, Mode, NoRecommendationError, StabilityWarning,
                                    TurningCut, recommend, spindle_speeds, xy_frf, zoa)
from substructure.units import Q_

M, FN, ZETA = 0.03993, 922.0, 0.011
K = M * (2 * np.pi * FN) ** 2


def benchmark_model() -> ModalModel:
    return ModalModel([Mode("x", Q_(FN, "Hz"), ZETA, Q_(K, "N/m"))])


def benchmark_cut(immersion: float) -> MillingCut:
    return MillingCut.from_spec(2, "10 mm", immersion=immersion, milling="down", kt="6e8 Pa", kn="2e8 Pa")


def multimode_model() -> ModalModel:
    return ModalModel([
        Mode("x", "650 Hz", 0.03, "2.0e7 N/m"), Mode("x", "1450 Hz", 0.02, "6.0e6 N/m"),
        Mode("x", "2900 Hz", 0.015, "1.5e7 N/m"), Mode("y", "700 Hz", 0.025, "1.8e7 N/m"),
        Mode("y", "1600 Hz", 0.018, "8.0e6 N/m"),
    ])


SPEEDS = spindle_speeds("4000 rpm", "24000 rpm", "20 rpm")


# -- closed form ---------------------------------------------------------------------


def test_absolute_limit_single_mode_slot_closed_form():
    cut = benchmark_cut(1.0)
    h0 = -cut.mean_force_matrix()[0, 0]  # the mean of h(t): N Kn / 4 for the slot
    assert h0 == pytest.approx(2 * 2e8 / 4)
    lobes = zoa(benchmark_model(), cut, SPEEDS)
    closed = 2 * K * ZETA * (1 + ZETA) / h0
    assert lobes.absolute_limit_m == pytest.approx(closed, rel=1e-6)
    assert closed * 1e3 == pytest.approx(0.2981, abs=5e-5)  # the benchmark's number
    assert lobes.absolute_limit_frequency_hz == pytest.approx(FN * np.sqrt(1 + 2 * ZETA), rel=1e-6)
    assert lobes.depth_limit_m.min() >= closed * (1 - 1e-9)


@pytest.mark.parametrize("immersion, milling", [(0.5, "up"), (0.25, "down"), (0.05, "down"), (0.05, "up")])
def test_absolute_limit_closed_form_with_directional_factor(immersion, milling):
    cut = MillingCut.from_spec(3, "10 mm", immersion=immersion, milling=milling, kt="6e8 Pa", kn="2e8 Pa")
    h0 = -cut.mean_force_matrix()[0, 0]
    # Re G is at least -1/(4 k zeta (1 + zeta)) and at most 1/(4 k zeta (1 - zeta)).
    closed = 2 * K * ZETA * (1 + ZETA) / h0 if h0 > 0 else 2 * K * ZETA * (1 - ZETA) / -h0
    assert zoa(benchmark_model(), cut, SPEEDS).absolute_limit_m == pytest.approx(closed, rel=1e-6)


def test_turning_is_tlusty():
    cut = TurningCut("2000 MPa", orientation=0.7)
    lobes = zoa(benchmark_model(), cut, SPEEDS)
    assert lobes.absolute_limit_m == pytest.approx(4 * K * ZETA * (1 + ZETA) / (2 * 2e9 * 0.7), rel=1e-6)


# -- the lobes solve the characteristic equation ------------------------------------


def characteristic_residual(k0, g, depth, chatter_hz, speed_rpm, teeth):
    """|det(I - a (1 - exp(-i w T)) K0 G)| written out, with the relative size of its terms."""
    period = 60.0 / (teeth * speed_rpm)
    m = depth * (1 - np.exp(-2j * np.pi * chatter_hz * period)) * (k0 @ g)
    det = (1 - m[0, 0]) * (1 - m[1, 1]) - m[0, 1] * m[1, 0]
    return abs(det) / (1 + np.abs(m).sum() + abs(m[0, 0] * m[1, 1]) + abs(m[0, 1] * m[1, 0]))


def test_depth_limits_and_chatter_frequencies_solve_the_characteristic_equation():
    model = multimode_model()
    cut = MillingCut(4, "12 mm", "5 mm", kt="700 MPa", kn="210 MPa", milling="up")
    grid = Frequency.from_range("300 Hz", "4000 Hz", "0.5 Hz")
    lobes = zoa(FRF(grid, model.receptance(grid.hz), ("x", "y"), ("x", "y")), cut, SPEEDS)
    k0 = cut.mean_force_matrix()
    rng = np.random.default_rng(5)
    for i in rng.choice(np.flatnonzero(np.isfinite(lobes.depth_limit_m)), 40, replace=False):
        g = model.receptance([lobes.chatter_frequency_hz[i]])[0]
        res = characteristic_residual(k0, g, lobes.depth_limit_m[i], lobes.chatter_frequency_hz[i],
                                      lobes.spindle_speed_rpm[i], cut.teeth)
        assert res < 2e-3, (lobes.spindle_speed_rpm[i], res)


def test_cross_terms_are_used_and_solve_the_equation():
    f = Frequency.from_range("400 Hz", "2500 Hz", "0.1 Hz")
    g = ModalModel([Mode("x", "900 Hz", 0.02, "1e7 N/m")]).receptance(f.hz)[:, 0, 0]
    angle = np.radians(30)  # one mode along a direction 30 degrees from x
    u = np.array([np.cos(angle), np.sin(angle)])
    data = g[:, None, None] * np.outer(u, u)[None]
    parts = [FRF.single(f, data[:, i, j]) for i, j in ((0, 0), (1, 1), (0, 1), (1, 0))]
    full = xy_frf(*parts)
    diagonal = xy_frf(parts[0], parts[1])
    cut = MillingCut(3, "10 mm", "4 mm", kt="700 MPa", kn="210 MPa", milling="down")
    with_cross, without = zoa(full, cut, SPEEDS), zoa(diagonal, cut, SPEEDS)
    assert np.abs(with_cross.depth_limit_m / without.depth_limit_m - 1).max() > 0.05
    k0 = cut.mean_force_matrix()
    for i in np.flatnonzero(np.isfinite(with_cross.depth_limit_m))[::97]:
        fc = with_cross.chatter_frequency_hz[i]
        gi = np.array([[np.interp(fc, f.hz, data[:, r, c].real) + 1j * np.interp(fc, f.hz, data[:, r, c].imag)
                        for c in range(2)] for r in range(2)])
        assert characteristic_residual(k0, gi, with_cross.depth_limit_m[i], fc, with_cross.spindle_speed_rpm[i],
                                       cut.teeth) < 2e-3


# -- data or modes: the same lobes --------------------------------------------------


def test_multimode_frf_as_data_or_as_modes_gives_the_same_lobes():
    model = multimode_model()
    cut = MillingCut(4, "12 mm", "3 mm", kt="625 MPa", kn="100 MPa", milling="up")
    grid = Frequency.from_range("200 Hz", "6000 Hz", "0.5 Hz")
    data = FRF(grid, model.receptance(grid.hz), ("x", "y"), ("x", "y"))
    from_data = zoa(data, cut, SPEEDS)
    from_modes = zoa(model, cut, SPEEDS)
    assert from_data.absolute_limit_m == pytest.approx(from_modes.absolute_limit_m, rel=1e-4)
    assert from_data.absolute_limit_frequency_hz == pytest.approx(from_modes.absolute_limit_frequency_hz, rel=1e-3)
    finite = np.isfinite(from_modes.depth_limit_m)
    assert finite.mean() > 0.99
    np.testing.assert_array_equal(finite, np.isfinite(from_data.depth_limit_m))
    np.testing.assert_allclose(from_data.depth_limit_m[finite], from_modes.depth_limit_m[finite], rtol=5e-3)
    np.testing.assert_allclose(from_data.chatter_frequency_hz[finite], from_modes.chatter_frequency_hz[finite],
                               rtol=2e-3)
    assert np.median(np.abs(from_data.depth_limit_m / from_modes.depth_limit_m - 1)) < 1e-4


def test_one_symmetric_frf_means_y_equals_x():
    grid = Frequency.from_range("300 Hz", "3000 Hz", "1 Hz")
    h = FRF.single(grid, multimode_model().receptance(grid.hz)[:, 0, 0], "tool.tip:y", "tool.tip:y")
    cut = MillingCut(4, "12 mm", "3 mm", kt="625 MPa", kn="100 MPa")
    a, b = zoa(h, cut, SPEEDS), zoa(xy_frf(h, h), cut, SPEEDS)
    np.testing.assert_array_equal(a.depth_limit_m, b.depth_limit_m)


def test_lobes_are_listed_and_the_limit_is_their_lower_envelope():
    lobes = zoa(benchmark_model(), benchmark_cut(1.0), SPEEDS)
    env, grid = lobes.depth_limit_m, lobes.spindle_speed_rpm
    assert len(lobes.lobes) >= 3
    for speed, depth in lobes.lobes:
        ok = np.isfinite(speed) & (speed >= grid[0]) & (speed < grid[-1])
        j = np.searchsorted(grid, speed[ok], side="right") - 1
        # between two grid speeds a lobe lies above the lower of the two limits (up to its flat floor)
        assert np.all(depth[ok] >= np.minimum(env[j], env[j + 1]) * (1 - 1e-3))


# -- what the FRF must hold, and warnings --------------------------------------------


def test_frf_without_the_xy_data_is_an_error():
    assembly_frf = default_assembly().receptance("tool.tip",
                                                 frequency=Frequency.from_range("500 Hz", "900 Hz", "100 Hz"))
    cut = MillingCut(4, "12 mm", "3 mm", kt="625 MPa", kn="100 MPa")
    with pytest.raises(InvalidValueError, match="x \\(feed\\) and y.*xy_frf"):
        zoa(assembly_frf, cut, SPEEDS)  # (y, theta) receptances, not x and y
    with pytest.raises(InvalidValueError, match="rotational"):
        xy_frf(assembly_frf["tool.tip:theta", "tool.tip:theta"])
    with pytest.raises(InvalidValueError, match="both cross receptances"):
        xy_frf(assembly_frf["tool.tip:y", "tool.tip:y"], xy=assembly_frf["tool.tip:y", "tool.tip:y"])
    other = FRF.single(Frequency.from_range("500 Hz", "900 Hz", "50 Hz"), np.ones(9) * 1e-7)
    with pytest.raises(FrequencyAxisMismatchError, match="interpolate"):
        xy_frf(assembly_frf["tool.tip:y", "tool.tip:y"], other)
    with pytest.raises(InvalidValueError, match="ModalModel"):
        zoa(np.ones(10), cut, SPEEDS)


def test_speeds_in_hz_are_an_error():
    with pytest.raises(UnitError, match="rpm"):
        zoa(benchmark_model(), benchmark_cut(1.0), Q_(np.linspace(100, 300, 50), "Hz"))
    with pytest.raises(UnitError):
        zoa(benchmark_model(), benchmark_cut(1.0), np.linspace(5000, 20000, 50))


def test_a_limit_at_the_edge_of_the_band_warns_when_detection_is_off():
    assembly = default_assembly()  # free-free: rigid-body motion at the lowest lines
    h = assembly.receptance("tool.tip:y", frequency=Frequency.from_range("20 Hz", "5000 Hz", "10 Hz"))
    cut = MillingCut(4, "12 mm", "3 mm", kt="625 MPa", kn="100 MPa")
    with pytest.warns(StabilityWarning, match="first line"):
        zoa(h, cut, SPEEDS, band="all")
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        zoa(h.crop("500 Hz", "5000 Hz"), cut, SPEEDS)


def test_by_default_the_rigid_body_mass_line_is_left_out():
    assembly = default_assembly()
    h = assembly.receptance("tool.tip:y", frequency=Frequency.from_range("20 Hz", "5000 Hz", "10 Hz"))
    cut = MillingCut(4, "12 mm", "3 mm", kt="625 MPa", kn="100 MPa")
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        lobes = zoa(h, cut, SPEEDS)
    assert lobes.band.kind == "free-free" and 150 <= lobes.band.lo_hz <= 250
    finite = np.isfinite(lobes.chatter_frequency_hz)
    assert np.all(lobes.chatter_frequency_hz[finite] >= lobes.band.lo_hz)
    # the same as cropping by hand above the antiresonance
    by_hand = zoa(h.crop(lobes.band.lo_hz, None), cut, SPEEDS, band="all")
    np.testing.assert_allclose(lobes.depth_limit_m, by_hand.depth_limit_m)
    assert lobes.absolute_limit_m == pytest.approx(by_hand.absolute_limit_m)


def test_no_chatter_possible_gives_no_limit():
    # a mode only in y and a turning cut in x: the cut cannot excite it
    model = ModalModel([Mode("y", "900 Hz", 0.02, "1e7 N/m")])
    lobes = zoa(model, TurningCut("2000 MPa"), SPEEDS)
    assert np.all(np.isinf(lobes.depth_limit_m)) and lobes.absolute_limit_m == np.inf
    assert lobes.to_json()["absolute_limit_m"] is None


def test_a_band_without_the_resonance_is_an_error_and_a_minimum_on_its_edge_a_warning():
    f = np.arange(10.0, 2000.0, 0.25)
    r = f / FN
    frf = FRF.single(Frequency(f), 1.0 / (K * (1 - r ** 2 + 2j * ZETA * r)), output="t:y", input="t:y")
    cut = benchmark_cut(1.0)
    modes = ModalModel([Mode(d, Q_(FN, "Hz"), ZETA, Q_(K, "N/m")) for d in "xy"])  # y = x, as one FRF means
    closed = zoa(modes, cut, SPEEDS).absolute_limit_m
    with pytest.raises(InvalidValueError, match=r"never negative from 10 to 300 Hz: the band holds no resonance"):
        zoa(frf, cut, SPEEDS, band=(10.0, 300.0))  # Re H > 0 below the mode
    with pytest.warns(StabilityWarning, match=r"at the first line of the band \(1000 Hz\): the minimum may lie "):
        edge = zoa(frf, cut, SPEEDS, band=(1000.0, 1001.0))
    assert edge.absolute_limit_m > 2 * closed  # far too deep: why it is said
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        whole = zoa(frf, cut, SPEEDS, band=(500.0, 1500.0))
    assert whole.absolute_limit_m == pytest.approx(closed, rel=1e-3)


def test_low_speed_turning_from_modes_takes_a_graded_grid_within_the_cap(monkeypatch):
    """The default grid (a relative step of zeta / 50 from 0.3 to 3 f_n) times the lobes below 700 rpm exceeds
    MAX_LOBE_POINTS: the lines are graded around the mode instead, against the closed form and the default grid."""
    cut = TurningCut("2000 MPa")
    closed = 2 * K * ZETA * (1 + ZETA) / 2e9  # -1 / (2 Kf min Re G), min Re G = -1 / (4 k zeta (1 + zeta))
    low = zoa(benchmark_model(), cut, spindle_speeds("500 rpm", "3000 rpm", "10 rpm"))
    assert low.absolute_limit_m == pytest.approx(closed, rel=1e-9)
    assert low.depth_limit_m.min() == pytest.approx(closed, rel=2e-4)  # dense lobes reach down to it
    assert np.all(low.depth_limit_m >= closed * (1 - 1e-9))
    speeds = spindle_speeds("1000 rpm", "3000 rpm", "10 rpm")  # the default grid fits: 3.5e6 points
    default = zoa(benchmark_model(), cut, speeds)
    module = sys.modules[zoa.__module__]
    monkeypatch.setattr(module, "MAX_LOBE_POINTS", 1_000_000)
    graded = zoa(benchmark_model(), cut, speeds)
    np.testing.assert_allclose(graded.depth_limit_m, default.depth_limit_m, rtol=5e-4)
    np.testing.assert_allclose(graded.chatter_frequency_hz, default.chatter_frequency_hz, rtol=1e-5)
    with pytest.raises(InvalidValueError, match=r"lines graded around the modes x \d+ lobes x 2 = .* down to 100 rpm, "
                                                r"more than the limit MAX_LOBE_POINTS = 1e\+06 .*; raise the lowest "
                                                r"spindle speed to ([0-9.]+) rpm or more") as info:
        zoa(benchmark_model(), cut, spindle_speeds("100 rpm", "3000 rpm", "10 rpm"))
    lowest = float(str(info.value).split("spindle speed to ")[1].split(" rpm")[0])
    assert zoa(benchmark_model(), cut, Q_([np.ceil(lowest), 3000.0], "rpm")).absolute_limit_m == \
        pytest.approx(closed, rel=1e-9)


def _two_modes(f):
    """A driving point of two modes (closed form): 922 Hz, and a more flexible one at 1500 Hz."""
    r1, r2 = f / FN, f / 1500.0
    return 1.0 / (K * (1 - r1 ** 2 + 2j * ZETA * r1)) + 1.0 / (0.5 * K * (1 - r2 ** 2 + 2j * 0.01 * r2))


@pytest.mark.parametrize("top, warned", [(1400.0, True), (1100.0, True), (2500.0, False), (950.0, False)])
def test_an_frf_ending_on_the_flank_of_a_mode_above_its_band_warns(top, warned):
    # a soft hammer tip's band ended below the tool mode: the lobes were drawn from the lesser mode, their
    # recommendation five to twenty times too deep, without a word
    f = np.arange(100.0, top, 0.5)
    frf = FRF.single(Frequency(f), _two_modes(f), output="t:y", input="t:y")
    cut = benchmark_cut(1.0)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        lobes = zoa(frf, cut, SPEEDS, band="all")
    said = [str(w.message) for w in caught if "a mode lies above the band" in str(w.message)]
    assert bool(said) == warned, said
    if warned:
        (text,) = said
        assert text.startswith("zoa: a mode lies above the band: the FRF (t:y) rises from ")
        assert f"to the band's last line ({f[-1]:g} Hz)" in text and lobes.band.above in text
        with pytest.raises(NoRecommendationError, match=r"a mode lies above the FRF's band \(the FRF \(t:y\) rises"):
            recommend(lobes, cut)  # the lobes stand; a depth to cut at would ignore the mode above
        full = zoa(FRF.single(Frequency(np.arange(100.0, 3000.0, 0.5)), _two_modes(np.arange(100.0, 3000.0, 0.5)),
                              output="t:y", input="t:y"), cut, SPEEDS, band="all")
        assert lobes.absolute_limit_m > 1.5 * full.absolute_limit_m  # what the warning is for
    else:
        assert lobes.band.above is None


def test_a_model_s_grid_that_stops_below_a_mode_as_flexible_as_the_band_s_is_refused():
    from substructure.stability import assembly_structure

    assembly = default_assembly()  # its tool mode at about 1.5 kHz is the most flexible
    with pytest.raises(InvalidValueError, match=r"frequency: the grid stops at 1200 Hz, below a mode of the model at "
                                                r"about 1[45]\d\d Hz .* raise the grid's stop above"):
        assembly_structure(assembly, "tool.tip:y", Frequency.from_range("20 Hz", "1200 Hz", "2 Hz"))
    frf, band = assembly_structure(assembly, "tool.tip:y", Frequency.from_range("20 Hz", "5000 Hz", "2 Hz"))
    assert band.hi_hz == 5000.0  # the modes above 5 kHz are far stiffer at the tool point: accepted
    frf, band = assembly_structure(assembly, "tool.tip:y", Frequency.from_range("20 Hz", "2500 Hz", "2 Hz"))
    assert band.model and band.hi_hz == 2500.0  # its mode at 3.8 kHz, under half as flexible: accepted


def test_an_frf_gone_to_noise_above_the_hammer_s_band_is_no_mode_above_it():
    # beyond a hammer's band the force spectrum falls and H1's noise grows: |H| rises to the band's end, roughly
    assembly = default_assembly()
    grid = Frequency.from_range("2 Hz", "12800 Hz", "2 Hz")
    h = assembly.receptance("tool.tip:y", frequency=grid).data[:, 0, 0]
    rng = np.random.default_rng(7)
    cut = MillingCut(4, "12 mm", "3 mm", kt="625 MPa", kn="100 MPa")
    force = 1.0 / (1.0 + (grid.hz / 5000.0) ** 4)
    for _ in range(5):
        noisy = h + 1.3e-9 * (rng.normal(size=h.size) + 1j * rng.normal(size=h.size)) / force
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            zoa(FRF.single(grid, noisy, output="t:y", input="t:y"), cut, SPEEDS)
        assert not [w for w in caught if "a mode lies above" in str(w.message)]
    # the flank of the tool mode under 2 % of noise is one
    grid = Frequency.from_range("20 Hz", "1400 Hz", "2 Hz")
    h = assembly.receptance("tool.tip:y", frequency=grid).data[:, 0, 0]
    noisy = h * np.exp(0.02 * (rng.normal(size=h.size) + 1j * rng.normal(size=h.size)))
    with pytest.warns(StabilityWarning, match="a mode lies above the band"):
        zoa(FRF.single(grid, noisy, output="t:y", input="t:y"), cut, SPEEDS)


def test_a_model_with_a_measured_component_is_judged_as_data_above_its_grid():
    # a measured spindle-holder (known on its own lines only) cannot be probed above the grid: the probe raised
    from substructure import Assembly, MeasuredComponent
    from substructure.stability import assembly_structure

    assembly = default_assembly()
    cut = MillingCut(4, "12 mm", "3 mm", kt="625 MPa", kn="100 MPa")
    for stop, warned in (("5000 Hz", False), ("1400 Hz", True)):
        grid = Frequency.from_range("20 Hz", stop, "2 Hz")
        measured = MeasuredComponent("spindle-holder", assembly.without("tool").receptance("holder.tip",
                                                                                          frequency=grid))
        semi = Assembly("semi", components=(measured, assembly.component("tool")),
                        joints=(assembly.joint("holder-tool"),), frequency=grid)
        frf, band = assembly_structure(semi, "tool.tip:y")
        assert not band.model and band.hi_hz == grid.hz[-1]
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            zoa(frf, cut, SPEEDS, band=band)
        assert any("a mode lies above the band" in str(w.message) for w in caught) == warned
