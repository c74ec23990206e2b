"""Semi-discretization of milling stability (Insperger & Stepan, updated first-order method).

The tool point is a modal model (:class:`~substructure.stability.ModalModel`):
``M q'' + C q' + K q = a P^T K(t) (r(t) - r(t - T))``, ``r = P q`` the tool's
displacement in the directions that have modes, ``K(t)`` the T-periodic
cutting force matrix.  With the state ``z = (q, q')`` this is
``z' = A(t) z + B(t) r(t - T)``.

The delay period is split into intervals ``[t_i, t_i+1]``.  On each, ``A``
and ``B`` are replaced by their averages (exact integrals of ``K``), and the
delayed displacement by the straight line between its values at the ends of
the interval one period earlier (first order).  The interval's solution is
then exact:

``z_i+1 = Phi_i z_i + (G0_i - G1_i) r_i-K + G1_i r_i-K+1``,

where ``Phi_i = exp(A_i dt)``, ``G0_i = int exp(A_i (dt - s)) B_i ds`` and
``G1_i = int exp(A_i (dt - s)) B_i s/dt ds``, all three read off one matrix
exponential of the block matrix ``[[A, B, 0], [0, 0, I/dt], [0, 0, 0]] dt``
(Van Loan).  The product of the K steps is the monodromy matrix of the
period, acting on the state and the K displacements of the previous period;
the cut is stable when all its eigenvalues are inside the unit circle.

Choices beyond the original papers (kernels in
:mod:`~substructure.stability._semidiscrete`): the grid is aligned with the
angles where teeth enter and leave the cut and a stretch with no tooth in
the cut (free vibration, exact in one step) is one interval, so that the
intervals are spent on the cutting part only; the number of intervals
follows the speed (``max_phase_step``); the history holds displacements in
at most two directions, not every modal coordinate.

Everything is batched with numpy over (spindle speed, depth) pairs: the
matrix exponentials (a batched Pade 13 scaling-and-squaring), the products
of the steps (a loop over the K intervals, never over speeds) and the
eigenvalues of small monodromy matrices; from order
:data:`~substructure.stability._semidiscrete.ARNOLDI_ORDER` up (low speeds)
only the largest multipliers are computed, by implicitly restarted Arnoldi
iterations (ARPACK through SciPy), about 20 to 50 times faster than all
eigenvalues at orders 2,000 to 5,000.  :func:`sdm` finds the boundary for
all speeds at once: a coarse scan up a geometric depth ladder to each
speed's first unstable depth, regula falsi on the spectral radius inside
each bracket, and a continuation along the speeds that looks for a
neighbour's lobe below each limit.
"""

from __future__ import annotations

from typing import Any, Callable

import numpy as np

from ..errors import InvalidValueError
from ..units import Q_, finite_real, items_of, to_si, whole_number
from . import _semidiscrete
from ._semidiscrete import _chatter, _critical, _Plan, expm_batch, monodromy_order
from .speeds import as_speed_rpm
from .modal import ModalModel
from .result import Lobes
from .structure import xy_receptance
from .zoa import zoa_eigenvalues

__all__ = ["sdm", "spectral_radius", "expm_batch", "check_intervals", "SCHEME", "MAX_INTERVALS", "ERROR_COEFFICIENT",
           "FIXED_INTERVALS_ERROR", "MAX_FIXED_PHASE_STEP"]

MAX_INTERVALS = 2000
"""Most intervals per delay period: the monodromy matrix grows with them (``2 d + K p`` square)."""

ERROR_COEFFICIENT = 0.15
"""The first-order method's relative error on the limit is at most about ``ERROR_COEFFICIENT * step**2``.

``step`` is the phase ``omega_ref * dt`` [rad] of one interval.  Measured
against a fine run on one mode of 922 Hz (damping 0.011), two or three
teeth: 0.05 at a/D = 0.25 (up milling), 0.08 at a/D = 0.5, 0.1 in the slot
(down milling, the Insperger-Stepan benchmark); 0.15 is taken as the bound.
"""

FIXED_INTERVALS_ERROR = 0.03
"""The largest error estimate (relative, on the limit) a fixed count of intervals may have at the lowest speed."""

MAX_FIXED_PHASE_STEP = (FIXED_INTERVALS_ERROR / ERROR_COEFFICIENT) ** 0.5
"""The largest phase step [rad] of an interval with a fixed count (about 0.447 rad: 3 % at 0.15 step^2)."""

SCHEME = ("updated first-order semi-discretization (Insperger & Stepan 2004), "
          "grid aligned with tooth entry and exit, one step per free-vibration stretch")


def _check_model(modes: Any) -> ModalModel:
    if not isinstance(modes, ModalModel):
        raise InvalidValueError(
            f"modes: got {type(modes).__name__}; semi-discretization needs modal parameters: a ModalModel, "
            "or fit one to FRF data with fit_modes(frf) (zero-order works on FRF data directly)"
        )
    return modes


def _check_intervals(intervals: Any) -> None:
    if isinstance(intervals, (int, np.integer)) and not isinstance(intervals, bool) and intervals > MAX_INTERVALS:
        raise InvalidValueError(
            f"intervals: got {intervals}; the limit is MAX_INTERVALS = {MAX_INTERVALS} per delay period (the "
            "monodromy matrix and its memory grow with the square of the count); the default "
            "(intervals=None) chooses the count from the modes")


def check_intervals(modes: ModalModel, cut: Any, speeds: Any, intervals: int | None, name: str = "intervals") -> None:
    """Refuse a fixed count of intervals too coarse for the modes at the lowest speed.

    Parameters
    ----------
    modes : ModalModel
        Modal parameters (their reference frequency sets the phase step).
    cut : MillingCut or TurningCut
        The cut (the cutting part of the delay period).
    speeds : pint.Quantity
        Spindle speeds in rpm; the lowest has the longest intervals.
    intervals : int or None
        The count; None (chosen per speed) is always accepted.
    name : str, default "intervals"
        How the count is named in the message (``--intervals`` on the command line).

    Raises
    ------
    InvalidValueError
        When one interval spans more than ``MAX_FIXED_PHASE_STEP`` of the
        reference mode's phase (error estimate above
        ``FIXED_INTERVALS_ERROR``); the message gives the least count.
    """
    if intervals is None:
        return
    model = _check_model(modes)
    _check_intervals(intervals)
    speeds_rpm = as_speed_rpm(speeds)
    plan = _Plan(model, cut, intervals, 20, 0.2)
    phase = float(plan.cut_phase(speeds_rpm.min()))
    step = phase / intervals
    if step > MAX_FIXED_PHASE_STEP:
        least = int(np.ceil(phase / MAX_FIXED_PHASE_STEP))
        raise InvalidValueError(
            f"{name}: got {intervals}; at {speeds_rpm.min():g} rpm one interval spans a phase step of {step:.3g} rad "
            f"of the {plan.reference_hz:.4g} Hz mode, an error of up to about {ERROR_COEFFICIENT:g} step^2 = "
            f"{ERROR_COEFFICIENT * step ** 2:.1%} on the limit; at most {MAX_FIXED_PHASE_STEP:.3g} rad "
            f"({FIXED_INTERVALS_ERROR:.0%}) is accepted: give at least {least} intervals, or leave the count out "
            "to have it chosen per speed")


def _depths_m(depths: Any) -> np.ndarray:
    if hasattr(depths, "m_as"):
        if not depths.check("[length]"):
            raise InvalidValueError(f"depths: got {depths!r}; expected lengths (e.g. Q_([1, 2], 'mm'))")
        a = np.atleast_1d(np.asarray(depths.m_as("m"), dtype=float))
    else:
        a = np.atleast_1d(to_si(depths, "depths", "m"))
    if a.ndim != 1 or np.any(~np.isfinite(a)) or np.any(a < 0):
        raise InvalidValueError("depths: expected a scalar or 1-D array of finite depths of cut >= 0")
    return a


def spectral_radius(modes: ModalModel, cut: Any, speeds: Any, depths: Any, *, intervals: int | None = None,
                    min_intervals: int = 20, max_phase_step: float = 0.2) -> np.ndarray:
    """Largest modulus of the monodromy's eigenvalues: below 1 is stable.

    Parameters
    ----------
    modes : ModalModel
        Modal parameters in x and y (Hz, damping ratio, N/m).
    cut : MillingCut or TurningCut
        The cut (cutting pressures in Pa, tool and radial depth in m).
    speeds : pint.Quantity
        Spindle speeds in rpm (1-D).
    depths : pint.Quantity or str
        Axial depths of cut (lengths, scalar or 1-D).
    intervals : int, optional
        Intervals in the cutting part of the delay period, the same at every
        speed.  Default: chosen per speed (see ``max_phase_step``).
    min_intervals : int, default 20
        Fewest intervals in the cut when they are chosen per speed.
    max_phase_step : float, default 0.2
        Largest ``omega_ref * dt`` [rad] of an interval when they are chosen
        per speed; as in ``sdm``, whose documentation gives its error.

    Returns
    -------
    ndarray, shape (n_speeds, n_depths)
        The spectral radius (dimensionless) at each speed and depth.
    """
    model = _check_model(modes)
    n = as_speed_rpm(speeds)
    a = _depths_m(depths)
    _check_intervals(intervals)
    nn, aa = np.meshgrid(n, a, indexing="ij")
    plan = _Plan(model, cut, intervals, min_intervals, max_phase_step)
    rho, _ = _critical(model, plan, nn.ravel(), aa.ravel())
    return rho.reshape(nn.shape)


def _reference_depth(model: ModalModel, cut: Any) -> float:
    """The zero-order absolute limit of the model (a scale for the depth search)."""
    f, g = xy_receptance(model)
    lam = zoa_eigenvalues(cut.mean_force_matrix(), g)
    re = lam.real.max()
    if re > 0:
        return 1.0 / (2.0 * re)
    scale = np.abs(cut.force_matrix(np.linspace(0, cut.period_angle, 64))).max()
    return float(model.arrays()["stiffness"].min() / max(scale, 1e-300))


def _bracket(model: ModalModel, plan: _Plan, speeds: np.ndarray, ladder: np.ndarray, progress=None):
    """Coarse scan up the depth ladder, speed by speed, until the first unstable depth.

    All speeds still searching are evaluated in one batch per rung; a speed
    leaves the scan at its first unstable rung.  A speed unstable at the
    lowest rung steps down (halving) until stable.  Returns the brackets
    ``(lo, hi)`` (``hi = inf``: stable up to the top of the ladder), the
    critical multipliers at ``hi`` and the number of evaluations.
    """
    ns = speeds.size
    lo, hi = np.zeros(ns), np.full(ns, np.inf)
    mu_hi = np.full(ns, np.nan, dtype=complex)
    rho_lo = np.zeros(ns)
    rung = np.zeros(ns, dtype=int)  # next rung to try going up
    up, down = np.arange(ns), np.zeros(0, dtype=int)
    evaluations, halvings = 0, 0
    step = 0
    while up.size or down.size:
        trial = np.concatenate([ladder[rung[up]], hi[down] / 2.0])
        who = np.concatenate([up, down])
        step += 1
        if progress:
            progress(f"semi-discretization: coarse scan of the depths, step {step}: {who.size} of {ns} speeds")
        rho, mu = _critical(model, plan, speeds[who], trial)
        evaluations += who.size
        bad = rho > 1.0
        hi[who[bad]], mu_hi[who[bad]] = trial[bad], mu[bad]
        lo[who[~bad]], rho_lo[who[~bad]] = trial[~bad], rho[~bad]
        going_up = np.isin(who, up)
        first_rung = going_up & bad & (rung[who] == 0)
        rung[who[going_up & ~bad]] += 1
        up = who[going_up & ~bad]
        up = up[rung[up] < ladder.size]
        down = np.concatenate([who[~going_up & bad], who[first_rung]])
        halvings += int(down.size > 0)
        if halvings > 40:
            raise InvalidValueError("sdm: unstable at every depth tried (is the structure unstable without cutting?)")
    return lo, hi, mu_hi, rho_lo, evaluations


def _refine(model: ModalModel, plan: _Plan, speeds: np.ndarray, lo: np.ndarray, hi: np.ndarray,
            mu_hi: np.ndarray, rho_lo: np.ndarray, rtol: float, progress=None) -> int:
    """Shrink every finite bracket to ``hi / lo <= 1 + rtol`` in place; returns the evaluations.

    Regula falsi on ``log(rho)`` against ``log(depth)`` with the Illinois
    modification (superlinear on the smooth spectral radius), each trial kept
    0.45 ``rtol`` inside the bracket so that both ends move: a bisection-safe
    bracket that needs about three evaluations from a ratio of sqrt(2).
    """
    tol = np.log1p(rtol)
    active = np.flatnonzero(np.isfinite(hi))
    if not active.size:
        return 0
    g_lo = np.log(np.maximum(rho_lo[active], 1e-300))
    g_hi = np.log(np.abs(mu_hi[active]))
    side = np.zeros(active.size, dtype=int)
    evaluations = 0
    for _ in range(100):
        wide = np.log(hi[active] / lo[active]) > tol
        active, g_lo, g_hi, side = active[wide], g_lo[wide], g_hi[wide], side[wide]
        if not active.size:
            break
        if progress:
            progress(f"semi-discretization: narrowing the limits to {rtol:.1%}: {active.size} of {speeds.size} speeds")
        x0, x1 = np.log(lo[active]), np.log(hi[active])
        x = x0 + (x1 - x0) * g_lo / (g_lo - g_hi)
        x = np.clip(x, x0 + 0.45 * tol, x1 - 0.45 * tol)
        rho, mu = _critical(model, plan, speeds[active], np.exp(x))
        evaluations += active.size
        g = np.log(np.maximum(rho, 1e-300))
        bad = rho > 1.0
        hi[active[bad]], mu_hi[active[bad]] = np.exp(x[bad]), mu[bad]
        lo[active[~bad]], rho_lo[active[~bad]] = np.exp(x[~bad]), rho[~bad]
        g_lo = np.where(bad, np.where(side == 1, g_lo / 2.0, g_lo), g)
        g_hi = np.where(bad, g, np.where(side == -1, g_hi / 2.0, g_hi))
        side = np.where(bad, 1, -1)
    return evaluations


def _continue(model: ModalModel, plan: _Plan, speeds: np.ndarray, lo: np.ndarray, hi: np.ndarray,
              mu_hi: np.ndarray, rho_lo: np.ndarray, rtol: float, coarse_ratio: float, progress=None) -> int:
    """Continuation along the speeds: look for a neighbour's lobe below a speed's limit.

    The coarse scan can step over a narrow unstable band (near the tip of a
    lobe).  Lobes are continuous in speed, so where a speed's limit lies well
    above a neighbour's, depths around the neighbour's limit are probed; an
    unstable probe gives a new, lower bracket, which is refined, and its
    neighbours are checked in the next round.  Updates in place; returns the
    evaluations.
    """
    factors = np.array([0.92, 0.97, 1.02, 1.07, 1.13])
    evaluations = 0
    todo = np.ones(speeds.size, dtype=bool)
    for _ in range(200):
        limit = np.where(np.isfinite(hi), np.sqrt(lo * hi), np.inf)
        nb = np.minimum(np.concatenate([[np.inf], limit[:-1]]), np.concatenate([limit[1:], [np.inf]]))
        check = np.flatnonzero(todo & np.isfinite(nb) & (limit > 1.15 * nb))
        if not check.size:
            break
        depth = nb[check, None] * factors[None, :]
        keep = depth < lo[check, None]
        who, depth = np.broadcast_to(check[:, None], keep.shape)[keep], depth[keep]
        todo[:] = False
        if not who.size:
            continue
        if progress:
            progress(f"semi-discretization: {check.size} of {speeds.size} speeds probed below a neighbour's lobe")
        rho, mu = _critical(model, plan, speeds[who], depth)
        evaluations += who.size
        changed = []
        for i in np.unique(who):
            mine = who == i
            bad = mine & (rho > 1.0)
            if not bad.any():
                continue
            k = np.flatnonzero(bad)[np.argmin(depth[bad])]
            below = mine & (rho <= 1.0) & (depth < depth[k])
            hi[i], mu_hi[i] = depth[k], mu[k]
            if below.any():
                j = np.flatnonzero(below)[np.argmax(depth[below])]
                lo[i], rho_lo[i] = depth[j], rho[j]
            else:
                lo[i], rho_lo[i] = 0.0, 0.0
            changed.append(i)
        if not changed:
            continue
        changed = np.array(changed)
        down = changed[lo[changed] == 0.0]
        while down.size:  # a stable depth below the new unstable one
            trial = hi[down] / coarse_ratio
            rho, mu = _critical(model, plan, speeds[down], trial)
            evaluations += down.size
            bad = rho > 1.0
            hi[down[bad]], mu_hi[down[bad]] = trial[bad], mu[bad]
            lo[down[~bad]], rho_lo[down[~bad]] = trial[~bad], rho[~bad]
            down = down[bad]
        evaluations += _refine(model, plan, speeds, lo, hi, mu_hi, rho_lo, rtol)
        todo[np.clip(np.concatenate([changed - 1, changed + 1]), 0, speeds.size - 1)] = True
    return evaluations


def sdm(modes: ModalModel, cut: Any, speeds: Any, *, intervals: int | None = None, min_intervals: int = 20,
        max_phase_step: float = 0.2, rtol: float = 0.005, depth_range: tuple[Any, Any] | None = None,
        coarse_ratio: float = 2.0 ** 0.5, label: str | None = None,
        progress: Callable[[str], None] | None = None) -> Lobes:
    """Stability lobes by semi-discretization.

    Parameters
    ----------
    modes : ModalModel
        Modal parameters in x and y (fit them to FRF data with
        :func:`~substructure.stability.fit_modes`).
    cut : MillingCut or TurningCut
        The cut (cutting pressures in Pa, tool and radial depth in m).
    speeds : pint.Quantity
        Spindle speeds in rpm, strictly increasing.
    intervals : int, optional
        Intervals in the cutting part of the delay period, the same at every
        speed.  Default: chosen per speed (see ``max_phase_step``).  A count
        whose interval at the lowest speed spans more than
        ``MAX_FIXED_PHASE_STEP`` of the reference mode's phase is refused
        (``check_intervals``), naming the least count accepted.
    min_intervals : int, default 20
        Fewest intervals in the cut when they are chosen per speed.
    max_phase_step : float, default 0.2
        Largest ``omega_ref * dt`` [rad] of an interval when they are chosen
        per speed (``omega_ref``: the highest natural frequency among the
        dominant modes).  The first-order method's error on the limit is
        about ``0.1 * max_phase_step**2`` (0.4 % at 0.2 rad on the
        Insperger-Stepan benchmark; at most about ``ERROR_COEFFICIENT``
        times the square).
        The result reports the discretisation used (``Lobes.discretisation``).
    rtol : float, default 0.005
        Relative width of the final bracket of the boundary; the reported
        limit is its geometric middle.
    depth_range : (quantity, quantity), optional
        Depths scanned; default from 1/4 to 64 times the zero-order
        absolute limit of the model (the reference depth).  A speed stable over the whole range
        gets ``inf``; the lower end is lowered until it is stable.
    coarse_ratio : float, default sqrt(2)
        Ratio of neighbouring depths of the coarse scan (below half the
        reference depth the ladder steps by 2).  An unstable band narrower
        than a rung, below the first unstable rung, can be missed.
    label : str, optional
        Legend label.
    progress : callable, optional
        Called with a line at each step of the search (the coarse scan, the
        narrowing of the limits, the probes below a neighbour's lobe), and
        with a line for each new run of the lobes at other speeds later
        (``Lobes.limit_on``, the recommendation's speed windows): at low
        speeds, with many intervals per delay period, a run takes minutes.
        The result does not depend on it.

    Returns
    -------
    Lobes
        With ``bifurcation`` and ``discretisation``.
    """
    model = _check_model(modes)
    speeds_rpm = as_speed_rpm(speeds)
    for name, value, inside, expected in (
            ("rtol", rtol, lambda v: 0 < v < 0.5, "a relative tolerance in (0, 0.5)"),
            ("coarse_ratio", coarse_ratio, lambda v: v > 1.0, "a ratio > 1"),
            ("max_phase_step", max_phase_step, lambda v: v > 0, "a positive angle in rad")):
        if not (finite_real(value) and inside(value)):
            raise InvalidValueError(f"{name}: got {value!r}; expected {expected}")
    whole_number(min_intervals, "min_intervals", 1, maximum=MAX_INTERVALS)
    check_intervals(model, cut, speeds, intervals)
    return _sdm(model, cut, speeds_rpm, intervals=intervals, min_intervals=min_intervals,
                max_phase_step=max_phase_step, rtol=rtol, depth_range=depth_range, coarse_ratio=coarse_ratio,
                label=label, progress=progress)


def _sdm(model: ModalModel, cut: Any, speeds_rpm: np.ndarray, *, intervals: int | None, min_intervals: int,
         max_phase_step: float, rtol: float, depth_range: tuple[Any, Any] | None, coarse_ratio: float,
         label: str | None, progress: Callable[[str], None] | None) -> Lobes:
    """:func:`sdm` on checked arguments (a fixed count is not checked again: the recommendation's speed windows
    reach a little below the speeds it was checked on)."""
    plan = _Plan(model, cut, intervals, min_intervals, max_phase_step)
    need = int(plan.intervals_for(speeds_rpm).max())
    if need > MAX_INTERVALS:
        lowest = float(speeds_rpm[0]) * need / MAX_INTERVALS  # the count falls as 1 / speed
        while int(plan.intervals_for(np.array([lowest])).max()) > MAX_INTERVALS:
            lowest *= 1.01
        raise InvalidValueError(
            f"speeds: the lowest speed {speeds_rpm[0]:g} rpm needs {need} intervals per delay period for a phase "
            f"step of {max_phase_step:g} rad at {plan.reference_hz:.4g} Hz, more than MAX_INTERVALS = "
            f"{MAX_INTERVALS}; start the speeds at {lowest:.5g} rpm or above (--speeds), take the zero-order "
            "method at these speeds (--method zoa), or a larger max_phase_step (in Python)")
    if depth_range is None:
        ref = _reference_depth(model, cut)
        lo, hi = ref / 4.0, ref * 64.0
        ladder = np.concatenate([[ref / 4.0], ref * coarse_ratio ** np.arange(
            np.floor(np.log(0.5) / np.log(coarse_ratio)), np.log(64.0) / np.log(coarse_ratio) + 1e-9)])
    else:
        pair = items_of(depth_range, "depth_range", "two depths with units, (low, high)")
        if len(pair) != 2:
            raise InvalidValueError(f"depth_range: got {depth_range!r}; expected (low, high), two depths with units")
        lo, hi = (to_si(v, f, "m") for v, f in zip(pair, ("depth_range[0]", "depth_range[1]")))
        if not 0 < lo < hi:
            raise InvalidValueError(f"depth_range: got {depth_range!r}; expected 0 < low < high")
        ladder = np.geomspace(lo, hi, int(np.ceil(np.log(hi / lo) / np.log(coarse_ratio))) + 1)
    ns = speeds_rpm.size
    if progress:
        counts = plan.intervals_for(speeds_rpm)
        order = max(monodromy_order(model, plan.grid(int(m))) for m in np.unique(counts))
        progress(f"semi-discretization: {ns} speeds, {int(counts.min())} to {int(counts.max())} intervals in the "
                 f"cut per delay period (eigenvalue problems of order up to {order}: the lowest speeds cost most)")
    lo_d, hi_d, mu_hi, rho_lo, evaluations = _bracket(model, plan, speeds_rpm, ladder, progress)
    evaluations += _refine(model, plan, speeds_rpm, lo_d, hi_d, mu_hi, rho_lo, rtol, progress)
    evaluations += _continue(model, plan, speeds_rpm, lo_d, hi_d, mu_hi, rho_lo, rtol, coarse_ratio, progress)
    found = np.isfinite(hi_d)
    limit = np.where(found, np.sqrt(lo_d * hi_d), np.inf)
    counts = plan.intervals_for(speeds_rpm)
    chatter = np.full(ns, np.nan)
    kinds = ["none"] * ns
    if found.any():
        f_c, k_c = _chatter(model, plan, speeds_rpm[found], limit[found])
        chatter[found] = f_c
        for i, kind in zip(np.flatnonzero(found), k_c):
            kinds[i] = kind
    info = {
        "scheme": SCHEME,
        "intervals_in_cut": [int(counts.min()), int(counts.max())],
        "intervals_per_period": [plan.grid(int(m)).size for m in (counts.min(), counts.max())],
        "monodromy_order": [monodromy_order(model, plan.grid(int(m))) for m in (counts.min(), counts.max())],
        "arnoldi_from_order": _semidiscrete.ARNOLDI_ORDER,
        "max_phase_step_rad": None if intervals is not None else max_phase_step,
        "reference_frequency_hz": plan.reference_hz,
        "depth_rtol": rtol,
        "depth_range_m": [float(lo), float(hi)],
        "coarse_ratio": coarse_ratio,
        "evaluations_per_speed": round(evaluations / ns, 2),
    }
    source = _SdmSource(model, cut, dict(intervals=intervals, min_intervals=min_intervals,
                                          max_phase_step=max_phase_step, rtol=rtol, depth_range=depth_range,
                                          coarse_ratio=coarse_ratio), speeds_rpm, limit, chatter, progress)
    return Lobes("sdm", speeds_rpm, limit, chatter, cut=cut, bifurcation=kinds, discretisation=info, label=label,
                 source=source)


class _SdmSource:
    """Re-runs semi-discretization with the same model, cut and settings at other speeds.

    A speed computed once keeps its limit (the first run's speeds and those of
    every later run): the recommendation's overlapping speed windows cost a
    speed once.  Each new run is one line to the first run's ``progress``
    (its own steps are not said).
    """

    def __init__(self, model: ModalModel, cut: Any, settings: dict, speeds: np.ndarray, depth: np.ndarray,
                 chatter: np.ndarray, progress: Callable[[str], None] | None = None) -> None:
        self.model, self.cut, self.settings, self.progress = model, cut, settings, progress
        self.known = dict(zip(speeds.tolist(), zip(depth.tolist(), chatter.tolist())))

    def __getstate__(self) -> dict:  # lobes sent to another process leave the progress lines behind
        return {**self.__dict__, "progress": None}

    def limit(self, speeds: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        new = np.unique([n for n in speeds.tolist() if n not in self.known])
        if new.size:
            if self.progress:
                self.progress(f"semi-discretization: a new run on {new.size} speeds, {new[0]:.6g} to "
                              f"{new[-1]:.6g} rpm")
            result = _sdm(self.model, self.cut, as_speed_rpm(Q_(new, "rpm")), label=None, progress=None,
                          **self.settings)
            self.known.update(zip(new.tolist(), zip(result.depth_limit_m.tolist(),
                                                    result.chatter_frequency_hz.tolist())))
        found = np.array([self.known[n] for n in speeds.tolist()], dtype=float).reshape(-1, 2)
        return found[:, 0], found[:, 1]

