"""Compiled kernels (internal): Timoshenko segments, free-free chains and coupling updates.

The numerical hot path of every model evaluation, compiled with numba.  Each
kernel runs one loop over frequency lines and does all the work of a line in
registers and small scratch arrays: the closed-form transfer matrices of the
segments (:func:`_transfer`), their product and the free-end receptance
formula (:func:`chain_receptance`), and the 2x2 update of the coupling engine
(:func:`couple_link`).  Nothing is allocated per line and no intermediate
array over all lines is formed, which is what made the vectorised numpy
version memory-bound.

The mathematics is the one documented in :mod:`substructure.beams` and
:mod:`substructure._engine`; those modules prepare the inputs (sections,
intervals, nodes, cluster bookkeeping) and call these kernels, which are the
only implementation of the formulas.

Conventions for numba:

* ``fastmath=False``: IEEE arithmetic, no reassociation, so the rounding
  analysis of ``docs/beams.md`` holds;
* ``error_model="numpy"``: a division by zero gives inf/nan as in numpy
  (numba's default raises), and complex reciprocals are written out
  (:func:`_cinv`) because numba's complex division raises on a zero divisor;
* ``cache=True``: compiled code is kept on disk (``__pycache__`` next to this
  file, else numba's user cache directory); when no cache directory is
  writable the kernels are compiled in memory instead (:func:`_jit`);
* the Python wrappers pass C-contiguous arrays of fixed dtypes, so that each
  kernel is compiled for one signature only.

This module imports numba; :mod:`substructure.beams` and
:mod:`substructure._engine` import it on first use, so that
``import substructure`` stays light.
"""

from __future__ import annotations

import itertools
import math
import os
from concurrent.futures import ThreadPoolExecutor

import numba
import numpy as np

__all__ = ["transfer_matrices", "segment_coefficients", "chain_receptance", "couple_link", "threads", "c_array"]


def _jit(func=None, *, cache=False):
    """``numba.njit`` with the options above.

    Only the kernels called from Python are cached on disk (``cache=True``):
    a cached kernel carries the code of the helpers it calls, so the helpers
    are compiled only when a kernel is.  Without a writable cache directory
    the kernels are compiled in memory instead.
    """
    if func is None:
        return lambda f: _jit(f, cache=cache)
    options = dict(fastmath=False, error_model="numpy", nogil=True)
    if cache:
        try:
            return numba.njit(cache=True, **options)(func)
        except RuntimeError:  # "cannot cache function ...: no locator available" (read-only install, no home)
            pass
    return numba.njit(**options)(func)


def c_array(a, dtype) -> np.ndarray:
    """``a`` as a C-contiguous, writeable array of ``dtype``, copied only when needed.

    Numba compiles a kernel anew for each layout, dtype and read-only flag of
    its arrays; passing every input through here keeps one signature per
    kernel (one compilation, one cache entry).
    """
    return np.require(a, dtype=dtype, requirements=("C", "W"))


MIN_LINES_PER_TASK = 2048
"""Lines below which a kernel call is not split between threads."""

_pool_state: dict = {}


def threads() -> int:
    """Threads the kernels use: ``NUMBA_NUM_THREADS`` (default: the number of CPUs)."""
    return max(1, int(numba.config.NUMBA_NUM_THREADS))


def _pool() -> ThreadPoolExecutor:
    """The helper threads (``threads() - 1``: the calling thread works too), one pool per process.

    A forked child gets its own pool (the parent's threads do not exist in it).
    """
    pid = os.getpid()
    if _pool_state.get("pid") != pid:
        _pool_state["pool"] = ThreadPoolExecutor(
            max_workers=max(1, threads() - 1), thread_name_prefix="substructure-kernel"
        )
        _pool_state["pid"] = pid
    return _pool_state["pool"]


def over_lines(kernel, n: int, *args) -> bool:
    """Run ``kernel(*args, lo, hi)`` over the lines ``0 .. n - 1``, split between threads.

    The kernels release the GIL (``nogil``), so plain Python threads run them
    in parallel, each task writing its own lines of the output.  The lines
    are cut into a few tasks per thread; the calling thread and
    ``threads() - 1`` helpers take tasks in turn until none is left, so that
    a thread slowed by other work on the machine just takes fewer.  Calls of
    fewer than ``2 * MIN_LINES_PER_TASK`` lines, or with one thread, run in
    the calling thread alone.  Returns the ``and`` of the kernel's results
    (True for kernels that return nothing).
    """
    n_threads = threads()
    n_tasks = min(4 * n_threads, n // MIN_LINES_PER_TASK) if n_threads > 1 else 1
    if n_tasks <= 1:
        return kernel(*args, 0, n) is not False
    bounds = [n * k // n_tasks for k in range(n_tasks + 1)]
    claim = itertools.count()  # next() is atomic under the GIL

    def work() -> bool:
        ok = True
        for k in iter(claim.__next__, None):
            if k >= n_tasks:
                return ok
            ok = (kernel(*args, bounds[k], bounds[k + 1]) is not False) and ok
        return ok

    helpers = [_pool().submit(work) for _ in range(min(n_threads, n_tasks) - 1)]
    ok = work()
    # a helper still queued (behind other callers' helpers) has nothing left to do
    return all([h.cancel() or h.result() for h in helpers]) and ok


# 1/k! for the power series of the divided differences (k = 2n and 2n + 1, n <= 11)
_INV_FACTORIAL = np.array([1.0 / math.factorial(k) for k in range(24)])
_SERIES_LIMIT = 0.5  # |s L^2| below which the series are summed (docs/beams.md)
# Terms of the series: the smallest n >= 2 with |z|^n / (2n)! <= 1e-18, i.e.
# |z| <= (1e-18 (2n)!)^(1/n) = _SERIES_BOUND[n] (9 terms at |z| = 0.5).
_SERIES_BOUND = np.array([0.0] + [(1e-18 * math.factorial(2 * n)) ** (1.0 / n) for n in range(1, 12)])
_SERIES_LIMIT2 = _SERIES_LIMIT**2
_SERIES_BOUND2 = _SERIES_BOUND**2


# ---------------------------------------------------------------------------
# Scalar helpers


@_jit
def _cinv(z):
    """``1 / z`` by Smith's method; inf/nan for ``z = 0`` instead of an exception."""
    zr, zi = z.real, z.imag
    if abs(zr) >= abs(zi):
        r = zi / zr
        d = zr + zi * r
        return complex(1.0 / d, -r / d)
    r = zr / zi
    d = zr * r + zi
    return complex(r / d, -1.0 / d)


@_jit
def _crecip(z):
    """``1 / z = conj(z) / |z|^2`` for ``z`` well inside the range of doubles (wavenumbers), else Smith's."""
    zr, zi = z.real, z.imag
    d = zr * zr + zi * zi
    if 1e-290 < d < 1e290:
        f = 1.0 / d
        return complex(zr * f, -zi * f)
    return _cinv(z)


_SPLIT = 134217729.0  # 2^27 + 1: Veltkamp's splitting of a double into two halves


@_jit
def _dot4(a1, b1, a2, b2, a3, b3, a4, b4):
    """``a1 b1 + a2 b2 + a3 b3 + a4 b4`` as accurate as in twice the precision.

    Ogita, Rump and Oishi's Dot2: each product split exactly into ``p + e``
    (Dekker, with Veltkamp's splitting, no fused multiply-add needed), the
    ``p`` summed with exact error terms (Knuth's TwoSum), the errors added at
    the end.
    """
    total = 0.0
    err = 0.0
    for k in range(4):
        if k == 0:
            a, b = a1, b1
        elif k == 1:
            a, b = a2, b2
        elif k == 2:
            a, b = a3, b3
        else:
            a, b = a4, b4
        p = a * b
        t = _SPLIT * a
        ah = t - (t - a)
        al = a - ah
        t = _SPLIT * b
        bh = t - (t - b)
        bl = b - bh
        err += ((ah * bh - p) + ah * bl + al * bh) + al * bl
        s = total + p
        z = s - total
        err += (total - (s - z)) + (p - z)
        total = s
    return total + err


@_jit
def _det2(a, b, c, d):
    """``a d - b c`` of complex numbers, compensated.

    Near a natural frequency the two products cancel; summed naively their
    difference is only known to ``eps |a d|`` and can come out exactly 0 at a
    line next to the pole.  Where they cancel to less than ``1e-3`` of their
    size it is computed compensated: the determinant of the rounded entries,
    correctly rounded, which varies smoothly through the pole.  Elsewhere the
    plain difference has a relative error below ``3e-13`` and is used.
    """
    ad = a * d
    bc = b * c
    det = ad - bc
    # |det| well above the rounding of the products: the plain difference is exact enough
    size = abs(ad.real) + abs(ad.imag) + abs(bc.real) + abs(bc.imag)
    if abs(det.real) + abs(det.imag) > 1e-3 * size:
        return det
    re = _dot4(a.real, d.real, -a.imag, d.imag, -b.real, c.real, b.imag, c.imag)
    im = _dot4(a.real, d.imag, a.imag, d.real, -b.real, c.imag, -b.imag, c.real)
    return complex(re, im)


@_jit
def _csqrt(z):
    """Principal square root (``Re >= 0``, branch cut on the negative real axis, as numpy)."""
    x, y = z.real, z.imag
    if x == 0.0 and y == 0.0:
        return complex(0.0, y)
    r2 = x * x + y * y
    r = math.sqrt(r2) if 0.0 < r2 < math.inf else math.hypot(x, y)  # hypot only when x^2 + y^2 under/overflows
    if x >= 0.0:
        t = math.sqrt(0.5 * (r + x))
        return complex(t, 0.5 * y / t)
    t = math.sqrt(0.5 * (r - x))
    return complex(0.5 * abs(y) / t, math.copysign(t, y))


@_jit
def _coefficients(ei, kga, rhoa, rhoi):
    """Per-segment constants: ``a / w2``, ``e / w2``, ``rhoA / EI``, ``1 / EI``, ``1 / kGA``."""
    iei = _cinv(ei)
    ikga = _cinv(kga)
    return -rhoa * ikga, -rhoi * iei, rhoa * iei, iei, ikga


@_jit
def _wavenumbers(ca, ce, cr, w2):
    """``a, e`` (the diagonal of ``A^2``) and the eigenvalues ``s1, s2`` of ``A^2``."""
    a = w2 * ca
    e = w2 * ce
    half = 0.5 * (a - e)
    root = _csqrt(half * half + w2 * cr)
    mean = 0.5 * (a + e)
    return a, e, mean + root, mean - root


@_jit
def _transfer(ca, ce, cr, iei, ikga, rhoa, rhoi, length, w2, t, at):
    """Write ``T = exp(A L)`` of one segment at one line (``w2 = omega^2``) into ``t[at]`` (4x4).

    ``exp(A L) = C(A^2) + A S(A^2)`` with ``C(s) = cosh(L sqrt s)`` and
    ``S(s) = sinh(L sqrt s) / sqrt s``; ``g(A^2) = g(s2) I + g[s1, s2] (A^2 - s2 I)``.
    The divided differences come from their power series where
    ``max |s L^2| < 0.5`` (terms until ``|z|^n / (2n)! < 1e-18``), else from
    one exponential per wavenumber.
    """
    a, e, s1, s2 = _wavenumbers(ca, ce, cr, w2)
    l2 = length * length
    z1 = s1 * l2
    z2 = s2 * l2
    # max |z|^2, compared with the squared limits (no square roots)
    bound2 = max(z1.real * z1.real + z1.imag * z1.imag, z2.real * z2.real + z2.imag * z2.imag)
    if bound2 < _SERIES_LIMIT2:
        # h_n: complete homogeneous symmetric polynomial of degree n in z1, z2
        # (the divided difference of z^(n+1)); pow2 = z2^n.
        n_terms = 2
        while bound2 > _SERIES_BOUND2[n_terms]:
            n_terms += 1
        sc = 1.0 + 0j
        ss = 1.0 + 0j
        dc = 0j
        ds = 0j
        h = 1.0 + 0j
        pow2 = 1.0 + 0j
        for n in range(1, n_terms + 1):
            rc = _INV_FACTORIAL[2 * n]
            rs = _INV_FACTORIAL[2 * n + 1]
            dc += rc * h
            ds += rs * h
            pow2 = pow2 * z2
            sc += rc * pow2
            ss += rs * pow2
            h = z1 * h + pow2
        c0 = sc
        c1 = l2 * dc
        g0 = length * ss
        g1 = l2 * length * ds
    else:
        # cosh and sinh from exp(r L) = e^x (cos y + i sin y); Re r >= 0, so
        # exp(-r L) = e^-x (cos y - i sin y) <= 1 does not overflow first.
        r1 = _csqrt(s1)
        r2 = _csqrt(s2)
        x1, y1 = r1.real * length, r1.imag * length
        x2, y2 = r2.real * length, r2.imag * length
        p1 = math.exp(x1)
        p2 = math.exp(x2)
        m1 = 1.0 / p1
        m2 = 1.0 / p2
        cy1, sy1 = math.cos(y1), math.sin(y1)
        cy2, sy2 = math.cos(y2), math.sin(y2)
        ch1 = complex(0.5 * (p1 + m1) * cy1, 0.5 * (p1 - m1) * sy1)
        ch2 = complex(0.5 * (p2 + m2) * cy2, 0.5 * (p2 - m2) * sy2)
        sh1 = complex(0.5 * (p1 - m1) * cy1, 0.5 * (p1 + m1) * sy1) * _crecip(r1)
        sh2 = complex(0.5 * (p2 - m2) * cy2, 0.5 * (p2 + m2) * sy2) * _crecip(r2)
        ids = _crecip(s1 - s2)
        c0 = ch2
        c1 = (ch1 - ch2) * ids
        g0 = sh2
        g1 = (sh1 - sh2) * ids
    alpha = c0 - c1 * s2
    beta = g0 - g1 * s2
    gamma = c1
    delta = g1
    ma = w2 * rhoa
    mi = w2 * rhoi
    # T = alpha I + beta A + gamma A^2 + delta A^3, entry by entry (A, A^2, A^3 are sparse)
    d00 = alpha + gamma * a
    d11 = alpha + gamma * e
    t[at, 0, 0] = d00
    t[at, 2, 2] = d00
    t[at, 1, 1] = d11
    t[at, 3, 3] = d11
    t[at, 0, 1] = beta + delta * (a + e)
    t[at, 0, 2] = beta * ikga + delta * (a * ikga - iei)
    g_ei = gamma * iei
    t[at, 0, 3] = g_ei
    t[at, 1, 2] = -g_ei
    d_ma_ei = delta * ma * iei
    t[at, 1, 0] = d_ma_ei
    t[at, 2, 3] = -d_ma_ei
    t[at, 1, 3] = (beta + delta * e) * iei
    t[at, 2, 0] = -(beta + delta * a) * ma
    g_ma = gamma * ma
    t[at, 3, 0] = g_ma
    t[at, 2, 1] = -g_ma
    t[at, 3, 1] = -beta * mi + delta * (ma - mi * e)
    t[at, 3, 2] = -beta + delta * (mi * iei - a)


# ---------------------------------------------------------------------------
# Kernels over frequency lines


@_jit
def _base_columns(tmat, seg_of, nodes, cols, tmp, pre):
    """The ``u``-columns of ``T(0 -> x)``, carried from the base to the tip.

    ``pre[p]`` receives ``P_p,uu = T(0 -> x_p)[0:2, 0:2]`` at each node and
    ``cols`` ends as ``M[:, 0:2]``, ``M = T(0 -> L)``.
    """
    n_int = seg_of.size
    m = nodes.size
    p = 0
    fresh = True  # cols is still the identity: the first product is a copy
    for k in range(n_int + 1):
        if p < m and nodes[p] == k:
            for r in range(2):
                for c in range(2):
                    pre[p, r, c] = (1.0 if r == c else 0.0) if fresh else cols[r, c]
            p += 1
        if k == n_int:
            break
        s = seg_of[k]
        if fresh:
            for r in range(4):
                cols[r, 0] = tmat[s, r, 0]
                cols[r, 1] = tmat[s, r, 1]
            fresh = False
        else:
            for r in range(4):
                for c in range(2):
                    tmp[r, c] = (tmat[s, r, 0] * cols[0, c] + tmat[s, r, 1] * cols[1, c]
                                 + tmat[s, r, 2] * cols[2, c] + tmat[s, r, 3] * cols[3, c])
            for r in range(4):
                cols[r, 0] = tmp[r, 0]
                cols[r, 1] = tmp[r, 1]


@_jit
def _tip_rows(tmat, seg_of, nodes, rows, tmp, post):
    """The ``F``-rows of ``T(x -> L)``, carried from the tip to the base.

    ``post[p]`` receives ``S_p,FF = T(x_p -> L)[2:4, 2:4]`` at each node.
    """
    n_int = seg_of.size
    p = nodes.size - 1
    fresh = True  # rows is still the identity
    for k in range(n_int, -1, -1):
        if p >= 0 and nodes[p] == k:
            for r in range(2):
                for c in range(2):
                    post[p, r, c] = (1.0 if r == c else 0.0) if fresh else rows[r, c + 2]
            p -= 1
        if k == 0 or p < 0:
            break
        s = seg_of[k - 1]
        if fresh:
            for c in range(4):
                rows[0, c] = tmat[s, 2, c]
                rows[1, c] = tmat[s, 3, c]
            fresh = False
        else:
            for r in range(2):
                for c in range(4):
                    tmp[r, c] = (rows[r, 0] * tmat[s, 0, c] + rows[r, 1] * tmat[s, 1, c]
                                 + rows[r, 2] * tmat[s, 2, c] + rows[r, 3] * tmat[s, 3, c])
            for c in range(4):
                rows[0, c] = tmp[0, c]
                rows[1, c] = tmp[1, c]


@_jit
def _chain_line(tmat, seg_of, nodes, place, out, q, cols, rows, tmp_c, tmp_r, pre, post):
    """Free-free receptances of a chain at its nodes, one line, into ``out[:, :, q]``.

    ``Y_ij = P_i,uu M_Fu^-1 S_j,FF`` for ``x_i <= x_j``, with
    ``P_i = T(0 -> x_i)``, ``S_j = T(x_j -> L)`` and ``M = T(0 -> L)``
    (state ``[u; F]``, ``u = [w, psi]``, ``F = [V, M]``); ``Y_ji = Y_ij^T``.

    The blocks below the diagonal are not computed from their own formula,
    ``Y_ij - T(x_j -> x_i)_uF``: its two terms grow like ``exp(k (x_i - x_j))``
    and cancel, which loses ``exp(k L)`` more digits than the blocks above,
    whose three factors stay bounded.  The beam is reciprocal (its operator
    is complex-symmetric, with or without loss factors), so the blocks below
    are the transposes of the blocks above.  Node ``i`` goes to the block
    row and column ``place[i]`` of ``out``.
    """
    m = nodes.size
    _base_columns(tmat, seg_of, nodes, cols, tmp_c, pre)
    _tip_rows(tmat, seg_of, nodes, rows, tmp_r, post)
    idet = _cinv(_det2(cols[2, 0], cols[2, 1], cols[3, 0], cols[3, 1]))
    i00 = cols[3, 1] * idet
    i11 = cols[2, 0] * idet
    i01 = -cols[2, 1] * idet
    i10 = -cols[3, 0] * idet
    for i in range(m):
        # left = P_i,uu M_Fu^-1
        l00 = pre[i, 0, 0] * i00 + pre[i, 0, 1] * i10
        l01 = pre[i, 0, 0] * i01 + pre[i, 0, 1] * i11
        l10 = pre[i, 1, 0] * i00 + pre[i, 1, 1] * i10
        l11 = pre[i, 1, 0] * i01 + pre[i, 1, 1] * i11
        pi = 2 * place[i]
        for j in range(i, m):
            pj = 2 * place[j]
            y00 = l00 * post[j, 0, 0] + l01 * post[j, 1, 0]
            y01 = l00 * post[j, 0, 1] + l01 * post[j, 1, 1]
            y10 = l10 * post[j, 0, 0] + l11 * post[j, 1, 0]
            y11 = l10 * post[j, 0, 1] + l11 * post[j, 1, 1]
            out[pi, pj, q] = y00
            out[pi, pj + 1, q] = y01
            out[pi + 1, pj, q] = y10
            out[pi + 1, pj + 1, q] = y11
            if j > i:
                out[pj, pi, q] = y00
                out[pj + 1, pi, q] = y01
                out[pj, pi + 1, q] = y10
                out[pj + 1, pi + 1, q] = y11


@_jit(cache=True)
def segment_coefficients(ei, kga, rhoa, rhoi, omega_max):
    """:func:`_coefficients` of segments ``(n_u, n_c)``: ``(n_u, n_c, 5)`` complex.

    Also the largest wavenumber ``sqrt(max(|s1|, |s2|))`` of each segment at
    ``omega_max``, ``(n_u, n_c)``, from which a chain is cut into pieces.
    """
    n_u, n_c = ei.shape
    coef = np.empty((n_u, n_c, 5), dtype=np.complex128)
    k_max = np.empty((n_u, n_c))
    w2 = omega_max * omega_max
    for u in range(n_u):
        for c in range(n_c):
            ca, ce, cr, iei, ikga = _coefficients(ei[u, c], kga[u, c], rhoa[u, c], rhoi[u, c])
            coef[u, c, 0] = ca
            coef[u, c, 1] = ce
            coef[u, c, 2] = cr
            coef[u, c, 3] = iei
            coef[u, c, 4] = ikga
            _, _, s1, s2 = _wavenumbers(ca, ce, cr, w2)
            k_max[u, c] = math.sqrt(max(abs(s1), abs(s2)))
    return coef, k_max


@_jit(cache=True)
def chain_lines(omega, coef, rhoa, rhoi, length, slot, table, seg_of, nodes, place, out, table_only, lo, hi):
    """Lines ``lo .. hi - 1`` of :func:`chain_receptance` into ``out`` (line ``q = c * n_f + i``).

    With ``table_only``, instead, the transfer matrices of the shared
    segments (``slot[u] >= 0``) at the frequency lines ``lo .. hi - 1`` into
    ``table[slot[u] * n_f + i]``.  (One compiled function for both, so that
    the closed form is compiled once.)
    """
    n_f = omega.size
    n_u = slot.size
    m = nodes.size
    tmat = np.empty((n_u, 4, 4), dtype=np.complex128)
    cols = np.empty((4, 2), dtype=np.complex128)
    rows = np.empty((2, 4), dtype=np.complex128)
    tmp_c = np.empty((4, 2), dtype=np.complex128)
    tmp_r = np.empty((2, 4), dtype=np.complex128)
    pre = np.empty((m, 2, 2), dtype=np.complex128)
    post = np.empty((m, 2, 2), dtype=np.complex128)
    for q in range(lo, hi):
        c = 0 if table_only else q // n_f
        i = q - c * n_f
        w2 = omega[i] * omega[i]
        for u in range(n_u):
            shared = slot[u] >= 0
            if shared and not table_only:
                at = slot[u] * n_f + i
                for r in range(4):
                    for cc in range(4):
                        tmat[u, r, cc] = table[at, r, cc]
            elif shared or not table_only:
                # (one call site: the closed form is compiled once)
                _transfer(coef[u, c, 0], coef[u, c, 1], coef[u, c, 2], coef[u, c, 3], coef[u, c, 4],
                          rhoa[u, c], rhoi[u, c], length[u, c], w2, tmat, u)
                if table_only:
                    at = slot[u] * n_f + i
                    for r in range(4):
                        for cc in range(4):
                            table[at, r, cc] = tmat[u, r, cc]
        if not table_only:
            _chain_line(tmat, seg_of, nodes, place, out, q, cols, rows, tmp_c, tmp_r, pre, post)


_NO_NODES = np.zeros(0, dtype=np.int64)
_NO_OUT = np.zeros((0, 0, 0), dtype=np.complex128)


def _shared_table(omega, coef, rhoa, rhoi, length, shared):
    """``slot`` (place of each shared segment in the table, else -1) and the table of their transfer matrices."""
    slot = np.full(shared.size, -1, dtype=np.int64)
    slot[shared] = np.arange(int(np.count_nonzero(shared)))
    table = np.empty((int(np.count_nonzero(shared)) * omega.size, 4, 4), dtype=np.complex128)
    if table.size:
        over_lines(chain_lines, omega.size, omega, coef, rhoa, rhoi, length, slot, table,
                   _NO_NODES, _NO_NODES, _NO_NODES, _NO_OUT, True)
    return slot, table


def transfer_matrices(omega, ei, kga, rhoa, rhoi, length):
    """``T = exp(A L)`` of uniform segments at every line: ``(n_u, n_f, 4, 4)`` complex.

    ``ei, kga`` complex and ``rhoa, rhoi, length`` float, arrays ``(n_u, 1)``.
    """
    coef, _ = segment_coefficients(ei, kga, rhoa, rhoi, 0.0)
    _, table = _shared_table(omega, coef, rhoa, rhoi, length, np.ones(ei.shape[0], dtype=bool))
    return table.reshape(ei.shape[0], omega.size, 4, 4)


def chain_receptance(omega, ei, kga, rhoa, rhoi, length, shared, seg_of, nodes, place):
    """Free-free receptances of chains of uniform intervals, for many configurations.

    Parameters (arrays, C-contiguous)
    ----------
    omega : float64 (n_f,)
        Angular frequency lines.
    ei, kga : complex128 (n_u, n_c); rhoa, rhoi, length : float64 (n_u, n_c)
        Section and length of each distinct segment ``u`` in each
        configuration ``c``.
    shared : bool (n_u,)
        Segment ``u`` is the same in every configuration: its transfer
        matrices are computed once per line and reused.
    seg_of : int64 (n_int,)
        The segment of each interval, base to tip.
    nodes : int64 (m,)
        Sorted, distinct node indices in ``0 .. n_int`` (node ``k`` is the
        base of interval ``k``; node ``n_int`` is the tip).
    place : int64 (m,)
        Where node ``i`` goes in the result (a permutation of ``0 .. m - 1``).

    Returns
    -------
    complex128 (2m, 2m, n_c * n_f)
        DOFs ``(y, theta)`` per node; the last axis runs over configurations
        first (``index = c * n_f + line``).
    """
    n_c = ei.shape[1]
    m = nodes.size
    coef, _ = segment_coefficients(ei, kga, rhoa, rhoi, 0.0)
    slot, table = _shared_table(omega, coef, rhoa, rhoi, length, shared)
    out = np.empty((2 * m, 2 * m, n_c * omega.size), dtype=np.complex128)
    over_lines(chain_lines, out.shape[-1], omega, coef, rhoa, rhoi, length, slot, table, seg_of, nodes, place,
               out, False)
    return out


# ---------------------------------------------------------------------------
# The coupling update


@_jit
def _block(ya, yb, sp, p, sq, pq, line):
    """Block ``(p, pq)`` of the block-diagonal pair ``diag(ya, yb)`` at one line, as four entries."""
    if sp != sq:
        return 0j, 0j, 0j, 0j
    r = 2 * p
    c = 2 * pq
    if sp == 0:  # (no array variable: binding one costs a reference count per call)
        return ya[r, c, line], ya[r, c + 1, line], ya[r + 1, c, line], ya[r + 1, c + 1, line]
    return yb[r, c, line], yb[r, c + 1, line], yb[r + 1, c, line], yb[r + 1, c + 1, line]


@_jit(cache=True)
def couple_lines(ya, yb, a_src, a_idx, b_src, b_idx, src, idx, stiffness, rigid, out, lo, hi):
    """Lines ``lo .. hi - 1`` of :func:`couple_link` into ``out``; False if any entry is not finite."""
    n = ya.shape[2]
    n_k = stiffness.shape[2]
    m = src.size
    uw = np.empty((m, 4), dtype=np.complex128)
    ground = b_src < 0
    bad = 0j  # stays 0 while every entry is finite (x - x is nan for inf and nan)
    for q in range(lo, hi):
        # S = B Y B^T = (Y_aa + Y_bb) - (Y_ab + Y_ba)
        s00, s01, s10, s11 = _block(ya, yb, a_src, a_idx, a_src, a_idx, q)
        if not ground:
            b00, b01, b10, b11 = _block(ya, yb, b_src, b_idx, b_src, b_idx, q)
            x00, x01, x10, x11 = _block(ya, yb, a_src, a_idx, b_src, b_idx, q)
            z00, z01, z10, z11 = _block(ya, yb, b_src, b_idx, a_src, a_idx, q)
            s00 = (s00 + b00) - (x00 + z00)
            s01 = (s01 + b01) - (x01 + z01)
            s10 = (s10 + b10) - (x10 + z10)
            s11 = (s11 + b11) - (x11 + z11)
        # W = S^-1 (rigid), or W = K (I + S K)^-1
        if rigid:
            e00, e01, e10, e11 = s00, s01, s10, s11
        else:
            kq = q if n_k == n else 0
            k00, k01 = stiffness[0, 0, kq], stiffness[0, 1, kq]
            k10, k11 = stiffness[1, 0, kq], stiffness[1, 1, kq]
            e00 = 1.0 + s00 * k00 + s01 * k10
            e01 = s00 * k01 + s01 * k11
            e10 = s10 * k00 + s11 * k10
            e11 = 1.0 + s10 * k01 + s11 * k11
        idet = _cinv(_det2(e00, e01, e10, e11))
        w00, w01, w10, w11 = e11 * idet, -e01 * idet, -e10 * idet, e00 * idet
        if not rigid:
            f00, f01, f10, f11 = w00, w01, w10, w11
            w00 = k00 * f00 + k01 * f10
            w01 = k00 * f01 + k01 * f11
            w10 = k10 * f00 + k11 * f10
            w11 = k10 * f01 + k11 * f11
        for i in range(m):
            # (Y B^T)_i = Y_ia - Y_ib, times W
            u00, u01, u10, u11 = _block(ya, yb, src[i], idx[i], a_src, a_idx, q)
            if not ground:
                x00, x01, x10, x11 = _block(ya, yb, src[i], idx[i], b_src, b_idx, q)
                u00 -= x00
                u01 -= x01
                u10 -= x10
                u11 -= x11
            uw[i, 0] = u00 * w00 + u01 * w10
            uw[i, 1] = u00 * w01 + u01 * w11
            uw[i, 2] = u10 * w00 + u11 * w10
            uw[i, 3] = u10 * w01 + u11 * w11
        for j in range(m):
            # (B Y)_j = Y_aj - Y_bj
            v00, v01, v10, v11 = _block(ya, yb, a_src, a_idx, src[j], idx[j], q)
            if not ground:
                x00, x01, x10, x11 = _block(ya, yb, b_src, b_idx, src[j], idx[j], q)
                v00 -= x00
                v01 -= x01
                v10 -= x10
                v11 -= x11
            for i in range(m):
                y00, y01, y10, y11 = _block(ya, yb, src[i], idx[i], src[j], idx[j], q)
                y00 -= uw[i, 0] * v00 + uw[i, 1] * v10
                y01 -= uw[i, 0] * v01 + uw[i, 1] * v11
                y10 -= uw[i, 2] * v00 + uw[i, 3] * v10
                y11 -= uw[i, 2] * v01 + uw[i, 3] * v11
                out[2 * i, 2 * j, q] = y00
                out[2 * i, 2 * j + 1, q] = y01
                out[2 * i + 1, 2 * j, q] = y10
                out[2 * i + 1, 2 * j + 1, q] = y11
                bad += ((y00 - y00) + (y01 - y01)) + ((y10 - y10) + (y11 - y11))
    return bad == 0j


def couple_link(ya, yb, a_src, a_idx, b_src, b_idx, src, idx, stiffness, rigid):
    """One link of the coupling engine on all lines: ``Y_c = Y - (Y B^T) W (B Y)``.

    ``Y`` is block diagonal, ``diag(ya, yb)`` (``yb`` is ignored when every
    point is in ``ya``), with 2x2 blocks per point; a point is ``(src, idx)``,
    ``src`` 0 for ``ya`` and 1 for ``yb``.  The link acts on
    ``u_a - u_b`` (``b_src < 0``: to the ground) with
    ``W = S^-1`` (``rigid``) or ``W = K (I + S K)^-1``, ``S = B Y B^T``;
    ``stiffness`` is ``(2, 2, n)`` or ``(2, 2, 1)``.  Returns the coupled
    receptances between the kept points ``(src, idx)``, ``(2k, 2k, n)``, and
    whether every entry is finite.
    """
    n = ya.shape[2]
    out = np.empty((2 * src.size, 2 * src.size, n), dtype=np.complex128)
    finite = over_lines(couple_lines, n, ya, yb, a_src, a_idx, b_src, b_idx, src, idx, stiffness, rigid, out)
    return out, finite
