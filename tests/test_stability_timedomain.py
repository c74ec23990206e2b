"""Semi-discretization and zero order against a time-domain simulation of the delay equation.

The simulation below is written here, independently of the library: the
equations of motion of the modes in x and y,

``m q'' + c q' + k q = P^T F``,  ``F = a K(t) (r(t) - r(t - T))``,  ``r = P q``,

with the cutting force of each tooth in the cut computed from its chip
thickness ``h = dx sin(phi) + dy cos(phi)`` (``Ft = Kt a h``, ``Fn = Kn a h``),
integrated by the classical Runge-Kutta method.  The steps are uniform in
angle within each stretch between a tooth's entry and exit, so that the
delayed displacements are stored values one period back; at half steps they
are cubic Hermite interpolants of the stored displacements and velocities.
The growth rate per period of the vibration tells stable from unstable.
"""

from __future__ import annotations

import importlib

import numpy as np
import pytest

from substructure.stability import MillingCut, ModalModel, Mode, sdm, zoa
from substructure.units import Q_

M, FN, ZETA = 0.03993, 922.0, 0.011
K = M * (2 * np.pi * FN) ** 2
BENCHMARK = [("x", FN, ZETA, K)]


def tooth_forces(phi, kt, kn):
    """Force per unit depth and per unit chip thickness change of a tooth at ``phi``: 2x2 (x, y)."""
    s, c = np.sin(phi), np.cos(phi)
    f_dir = np.array([-(kt * c + kn * s), kt * s - kn * c])  # Fx, Fy per unit h
    h_dir = np.array([s, c])  # h per unit (dx, dy)
    return np.outer(f_dir, h_dir)


def simulate(modes, teeth, kt, kn, phi_st, phi_ex, speed_rpm, depth_m, periods=300, step=0.12, seed=0):
    """Per-period amplitude (cases, periods) of the tool vibration; cases are (speed, depth) pairs."""
    speed_rpm, depth_m = np.asarray(speed_rpm, float), np.asarray(depth_m, float)
    n_case, d = speed_rpm.size, len(modes)
    direction = np.array([0 if m[0] == "x" else 1 for m in modes])
    wn = 2 * np.pi * np.array([m[1] for m in modes])
    zeta = np.array([m[2] for m in modes])
    mass = np.array([m[3] for m in modes]) / wn**2
    p = np.zeros((2, d))
    p[direction, np.arange(d)] = 1.0
    pitch = 2 * np.pi / teeth
    spin = 2 * np.pi * speed_rpm / 60.0  # rad/s

    def in_cut(theta):
        phi = np.mod(theta + np.arange(teeth) * pitch, 2 * np.pi)
        return phi, (phi > phi_st) & (phi < phi_ex)

    # angle grid of one tooth period, aligned with entry and exit, fine enough at the slowest speed
    cuts = sorted({0.0, pitch, np.mod(phi_st, pitch), np.mod(phi_ex, pitch)})
    edges = [0.0]
    for a, b in zip(cuts[:-1], cuts[1:]):
        if b - a > 1e-12:
            count = max(8, int(np.ceil(wn.max() * (b - a) / spin.min() / step)))
            edges += list(np.linspace(a, b, count + 1)[1:])
    edges = np.array(edges)
    dth = np.diff(edges)
    n_step = dth.size

    def kmat(theta, mid):
        """Cutting force matrix (2x2) at angle theta, teeth in the cut decided at the step's middle."""
        phi, _ = in_cut(theta)
        _, inside = in_cut(mid)
        out = np.zeros((2, 2))
        for j in np.flatnonzero(inside):
            out += tooth_forces(phi[j], kt, kn)
        return out

    stages = [(kmat(edges[i], edges[i] + dth[i] / 2), kmat(edges[i] + dth[i] / 2, edges[i] + dth[i] / 2),
               kmat(edges[i + 1], edges[i] + dth[i] / 2)) for i in range(n_step)]

    def accel(q, v, r_delayed, kk):
        r = q @ p.T  # (cases, 2)
        force = depth_m[:, None] * ((r - r_delayed) @ kk.T)
        return (force @ p) / mass - 2 * zeta * wn * v - wn**2 * q

    rng = np.random.default_rng(seed)
    q = 1e-6 * rng.standard_normal((n_case, d))
    v = 1e-6 * wn * rng.standard_normal((n_case, d))
    hist_q = np.repeat(q[None], n_step + 1, axis=0)
    hist_v = np.repeat(v[None], n_step + 1, axis=0)
    amplitude = np.zeros((n_case, periods))
    for period in range(periods):
        new_q, new_v = np.empty_like(hist_q), np.empty_like(hist_v)
        new_q[0], new_v[0] = q, v
        peak = np.abs(q @ p.T).max(axis=1)
        for i in range(n_step):
            h = (dth[i] / spin)[:, None]
            q0, v0, q1, v1 = hist_q[i], hist_v[i], hist_q[i + 1], hist_v[i + 1]
            r0, r1 = q0 @ p.T, q1 @ p.T
            rm = 0.5 * (q0 + q1) @ p.T + (h * (v0 - v1) / 8.0) @ p.T  # Hermite midpoint
            k0, km, k1 = stages[i]
            a1 = accel(q, v, r0, k0)
            a2 = accel(q + 0.5 * h * v, v + 0.5 * h * a1, rm, km)
            a3 = accel(q + 0.5 * h * (v + 0.5 * h * a1), v + 0.5 * h * a2, rm, km)
            a4 = accel(q + h * (v + 0.5 * h * a2), v + h * a3, r1, k1)
            q = q + h * v + h * h / 6.0 * (a1 + a2 + a3)
            v = v + h / 6.0 * (a1 + 2 * a2 + 2 * a3 + a4)
            new_q[i + 1], new_v[i + 1] = q, v
            peak = np.maximum(peak, np.abs(q @ p.T).max(axis=1))
        hist_q, hist_v = new_q, new_v
        amplitude[:, period] = peak
    return amplitude


def growth_per_period(amplitude):
    """Slope of log(amplitude) over the second half of the run (per period)."""
    n = amplitude.shape[1]
    t = np.arange(n // 2, n)
    return np.polyfit(t, np.log(amplitude[:, n // 2:]).T, 1)[0]


def benchmark(immersion):
    model = ModalModel([Mode(*m[:1], Q_(m[1], "Hz"), m[2], Q_(m[3], "N/m")) for m in BENCHMARK])
    cut = MillingCut.from_spec(2, "10 mm", immersion=immersion, milling="down", kt="6e8 Pa", kn="2e8 Pa")
    return model, cut


def test_the_simulation_decays_freely_at_the_modal_rate():
    amp = simulate(BENCHMARK, 2, 6e8, 2e8, 0.0, np.pi, [10000.0], [0.0], periods=60)
    period = 60.0 / (2 * 10000.0)
    assert growth_per_period(amp)[0] == pytest.approx(-ZETA * 2 * np.pi * FN * period, rel=0.02)


@pytest.mark.parametrize("immersion, speeds", [
    (1.0, [10150.0, 13000.0, 16000.0, 21000.0]),   # floors, a flank, the period-doubling range
    (0.05, [8400.0, 12150.0, 18200.0, 22000.0]),   # Hopf floors, a period-doubling floor
])
def test_sdm_boundary_is_within_2_percent_of_the_time_domain(immersion, speeds):
    model, cut = benchmark(immersion)
    lobes = sdm(model, cut, Q_(speeds, "rpm"))
    limit = lobes.depth_limit_m
    assert np.all(np.isfinite(limit))
    st, ex = cut.angles
    cases_n = np.repeat(speeds, 2)
    cases_a = np.ravel(np.column_stack([0.98 * limit, 1.02 * limit]))
    rate = growth_per_period(simulate(BENCHMARK, 2, 6e8, 2e8, st, ex, cases_n, cases_a)).reshape(-1, 2)
    assert np.all(rate[:, 0] < 0), f"not decaying just below the limit: {rate[:, 0]}"
    assert np.all(rate[:, 1] > 0), f"not growing just above the limit: {rate[:, 1]}"
    if immersion == 0.05:
        assert "flip" in lobes.bifurcation and "hopf" in lobes.bifurcation


def test_zero_order_failure_at_low_immersion_is_real():
    """At a/D = 0.05 the zero order misses the period-doubling lobes: it calls chattering cuts stable."""
    model, cut = benchmark(0.05)
    speeds = Q_([18200.0], "rpm")
    a_sdm, a_zoa = sdm(model, cut, speeds).depth_limit_m[0], zoa(model, cut, speeds).depth_limit_m[0]
    assert a_zoa > 3 * a_sdm
    middle = np.sqrt(a_sdm * a_zoa)  # stable according to the zero order
    st, ex = cut.angles
    rate = growth_per_period(simulate(BENCHMARK, 2, 6e8, 2e8, st, ex, [18200.0], [middle], periods=120))
    assert rate[0] > 0.05


def test_two_directions_and_several_modes_match_the_time_domain(monkeypatch):
    """Through Arnoldi iterations, the path of large monodromy matrices (low speeds); LAPACK's is checked above."""
    monkeypatch.setattr(importlib.import_module("substructure.stability._semidiscrete"), "ARNOLDI_ORDER", 0)
    modes = [("x", 700.0, 0.02, 1.2e7), ("x", 1500.0, 0.03, 2.5e7), ("y", 820.0, 0.025, 1.0e7)]
    model = ModalModel([Mode(dn, Q_(f, "Hz"), z, Q_(k, "N/m")) for dn, f, z, k in modes])
    cut = MillingCut(3, "16 mm", "8 mm", kt="700 MPa", kn="210 MPa", milling="up")
    speeds = [9000.0, 14500.0]
    limit = sdm(model, cut, Q_(speeds, "rpm")).depth_limit_m
    st, ex = cut.angles
    cases_a = np.ravel(np.column_stack([0.97 * limit, 1.03 * limit]))
    rate = growth_per_period(simulate(modes, 3, 7e8, 2.1e8, st, ex, np.repeat(speeds, 2), cases_a,
                                      periods=240)).reshape(-1, 2)
    assert np.all(rate[:, 0] < 0) and np.all(rate[:, 1] > 0), rate
