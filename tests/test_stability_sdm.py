"""Semi-discretization (substructure.stability.sdm): kernels, convergence, the benchmark, errors.

The comparison with a time-domain simulation is in test_stability_timedomain.py.
"""

from __future__ import annotations

import importlib

import numpy as np
import pytest
from scipy.linalg import expm

from substructure import FRF, Frequency, InvalidValueError, UnitError
from substructure.stability import (MillingCut, ModalModel, Mode, TurningCut, spectral_radius, spindle_speeds, sdm,
                                    zoa)
from substructure.units import Q_

sdm_module = importlib.import_module("substructure.stability.sdm")

M, FN, ZETA = 0.03993, 922.0, 0.011
K = M * (2 * np.pi * FN) ** 2
MODEL = ModalModel([Mode("x", Q_(FN, "Hz"), ZETA, Q_(K, "N/m"))])


def benchmark_cut(immersion):
    return MillingCut.from_spec(2, "10 mm", immersion=immersion, milling="down", kt="6e8 Pa", kn="2e8 Pa")


def floors(depth):
    """Indices of the lobe floors: local minima below twice the lowest limit."""
    return [i for i in range(1, depth.size - 1)
            if depth[i] <= depth[i - 1] and depth[i] < depth[i + 1] and depth[i] < 2 * depth.min()]


def test_batched_matrix_exponential_matches_scipy():
    rng = np.random.default_rng(3)
    a = rng.standard_normal((40, 6, 6)) * rng.choice([0.01, 1.0, 30.0], size=(40, 1, 1))
    expected = np.array([expm(x) for x in a])
    np.testing.assert_allclose(sdm_module.expm_batch(a), expected, rtol=1e-10, atol=1e-12 * np.abs(expected).max())
    np.testing.assert_allclose(sdm_module.expm_batch(np.zeros((2, 3, 3))), np.broadcast_to(np.eye(3), (2, 3, 3)),
                               atol=1e-15)


def test_without_cutting_the_spectral_radius_is_the_free_decay():
    speeds = Q_([6000.0, 15000.0], "rpm")
    rho = spectral_radius(MODEL, benchmark_cut(0.3), speeds, Q_(0.0, "m"))[:, 0]
    period = 60.0 / (2 * speeds.m)
    np.testing.assert_allclose(rho, np.exp(-ZETA * 2 * np.pi * FN * period), rtol=1e-9)


def test_spectral_radius_grows_through_one_at_the_limit():
    cut = benchmark_cut(1.0)
    lobes = sdm(MODEL, cut, Q_([16000.0], "rpm"))
    a = lobes.depth_limit_m[0]
    rho = spectral_radius(MODEL, cut, Q_([16000.0], "rpm"), Q_([0.99 * a, 1.01 * a], "m"))[0]
    assert rho[0] < 1 < rho[1]


@pytest.mark.parametrize("immersion", [1.0, 0.05])
def test_semi_discretization_is_converged_and_reports_its_discretisation(immersion):
    speeds = spindle_speeds("6000 rpm", "24000 rpm", "300 rpm")
    cut = benchmark_cut(immersion)
    default = sdm(MODEL, cut, speeds)
    fine = sdm(MODEL, cut, speeds, max_phase_step=0.1, rtol=0.001)
    info = default.discretisation
    assert info["scheme"].startswith("updated first-order semi-discretization")
    assert info["max_phase_step_rad"] == 0.2 and info["depth_rtol"] == 0.005
    lo, hi = info["intervals_in_cut"]
    assert 20 <= lo <= hi
    assert info["monodromy_order"] == [2 + k for k in info["intervals_per_period"]]  # one mode, one direction
    assert info["arnoldi_from_order"] == 400
    change = np.abs(default.depth_limit_m / fine.depth_limit_m - 1)
    assert np.median(change) < 0.005
    for i in floors(fine.depth_limit_m):  # where the limit matters most; flanks shift with the speed
        assert change[i] < 0.006
    fixed = sdm(MODEL, cut, Q_([20000.0], "rpm"), intervals=40)
    assert fixed.discretisation["intervals_in_cut"] == [40, 40]


def test_the_progress_lines_do_not_change_the_lobes():
    speeds = spindle_speeds("8000 rpm", "20000 rpm", "1000 rpm")
    lines: list[str] = []
    said = sdm(MODEL, benchmark_cut(1.0), speeds, progress=lines.append)
    plain = sdm(MODEL, benchmark_cut(1.0), speeds)
    np.testing.assert_array_equal(said.depth_limit_m, plain.depth_limit_m)
    assert lines[0].startswith("semi-discretization: 13 speeds, ") and "eigenvalue problems of order up to" in lines[0]
    assert lines[1] == "semi-discretization: coarse scan of the depths, step 1: 13 of 13 speeds"
    assert any(line.startswith("semi-discretization: narrowing the limits to 0.5%: ") for line in lines)


def test_zero_order_is_within_10_percent_of_semi_discretization_for_the_slot():
    speeds = spindle_speeds("5000 rpm", "25000 rpm", "50 rpm")
    cut = benchmark_cut(1.0)
    z, s = zoa(MODEL, cut, speeds), sdm(MODEL, cut, speeds)
    assert z.absolute_limit_m == pytest.approx(s.min_limit_m, rel=0.10)
    bottoms = floors(s.depth_limit_m)
    assert len(bottoms) >= 4
    for i in bottoms:
        assert z.depth_limit_m[i] == pytest.approx(s.depth_limit_m[i], rel=0.10)
    # the best speeds (the pockets between lobes) agree in speed
    best_zoa = [n for n, _ in z.best_speeds(2)]
    best_sdm = [n for n, _ in s.best_speeds(6)]
    for n in best_zoa:
        assert min(abs(n - m) for m in best_sdm) / n < 0.02


def test_zero_order_fails_at_low_immersion_and_says_so_here():
    """a/D = 0.05: period-doubling lobes that the zero order cannot see, some far below its lobes."""
    speeds = spindle_speeds("5000 rpm", "25000 rpm", "50 rpm")
    cut = benchmark_cut(0.05)
    z, s = zoa(MODEL, cut, speeds), sdm(MODEL, cut, speeds)
    ratio = z.depth_limit_m / s.depth_limit_m
    flip = np.array(s.bifurcation) == "flip"
    assert flip.mean() > 0.2
    assert ratio[flip].max() > 3.0  # the zero order promises more than three times the real limit
    assert s.min_limit_m < 0.7 * z.absolute_limit_m  # its "absolute" limit is not a lower bound
    hopf_floors = [i for i in floors(s.depth_limit_m) if s.bifurcation[i] == "hopf"]
    assert hopf_floors and all(abs(ratio[i] - 1) < 0.12 for i in hopf_floors)  # where it is right


def test_chatter_frequencies():
    speeds = Q_([16000.0, 21000.0], "rpm")
    lobes = sdm(MODEL, benchmark_cut(1.0), speeds)
    assert lobes.bifurcation == ("hopf", "flip")
    assert 900 < lobes.chatter_frequency_hz[0] < 1000  # near the mode, above it
    tooth_hz = 2 * 21000.0 / 60
    assert (lobes.chatter_frequency_hz[1] / tooth_hz) % 1 == pytest.approx(0.5)  # half the tooth passing


def test_continuation_finds_a_narrow_band_the_coarse_scan_steps_over():
    cut = benchmark_cut(1.0)
    speeds = spindle_speeds("18500 rpm", "18800 rpm", "50 rpm")
    lobes = sdm(MODEL, cut, speeds)
    i = int(np.argmin(np.abs(speeds.m - 18700)))
    a = lobes.depth_limit_m[i]
    assert a < 1.6e-3  # the tip of a lobe: unstable from about 1.4 to 1.75 mm only
    rho = spectral_radius(MODEL, cut, Q_([18700.0], "rpm"), Q_([0.99 * a, 1.01 * a], "m"))[0]
    assert rho[0] < 1 < rho[1]


def test_turning_agrees_with_the_exact_zero_order():
    """Turning has a constant force matrix: Tlusty's (zero-order) lobes are exact.

    (Semi-discretization of turning costs more at low speeds, with many vibration
    periods per revolution; the zero order is the method to use there.)
    """
    cut = TurningCut("1500 MPa", orientation=0.6)
    speeds = spindle_speeds("16000 rpm", "30000 rpm", "350 rpm")
    z, s = zoa(MODEL, cut, speeds), sdm(MODEL, cut, speeds)
    step = np.abs(np.diff(np.log(z.depth_limit_m)))
    smooth = np.concatenate([[step[0]], np.maximum(step[:-1], step[1:]), [step[-1]]]) < 0.3  # off the steep flanks
    assert smooth.mean() > 0.8
    np.testing.assert_allclose(s.depth_limit_m[smooth], z.depth_limit_m[smooth], rtol=0.01)
    np.testing.assert_allclose(s.chatter_frequency_hz[smooth], z.chatter_frequency_hz[smooth], rtol=0.002)


def test_two_directions_use_the_y_modes():
    xy = ModalModel([Mode("x", "900 Hz", 0.02, "1e7 N/m"), Mode("y", "900 Hz", 0.02, "1e7 N/m")])
    x_only = ModalModel([Mode("x", "900 Hz", 0.02, "1e7 N/m")])
    cut = MillingCut(3, "12 mm", "6 mm", kt="700 MPa", kn="210 MPa")
    speeds = Q_([9000.0, 13000.0], "rpm")
    assert np.all(sdm(xy, cut, speeds).depth_limit_m < sdm(x_only, cut, speeds).depth_limit_m)


def test_errors():
    cut = benchmark_cut(1.0)
    speeds = Q_([10000.0], "rpm")
    frf = FRF.single(Frequency.from_range("500 Hz", "1500 Hz", "1 Hz"), np.ones(1001) * 1e-7)
    with pytest.raises(InvalidValueError, match="fit_modes"):
        sdm(frf, cut, speeds)
    with pytest.raises(InvalidValueError, match="intervals"):
        sdm(MODEL, cut, speeds, intervals=0)
    with pytest.raises(InvalidValueError, match="rtol"):
        sdm(MODEL, cut, speeds, rtol=0.0)
    with pytest.raises(InvalidValueError, match="depth_range"):
        sdm(MODEL, cut, speeds, depth_range=("2 mm", "1 mm"))
    with pytest.raises(UnitError, match="rpm"):
        sdm(MODEL, cut, Q_([100.0], "Hz"))
    with pytest.raises(UnitError):
        spectral_radius(MODEL, cut, speeds, 0.001)


def test_a_speed_stable_over_the_whole_range_has_no_limit():
    lobes = sdm(MODEL, benchmark_cut(1.0), Q_([16000.0], "rpm"), depth_range=("0.01 mm", "0.1 mm"))
    assert np.isinf(lobes.depth_limit_m[0]) and np.isnan(lobes.chatter_frequency_hz[0])
    assert lobes.to_json()["depth_limit_m"] == [None]


semidiscrete = importlib.import_module("substructure.stability._semidiscrete")


@pytest.mark.parametrize("model, cut", [
    (MODEL, benchmark_cut(1.0)),
    (ModalModel([Mode("x", "900 Hz", 0.02, "1e7 N/m"), Mode("y", "900 Hz", 0.02, "1e7 N/m"),
                 Mode("x", "2500 Hz", 0.03, "3e7 N/m")]), benchmark_cut(0.3)),
    (ModalModel([Mode("x", "900 Hz", 0.02, "1e7 N/m"), Mode("y", "900 Hz", 0.02, "1e7 N/m")]),
     TurningCut("1500 MPa", orientation=0.6)),  # two equal multipliers in modulus
], ids=["one-mode-slot", "three-modes-xy", "turning-equal-xy"])
def test_arnoldi_gives_the_largest_multiplier_of_the_full_eigenvalue_problem(model, cut):
    """Large monodromy matrices: Arnoldi iterations, checked against all eigenvalues (LAPACK)."""
    grid = semidiscrete._Plan(model, cut, 420, 20, 0.2).grid(420)
    u = semidiscrete._monodromy(model, grid, np.array([3000.0, 9000.0]), np.array([2e-3, 3e-4]))
    assert u.shape[1] >= semidiscrete.ARNOLDI_ORDER
    mu, vec = semidiscrete._largest(u, vectors=True)
    full = np.linalg.eigvals(u)
    np.testing.assert_allclose(np.abs(mu), np.abs(full).max(axis=1), rtol=1e-9)
    residual = np.linalg.norm(np.einsum("bij,bj->bi", u, vec) - mu[:, None] * vec, axis=1)
    assert np.all(residual < 1e-9 * np.abs(mu) * np.linalg.norm(vec, axis=1))


def test_the_lobes_are_the_same_through_arnoldi_iterations(monkeypatch):
    """Every eigenvalue problem through Arnoldi: the same limits, chatter and bifurcations as through LAPACK."""
    speeds = spindle_speeds("9000 rpm", "21000 rpm", "1000 rpm")
    cut = benchmark_cut(0.05)
    full = sdm(MODEL, cut, speeds)
    monkeypatch.setattr(semidiscrete, "ARNOLDI_ORDER", 0)
    arnoldi = sdm(MODEL, cut, speeds)
    np.testing.assert_allclose(arnoldi.depth_limit_m, full.depth_limit_m, rtol=1e-9)
    np.testing.assert_allclose(arnoldi.chatter_frequency_hz, full.chatter_frequency_hz, rtol=1e-9)
    assert arnoldi.bifurcation == full.bifurcation and "flip" in full.bifurcation and "hopf" in full.bifurcation


def test_where_arnoldi_does_not_converge_all_eigenvalues_answer(monkeypatch):
    import scipy.sparse.linalg

    grid = semidiscrete._Plan(MODEL, benchmark_cut(1.0), 420, 20, 0.2).grid(420)
    u = semidiscrete._monodromy(MODEL, grid, np.array([3000.0]), np.array([2e-3]))
    expected = np.abs(np.linalg.eigvals(u)).max()

    def no_convergence(*args, **kwargs):
        raise scipy.sparse.linalg.ArpackNoConvergence("no convergence", np.empty(0), np.empty((0, 0)))

    monkeypatch.setattr(scipy.sparse.linalg, "eigs", no_convergence)
    assert abs(semidiscrete._largest(u)[0][0]) == pytest.approx(expected, rel=1e-12)
    u[0, 0, 5] = np.nan
    with pytest.raises(np.linalg.LinAlgError, match="infs or NaNs"):
        semidiscrete._largest(u)


def test_a_fixed_count_too_coarse_for_the_mode_is_refused_and_the_least_one_is_within_its_bound():
    cut = benchmark_cut(1.0)  # the slot: the tooth cuts the whole delay period of 60 / (2 n) s
    speeds = Q_([15000.0, 15500.0, 16000.0], "rpm")
    phase = 2 * np.pi * FN * 60.0 / (2 * 15000.0)  # of the mode over the cut at the lowest speed
    least = int(np.ceil(phase / np.sqrt(sdm_module.FIXED_INTERVALS_ERROR / sdm_module.ERROR_COEFFICIENT)))
    assert least == 26
    for coarse in (1, 2, 5, least - 1):
        with pytest.raises(InvalidValueError, match=rf"^intervals: got {coarse}; .*phase step of "
                                                    rf"{phase / coarse:.3g} rad.* at least {least} intervals"):
            sdm(MODEL, cut, speeds, intervals=coarse)
    fine = sdm(MODEL, cut, speeds, max_phase_step=0.05, rtol=0.001).depth_limit_m
    at_least = sdm(MODEL, cut, speeds, intervals=least, rtol=0.001)
    assert at_least.discretisation["intervals_in_cut"] == [least, least]
    error = np.abs(at_least.depth_limit_m / fine - 1)
    assert np.all(error < sdm_module.FIXED_INTERVALS_ERROR)
    assert np.all(error > 0.1 * sdm_module.FIXED_INTERVALS_ERROR)  # the count is not needlessly fine


def test_speeds_too_low_for_the_most_intervals_name_the_lowest_speed_that_fits():
    """The count of intervals grows as 1 / speed: the message names the lowest speed within MAX_INTERVALS (checked
    here on the plan of intervals), the options that help, and no Python-only advice alone."""
    import re

    cut = benchmark_cut(1.0)
    with pytest.raises(InvalidValueError) as info:
        sdm(MODEL, cut, Q_([100.0, 200.0], "rpm"))
    text = str(info.value)
    assert "--speeds" in text and "--method zoa" in text, text
    lowest = float(re.search(r"start the speeds at (\S+) rpm", text).group(1))
    plan = sdm_module._Plan(MODEL, cut, None, 20, 0.2)
    assert plan.intervals_for(np.array([lowest])).max() <= sdm_module.MAX_INTERVALS
    assert plan.intervals_for(np.array([0.97 * lowest])).max() > sdm_module.MAX_INTERVALS
