"""Independent finite-element reference for Timoshenko beam assemblies (test helper).

This module is the *second method* used by the test-suite to check the
library's closed-form Timoshenko receptances and its receptance-coupling
engine.  It deliberately imports nothing from ``substructure``; all inputs are
SI floats.  Conventions follow ``docs/conventions.md``: DOFs per node
``(y, theta)``, loads ``(f, m)``, ``x(t) = X exp(i omega t)``, loss factor as a
complex modulus on both E and G, Cowper (1966) shear coefficient.

Element
-------
Two-node Timoshenko element with *independent, field-consistent* hierarchical
interpolation: transverse displacement ``y`` of degree ``order + 1`` and
bending rotation ``theta`` (``psi`` of Timoshenko theory) of degree ``order``
(default 3).  Nodal DOFs ``(y1, theta1, y2, theta2)``; the higher terms are
Legendre bubble modes ``xi(1-xi)P_k(2xi-1)`` (Szabo & Babuska, *Finite Element
Analysis*, 1991) whose amplitudes are internal DOFs of the element, kept in the
global system (no condensation, so the mass stays consistent).  For
``order = 2`` this is Reddy's "consistent interpolation element" (cubic y,
quadratic theta; J.N. Reddy, *On locking-free shear deformable beam finite
elements*, CMAME 149, 1997, 113-132).  Because ``y' - theta`` has the degree
of ``theta`` the element does not lock, and since the static Timoshenko
solution (cubic y, quadratic theta) lies in the space for ``order >= 2``,
static condensation of the internal DOFs gives exactly the 4x4 stiffness of
the Friedman & Kosmatka (1993) interdependent interpolation element, exact for
nodal loads (one element reproduces ``L^3/(3EI) + L/(kappa G A)``).  Stiffness
and consistent mass (``rho*A`` and rotary ``rho*I``) come from Gauss
quadrature, exact for these polynomials.  Eigenvalues are Rayleigh-Ritz upper
bounds converging as ``h^(2*order)`` (measured: h^6 for order 3; the 4-DOF IIE
with consistent mass converges only as h^2 on thick beams, measured, hence
this choice).  Complex ``EI`` and ``kappa*G*A`` (loss factor) enter the
stiffness directly.

Default mesh (measured in ``test_fe_reference.py`` and against order-4,
200-element meshes): order 3, element length about ``L_beam/20``
(``ELEMENTS_PER_BEAM``), at least one element per segment.  First five
frequencies of free-free and clamped uniform (L/d = 2 ... 25), stepped
spindle-like, holder-like and tool-like beams are within 2.5e-6 of converged
and change by < 2.5e-6 when the mesh is doubled.

Tapered segments
----------------
A segment may have a :class:`Taper` instead of a uniform :class:`Section`:
ring diameters linear along it.  Each element then integrates the varying
``EI``, ``kappa*G*A``, ``rho*A`` and ``rho*I`` at its own Gauss points
(``order + 6`` points: exact for the polynomial parts, ``kappa`` varies
slowly), so the taper is represented continuously and the mesh converges to
the continuous tapered beam (measured in ``test_fe_reference.py`` against
the closed-form static compliance of a tapered cantilever).

Usage
-----
>>> m = Model()
>>> b = m.add_beam([(0.1, ring(0.08, 0.04, STEEL)),
...                 (0.08, section(0.05, 0.02, STEEL, insert=CARBIDE))], points=[0.05])
>>> m.add_mass((b, m.length(b)), 0.004, J=1e-8)             # sensor
>>> f_n = m.natural_frequencies(5)                          # Hz, rigid modes dropped
>>> H = m.point_receptance(np.linspace(10, 5000, 500), (b, m.length(b)))  # (500, 2, 2)
>>> t = m.add_beam([(0.05, ring(0.02, 0.0, CARBIDE))])
>>> m.add_joint((b, m.length(b)), (t, 0.0), [[5e7, 2e5], [2e5, 4e4]], [[30, 0], [0, 0.01]])
"""

from __future__ import annotations

import hashlib
import math
from collections import OrderedDict
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np
from numpy.polynomial import Legendre
from numpy.polynomial import Polynomial as P
import scipy.linalg
import scipy.sparse
import scipy.sparse.linalg

SOLVED_KEPT = 64
"""Receptances of the last solves kept (a few MB): the tests measure the same rigs again with other noise."""
_SOLVED: OrderedDict = OrderedDict()

ORDER = 3
ELEMENTS_PER_BEAM = 20
MIN_PER_SEGMENT = 1
_DOF = {"y": 0, "theta": 1}


# --------------------------------------------------------------------------- sections
class Material(NamedTuple):
    E: float          # Young's modulus [Pa]
    nu: float         # Poisson ratio
    rho: float        # density [kg/m^3]
    eta: float = 0.0  # loss factor


STEEL = Material(210e9, 0.29, 7850.0)
CARBIDE = Material(580e9, 0.22, 14500.0)


def cowper_kappa(nu: float, m: float = 0.0) -> float:
    """Cowper (1966) shear coefficient of a hollow circle, ``m = id/od``."""
    a = (1.0 + m * m) ** 2
    return 6.0 * (1.0 + nu) * a / ((7.0 + 6.0 * nu) * a + (20.0 + 12.0 * nu) * m * m)


@dataclass(frozen=True)
class Section:
    """Section properties of one beam slice; ``+`` stacks layers (composite)."""
    EI: complex
    kGA: complex
    rhoA: float
    rhoI: float
    A: float = 0.0
    I: float = 0.0  # noqa: E741 (the second moment of area, as in the formulas)

    def __add__(self, other: "Section") -> "Section":
        return Section(self.EI + other.EI, self.kGA + other.kGA, self.rhoA + other.rhoA,
                       self.rhoI + other.rhoI, self.A + other.A, self.I + other.I)


def ring(od: float, id: float, mat: Material) -> Section:
    """Circular ring (``id = 0``: solid) of one material."""
    A = math.pi / 4.0 * (od**2 - id**2)
    I = math.pi / 64.0 * (od**4 - id**4)  # noqa: E741 (the second moment of area)
    c = 1.0 + 1j * mat.eta
    G = mat.E / (2.0 * (1.0 + mat.nu))
    kappa = cowper_kappa(mat.nu, id / od)
    return Section(mat.E * c * I, kappa * G * c * A, mat.rho * A, mat.rho * I, A, I)


def section(od: float, id: float, mat: Material, insert: Material | None = None,
            insert_id: float = 0.0) -> Section:
    """Ring ``od``/``id`` plus, optionally, an insert of ``insert`` filling the bore
    (itself a ring ``id``/``insert_id``, solid by default)."""
    s = ring(od, id, mat)
    if insert is not None and id > 0.0:
        s = s + ring(id, insert_id, insert)
    return s


def fluted(od: float, ratio: float, mat: Material) -> Section:
    """Fluted tool part: solid circle of equivalent diameter ``ratio*od``."""
    return ring(ratio * od, 0.0, mat)


@dataclass(frozen=True)
class Taper:
    """A section varying along a segment: ring diameters linear in the position.

    ``od`` goes from ``od0`` (segment start) to ``od1`` (segment end), ``id``
    from ``id0`` to ``id1``; ``ratio`` scales the outer diameter (fluted
    parts); an optional uniform ``insert`` ring (``insert_od``/``insert_id``)
    of another material fills the bore.  ``at(t)`` is the section at the
    fraction ``t`` of the segment; elements integrate it by Gauss quadrature
    (:func:`element`), so nothing is stepped.
    """
    od0: float
    od1: float
    id0: float
    id1: float
    mat: Material
    ratio: float = 1.0
    insert: Material | None = None
    insert_od: float = 0.0
    insert_id: float = 0.0

    def at(self, t: float) -> Section:
        od = (self.od0 + (self.od1 - self.od0) * t) * self.ratio
        idd = self.id0 + (self.id1 - self.id0) * t
        s = ring(od, idd, self.mat)
        if self.insert is not None:
            s = s + ring(self.insert_od, self.insert_id, self.insert)
        return s

    def part(self, t0: float, t1: float) -> "Taper":
        """The same taper restricted to the fractions ``[t0, t1]`` of the segment."""
        def lin(a, b, t):
            return a + (b - a) * t

        return Taper(lin(self.od0, self.od1, t0), lin(self.od0, self.od1, t1),
                     lin(self.id0, self.id1, t0), lin(self.id0, self.id1, t1),
                     self.mat, self.ratio, self.insert, self.insert_od, self.insert_id)

    def mass(self, length: float) -> float:
        """Exact mass of a segment of this taper (Gauss quadrature of rho*A)."""
        xg, wg = np.polynomial.legendre.leggauss(4)
        return float(sum(w / 2 * self.at((x + 1) / 2).rhoA for x, w in zip(xg, wg)) * length)


# --------------------------------------------------------------------------- element
def _basis(q: int) -> list[P]:
    """Hierarchical degree-q basis on xi in [0, 1]: 1-xi, xi, then the bubbles
    xi(1-xi) P_k(2xi-1), k = 0..q-2 (P_k Legendre; they vanish at both nodes)."""
    xi, t = P([0.0, 1.0]), P([-1.0, 2.0])
    bub = [xi * (1 - xi) * Legendre.basis(k).convert(kind=P)(t) for k in range(q - 1)]
    return [1 - xi, xi, *bub]


def element(L: float, s: Section, order: int = ORDER):
    """Element matrices ``(K complex, M real)``, size ``2*order + 3``.

    DOFs: ``y1, th1, y2, th2`` then ``order`` bubble amplitudes of ``y`` and
    ``order - 1`` of ``theta`` (internal, not shared between elements).
    ``y`` has degree ``order + 1``, ``theta`` degree ``order``.
    """
    p = order
    if p < 1:
        raise ValueError("order must be >= 1 (>= 2 for exact statics)")
    by, bt = _basis(p + 1), _basis(p)
    n = 2 * p + 3
    varying = isinstance(s, Taper)
    # exact to degree 2p+3 for a uniform section; a taper's rho*A (degree 2) and
    # rho*I, EI (degree 4) raise the degree to 2p+6: p+4 points, and p+6 for kappa,
    # which varies as a rational function of id/od when the bore is not proportional.
    xg, wg = np.polynomial.legendre.leggauss(p + 6 if varying else p + 2)
    xg, wg = (xg + 1) / 2, wg * L / 2
    Ny, dNy, Nt, dNt = (np.zeros((len(xg), n)) for _ in range(4))
    cy = [0, 2, *range(4, 4 + p)]                            # columns of y functions
    ct = [1, 3, *range(4 + p, n)]                            # columns of theta functions
    for c, f in zip(cy, by):
        Ny[:, c], dNy[:, c] = f(xg), f.deriv()(xg) / L
    for c, f in zip(ct, bt):
        Nt[:, c], dNt[:, c] = f(xg), f.deriv()(xg) / L
    g = dNy - Nt                                             # shear strain y' - theta
    if varying:
        secs = [s.at(x) for x in xg]
        EI, kGA, rhoA, rhoI = (np.array([getattr(q, f) for q in secs]) for f in ("EI", "kGA", "rhoA", "rhoI"))
    else:
        EI, kGA, rhoA, rhoI = (np.full(len(xg), getattr(s, f)) for f in ("EI", "kGA", "rhoA", "rhoI"))
    def quad(c, A, B):
        return np.einsum("g,gi,gj->ij", wg * c, A, B)

    K = quad(EI, dNt, dNt) + quad(kGA, g, g)
    M = quad(rhoA, Ny, Ny) + quad(rhoI, Nt, Nt)
    return np.asarray(K, complex), M.real


def condensed_stiffness(K: np.ndarray) -> np.ndarray:
    """Static condensation of an element stiffness onto ``y1, th1, y2, th2``."""
    a, b = slice(0, 4), slice(4, None)
    return K[a, a] - K[a, b] @ np.linalg.solve(K[b, b], K[b, a])


def _mat2(v) -> np.ndarray:
    """2x2 from a 2x2, a 2-vector (diagonal per DOF) or a scalar (y only)."""
    a = np.asarray(v, dtype=complex)
    if a.ndim == 0:
        return np.array([[a, 0], [0, 0]], dtype=complex)
    if a.shape == (2,):
        return np.diag(a)
    if a.shape == (2, 2):
        return a
    raise ValueError(f"expected a scalar, 2-vector or 2x2, got shape {a.shape}")


# --------------------------------------------------------------------------- model
class Model:
    """FE assembly of beams plus point masses, ground springs, joints and constraints.

    A point is ``(beam, x)`` or ``(beam, x, "y"|"theta")`` (default ``"y"``), or
    a global DOF index ``int``.  Positions ``x`` must be nodes: pass them in
    ``add_beam(points=...)`` (segment ends are always nodes).
    """

    def __init__(self, order: int = ORDER):
        self.order = order                   # theta degree of the elements (>= 1)
        self.x: list[np.ndarray] = []        # node positions per beam
        self._off: list[int] = []            # first global DOF per beam
        self.ndof = 0
        self._blocks = []                    # (dofs, K0, C, M) dense blocks to scatter
        self._clamped: set[int] = set()
        self._merge: list[tuple[int, int]] = []

    # ---- building
    def add_beam(self, segments, n_elem: int | None = None, points=()) -> int:
        """Add a beam from ``segments = [(length, Section or Taper), ...]`` (base to tip).

        ``n_elem``: elements per segment (default: element length about
        ``L_beam/ELEMENTS_PER_BEAM``, >= ``MIN_PER_SEGMENT`` per segment).
        ``points``: extra positions that become nodes (sub-intervals keep the
        segment's element density).  Returns the beam index.
        """
        ends = np.concatenate([[0.0], np.cumsum([float(L) for L, _ in segments])])
        total, off, tol = ends[-1], self.ndof, 1e-9 * ends[-1]
        pts = np.asarray(sorted(float(p) for p in points))
        xs, elems = [0.0], []
        for i, (L, sec) in enumerate(segments):
            n_seg = n_elem or max(MIN_PER_SEGMENT, math.ceil(L / total * ELEMENTS_PER_BEAM - 1e-9))
            inner = pts[(pts > ends[i] + tol) & (pts < ends[i + 1] - tol)]
            cuts = np.concatenate([[ends[i]], inner, [ends[i + 1]]])
            for a, b in zip(cuts[:-1], cuts[1:]):
                n = max(1, math.ceil(n_seg * (b - a) / L - 1e-9))
                if isinstance(sec, Taper):   # each element integrates its own part of the taper
                    t = (a - ends[i] + (b - a) * np.arange(n + 1) / n) / L
                    elems += [element((b - a) / n, sec.part(t0, t1), self.order) for t0, t1 in zip(t[:-1], t[1:])]
                else:
                    elems += [element((b - a) / n, sec, self.order)] * n
                xs.extend(a + (b - a) * np.arange(1, n + 1) / n)
        n_int = 2 * self.order - 1                       # internal DOFs per element
        first_int = off + 2 * len(xs)
        for e, (Ke, Me) in enumerate(elems):
            d = [*range(off + 2 * e, off + 2 * e + 4),
                 *range(first_int + n_int * e, first_int + n_int * (e + 1))]
            self._blocks.append((d, Ke, np.zeros(Ke.shape), Me))
        self.x.append(np.array(xs))
        self._off.append(off)
        self.ndof = first_int + n_int * len(elems)
        return len(self.x) - 1

    def node(self, beam: int, x: float) -> int:
        """Index of the node exactly at ``x`` (ValueError if none)."""
        i, xn = self.nearest_node(beam, x)
        if abs(xn - x) > 1e-9 * max(1.0, self.length(beam)):
            raise ValueError(f"beam {beam}: no node at x={x} (nearest {xn}); add it to points=")
        return i

    def nearest_node(self, beam: int, x: float) -> tuple[int, float]:
        """``(index, position)`` of the node nearest to ``x``."""
        i = int(np.argmin(np.abs(self.x[beam] - x)))
        return i, float(self.x[beam][i])

    def length(self, beam: int) -> float:
        return float(self.x[beam][-1])

    def dof(self, point) -> int:
        """Global (unreduced) DOF index of ``(beam, x[, 'y'|'theta'])`` or an int."""
        if isinstance(point, (int, np.integer)):
            return int(point)
        beam, x, *d = point
        return self._off[beam] + 2 * self.node(beam, x) + _DOF[d[0] if d else "y"]

    def _dofs2(self, point) -> list[int]:
        d = self._off[point[0]] + 2 * self.node(point[0], point[1])
        return [d, d + 1]

    def add_mass(self, point, m: float, J: float = 0.0):
        """Point mass ``m`` [kg] with rotary inertia ``J`` [kg m^2] at ``(beam, x)``."""
        z = np.zeros((2, 2))
        self._blocks.append((self._dofs2(point), z, z, np.diag([m, J])))

    def add_support(self, point, k, c=0.0):
        """Spring/damper to ground at ``(beam, x)``: dynamic stiffness ``k + i w c``
        (each a 2x2, a per-DOF 2-vector ``(k_y, k_theta)``, or a scalar = y only)."""
        self._blocks.append((self._dofs2(point), _mat2(k), _mat2(c), np.zeros((2, 2))))

    def add_joint(self, point_a, point_b, k, c=0.0):
        """Joint: ``[f, m] = (k + i w c) [y_a - y_b, th_a - th_b]``, ``k`` and ``c`` as
        ``[[kyf, kym], [ktf, ktm]]`` (or per-DOF 2-vectors / scalar, see add_support)."""
        def blk(A):
            return np.block([[A, -A], [-A, A]])

        dofs = self._dofs2(point_a) + self._dofs2(point_b)
        self._blocks.append((dofs, blk(_mat2(k)), blk(_mat2(c)), np.zeros((4, 4))))

    def add_rigid(self, point_a, point_b, dofs=("y", "theta")):
        """Rigid connection: the listed DOFs of the two points become one DOF."""
        a, b = self._dofs2(point_a), self._dofs2(point_b)
        self._merge += [(a[_DOF[d]], b[_DOF[d]]) for d in dofs]

    def clamp(self, point, dofs=("y", "theta")):
        """Fix the listed DOFs of ``(beam, x)`` to ground."""
        a = self._dofs2(point)
        self._clamped.update(a[_DOF[d]] for d in dofs)

    # ---- assembly
    def reduction(self) -> np.ndarray:
        """``red[full_dof]`` = reduced DOF after merges and clamps (-1 = clamped)."""
        parent = list(range(self.ndof))

        def root(i):
            while parent[i] != i:
                parent[i] = parent[parent[i]]
                i = parent[i]
            return i

        for a, b in self._merge:
            parent[root(a)] = root(b)
        fixed = {root(i) for i in self._clamped}
        ids: dict[int, int] = {}
        red = np.full(self.ndof, -1)
        for i in range(self.ndof):
            if (r := root(i)) not in fixed:
                red[i] = ids.setdefault(r, len(ids))
        return red

    def matrices(self):
        """Reduced sparse (CSC) ``K0, C, M`` and the map ``red``; the dynamic
        stiffness is ``K0 + i w C - w^2 M`` (K0 complex: loss factor, joints)."""
        red = self.reduction()
        n = int(red.max()) + 1
        rows, cols, vals = [], [], [[], [], []]
        for d, *mats in self._blocks:
            r = red[np.asarray(d)]
            ii, jj = np.meshgrid(r, r, indexing="ij")
            keep = (ii >= 0) & (jj >= 0)
            rows.append(ii[keep])
            cols.append(jj[keep])
            for v, A in zip(vals, mats):
                v.append(np.asarray(A, complex)[keep])
        rc = (np.concatenate(rows), np.concatenate(cols))
        K0, C, M = (scipy.sparse.csc_matrix((np.concatenate(v), rc), shape=(n, n)) for v in vals)
        return K0, C, M.real, red

    # ---- results
    def natural_frequencies(self, n: int | None = None, skip_rigid=True,
                            rigid_hz: float = 1.0) -> np.ndarray:
        """Undamped natural frequencies [Hz] from ``eigh(Re K0, M)`` (dampers
        ignored; ``eig`` if ``K0`` is not symmetric; sparse shift-invert ``eigsh``
        for the lowest ones when ``n`` is given and the model is large).
        ``skip_rigid``: True drops |f| < ``rigid_hz`` (rigid-body zeros come out
        as ~0.01 Hz round-off); an int drops that many lowest ones; False keeps
        all (signed square root of the eigenvalues)."""
        K0, _, M, _ = self.matrices()
        K, N = K0.real, M.shape[0]
        sym = abs(K - K.T).max() <= 1e-12 * abs(K).max()
        extra = 2 * len(self.x) if skip_rigid is True else int(skip_rigid)
        if sym and n is not None and N > 400 and n + extra < N - 2:
            lam = np.sort(scipy.sparse.linalg.eigsh(K, n + extra, M, sigma=-1.0,
                                                    return_eigenvectors=False))
        elif sym:
            lam = scipy.linalg.eigh(K.toarray(), M.toarray(), eigvals_only=True)
        else:
            lam = np.sort(scipy.linalg.eigvals(K.toarray(), M.toarray()).real)
        f = np.sign(lam) * np.sqrt(np.abs(lam)) / (2 * math.pi)
        if skip_rigid is True:
            f = f[np.abs(f) >= rigid_hz]
        elif skip_rigid:
            f = f[int(skip_rigid):]
        return f if n is None else f[:n]

    def receptance(self, f_hz, outputs, inputs=None, decay: float = 0.0) -> np.ndarray:
        """Receptances ``(n_freq, n_out, n_in)`` between points (outputs: y or theta;
        inputs: force on y, moment on theta).  Clamped DOFs give 0.  ``f_hz = 0``
        is the static compliance of a constrained structure.  One sparse LU per
        frequency (fast for the banded beam matrices).  ``decay``: at the complex
        angular frequency ``2 pi f - i decay`` (the same matrices, ``w`` complex)."""
        inputs = outputs if inputs is None else inputs
        w = 2 * math.pi * np.atleast_1d(np.asarray(f_hz, float)) - 1j * decay
        K0, C, M, red = self.matrices()
        oi = np.array([red[self.dof(p)] for p in outputs])
        ii = np.array([red[self.dof(p)] for p in inputs])
        # the same system solved again (a rig measured anew with other noise): the answer of the last solve, the
        # same numbers (keyed by every number the solve reads)
        digest = hashlib.sha256()
        for a in (K0, C, M):
            a = a.tocsc()
            for part in (a.data, a.indices, a.indptr, np.array(a.shape)):
                digest.update(np.ascontiguousarray(part).tobytes())
        for part in (oi, ii, w):
            digest.update(np.ascontiguousarray(part).tobytes())
        key = digest.hexdigest()
        if key in _SOLVED:
            _SOLVED.move_to_end(key)
            return _SOLVED[key].copy()
        B = np.zeros((M.shape[0], len(ii)), complex)
        B[ii[ii >= 0], np.flatnonzero(ii >= 0)] = 1.0
        H = np.zeros((len(w), len(oi), len(ii)), complex)
        # K0 + i w C - w^2 M on the entries any of them holds (sorted, as a sparse sum gives them), its values
        # computed as that sum computes them, entries that come out zero left out as it leaves them out
        union = (abs(K0) + abs(C) + abs(M)).tocsc()
        union.sort_indices()
        rows, cols = union.indices, np.repeat(np.arange(union.shape[1]), np.diff(union.indptr))
        k_u, c_u, m_u = (np.asarray(A.tocsc()[rows, cols]).ravel() for A in (K0, C, M))
        for k, wk in enumerate(w):
            data = k_u + 1j * wk * c_u - wk**2 * m_u
            if np.all(data != 0):
                A = scipy.sparse.csc_matrix((data, union.indices, union.indptr), shape=union.shape)
            else:
                A = scipy.sparse.csc_matrix((data, (rows, cols)), shape=union.shape)
                A.eliminate_zeros()
            X = scipy.sparse.linalg.splu(A).solve(B)
            H[k, oi >= 0] = X[oi[oi >= 0]]
        _SOLVED[key] = H.copy()
        while len(_SOLVED) > SOLVED_KEPT:
            _SOLVED.popitem(last=False)
        return H

    def point_receptance(self, f_hz, point_out, point_in=None) -> np.ndarray:
        """``[[H, L], [N, P]]`` (n_freq, 2, 2) from ``(beam, x)`` (input) to
        ``(beam, x)`` (output); default input = output point."""
        point_in = point_out if point_in is None else point_in
        o = [(*point_out[:2], d) for d in _DOF]
        return self.receptance(f_hz, o, [(*point_in[:2], d) for d in _DOF])
