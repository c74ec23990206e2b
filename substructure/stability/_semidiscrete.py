"""Kernels of semi-discretization: the discretised period, the step maps, the monodromy matrices.

Private to :mod:`substructure.stability.sdm`, which explains the method.  The
delay period of a cut is split into intervals aligned with the angles where
teeth enter and leave the cut (:class:`_Grid`); each interval's exact
solution of the averaged equations with a linearly interpolated delayed
displacement gives a step map (:func:`_steps`, one Van Loan matrix
exponential per interval, :func:`expm_batch`); their product is the
monodromy matrix (:func:`_monodromy`), whose critical multiplier
:func:`_critical` computes for many (speed, depth) pairs at once (all
eigenvalues of small matrices, Arnoldi iterations from
:data:`ARNOLDI_ORDER` up: :func:`_largest`).
:class:`_Plan` chooses the intervals per speed; :func:`_chatter` reads the
chatter frequency off the critical Floquet solution.
"""

from __future__ import annotations

import os
from concurrent.futures import ThreadPoolExecutor
from typing import Any

import numpy as np

from .._kernels import one_blas_thread
from ..errors import InvalidValueError
from ..units import whole_number
from .modal import ModalModel

__all__ = ["expm_batch", "ARNOLDI_ORDER"]  # the rest is private to substructure.stability.sdm

_PADE13 = (64764752532480000.0, 32382376266240000.0, 7771770303897600.0, 1187353796428800.0,
           129060195264000.0, 10559470521600.0, 670442572800.0, 33522128640.0, 1323241920.0,
           40840800.0, 960960.0, 16380.0, 182.0, 1.0)
_THETA13 = 5.371920351148152


def expm_batch(a: np.ndarray) -> np.ndarray:
    """Matrix exponentials of a stack of real square matrices, shape ``(..., s, s)``.

    Pade approximant of degree 13 with scaling and squaring (Higham 2005),
    the scaling chosen per matrix from its 1-norm.
    """
    a = np.asarray(a, dtype=float)
    shape = a.shape
    s = shape[-1]
    a = a.reshape(-1, s, s)
    norm = np.abs(a).sum(axis=1).max(axis=1)
    with np.errstate(divide="ignore"):
        squarings = np.maximum(0, np.ceil(np.log2(np.where(norm > 0, norm, 1.0) / _THETA13))).astype(int)
    a = a / (2.0 ** squarings)[:, None, None]
    b = _PADE13
    eye = np.eye(s)
    a2 = a @ a
    a4 = a2 @ a2
    a6 = a4 @ a2
    u = a @ (a6 @ (b[13] * a6 + b[11] * a4 + b[9] * a2) + b[7] * a6 + b[5] * a4 + b[3] * a2 + b[1] * eye)
    v = a6 @ (b[12] * a6 + b[10] * a4 + b[8] * a2) + b[6] * a6 + b[4] * a4 + b[2] * a2 + b[0] * eye
    e = np.linalg.solve(v - u, v + u)
    for k in range(int(squarings.max(initial=0))):
        more = squarings > k
        e[more] = e[more] @ e[more]
    return e.reshape(shape)


class _Grid:
    """The discretised delay period of a cut: interval angles, cutting flags, mean force matrices."""

    def __init__(self, cut: Any, intervals: int) -> None:
        whole_number(intervals, "intervals", 1)
        arcs = cut.period_arcs()
        cutting_length = sum(b - a for a, b, c in arcs if c)
        edges, flags = [arcs[0][0]], []
        for a, b, cutting in arcs:
            count = max(1, int(round(intervals * (b - a) / cutting_length))) if cutting else 1
            edges += list(np.linspace(a, b, count + 1)[1:])
            flags += [cutting] * count
        self.theta = np.array(edges)
        self.cutting = np.array(flags, dtype=bool)
        self.period_angle = cut.period_angle
        self.mean = np.zeros((self.cutting.size, 2, 2))
        if self.cutting.any():
            idx = np.flatnonzero(self.cutting)
            self.mean[idx] = cut.force_matrix_average(self.theta[idx], self.theta[idx + 1])

    @property
    def size(self) -> int:
        return int(self.cutting.size)


def _model_matrices(model: ModalModel):
    """Modal mass, damping, stiffness and the map ``P`` (p x d) from modal to active x/y displacements."""
    arr = model.arrays()
    d = arr["stiffness"].size
    active = np.unique(arr["direction"])  # directions that have modes; the others are rigid
    p = (arr["direction"][None, :] == active[:, None]).astype(float)
    minv = 1.0 / arr["mass"]
    damping = 2.0 * arr["damping_ratio"] * np.sqrt(arr["stiffness"] * arr["mass"])
    return d, active, p, minv, arr["stiffness"], damping


def _steps(model: ModalModel, grid: _Grid, speed_rpm: np.ndarray, depth_m: np.ndarray):
    """The step maps ``z_i+1 = Phi_i z_i + R0_i r_i-K + R1_i r_i-K+1`` for pairs (speed, depth).

    Returns ``phi (B, K, n, n)``, ``r0``, ``r1 (B, K, n, p)``, ``select (p, n)`` (``r = select @ z``)
    and the free-vibration matrix ``A0 (n, n)``.
    """
    d, active, p, minv, ks, cs = _model_matrices(model)
    np_ = active.size
    n_state, n_int = 2 * d, grid.size
    bsz = speed_rpm.size
    omega = 2.0 * np.pi * speed_rpm / 60.0  # rad/s of the spindle
    dt = np.diff(grid.theta)[None, :] / omega[:, None]  # (B, K)
    kbar = grid.mean[:, active][:, :, active]  # (K, p, p) force matrices in the active directions
    w = np.einsum("ai,kab,bj->kij", p, kbar, p)  # on current modal displacements (K, d, d)
    wd = np.einsum("ai,kab->kib", p, kbar)  # on delayed displacements (K, d, p)
    select = np.zeros((np_, n_state))
    select[:, :d] = p  # r = select @ z
    free = np.zeros((n_state, n_state))
    free[:d, d:] = np.eye(d)
    free[d:, :d] = -minv[:, None] * np.diag(ks)
    free[d:, d:] = -np.diag(minv * cs)
    phi = np.empty((bsz, n_int, n_state, n_state))
    r0 = np.zeros((bsz, n_int, n_state, np_))
    r1 = np.zeros((bsz, n_int, n_state, np_))
    cut_idx = np.flatnonzero(grid.cutting)
    free_idx = np.flatnonzero(~grid.cutting)
    if free_idx.size:
        phi[:, free_idx] = expm_batch(free[None, None] * dt[:, free_idx, None, None])
    if cut_idx.size:
        size = n_state + 2 * np_
        aug = np.zeros((bsz, cut_idx.size, size, size))
        h = dt[:, cut_idx, None, None]
        scale = depth_m[:, None, None, None] * minv[None, None, :, None] * h
        aug[:, :, :n_state, :n_state] = free * h
        aug[:, :, d:n_state, :d] += scale * w[None, cut_idx]
        aug[:, :, d:n_state, n_state:n_state + np_] = -scale * wd[None, cut_idx]
        aug[:, :, n_state:n_state + np_, n_state + np_:] = np.eye(np_)
        e = expm_batch(aug)
        phi[:, cut_idx] = e[..., :n_state, :n_state]
        g0 = e[..., :n_state, n_state:n_state + np_]
        g1 = e[..., :n_state, n_state + np_:]
        r0[:, cut_idx] = g0 - g1
        r1[:, cut_idx] = g1
    return phi, r0, r1, select, free


def monodromy_order(model: ModalModel, grid: _Grid) -> int:
    """The order ``N = 2d + K p`` of the monodromy matrix (d modes, K grid intervals, p directions with modes)."""
    return 2 * len(model.modes) + grid.size * int(np.unique(model.arrays()["direction"]).size)


def _monodromy(model: ModalModel, grid: _Grid, speed_rpm: np.ndarray, depth_m: np.ndarray) -> np.ndarray:
    """Monodromy matrices for pairs (speed, depth), shape ``(B, N, N)``, ``N = 2d + K p``.

    The state is ``[z_0, r_-1, ..., r_-K]``: the modal state now and the
    tool's displacements in the ``p`` directions that have modes at the K
    grid points of the previous period (the delayed term needs only those).
    """
    return _assemble(grid, *_steps(model, grid, speed_rpm, depth_m)[:4])


def _assemble(grid: _Grid, phi: np.ndarray, r0: np.ndarray, r1: np.ndarray, select: np.ndarray) -> np.ndarray:
    """The product of the step maps as a matrix on ``[z_0, r_-1, ..., r_-K]``.

    Before step ``i`` only the columns of ``z_0`` and of the ``i + 1`` oldest
    displacements can be non-zero (the others have not entered yet): the
    steps multiply those alone, half the work of the whole matrix.
    """
    bsz, n_int, n_state = phi.shape[0], phi.shape[1], phi.shape[2]
    np_ = select.shape[0]
    size = n_state + n_int * np_

    def col(j: int) -> slice:  # columns of r_j (j < 0) in the initial state [z0, r_-1, ..., r_-K]
        return slice(n_state + (-j - 1) * np_, n_state + (-j) * np_)

    u = np.zeros((bsz, size, size))
    z = np.zeros((bsz, n_state, size))
    z[:, :, :n_state] = np.eye(n_state)
    for i in range(n_int):
        lo = n_state + (n_int - i - 1) * np_  # the columns of r_-K ... r_i-K, the only delayed ones so far
        lag = n_int - 1 - i
        u[:, n_state + lag * np_:n_state + (lag + 1) * np_, :n_state] = select @ z[:, :, :n_state]
        u[:, n_state + lag * np_:n_state + (lag + 1) * np_, lo:] = select @ z[:, :, lo:]
        z[:, :, :n_state] = phi[:, i] @ z[:, :, :n_state]
        z[:, :, lo:] = phi[:, i] @ z[:, :, lo:]
        if grid.cutting[i]:
            z[:, :, col(i - n_int)] += r0[:, i]
            if i == n_int - 1:  # r_0 = select @ z_0
                z[:, :, :n_state] += r1[:, i] @ select
            else:
                z[:, :, col(i - n_int + 1)] += r1[:, i]
    u[:, :n_state] = z
    return u


class _Plan:
    """How finely each spindle speed is discretised, and the grids (cached by interval count).

    With ``intervals`` given, every speed uses that many intervals in the cut.
    Otherwise a speed gets ``max(min_intervals, ceil(omega_ref * T_cut / max_phase_step))``,
    rounded up on a ladder of counts (so that speeds share grids and batch
    together): ``omega_ref * dt`` stays below ``max_phase_step`` [rad], with
    ``omega_ref`` the highest natural frequency among the modes whose peak
    receptance is at least a tenth of the largest.
    """

    def __init__(self, model: ModalModel, cut: Any, intervals: int | None, min_intervals: int,
                 max_phase_step: float) -> None:
        for name, value in (("intervals", intervals), ("min_intervals", min_intervals)):
            if value is not None:
                whole_number(value, name, 1)
        if not max_phase_step > 0:
            raise InvalidValueError(f"max_phase_step: got {max_phase_step!r}; expected a positive angle in rad")
        self.cut, self.fixed, self.min_intervals, self.max_phase_step = cut, intervals, min_intervals, max_phase_step
        arr = model.arrays()
        peak = 1.0 / (2.0 * arr["stiffness"] * arr["damping_ratio"])
        self.reference_hz = float(arr["frequency_hz"][peak >= 0.1 * peak.max()].max())
        self.cut_fraction = sum(b - a for a, b, c in cut.period_arcs() if c) / cut.period_angle
        self.teeth = cut.regenerations_per_revolution
        self._grids: dict[int, _Grid] = {}

    def cut_phase(self, speed_rpm: np.ndarray) -> np.ndarray:
        """``omega_ref * T_cut`` [rad]: the phase of the reference mode over the cutting part of a delay period."""
        return 2 * np.pi * self.reference_hz * self.cut_fraction * 60.0 / (self.teeth * np.asarray(speed_rpm))

    def intervals_for(self, speed_rpm: np.ndarray) -> np.ndarray:
        if self.fixed is not None:
            return np.full(speed_rpm.size, int(self.fixed))
        t_cut = self.cut_fraction * 60.0 / (self.teeth * speed_rpm)
        need = np.maximum(self.min_intervals, np.ceil(2 * np.pi * self.reference_hz * t_cut / self.max_phase_step))
        ladder = np.unique(np.round(self.min_intervals * 1.1 ** np.arange(80)).astype(int))
        return ladder[np.minimum(np.searchsorted(ladder, need), ladder.size - 1)]

    def grid(self, intervals: int) -> _Grid:
        if intervals not in self._grids:
            self._grids[intervals] = _Grid(self.cut, int(intervals))
        return self._grids[intervals]


def _workers() -> int:
    return max(1, min(4, os.cpu_count() or 1))


ARNOLDI_ORDER = 400
"""From this order up the largest multiplier comes from Arnoldi iterations, not from every eigenvalue.

Full eigenvalue problems cost the cube of the order: at 2,000 rpm on a tool
with modes up to 4 kHz the monodromy matrix is of order about 3,900, 26 s
per (speed, depth) pair; implicitly restarted Arnoldi (ARPACK, matrix-vector
products only) finds its largest multipliers in about 0.5 s, the same to
about 1e-14 relative.
"""
_RITZ = 6  # multipliers of largest modulus Arnoldi converges (several, so that near ties are resolved)


def _largest(u: np.ndarray, vectors: bool = False) -> tuple[np.ndarray, np.ndarray | None]:
    """The multiplier of largest modulus of each matrix of a stack ``(B, N, N)``, and its eigenvector.

    Below :data:`ARNOLDI_ORDER` all eigenvalues of the stack at once (LAPACK);
    from it up Arnoldi iterations per matrix from a fixed start vector (the
    same answer on every run), with the full problem where ARPACK does not
    converge.
    """
    rows = np.arange(u.shape[0])
    if u.shape[-1] < ARNOLDI_ORDER:
        if vectors:
            w, v = np.linalg.eig(u)
            k = np.argmax(np.abs(w), axis=1)
            return w[rows, k], v[rows, :, k]
        w = np.linalg.eigvals(u)
        return w[rows, np.argmax(np.abs(w), axis=1)], None
    from scipy.sparse.linalg import ArpackError, ArpackNoConvergence, eigs

    start = np.random.default_rng(0).standard_normal(u.shape[-1])
    mu = np.empty(rows.size, dtype=complex)
    vec = np.empty((rows.size, u.shape[-1]), dtype=complex) if vectors else None
    for j in rows:
        found = None
        if np.isfinite(u[j]).all():  # else LAPACK below says what is wrong (ARPACK fails less clearly)
            try:
                found = eigs(u[j], k=_RITZ, which="LM", v0=start, tol=0.0, return_eigenvectors=True)
            except (ArpackNoConvergence, ArpackError):
                pass
        w, v = found if found is not None else np.linalg.eig(u[j])
        k = int(np.argmax(np.abs(w)))
        mu[j] = w[k]
        if vec is not None:
            vec[j] = v[:, k]
    return mu, vec


def _chunks(model: ModalModel, plan: _Plan, speed_rpm: np.ndarray) -> list[tuple[_Grid, np.ndarray]]:
    """The pairs grouped by grid and cut into chunks whose monodromy matrices fit in bounded memory."""
    d = len(model.modes)
    p = np.unique(model.arrays()["direction"]).size
    counts = plan.intervals_for(speed_rpm)
    tasks = []
    for m in np.unique(counts):
        grid = plan.grid(int(m))
        pairs = np.flatnonzero(counts == m)
        per_pair = int(grid.cutting.sum()) * (2 * d + 2 * p) ** 2 * 12 + 4 * monodromy_order(model, grid) ** 2
        chunk = max(1, min(int(2e7 // per_pair), -(-pairs.size // _workers())))
        tasks += [(grid, pairs[s:s + chunk]) for s in range(0, pairs.size, chunk)]
    return tasks


def _critical(model: ModalModel, plan: _Plan, speed_rpm: np.ndarray, depth_m: np.ndarray
              ) -> tuple[np.ndarray, np.ndarray]:
    """Spectral radius and the critical multiplier for pairs (speed, depth).

    Pairs are grouped by grid and cut into chunks (bounded memory); chunks
    run on a few threads (numpy releases the GIL in its batched kernels)
    with BLAS held to one thread each: many small eigenvalue problems are
    fastest one per core, and a multi-threaded BLAS on matrices of this
    size is several times slower when the cores are busy.
    """
    mu = np.empty(speed_rpm.size, dtype=complex)
    tasks = _chunks(model, plan, speed_rpm)

    def run(task) -> None:
        grid, part = task
        mu[part] = _largest(_monodromy(model, grid, speed_rpm[part], depth_m[part]))[0]

    with one_blas_thread():
        if len(tasks) == 1 or _workers() == 1:
            for task in tasks:
                run(task)
        else:
            with ThreadPoolExecutor(max_workers=_workers()) as pool:
                list(pool.map(run, tasks))
    return np.abs(mu), mu


def _chatter(model: ModalModel, plan: _Plan, speed_rpm: np.ndarray, depth_m: np.ndarray) -> tuple[np.ndarray, list]:
    """Chatter frequency and bifurcation at the limit, from the critical Floquet solution.

    The critical multiplier ``mu`` fixes the chatter frequencies only up to
    tooth-passing harmonics: the vibration is ``r(t) = exp(lambda t) p(t)``
    with ``exp(lambda T) = mu`` and ``p`` periodic, so it holds the
    frequencies ``(arg(mu) / 2 pi + k) / T`` together.  The one reported is
    the strongest: the trajectory of the critical eigenvector is followed
    over one period (free-vibration stretches sampled exactly in between),
    ``p`` is fitted with harmonics by least squares, and the largest
    harmonic wins.  For turning (a constant ``p``) that is the chatter
    frequency itself.  ``bifurcation`` is ``"flip"`` for a real negative
    multiplier (period doubling), ``"fold"`` for a real positive one, else
    ``"hopf"``.
    """
    freq = np.empty(speed_rpm.size)
    kinds = [""] * speed_rpm.size
    f_top = 1.5 * model.arrays()["frequency_hz"].max()
    for grid, idx in _chunks(model, plan, speed_rpm):
        phi, r0, r1, select, free = _steps(model, grid, speed_rpm[idx], depth_m[idx])
        with one_blas_thread():
            mu, vec = _largest(_assemble(grid, phi, r0, r1, select), vectors=True)
        assert vec is not None
        period = 60.0 / (plan.teeth * speed_rpm[idx])
        harmonics = int(np.ceil(f_top * period.max())) + 1
        n_state, n_int, n_dir = phi.shape[2], grid.size, select.shape[0]
        spin = 2.0 * np.pi * speed_rpm[idx] / 60.0
        z = vec[:, :n_state]

        def delayed(j: int) -> np.ndarray:  # r_j of the previous period (j < 0), or r_0
            if j == 0:
                return vec[:, :n_state] @ select.T
            return vec[:, n_state + (-j - 1) * n_dir:n_state + (-j) * n_dir]

        angles, samples = [], []
        for i in range(n_int):
            angles.append(np.full(idx.size, grid.theta[i]))
            samples.append(z @ select.T)
            if not grid.cutting[i]:  # sample the free vibration in between, exactly
                width = grid.theta[i + 1] - grid.theta[i]
                extra = int(np.ceil(width / grid.period_angle * (4 * harmonics + 4)))
                frac = np.arange(1, extra) / extra
                if frac.size:
                    e = expm_batch(free[None, None] * (frac[None, :, None, None] * width / spin[:, None, None, None]))
                    r = np.einsum("pn,bsnm,bm->bsp", select, e, z)
                    angles += list(grid.theta[i] + frac[:, None] * width * np.ones(idx.size))
                    samples += list(np.moveaxis(r, 1, 0))
            nxt = np.einsum("bnm,bm->bn", phi[:, i], z)
            if grid.cutting[i]:
                nxt += np.einsum("bnp,bp->bn", r0[:, i], delayed(i - n_int))
                nxt += np.einsum("bnp,bp->bn", r1[:, i], delayed(i - n_int + 1))
            z = nxt
        s = np.array(angles)[:, 0] / grid.period_angle  # t / T in [0, 1), the same for every speed
        periodic = np.array(samples) * np.exp(-np.log(mu)[None, :, None] * s[:, None, None])  # (S, B, p)
        h = min(harmonics, (s.size - 1) // 4)
        order = np.arange(-h, h + 1)
        basis = np.exp(2j * np.pi * order[None, :] * s[:, None])
        coef = np.linalg.lstsq(basis, periodic.reshape(s.size, -1), rcond=None)[0].reshape(order.size, idx.size, -1)
        strongest = order[np.argmax(np.linalg.norm(coef, axis=2), axis=0)]
        freq[idx] = np.abs((np.angle(mu) / (2 * np.pi) + strongest) / period)
        for j, a in zip(idx, np.abs(np.angle(mu))):
            kinds[j] = "flip" if a > np.pi - 1e-9 else ("fold" if a < 1e-9 else "hopf")
    return freq, kinds
