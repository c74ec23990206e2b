"""Exact Timoshenko beams: sections, segments and receptances of stepped beams.

A stepped beam is a chain of uniform segments (conventions.md, Geometry).  Each
segment's dynamic stiffness is the closed-form solution of the Timoshenko
equations, with no discretisation and no modal truncation:

* the first-order system ``z' = A(omega) z`` for the state
  ``z = [w, psi, V, M]`` (displacement, section rotation, shear force,
  bending moment) has the transfer matrix ``T = exp(A L)``;
* the characteristic polynomial of ``A`` is even, so
  ``exp(A L) = C(A^2) + A S(A^2)`` with the entire functions
  ``C(s) = cosh(L sqrt(s))`` and ``S(s) = sinh(L sqrt(s)) / sqrt(s)``;
* ``A^2`` has the two eigenvalues ``s1, s2`` (the squared wavenumbers of the
  two Timoshenko branches), so ``g(A^2) = g(s2) I + g[s1, s2] (A^2 - s2 I)``
  with the divided difference ``g[s1, s2]``, evaluated by its power series
  where ``s L^2`` is small (low frequency, and exactly at ``omega = 0``).

Receptances between any points of a free-free stepped beam follow from the
transfer matrices between the points and the free-end conditions (see
:func:`_chain_receptance`): one 2x2 inversion per frequency line, singular
only at the beam's own natural frequencies, with the rigid-body ``omega^2``
factor carried exactly, so that the lowest lines are as accurate as the
rest.  The segment dynamic stiffness (for joints of beam pieces and for
teaching) follows from the blocks of ``T``.  Everything is vectorised over
frequency (and over configurations in sweeps).

Shear coefficient: Cowper (1966) for a hollow circular section,
``kappa = 6(1+nu)(1+m^2)^2 / ((7+6nu)(1+m^2)^2 + (20+12nu)m^2)``, ``m = id/od``
(0.886 for a solid steel section).  A composite section (a bore filled by an
``Insert``) sums ``EI``, ``kappa G A``, ``rho A`` and ``rho I`` over its
layers, each with its own ``kappa``.  A fluted length is a solid section of
the equivalent diameter ``diameter_ratio * od`` for both stiffness and mass.
"""

from __future__ import annotations

import math
from typing import Sequence

import attrs
import numpy as np
import pint

from . import _blocks as bk
from ._engine import Link, couple_substructures
from .errors import InvalidValueError
from .materials import Material, get_material
from .units import dimensionless, quantity

__all__ = [
    "Insert",
    "Flutes",
    "Segment",
    "Section",
    "shear_coefficient",
    "segment_dynamic_stiffness",
    "stepped_beam_receptance",
    "stepped_beam_receptance_batch",
]



def _length(field: str, *, allow_zero: bool = False):
    def convert(value) -> pint.Quantity:
        q = quantity(value, field, "[length]")
        if q.magnitude < 0 or (q.magnitude == 0 and not allow_zero):
            expected = "a length >= 0" if allow_zero else "a positive length"
            raise InvalidValueError(f"{field}: got {value!r}; expected {expected}")
        return q

    return convert


def _material(value) -> Material:
    if isinstance(value, Material):
        return value
    if isinstance(value, str):
        return get_material(value)
    raise InvalidValueError(
        f"material: got {value!r}; expected a Material or a catalogue name (steel, carbide, aluminium)"
    )


def shear_coefficient(nu: float, ratio: float = 0.0) -> float:
    """Cowper's (1966) shear coefficient of a hollow circular section.

    Parameters
    ----------
    nu : float
        Poisson ratio.
    ratio : float
        Inner to outer diameter, ``m = id / od`` (0 for a solid section).
    """
    m2 = ratio * ratio
    a = (1.0 + m2) ** 2
    return 6.0 * (1.0 + nu) * a / ((7.0 + 6.0 * nu) * a + (20.0 + 12.0 * nu) * m2)


@attrs.frozen
class Section:
    """Section properties of a segment in SI units (complex with loss factor).

    Attributes
    ----------
    EI : complex
        Bending stiffness [N m^2].
    kGA : complex
        Shear stiffness ``kappa G A`` [N].
    rhoA : float
        Mass per length [kg/m].
    rhoI : float
        Rotary inertia per length [kg m].
    """

    EI: complex
    kGA: complex
    rhoA: float
    rhoI: float

    def __add__(self, other: "Section") -> "Section":
        return Section(self.EI + other.EI, self.kGA + other.kGA, self.rhoA + other.rhoA, self.rhoI + other.rhoI)

    @classmethod
    def ring(cls, od: float, id: float, material: Material) -> "Section":
        """A circular ring of one material (``id = 0`` for a solid circle), SI inputs."""
        area = math.pi / 4.0 * (od**2 - id**2)
        inertia = math.pi / 64.0 * (od**4 - id**4)
        kappa = shear_coefficient(material.nu, id / od)
        return cls(
            EI=material.E_si * inertia,
            kGA=kappa * material.G_si * area,
            rhoA=material.rho_si * area,
            rhoI=material.rho_si * inertia,
        )


@attrs.frozen
class Insert:
    """A concentric body filling a segment's bore, e.g. the tool shank in a holder.

    Parameters
    ----------
    od : quantity or str
        Outer diameter of the insert; at most the bore (``id``) of its segment.
    material : Material or str
    id : quantity or str, default "0 mm"
        Inner diameter of the insert (0 for a solid shank).
    """

    od: pint.Quantity = attrs.field(converter=_length("insert.od"))
    material: Material = attrs.field(converter=_material)
    id: pint.Quantity = attrs.field(default="0 mm", converter=_length("insert.id", allow_zero=True))

    def __attrs_post_init__(self) -> None:
        if self.id >= self.od:
            raise InvalidValueError(
                f"insert.id: got {self.id:~P} with insert.od {self.od:~P}; expected id < od"
            )


def _ratio(value) -> float:
    r = dimensionless(value, "flutes.diameter_ratio")
    if not 0.0 < r <= 1.0:
        raise InvalidValueError(f"flutes.diameter_ratio: got {value!r}; expected a ratio in (0, 1]")
    return r


@attrs.frozen
class Flutes:
    """Fluted length of a tool, modelled by an equivalent solid diameter.

    The fluted section is a circle of diameter ``diameter_ratio * od`` for
    both its stiffness and its mass (0.8 is a common value for two- to
    four-flute end mills).
    """

    diameter_ratio: float = attrs.field(converter=_ratio)


@attrs.frozen
class Segment:
    """A uniform piece of a stepped beam.

    Parameters
    ----------
    length, od : quantity or str
        Length and outer diameter, e.g. ``"30 mm"``.
    id : quantity or str, default "0 mm"
        Inner diameter (bore); 0 for a solid section.
    material : Material or str, default "steel"
    insert : Insert, optional
        A body of another material filling the bore.
    flutes : Flutes, optional
        Fluted section (tools).
    """

    length: pint.Quantity = attrs.field(converter=_length("length"))
    od: pint.Quantity = attrs.field(converter=_length("od"))
    id: pint.Quantity = attrs.field(default="0 mm", converter=_length("id", allow_zero=True))
    material: Material = attrs.field(default="steel", converter=_material)
    insert: Insert | None = attrs.field(default=None)
    flutes: Flutes | None = attrs.field(default=None)
    # SI values, derived once (the kernels need them at every call)
    _si: tuple = attrs.field(init=False, eq=False, repr=False)

    def __attrs_post_init__(self) -> None:
        if self.id >= self.od:
            raise InvalidValueError(f"id: got {self.id:~P} with od {self.od:~P}; expected id < od")
        if self.insert is not None:
            if not isinstance(self.insert, Insert):
                raise InvalidValueError(f"insert: got {self.insert!r}; expected an Insert")
            if self.id.magnitude == 0:
                raise InvalidValueError("insert: the segment is solid (id = 0); an insert needs a bore")
            if self.insert.od > self.id:
                raise InvalidValueError(
                    f"insert.od: got {self.insert.od:~P}, larger than the bore id {self.id:~P}"
                )
        if self.flutes is not None:
            if not isinstance(self.flutes, Flutes):
                raise InvalidValueError(f"flutes: got {self.flutes!r}; expected Flutes")
            if self.flutes.diameter_ratio * self.od <= self.id:
                raise InvalidValueError(
                    "flutes.diameter_ratio: the equivalent diameter "
                    f"{self.flutes.diameter_ratio} * {self.od:~P} is not larger than the bore {self.id:~P}"
                )
        od = self.od.m_as("m")
        if self.flutes is not None:
            od = od * self.flutes.diameter_ratio
        sec = Section.ring(od, self.id.m_as("m"), self.material)
        if self.insert is not None:
            sec = sec + Section.ring(self.insert.od.m_as("m"), self.insert.id.m_as("m"), self.insert.material)
        object.__setattr__(self, "_si", (float(self.length.m_as("m")), sec))

    @property
    def length_m(self) -> float:
        return self._si[0]

    def section(self) -> Section:
        """Section properties in SI units (layers summed)."""
        return self._si[1]

    def mass(self) -> float:
        """Mass of the segment (with its insert) in kg."""
        return self.section().rhoA * self.length_m


# ---------------------------------------------------------------------------
# Closed-form segment dynamic stiffness


def _squared_wavenumbers(sec: Section, w2: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """``a, e`` (diagonal of A^2) and the eigenvalues ``s1, s2`` of ``A^2``."""
    a = w2 * (-sec.rhoA / sec.kGA)
    e = w2 * (-sec.rhoI / sec.EI)
    half = 0.5 * (a - e)
    root = np.sqrt(half * half + w2 * (sec.rhoA / sec.EI) + 0j)
    mean = 0.5 * (a + e)
    return a, e, mean + root, mean - root


def _series(z1: np.ndarray, z2: np.ndarray, length: np.ndarray):
    """``C(s2), C[s1,s2], S(s2), S[s1,s2]`` by power series, for ``|s L^2| < 0.5``.

    ``z = s L^2``; ``h_n`` is the complete homogeneous symmetric polynomial of
    degree n in ``z1, z2`` (the divided difference of ``z^(n+1)``); terms are
    summed until they fall below double precision, ``|z|^n / (2n)! < 1e-18``.
    """
    bound = float(np.max(np.maximum(np.abs(z1), np.abs(z2)))) if z1.size else 0.0
    n_terms = 2
    while bound**n_terms / math.factorial(2 * n_terms) > 1e-18:
        n_terms += 1
    sc = np.ones_like(z2)
    ss = np.ones_like(z2)
    dc = np.zeros_like(z2)
    ds = np.zeros_like(z2)
    h = np.ones_like(z2)  # h_0
    pow2 = np.ones_like(z2)
    for n in range(1, n_terms + 1):
        rc, rs = 1.0 / math.factorial(2 * n), 1.0 / math.factorial(2 * n + 1)
        dc += rc * h
        ds += rs * h
        pow2 = pow2 * z2
        sc += rc * pow2
        ss += rs * pow2
        h = z1 * h + pow2  # h_n = z1 h_{n-1} + z2^n
    return sc, length**2 * dc, length * ss, length**3 * ds


def _direct(s1: np.ndarray, s2: np.ndarray, length: np.ndarray):
    """``C(s2), C[s1,s2], S(s2), S[s1,s2]`` from exponentials, for ``|s L^2| >= 0.5``.

    cosh and sinh from one exponential each: the principal square root has
    ``Re >= 0``, so ``exp(-r L) <= 1`` and nothing overflows before ``exp(r L)``.
    """
    r1, r2 = np.sqrt(s1), np.sqrt(s2)
    e1, e2 = np.exp(r1 * length), np.exp(r2 * length)
    i1, i2 = 1.0 / e1, 1.0 / e2
    ch1, ch2 = 0.5 * (e1 + i1), 0.5 * (e2 + i2)
    sh1, sh2 = 0.5 * (e1 - i1) / r1, 0.5 * (e2 - i2) / r2
    ds12 = s1 - s2
    return ch2, (ch1 - ch2) / ds12, sh2, (sh1 - sh2) / ds12


def _functions(s1: np.ndarray, s2: np.ndarray, length):
    """``C(s2), C[s1,s2], S(s2), S[s1,s2]``, vectorised (``length`` scalar or per element)."""
    length = np.broadcast_to(np.asarray(length, dtype=float), s1.shape)
    z1, z2 = s1 * length**2, s2 * length**2
    small = np.maximum(np.abs(z1), np.abs(z2)) < 0.5
    if small.all():
        return _series(z1, z2, length)
    if not small.any():
        return _direct(s1, s2, length)
    out = tuple(np.empty_like(z2) for _ in range(4))
    big = ~small
    for o, v in zip(out, _series(z1[small], z2[small], length[small])):
        o[small] = v
    for o, v in zip(out, _direct(s1[big], s2[big], length[big])):
        o[big] = v
    return out


def segment_transfer_matrix(sec: Section, length: float, omega: np.ndarray) -> np.ndarray:
    """Transfer matrix ``T = exp(A L)`` of a uniform segment, shape ``(4, 4, n)``.

    State ``[w, psi, V, M]`` with ``V = kGA (w' - psi)`` and ``M = EI psi'``.
    """
    w2 = np.asarray(omega, dtype=float) ** 2
    a, e, s1, s2 = _squared_wavenumbers(sec, w2)
    c0, c1, g0, g1 = _functions(s1, s2, length)
    alpha = c0 - c1 * s2
    beta = g0 - g1 * s2
    gamma, delta = c1, g1
    inv_ei, inv_kga = 1.0 / sec.EI, 1.0 / sec.kGA
    mA, mI = w2 * sec.rhoA, w2 * sec.rhoI
    t = np.empty((4, 4, w2.size), dtype=complex)
    # T = alpha I + beta A + gamma A^2 + delta A^3, written entry by entry
    # (A, A^2, A^3 are sparse), sharing the repeated entries.
    t[0, 0] = t[2, 2] = alpha + gamma * a
    t[1, 1] = t[3, 3] = alpha + gamma * e
    t[0, 1] = beta + delta * (a + e)
    t[0, 2] = beta * inv_kga + delta * (a * inv_kga - inv_ei)
    g_ei = gamma * inv_ei
    t[0, 3] = g_ei
    t[1, 2] = -g_ei
    d_ma_ei = delta * mA * inv_ei
    t[1, 0] = d_ma_ei
    t[2, 3] = -d_ma_ei
    t[1, 3] = (beta + delta * e) * inv_ei
    t[2, 0] = -(beta + delta * a) * mA
    g_ma = gamma * mA
    t[3, 0] = g_ma
    t[2, 1] = -g_ma
    t[3, 1] = -beta * mI + delta * (mA - mI * e)
    t[3, 2] = -beta + delta * (mI * inv_ei - a)
    return t


def segment_dynamic_stiffness(sec: Section, length: float, omega: np.ndarray):
    """Dynamic stiffness blocks ``(D11, D12, D21, D22)`` of a uniform segment.

    Each block has shape ``(2, 2, n)`` and relates the loads ``[f, m]`` applied
    at the ends to the displacements ``[y, theta]`` of the ends (1: base at
    ``x = 0``, 2: tip at ``x = length``).  Exact: no discretisation.
    """
    t = segment_transfer_matrix(sec, length, omega)
    t11, t12, t21, t22 = t[:2, :2], t[:2, 2:], t[2:, :2], t[2:, 2:]
    t12i = bk.inv2(t12)
    d11 = bk.mul2(t12i, t11)
    d12 = -t12i
    d21 = t21 - bk.mul2(t22, d11)
    d22 = bk.mul2(t22, t12i)
    return d11, d12, d21, d22


# ---------------------------------------------------------------------------
# Chains of segments: free-free receptances by transfer matrices


def _mul4(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Product of 4x4 stacks ``(4, 4, n)`` by 2x2 blocks."""
    out = np.empty(np.broadcast_shapes(a.shape, b.shape), dtype=complex)
    a11, a12, a21, a22 = a[:2, :2], a[:2, 2:], a[2:, :2], a[2:, 2:]
    b11, b12, b21, b22 = b[:2, :2], b[:2, 2:], b[2:, :2], b[2:, 2:]
    out[:2, :2] = bk.mul2(a11, b11) + bk.mul2(a12, b21)
    out[:2, 2:] = bk.mul2(a11, b12) + bk.mul2(a12, b22)
    out[2:, :2] = bk.mul2(a21, b11) + bk.mul2(a22, b21)
    out[2:, 2:] = bk.mul2(a21, b12) + bk.mul2(a22, b22)
    return out


def _product(mats: list[np.ndarray], n: int) -> np.ndarray | None:
    """``mats[-1] @ ... @ mats[0]`` (transfer in the +x direction); None when empty."""
    acc = None
    for t in mats:
        acc = t if acc is None else _mul4(t, acc)
    return acc


def _chain_single(intervals: list[tuple[Section, object]], nodes: list[int], omega: np.ndarray) -> np.ndarray:
    """Free-free receptances of a chain of uniform intervals at some of its nodes.

    ``intervals[k]`` spans node ``k`` to node ``k + 1``; ``nodes`` are sorted,
    distinct node indices.  With the state ``z = [u; F]`` (``u = [w, psi]``,
    ``F = [V, M]``) a load ``g`` at node ``j`` makes ``F`` jump by ``-g``; the
    free ends give ``F = 0`` before the base and after the tip, so

    ``Y_ij = P_i,uu M_Fu^-1 S_j,FF - [x_i > x_j] T_(j->i),uF``

    with ``P_i = T(0 -> x_i)``, ``S_j = T(x_j -> L)`` and ``M = T(0 -> L)``.
    ``M_Fu`` is singular only at the free-free natural frequencies, and its
    ``omega^2`` factor carries the rigid-body modes exactly, so the result is
    well conditioned down to the lowest frequency line.
    """
    n = omega.size
    cache: dict[tuple, np.ndarray] = {}
    mats = []
    for sec, length, *tile in intervals:
        key = (id(sec), id(length) if isinstance(length, np.ndarray) else length)
        if key not in cache:
            if tile:  # the same in every configuration of a batch: once, then repeated
                n_f, reps = tile[0]
                cache[key] = np.tile(segment_transfer_matrix(sec, length, omega[:n_f]), (1, 1, reps))
            else:
                cache[key] = segment_transfer_matrix(sec, length, omega)
        mats.append(cache[key])
    m = len(nodes)
    # Transfer matrices between consecutive requested nodes, and the overhangs
    # (None stands for the identity: an end that is itself a requested node).
    head = _product(mats[: nodes[0]], n)
    tail = _product(mats[nodes[-1] :], n)
    gaps = [_product(mats[nodes[k] : nodes[k + 1]], n) for k in range(m - 1)]

    def then(first, second):  # transfer through `first`, then `second`
        if first is None:
            return second
        if second is None:
            return first
        return _mul4(second, first)

    prefix = [head]
    for g in gaps:
        prefix.append(then(prefix[-1], g))
    total = then(prefix[-1], tail)
    suffix = [None] * m
    suffix[-1] = tail
    for k in range(m - 2, -1, -1):
        suffix[k] = then(gaps[k], suffix[k + 1])
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        mfu_inv = bk.inv2(total[2:, :2])
        left = [mfu_inv if prefix[i] is None else bk.mul2(prefix[i][:2, :2], mfu_inv) for i in range(m)]
        y = np.empty((2 * m, 2 * m, n), dtype=complex)
        for j in range(m):
            between = None
            for i in range(m):
                blk = left[i] if suffix[j] is None else bk.mul2(left[i], suffix[j][2:, 2:])
                if i > j:
                    between = gaps[i - 1] if between is None else _mul4(gaps[i - 1], between)
                    blk = blk - between[:2, 2:]
                y[2 * i : 2 * i + 2, 2 * j : 2 * j + 2] = blk
    return y


_CHUNK_KL = 8.0  # largest k L of one transfer-matrix chain: rounding ~ 1e-16 exp(8) ~ 3e-13


def _phase(sec: Section, length, omega_max: float) -> float:
    """Largest ``k L`` of an interval at ``omega_max`` (over a batch: the maximum)."""
    fields = [np.atleast_1d(getattr(sec, f)) for f in ("EI", "kGA", "rhoA", "rhoI")]
    _, _, s1, s2 = _squared_wavenumbers(Section(*fields), np.array(omega_max**2))
    k = np.sqrt(np.maximum(np.abs(s1), np.abs(s2)))
    return float(np.max(k * np.asarray(length, dtype=float)))


def _chain_receptance(
    intervals: list[tuple], nodes: list[int], omega: np.ndarray, phases: list[float] | None = None
) -> np.ndarray:
    """Free-free receptances of a chain at some of its nodes, for any length and frequency.

    The transfer-matrix rounding grows like ``exp(k L)`` (``k`` the evanescent
    bending wavenumber), so a chain with ``k L`` above 8 at the highest line is
    cut into pieces of ``k L <= 8``: each piece's receptances come from
    :func:`_chain_single` and the pieces are joined by rigid connections with
    the coupling engine, which is exact and well conditioned.  Short chains
    (the usual case) are one piece.
    """
    omega_max = float(np.max(omega))
    if phases is None:
        phases = [_phase(item[0], item[1], omega_max) for item in intervals]
    refined, node_map, piece_phases = [], [0], []
    for item, kl in zip(intervals, phases):
        n_sub = max(1, math.ceil(kl / _CHUNK_KL))
        piece = item if n_sub == 1 else (item[0], item[1] / n_sub, *item[2:])
        refined.extend([piece] * n_sub)
        piece_phases.extend([kl / n_sub] * n_sub)
        node_map.append(node_map[-1] + n_sub)
    phases = piece_phases
    nodes = [node_map[i] for i in nodes]
    bounds, acc = [0], 0.0
    for i, kl in enumerate(phases):
        if acc + kl > _CHUNK_KL and i > bounds[-1]:
            bounds.append(i)
            acc = 0.0
        acc += kl
    bounds.append(len(refined))
    if len(bounds) == 2:
        return _chain_single(refined, nodes, omega)
    blocks, links = [], []
    last = len(bounds) - 2
    for c, (n0, n1) in enumerate(zip(bounds[:-1], bounds[1:])):
        local = {nd for nd in nodes if n0 <= nd <= n1}
        if c > 0:
            local.add(n0)
            links.append(Link((c - 1, n0), (c, n0), None, "a beam's own cross-section"))
        if c < last:
            local.add(n1)
        local = sorted(local)
        y = _chain_single(refined[n0:n1], [nd - n0 for nd in local], omega)
        blocks.append(([(c, nd) for nd in local], y))
    outputs = []
    for nd in nodes:
        c = next(c for c, (n0, n1) in enumerate(zip(bounds[:-1], bounds[1:])) if n0 <= nd <= n1)
        outputs.append((c, nd))
    return couple_substructures(blocks, links, outputs)


def stepped_beam_receptance(
    segments: Sequence[Segment], positions: Sequence[float], frequency_hz: np.ndarray
) -> np.ndarray:
    """Free-free receptance matrix of a stepped beam between points.

    Parameters
    ----------
    segments : sequence of Segment
        Base to tip.
    positions : sequence of float
        Distinct positions from the base, in metres, within ``[0, length]``.
    frequency_hz : ndarray
        Frequency lines in Hz, all > 0 (a free-free beam has no static receptance).

    Returns
    -------
    ndarray, shape (2p, 2p, n_freq)
        Frequency-last receptances; DOFs ordered ``(y, theta)`` per position in
        the order given.
    """
    pos = np.asarray(positions, dtype=float)
    order = np.argsort(pos)
    sorted_pos = pos[order]
    if np.any(np.diff(sorted_pos) <= 0):
        raise InvalidValueError("positions: expected distinct positions")
    sections = [s.section() for s in segments]
    ends = np.concatenate([[0.0], np.cumsum([s.length_m for s in segments])])
    cuts = np.unique(np.concatenate([ends, sorted_pos]))
    intervals = []
    for x0, x1 in zip(cuts[:-1], cuts[1:]):
        k = int(np.clip(np.searchsorted(ends, 0.5 * (x0 + x1)) - 1, 0, len(segments) - 1))
        intervals.append((sections[k], float(x1 - x0)))
    nodes = [int(i) for i in np.searchsorted(cuts, sorted_pos)]
    y_sorted = bk.by_chunks(lambda f: _chain_receptance(intervals, nodes, 2.0 * np.pi * f), frequency_hz)
    m = len(sorted_pos)
    inverse = np.empty(m, dtype=int)
    inverse[order] = np.arange(m)
    dof = np.empty(2 * m, dtype=int)
    dof[0::2] = 2 * inverse
    dof[1::2] = 2 * inverse + 1
    return y_sorted[np.ix_(dof, dof)]


def _stack_sections(sections: Sequence[Section], repeat: int) -> Section:
    """One Section whose fields are arrays over configurations (each repeated)."""
    return Section(
        EI=np.repeat(np.array([s.EI for s in sections], dtype=complex), repeat),
        kGA=np.repeat(np.array([s.kGA for s in sections], dtype=complex), repeat),
        rhoA=np.repeat(np.array([s.rhoA for s in sections], dtype=float), repeat),
        rhoI=np.repeat(np.array([s.rhoI for s in sections], dtype=float), repeat),
    )


def stepped_beam_receptance_batch(
    configurations: Sequence[Sequence[Segment]], ends: Sequence[str], frequency_hz: np.ndarray
) -> np.ndarray:
    """End receptances of many stepped beams of the same layout, in one pass.

    Parameters
    ----------
    configurations : sequence of sequences of Segment
        One beam per configuration, all with the same number of segments
        (lengths, diameters and materials may differ).
    ends : sequence of {"base", "tip"}
        The points wanted (one or both ends), in this order.
    frequency_hz : ndarray
        Frequency lines, > 0.

    Returns
    -------
    ndarray, shape (2p, 2p, n_config * n_freq)
        Frequency-last receptances; the last axis runs over configurations
        first (``index = config * n_freq + line``).

    Notes
    -----
    The same closed form as :func:`stepped_beam_receptance`, evaluated on one
    long axis that holds every configuration's frequency lines, so that a
    sweep over tool overhangs costs a few numpy operations per segment.
    """
    n_seg = len(configurations[0])
    if any(len(c) != n_seg for c in configurations):
        raise InvalidValueError("configurations: every beam of a batch needs the same number of segments")
    if not ends or any(e not in ("base", "tip") for e in ends) or len(set(ends)) != len(ends):
        raise InvalidValueError(f"ends: got {ends!r}; expected 'base' and/or 'tip'")
    f = np.asarray(frequency_hz, dtype=float)
    n_f = f.size
    omega = np.tile(2.0 * np.pi * f, len(configurations))
    omega_max = 2.0 * np.pi * float(f.max())
    intervals, phases = [], []
    for j in range(n_seg):
        column = [cfg[j] for cfg in configurations]
        secs = [seg.section() for seg in column]
        lengths = np.array([seg.length_m for seg in column])
        if all(seg == column[0] for seg in column[1:]):
            intervals.append((secs[0], lengths[0], (n_f, len(column))))
            phases.append(_phase(secs[0], lengths[0], omega_max))
        else:
            intervals.append((_stack_sections(secs, n_f), np.repeat(lengths, n_f)))
            phases.append(_phase(_stack_sections(secs, 1), lengths, omega_max))
    nodes = sorted({"base": 0, "tip": n_seg}[e] for e in ends)
    y = _chain_receptance(intervals, nodes, omega, phases)
    if len(ends) == 2 and ends[0] == "tip":
        y = y[np.ix_([2, 3, 0, 1], [2, 3, 0, 1])]
    return y
