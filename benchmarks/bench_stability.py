"""Stability lobe benchmarks (issue 5).

Targets on a 2-core machine: zero order over 5,000 spindle speeds from a
2,500-line FRF under 0.2 s; semi-discretization of the Insperger-Stepan
benchmark, 200 speeds with the boundary found to 0.5 %, under 10 s (the slot,
a/D = 1, is the expensive case: its whole tooth period is cutting).
"""

from __future__ import annotations

import numpy as np

from substructure import Frequency
from substructure.io.assembly_toml import default_assembly
from substructure.stability import MillingCut, ModalModel, Mode, sdm, spindle_speeds, xy_frf, zoa
from substructure.units import Q_


def _zoa_inputs():
    frf = default_assembly().receptance("tool.tip:y", frequency=Frequency.from_hz(np.linspace(500.0, 5000.0, 2500)))
    cut = MillingCut(4, "12 mm", "3 mm", kt="625 MPa", kn="100 MPa", milling="up")
    speeds = Q_(np.linspace(1000.0, 30000.0, 5000), "rpm")
    return xy_frf(frf), cut, speeds


def _benchmark(immersion: float):
    m, fn, zeta = 0.03993, 922.0, 0.011
    model = ModalModel([Mode("x", Q_(fn, "Hz"), zeta, Q_(m * (2 * np.pi * fn) ** 2, "N/m"))])
    cut = MillingCut.from_spec(2, "10 mm", immersion=immersion, milling="down", kt="6e8 Pa", kn="2e8 Pa")
    return model, cut, Q_(np.linspace(5000.0, 25000.0, 200), "rpm")


def benchmarks():
    yield ("stability_zoa_5000_speeds_2500_lines", _zoa_inputs, lambda args: zoa(*args), 11)
    yield ("stability_sdm_insperger_stepan_slot_200_speeds_0.5pct", lambda: _benchmark(1.0),
           lambda args: sdm(*args, rtol=0.005), 3)
    yield ("stability_sdm_insperger_stepan_aD0.05_200_speeds_0.5pct", lambda: _benchmark(0.05),
           lambda args: sdm(*args, rtol=0.005), 5)
    yield ("stability_sdm_thesis_cut_3_modes_xy_50_speeds",
           lambda: (_fitted(), MillingCut(4, "12 mm", "3 mm", kt="625 MPa", kn="100 MPa"),
                    spindle_speeds("8000 rpm", "20000 rpm", "245 rpm")),
           lambda args: sdm(*args), 1)
    yield ("stability_sdm_fitted_slot_2000_rpm_5_speeds",
           lambda: (_fitted(), _slot(), spindle_speeds("2000 rpm", "2200 rpm", "50 rpm")),
           lambda args: sdm(*args), 1)


def _slot() -> MillingCut:
    return MillingCut(4, "12 mm", "12 mm", kt="767 MPa", kn="169 MPa", milling="up")


def _all_over_arnoldi() -> dict:
    """All eigenvalues (LAPACK) over Arnoldi iterations for one monodromy matrix of order about 2,000."""
    import time

    from threadpoolctl import threadpool_limits

    from substructure.stability import _semidiscrete as semi

    model = _fitted()
    plan = semi._Plan(model, _slot(), None, 20, 0.2)
    speed, depth = np.array([2000.0]), np.array([2e-4])
    u = semi._monodromy(model, plan.grid(int(plan.intervals_for(speed)[0])), speed, depth)
    with threadpool_limits(limits=1, user_api="blas"):
        t0 = time.perf_counter()
        full = np.abs(np.linalg.eigvals(u)).max()
        t1 = time.perf_counter()
        mu = semi._largest(u)[0]
        t2 = time.perf_counter()
    assert abs(abs(mu[0]) - full) <= 1e-9 * full
    return {"stability_sdm_all_eigenvalues_over_arnoldi": (t1 - t0) / (t2 - t1),
            "stability_sdm_monodromy_order": u.shape[1]}


_all_over_arnoldi.names = ("stability_sdm_all_eigenvalues_over_arnoldi",
                           "stability_sdm_monodromy_order")


def figures():
    yield ("stability_sdm_all_eigenvalues_over_arnoldi", _all_over_arnoldi)


def _fitted():
    from substructure.stability import fit_modes

    frf = default_assembly().receptance("tool.tip:y", frequency=Frequency.from_range("500 Hz", "5000 Hz", "2 Hz"))
    return fit_modes(frf)
