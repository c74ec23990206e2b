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

The dynamic stiffness follows from the blocks of ``T``.  Segments are
split, without approximation, into pieces no longer than 1.5 radians of the
largest wavenumber, which keeps every piece below its own first
clamped-end resonance (1.875 rad) and the arithmetic well conditioned.  Receptances
between any points are obtained by condensing the chain onto those points
and inverting the small remaining system, all vectorised over frequency.

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
]

_MAX_PIECE_PHASE = 1.5  # largest |wavenumber| * length of one piece [rad], below a cantilever's 1.875


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

    @property
    def length_m(self) -> float:
        return float(self.length.m_as("m"))

    def section(self) -> Section:
        """Section properties in SI units (layers summed)."""
        od = self.od.m_as("m")
        if self.flutes is not None:
            od = od * self.flutes.diameter_ratio
        sec = Section.ring(od, self.id.m_as("m"), self.material)
        if self.insert is not None:
            sec = sec + Section.ring(self.insert.od.m_as("m"), self.insert.id.m_as("m"), self.insert.material)
        return sec

    def mass(self) -> float:
        """Mass of the segment (with its insert) in kg."""
        return self.section().rhoA * self.length_m


# ---------------------------------------------------------------------------
# Closed-form segment dynamic stiffness


def _squared_wavenumbers(sec: Section, w2: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """``a, e`` (diagonal of A^2) and the eigenvalues ``s1, s2`` of ``A^2``."""
    a = -w2 * sec.rhoA / sec.kGA
    e = -w2 * sec.rhoI / sec.EI
    half = 0.5 * (a - e)
    root = np.sqrt(half * half + w2 * sec.rhoA / sec.EI + 0j)
    mean = 0.5 * (a + e)
    return a, e, mean + root, mean - root


def _functions(s1: np.ndarray, s2: np.ndarray, length: float):
    """``C(s2), C[s1,s2], S(s2), S[s1,s2]`` for one length, vectorised."""
    z1, z2 = s1 * length**2, s2 * length**2
    c0 = np.empty_like(z2)
    c1 = np.empty_like(z2)
    g0 = np.empty_like(z2)
    g1 = np.empty_like(z2)
    zmax = np.maximum(np.abs(z1), np.abs(z2))
    small = zmax < 0.5
    if np.any(small):
        a1, a2 = z1[small], z2[small]
        # Power series of C, S and of their divided differences (h_n: complete
        # homogeneous symmetric polynomial of degree n in a1, a2), summed until
        # the terms fall below double precision: |z|^n / (2n)! < 1e-18.
        bound = float(zmax[small].max())
        n_terms = 2
        while bound ** n_terms / math.factorial(2 * n_terms) > 1e-18:
            n_terms += 1
        sc = np.ones_like(a2)
        ss = np.ones_like(a2)
        dc = np.zeros_like(a2)
        ds = np.zeros_like(a2)
        h = np.ones_like(a2)  # h_0
        pow2 = np.ones_like(a2)
        fact_c, fact_s = 1.0, 1.0  # (2n)!, (2n+1)!
        for n in range(1, n_terms + 1):
            fact_c *= (2 * n - 1) * (2 * n)
            fact_s *= (2 * n) * (2 * n + 1)
            dc += h / fact_c
            ds += h / fact_s
            pow2 = pow2 * a2
            sc += pow2 / fact_c
            ss += pow2 / fact_s
            h = a1 * h + pow2  # h_n = a1 h_{n-1} + a2^n
        c0[small] = sc
        g0[small] = length * ss
        c1[small] = length**2 * dc
        g1[small] = length**3 * ds
    big = ~small
    if np.any(big):
        # cosh and sinh from one exponential each (the principal square root
        # has Re >= 0, so exp(-r L) <= 1 and nothing overflows before exp(r L)).
        r1, r2 = np.sqrt(s1[big]), np.sqrt(s2[big])
        e1, e2 = np.exp(r1 * length), np.exp(r2 * length)
        i1, i2 = 1.0 / e1, 1.0 / e2
        ch1, ch2 = 0.5 * (e1 + i1), 0.5 * (e2 + i2)
        sh1, sh2 = 0.5 * (e1 - i1) / r1, 0.5 * (e2 - i2) / r2
        ds12 = s1[big] - s2[big]
        c0[big], g0[big] = ch2, sh2
        c1[big] = (ch1 - ch2) / ds12
        g1[big] = (sh1 - sh2) / ds12
    return c0, c1, g0, g1


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
    EI, kGA, mA, mI = sec.EI, sec.kGA, w2 * sec.rhoA, w2 * sec.rhoI
    t = np.empty((4, 4, w2.size), dtype=complex)
    t[0, 0] = alpha + gamma * a
    t[0, 1] = beta + delta * (a + e)
    t[0, 2] = beta / kGA + delta * (a / kGA - 1.0 / EI)
    t[0, 3] = gamma / EI
    t[1, 0] = delta * mA / EI
    t[1, 1] = alpha + gamma * e
    t[1, 2] = -gamma / EI
    t[1, 3] = (beta + delta * e) / EI
    t[2, 0] = -(beta + delta * a) * mA
    t[2, 1] = -gamma * mA
    t[2, 2] = alpha + gamma * a
    t[2, 3] = -delta * mA / EI
    t[3, 0] = gamma * mA
    t[3, 1] = -beta * mI + delta * (mA - mI * e)
    t[3, 2] = -beta + delta * (mI / EI - a)
    t[3, 3] = alpha + gamma * e
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
# Chains of segments


def _pieces(segments: Sequence[Segment], positions: np.ndarray, omega_max: float):
    """Split the beam at segment ends, requested positions and for conditioning.

    Returns the node positions and, per piece, its section and length.
    """
    sections = [s.section() for s in segments]
    ends = np.concatenate([[0.0], np.cumsum([s.length_m for s in segments])])
    cuts = np.unique(np.concatenate([ends, positions]))
    nodes, pieces = [cuts[0]], []
    for x0, x1 in zip(cuts[:-1], cuts[1:]):
        mid = 0.5 * (x0 + x1)
        k = int(np.clip(np.searchsorted(ends, mid) - 1, 0, len(segments) - 1))
        sec = sections[k]
        _, _, s1, s2 = _squared_wavenumbers(sec, np.array([omega_max**2]))
        wavenumber = float(np.sqrt(max(abs(s1[0]), abs(s2[0]))))
        n_sub = max(1, math.ceil(wavenumber * (x1 - x0) / _MAX_PIECE_PHASE))
        for j in range(1, n_sub + 1):
            nodes.append(x0 + (x1 - x0) * j / n_sub if j < n_sub else x1)
            pieces.append((sec, (x1 - x0) / n_sub))
    return np.asarray(nodes), pieces


def _series(a, b):
    """Two-ports ``a`` (nodes i, j) and ``b`` (nodes j, k) joined at j, j condensed."""
    a11, a12, a21, a22 = a
    b11, b12, b21, b22 = b
    si = bk.inv2(a22 + b11)
    return (
        a11 - bk.mul2(a12, bk.mul2(si, a21)),
        -bk.mul2(a12, bk.mul2(si, b12)),
        -bk.mul2(bk.mul2(b21, si), a21),
        b22 - bk.mul2(b21, bk.mul2(si, b12)),
    )


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
    f = np.asarray(frequency_hz, dtype=float)
    omega = 2.0 * np.pi * f
    pos = np.asarray(positions, dtype=float)
    order = np.argsort(pos)
    sorted_pos = pos[order]
    nodes, pieces = _pieces(segments, sorted_pos, float(omega.max()))
    node_of = np.searchsorted(nodes, sorted_pos)
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        cache: dict[tuple, tuple] = {}
        blocks = []
        for sec, length in pieces:
            key = (id(sec), length)
            if key not in cache:
                cache[key] = segment_dynamic_stiffness(sec, length, omega)
            blocks.append(cache[key])

        # Condense the chain onto the requested nodes: super-elements between
        # consecutive requested nodes, and end stiffnesses of the free overhangs.
        def chain(i0: int, i1: int):
            acc = blocks[i0]
            for k in range(i0 + 1, i1):
                acc = _series(acc, blocks[k])
            return acc

        m = len(sorted_pos)
        n = omega.size
        diag = [np.zeros((2, 2, n), dtype=complex) for _ in range(m)]
        off = []
        if node_of[0] > 0:
            p11, p12, p21, p22 = chain(0, node_of[0])
            diag[0] += p22 - bk.mul2(p21, bk.mul2(bk.inv2(p11), p12))
        if node_of[-1] < len(nodes) - 1:
            p11, p12, p21, p22 = chain(node_of[-1], len(pieces))
            diag[-1] += p11 - bk.mul2(p12, bk.mul2(bk.inv2(p22), p21))
        for j in range(m - 1):
            p11, p12, p21, p22 = chain(node_of[j], node_of[j + 1])
            diag[j] += p11
            diag[j + 1] += p22
            off.append((p12, p21))
        g = np.zeros((2 * m, 2 * m, n), dtype=complex)
        for j in range(m):
            g[2 * j : 2 * j + 2, 2 * j : 2 * j + 2] = diag[j]
        for j, (p12, p21) in enumerate(off):
            g[2 * j : 2 * j + 2, 2 * j + 2 : 2 * j + 4] = p12
            g[2 * j + 2 : 2 * j + 4, 2 * j : 2 * j + 2] = p21
        y_sorted = bk.inv(g)
    # Back to the caller's order of positions.
    dof = np.empty(2 * m, dtype=int)
    inverse = np.empty(m, dtype=int)
    inverse[order] = np.arange(m)
    dof[0::2] = 2 * inverse
    dof[1::2] = 2 * inverse + 1
    return y_sorted[np.ix_(dof, dof)]
