"""The compiled beam kernel against an independent evaluation of the exact Timoshenko beam in extended precision.

The reference shares nothing with the kernel but the equations (docs/beams.md):

* ``T = exp(A L)`` of the first-order system ``z' = A z``, state
  ``z = [w, psi, V, M]``, by a Taylor series with scaling and squaring after a
  diagonal balancing, in numpy's ``longdouble`` (x86-64: 64-bit mantissa,
  eps 1.1e-19).  No eigenvalues, no cosh/sinh, no divided differences, no
  power series of the closed form.
* Receptances of a stepped beam by the finite-element-like route instead of
  the kernel's transfer-matrix chain: each piece's 4x4 dynamic stiffness from
  its ``T``, assembled into the global free-free stiffness and solved with
  unit loads by Gaussian elimination with partial pivoting, again in
  ``longdouble``.  The beam is cut into pieces of ``k L <= 2`` so that every
  piece's stiffness is well conditioned.

Stated tolerances (relative, per frequency line): transfer matrices 1e-13 of
their norm in balanced coordinates (measured <= 1.2e-15); receptances 1e-10
of the norm of the receptance matrix with rotations scaled by the beam
length, and the direct tip receptance 1e-10 of its own modulus (measured
<= 6.5e-12 and <= 5.8e-12, at 40 kHz: rounding in double grows with
``exp(k L)`` up to the chain cut at ``k L = 8``).  Cases: stiff and short, slender and long (cut into several
chains), hollow and damped, carbide, from 10 Hz to 40 kHz.
"""

import math

import numpy as np
import pytest

from substructure import Material, Segment
from substructure.beams import segment_transfer_matrix, stepped_beam_receptance

pytestmark = pytest.mark.skipif(
    np.finfo(np.longdouble).eps > 1e-18, reason="the reference needs an extended-precision longdouble"
)

LOSSY = Material("lossy steel", E="205 GPa", nu=0.29, rho="7850 kg/m^3", loss_factor=0.02)

SEGMENTS = {
    "stiff short": [Segment("5 mm", "40 mm", material="carbide")],
    "slender long": [Segment("160 mm", "6 mm", material="steel")],
    "hollow damped": [Segment("50 mm", "30 mm", "10 mm", material=LOSSY)],
    "stepped tool": [
        Segment("40 mm", "20 mm", material="steel"),
        Segment("25 mm", "16 mm", "4 mm", material=LOSSY),
        Segment("35 mm", "12 mm", material="carbide"),
        Segment("3 mm", "30 mm", material="steel"),
    ],
}

FREQUENCIES = np.concatenate([[10.0, 97.0], np.geomspace(400.0, 40000.0, 41)])


def system_matrix(sec, omega):
    """``A`` of ``z' = A z`` per line, (n, 4, 4) complex longdouble."""
    n = omega.size
    w2 = omega.astype(np.longdouble) ** 2
    a = np.zeros((n, 4, 4), dtype=np.clongdouble)
    a[:, 0, 1] = 1
    a[:, 0, 2] = 1 / np.clongdouble(complex(sec.kGA))
    a[:, 1, 3] = 1 / np.clongdouble(complex(sec.EI))
    a[:, 2, 0] = -w2 * np.longdouble(float(sec.rhoA))
    a[:, 3, 1] = -w2 * np.longdouble(float(sec.rhoI))
    a[:, 3, 2] = -1
    return a


def balance(a):
    """Powers of two ``d`` (n, 4) with ``diag(d)^-1 a diag(d)`` of comparable row and column norms."""
    mag = np.abs(a.astype(np.complex128))
    d = np.ones(mag.shape[:2])
    off = 1.0 - np.eye(4)
    for _ in range(30):
        b = mag * d[:, None, :] / d[:, :, None] * off
        rows, cols = b.sum(axis=2), b.sum(axis=1)
        with np.errstate(divide="ignore", invalid="ignore"):
            f = np.where((rows > 0) & (cols > 0), np.sqrt(rows / cols), 1.0)
        d *= np.exp2(np.round(np.log2(f)))
    return d


def expm_ld(a):
    """``exp(a)`` per line in longdouble: balancing, Taylor series of ``a / 2^s``, ``s`` squarings."""
    d = balance(a).astype(np.longdouble)
    b = a * d[:, None, :] / d[:, :, None]
    norm = np.abs(b.astype(np.complex128)).sum(axis=1).max()
    s = max(0, math.ceil(math.log2(max(norm, 1e-300) / 0.25)))
    x = b / np.longdouble(2.0) ** s
    term = np.broadcast_to(np.eye(4, dtype=np.clongdouble), b.shape).copy()
    e = term.copy()
    for k in range(1, 31):
        term = term @ x / k
        e = e + term
    for _ in range(s):
        e = e @ e
    return e / d[:, None, :] * d[:, :, None]


def solve_ld(k, rhs):
    """``k^-1 rhs`` per line by Gaussian elimination with partial pivoting in longdouble."""
    k, rhs = k.copy(), rhs.copy()
    n = k.shape[1]
    lines = np.arange(k.shape[0])
    for c in range(n):
        p = c + np.argmax(np.abs(k[:, c:, c].astype(np.complex128)), axis=1)
        k[lines, c], k[lines, p] = k[lines, p].copy(), k[lines, c].copy()
        rhs[lines, c], rhs[lines, p] = rhs[lines, p].copy(), rhs[lines, c].copy()
        f = k[:, c + 1:, c] / k[:, c, c][:, None]
        k[:, c + 1:] -= f[:, :, None] * k[:, c, None, :]
        rhs[:, c + 1:] -= f[:, :, None] * rhs[:, c, None, :]
    x = np.zeros_like(rhs)
    for c in range(n - 1, -1, -1):
        x[:, c] = (rhs[:, c] - np.einsum("lk,lkj->lj", k[:, c, c + 1:], x[:, c + 1:])) / k[:, c, c][:, None]
    return x


def inv2(m):
    """Inverse of 2x2 blocks (..., 2, 2)."""
    det = m[..., 0, 0] * m[..., 1, 1] - m[..., 0, 1] * m[..., 1, 0]
    out = np.empty_like(m)
    out[..., 0, 0], out[..., 1, 1] = m[..., 1, 1] / det, m[..., 0, 0] / det
    out[..., 0, 1], out[..., 1, 0] = -m[..., 0, 1] / det, -m[..., 1, 0] / det
    return out


def piece_stiffness(t):
    """End loads ``[g_0; g_L] = K [u_0; u_L]`` of a piece from its ``T`` (loads make ``F`` jump by ``-g``)."""
    tuu, tuf, tfu, tff = t[:, :2, :2], t[:, :2, 2:], t[:, 2:, :2], t[:, 2:, 2:]
    r = inv2(tuf)  # F_0 = r (u_L - tuu u_0); g_0 = -F_0; g_L = F_L = tfu u_0 + tff F_0
    k = np.empty(t.shape, dtype=t.dtype)
    k[:, :2, :2] = r @ tuu
    k[:, :2, 2:] = -r
    k[:, 2:, :2] = tfu - tff @ r @ tuu
    k[:, 2:, 2:] = tff @ r
    return k


def pieces(segments, positions, omega_max, max_kl=2.0):
    """Cuts (m) at segment ends, at ``positions`` and inside, pieces of ``k L <= max_kl``; each piece's section."""
    cuts, sections = [0.0], []
    for seg in segments:
        sec = seg.section()
        k_max = np.abs(np.linalg.eigvals(system_matrix(sec, np.array([omega_max]))[0].astype(np.complex128))).max()
        x0 = cuts[-1]
        inner = [p for p in positions if x0 < p < x0 + seg.length_m]
        for a, b in zip([x0] + inner, inner + [x0 + seg.length_m]):
            n_sub = max(1, math.ceil(k_max * (b - a) / max_kl))
            for i in range(1, n_sub + 1):
                cuts.append(a + (b - a) * i / n_sub)
                sections.append(sec)
    return np.array(cuts), sections


def by_stiffness(ts, cuts, at):
    """Receptances between nodes ``at`` by assembling the pieces' dynamic stiffness: (n, 2p, 2p)."""
    n_nodes, ell = cuts.size, cuts[-1]
    scale = np.tile([1.0, ell], n_nodes).astype(np.longdouble)  # rotations times the length: balanced units
    k = np.zeros((ts[0].shape[0], 2 * n_nodes, 2 * n_nodes), dtype=np.clongdouble)
    for i, t in enumerate(ts):
        k[:, 2 * i:2 * i + 4, 2 * i:2 * i + 4] += piece_stiffness(t)
    k = k / scale[None, :, None] / scale[None, None, :]
    dofs = [2 * n + j for n in at for j in (0, 1)]
    rhs = np.zeros((k.shape[0], 2 * n_nodes, len(dofs)), dtype=np.clongdouble)
    for c, dof in enumerate(dofs):
        rhs[:, dof, c] = 1
    return solve_ld(k, rhs)[:, dofs, :] / scale[dofs][None, :, None] / scale[dofs][None, None, :]


def by_transfer(ts, at):
    """Receptances between nodes ``at`` from the boundary-value problem of the whole chain: (n, 2p, 2p).

    Free ends (``F = 0`` at both), a load ``g`` at node ``j`` makes ``F`` jump by ``-g``:
    ``Y_ij = P_i,uu M_Fu^-1 S_j,FF - [x_i > x_j] T(x_j -> x_i)_uF`` with full products (no reciprocity).
    """
    def chain(i, j):
        out = np.broadcast_to(np.eye(4, dtype=np.clongdouble), ts[0].shape).copy()
        for t in ts[i:j]:
            out = t @ out
        return out

    n = len(ts)
    inv = inv2(chain(0, n)[:, 2:, :2])
    y = np.zeros((ts[0].shape[0], 2 * len(at), 2 * len(at)), dtype=np.clongdouble)
    for a, na in enumerate(at):
        for b, nb in enumerate(at):
            block = chain(0, na)[:, :2, :2] @ inv @ chain(nb, n)[:, 2:, 2:]
            if na > nb:
                block = block - chain(nb, na)[:, :2, 2:]
            y[:, 2 * a:2 * a + 2, 2 * b:2 * b + 2] = block
    return y


def reference_receptance(segments, positions, f_hz, route="best"):
    """Receptances between ``positions`` [m] (DOFs ``(w, psi)`` each), (2p, 2p, n) complex longdouble.

    ``route="best"`` takes, line by line, the boundary-value problem where the
    whole beam's ``k L <= 6`` (its rounding grows like ``exp(k L)``) and the
    stiffness assembly elsewhere (its rounding grows like the condition number
    of the free-free stiffness, large at low frequency where the rigid-body
    motion dominates).
    """
    omega = 2 * np.pi * np.asarray(f_hz, dtype=float)
    cuts, sections = pieces(segments, positions, omega.max())
    ts = [expm_ld(system_matrix(sec, omega) * np.longdouble(b - a)) for sec, a, b in zip(sections, cuts[:-1], cuts[1:])]
    at = [int(np.argmin(np.abs(cuts - p))) for p in positions]
    if route == "stiffness":
        y = by_stiffness(ts, cuts, at)
    elif route == "transfer":
        y = by_transfer(ts, at)
    else:
        kl = sum(
            np.abs(np.linalg.eigvals(system_matrix(sec, omega).astype(np.complex128))).max(axis=1) * (b - a)
            for sec, a, b in zip(sections, cuts[:-1], cuts[1:])
        )
        y = np.where((kl <= 6.0)[:, None, None], by_transfer(ts, at), by_stiffness(ts, cuts, at))
    return np.moveaxis(y, 0, -1)


@pytest.mark.parametrize("name", list(SEGMENTS))
def test_transfer_matrices_match_extended_precision(name):
    """Each segment's ``T`` (closed form, double) against ``exp(A L)`` in longdouble, in balanced coordinates."""
    for seg in SEGMENTS[name]:
        sec = seg.section()
        for length in (seg.length_m, seg.length_m / 7.0):
            omega = 2 * np.pi * FREQUENCIES
            a = system_matrix(sec, omega) * np.longdouble(length)
            ref = expm_ld(a)
            got = np.moveaxis(segment_transfer_matrix(sec, length, omega), -1, 0)
            d = balance(a)
            bal = lambda m: m * d[:, None, :] / d[:, :, None]  # noqa: E731
            diff = np.abs(bal(got - ref.astype(np.complex128))).max(axis=(1, 2))
            size = np.abs(bal(ref.astype(np.complex128))).max(axis=(1, 2))
            kl = np.abs(np.linalg.eigvals(a.astype(np.complex128))).max(axis=1)
            inside = kl <= 8.0  # the kernel's domain: longer chains are cut (beams._CHUNK_KL)
            assert inside.any()
            assert np.all(diff[inside] <= 1e-13 * size[inside]), (name, length, (diff / size).max())


@pytest.mark.parametrize("name", list(SEGMENTS))
def test_receptances_match_extended_precision(name):
    """Receptances at the base, inside and at the tip against the longdouble stiffness assembly."""
    segments = SEGMENTS[name]
    length = sum(s.length_m for s in segments)
    positions = [0.0, round(0.37 * length, 6), length]
    got = stepped_beam_receptance(segments, positions, FREQUENCIES)
    ref = reference_receptance(segments, positions, FREQUENCIES).astype(np.complex128)
    scale = np.tile([1.0, length], len(positions))[:, None, None]
    s_got, s_ref = got * scale * scale.transpose(1, 0, 2), ref * scale * scale.transpose(1, 0, 2)
    err = np.linalg.norm(s_got - s_ref, axis=(0, 1)) / np.linalg.norm(s_ref, axis=(0, 1))
    assert err.max() <= 1e-10, (name, err.max(), FREQUENCIES[np.argmax(err)])
    tip = np.abs(got[-2, -2] - ref[-2, -2]) / np.abs(ref[-2, -2])
    assert tip.max() <= 1e-10, (name, tip.max())


def test_the_reference_routes_agree_and_have_the_rigid_body_limit():
    """The reference itself: its two routes agree where both are well conditioned; the rigid-body limit."""
    segments = SEGMENTS["stepped tool"]
    length = sum(s.length_m for s in segments)
    f = np.geomspace(2000.0, 20000.0, 9)  # whole-beam k L between about 1.5 and 5
    by_t = reference_receptance(segments, [0.0, length], f, route="transfer").astype(np.complex128)
    by_k = reference_receptance(segments, [0.0, length], f, route="stiffness").astype(np.complex128)
    err = np.linalg.norm(by_t - by_k, axis=(0, 1)) / np.linalg.norm(by_t, axis=(0, 1))
    assert err.max() <= 1e-13
    seg = Segment("100 mm", "20 mm", material="steel")
    sec = seg.section()
    f = np.array([0.5, 1.0])
    y = reference_receptance([seg], [seg.length_m], f).astype(np.complex128)
    m, ell = float(sec.rhoA) * seg.length_m, seg.length_m
    j_cg = m * ell**2 / 12 + float(sec.rhoI) * ell  # about the centre
    rigid = -(1 / m + (ell / 2) ** 2 / j_cg) / (2 * np.pi * f) ** 2
    np.testing.assert_allclose(y[0, 0].real, rigid, rtol=1e-4)
