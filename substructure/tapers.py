"""Tapered (conical) segments: the fourth-order stepping that feeds them to the exact kernels.

A segment whose outer and inner diameters vary linearly along it
(:class:`~substructure.beams.Segment` with ``od_tip``/``id_tip``) has no
closed-form Timoshenko solution.  It is modelled by uniform pieces, so that
the exact uniform-segment machinery of :mod:`substructure.beams` and
:mod:`substructure._kernels` serves it unchanged: ``n`` equal steps, each
the two half-steps of the fourth-order commutator-free Magnus scheme of
Blanes & Moan (2006).  Over a step of length ``h``, with ``A1`` and ``A2``
the first-order Timoshenko matrices at the step's two Gauss points
(``x_mid -+ sqrt(3)/6 h``), the transfer matrix is
``exp(h/2 (c1 A1 + c2 A2)) exp(h/2 (c2 A1 + c1 A2))`` (base half first),
``c1, c2 = 1/2 +- sqrt(3)/3``.  ``A`` is linear in ``1/EI``, ``1/kGA``,
``rhoA`` and ``rhoI`` with fixed unit entries and ``c1 + c2 = 1``, so each
factor is the exact transfer matrix of a uniform section (harmonic
combinations of ``EI`` and ``kGA``, arithmetic ones of ``rhoA`` and
``rhoI``); these sections do not depend on the frequency.  The global error
falls as ``1/n^4``; the mass is integrated exactly (two-point Gauss per step
of a quadratic ``rhoA``).

The step count follows a measured error bound (docs/beams.md, "Tapered
segments"): no section property changes by more than
:data:`TAPER_STEP_RATIO` over a step, and no step is longer than
:data:`TAPER_STEP_PHASE` over the bending wavenumber at the highest
frequency line.  Static compliances and natural frequencies are then within
:data:`TAPER_ERROR_BOUND` (relative) of the continuous tapered beam.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, NamedTuple, Sequence

import attrs
import numpy as np

from ._chains import _phase, _stack_sections
from .sections import Section, shear_coefficient
from .errors import InvalidValueError
from .units import quantity

if TYPE_CHECKING:  # beams imports this module (Segment delegates its tapers to it); the annotations only
    from .beams import Segment

__all__ = ["TAPER_STEP_RATIO", "TAPER_STEP_PHASE", "TAPER_ERROR_BOUND", "check_taper", "step_count",
           "piece_sections", "section_at", "split", "mass", "piecewise_sections", "tapered_column"]
# TaperSI, taper_si, pieces and mass_si serve this module's functions and the fits' SI arrays
# (updating.beam_arrays.BeamArrays), which check what they are given: not for users

TAPER_STEP_RATIO = 0.3
"""Largest relative change of a section property over one step of a tapered segment (default steps)."""

TAPER_STEP_PHASE = 0.6
"""Largest bending wavenumber times step length ``k h`` at the highest frequency line (default steps)."""

TAPER_ERROR_BOUND = 1e-4
"""Bound on the relative error of the default stepped model of a taper (docs/beams.md, "Tapered segments")."""

MAX_TAPER_STEPS = 10_000
"""The most steps ``taper_steps`` may ask for (each is a beam element at every frequency line)."""


def _steps(value) -> int | None:
    if value is None:
        return None
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < 1:
        raise InvalidValueError(f"taper_steps: got {value!r}; expected a whole number of steps >= 1")
    if value > MAX_TAPER_STEPS:
        raise InvalidValueError(f"taper_steps: got {value!r}; expected at most {MAX_TAPER_STEPS:,} steps (each is a "
                                "beam element at every frequency line; the default error bound needs far fewer)")
    return int(value)


class TaperSI(NamedTuple):
    """A tapered segment as the SI numbers its sections along it follow from (a :class:`Segment`'s, or a row of
    the fits' arrays, :class:`~substructure.updating.structure.BeamArrays`).

    Parameters
    ----------
    length : float
        Its length [m].
    ends : tuple of float
        ``(od, od_tip, id, id_tip)`` [m].
    ratio : float
        The flutes' diameter ratio (1: no flutes).
    E, G : complex
        Young's and shear moduli with the loss factor, ``E (1 + i eta)`` [Pa].
    nu : float
        Poisson's ratio.
    rho : float
        Density [kg/m^3].
    insert : tuple or None
        ``(EI, kGA, rhoA, rhoI)`` of an insert in its (uniform) bore.
    steps : int or None
        ``taper_steps``; None for the count of the error bound.
    """

    length: float
    ends: tuple
    ratio: float
    E: complex
    G: complex
    nu: float
    rho: float
    insert: tuple | None
    steps: int | None


def taper_si(seg: Segment) -> TaperSI:
    """The SI numbers of a tapered :class:`Segment`.

    Parameters
    ----------
    seg : Segment
        A tapered segment.

    Returns
    -------
    TaperSI
        Its numbers.
    """
    mat, ins = seg.material, None
    if seg.insert is not None:
        s = Section.ring(seg.insert.od.m_as("m"), seg.insert.id.m_as("m"), seg.insert.material)
        ins = (s.EI, s.kGA, s.rhoA, s.rhoI)
    assert seg._taper is not None  # called for tapered segments only
    return TaperSI(seg.length_m, seg._taper, 1.0 if seg.flutes is None else seg.flutes.diameter_ratio, mat.E_si,
                   mat.G_si, mat.nu, mat.rho_si, ins, seg.taper_steps)


def _taper_arrays(tp: TaperSI, t: np.ndarray, part: tuple[float, float] = (0.0, 1.0)):
    """``EI, kGA, rhoA, rhoI`` arrays of a tapered segment at fractions ``t`` of its length (SI), or of the
    part of it between the fractions ``part`` (as :func:`split` cuts it, without building the parts)."""
    od0, od1, id0, id1 = tp.ends
    if part != (0.0, 1.0):
        t = part[0] + (part[1] - part[0]) * t
    od = od0 + (od1 - od0) * t
    idd = id0 + (id1 - id0) * t
    if tp.ratio != 1.0:
        od = od * tp.ratio
    area = math.pi / 4.0 * (od**2 - idd**2)
    inertia = math.pi / 64.0 * (od**4 - idd**4)
    kappa = shear_coefficient(tp.nu, idd / od)
    ei = tp.E * inertia
    kga = kappa * tp.G * area
    rhoa = tp.rho * area
    rhoi = tp.rho * inertia
    if tp.insert is not None:
        ei, kga, rhoa, rhoi = ei + tp.insert[0], kga + tp.insert[1], rhoa + tp.insert[2], rhoi + tp.insert[3]
    return (np.asarray(ei, dtype=complex), np.asarray(kga, dtype=complex), np.asarray(rhoa, dtype=float),
            np.asarray(rhoi, dtype=float))


def _taper_sections(seg: Segment, t: np.ndarray) -> list[Section]:
    """Sections of a tapered segment at fractions ``t`` of its length."""
    ei, kga, rhoa, rhoi = _taper_arrays(taper_si(seg), np.asarray(t, dtype=float))
    return [Section(complex(a), complex(b), float(c), float(d)) for a, b, c, d in zip(ei, kga, rhoa, rhoi)]


_GAUSS = math.sqrt(3.0) / 6.0          # Gauss points of a step at its middle -+ GAUSS * step
_CF = (0.5 + math.sqrt(3.0) / 3.0, 0.5 - math.sqrt(3.0) / 3.0)  # commutator-free Magnus weights


def _magnus_arrays(tp: TaperSI, n: int, part: tuple[float, float] = (0.0, 1.0)) -> tuple[np.ndarray, ...]:
    """The ``2 n`` uniform half-steps of the fourth-order commutator-free Magnus scheme, as arrays
    ``(EI, kGA, rhoA, rhoI)``.

    Over a step of length ``h`` with the section ``S1`` at its base-side
    Gauss point and ``S2`` at its tip-side one, the transfer matrix is
    ``exp(h/2 (c1 A1 + c2 A2)) exp(h/2 (c2 A1 + c1 A2))`` (applied base half
    first) with ``c1, c2 = 1/2 +- sqrt(3)/3`` (Blanes & Moan 2006).  ``A`` is
    linear in ``1/EI``, ``1/kGA``, ``rhoA`` and ``rhoI`` with fixed unit
    entries, and ``c1 + c2 = 1``, so each factor is the transfer matrix of a
    uniform section over ``h/2``: ``1/EI = c1/EI1 + c2/EI2``, ``1/kGA``
    likewise, ``rhoA = c1 rhoA1 + c2 rhoA2``, ``rhoI`` likewise.  The
    sections do not depend on the frequency.  ``part``: of the part between these fractions of the segment.
    """
    middle = (np.arange(n) + 0.5) / n
    t = np.column_stack([middle - _GAUSS / n, middle + _GAUSS / n]).ravel()
    c1, c2 = _CF
    out = []
    for k, x in enumerate(_taper_arrays(tp, t, part)):
        first, second = x[0::2], x[1::2]
        halves = np.empty(2 * n, dtype=x.dtype)
        if k < 2:  # EI, kGA: harmonic
            halves[0::2] = 1.0 / (c1 / first + c2 / second)
            halves[1::2] = 1.0 / (c2 / first + c1 / second)
        else:
            halves[0::2] = c1 * first + c2 * second
            halves[1::2] = c2 * first + c1 * second
        out.append(halves)
    return tuple(out)


def _magnus_sections(seg: Segment, n: int, part: tuple[float, float] = (0.0, 1.0)) -> list[Section]:
    """:func:`_magnus_arrays` of a segment, as sections."""
    return [Section(*row) for row in zip(*_magnus_arrays(taper_si(seg), n, part))]


def _auto_steps(tp: TaperSI, omega_max: float = 0.0, part: tuple[float, float] = (0.0, 1.0)) -> int:
    """Steps such that no section property changes by more than TAPER_STEP_RATIO over one
    step and, at ``omega_max``, no step is longer than TAPER_STEP_PHASE over the bending wavenumber.

    The largest logarithmic slope of ``|EI|``, ``|kGA|``, ``rhoA`` and ``rhoI``
    along the segment (from 257 samples) times the length over the ratio;
    the largest ``k L`` of the end sections over the phase.  ``part``: of the
    part between these fractions of the segment.
    """
    t = np.linspace(0.0, 1.0, 257)
    # the four properties' largest slope at once (the largest of the four largest)
    slope = np.max(np.abs(np.diff(np.log(np.abs(np.stack(_taper_arrays(tp, t, part)))), axis=1))) * (t.size - 1)
    n = math.ceil(slope / TAPER_STEP_RATIO - 1e-9)
    if omega_max > 0.0:
        ends = Section(*_taper_arrays(tp, np.array([0.0, 1.0]), part))  # both ends in one kernel call
        n = max(n, math.ceil(_phase(ends, tp.length * (part[1] - part[0]), omega_max) / TAPER_STEP_PHASE - 1e-9))
    return max(1, n)


def check_taper(seg: Segment) -> tuple[float, float, float, float] | None:
    """Validate a segment given ``od_tip``/``id_tip`` (called by :class:`Segment` itself).

    Parameters
    ----------
    seg : Segment
        The segment being built.

    Returns
    -------
    tuple of float or None
        Its end diameters ``(od, od_tip, id, id_tip)`` in metres when it is
        tapered; None when its ends are equal (a uniform segment).

    Raises
    ------
    InvalidValueError
        For ``id_tip >= od_tip``, an insert in a tapered bore, or flutes whose
        equivalent diameter at the tip does not exceed the bore.
    """
    od_tip = seg.od if seg.od_tip is None else seg.od_tip
    id_tip = seg.id if seg.id_tip is None else seg.id_tip
    if id_tip >= od_tip:
        raise InvalidValueError(
            f"id_tip: got {id_tip:~P} with od_tip {od_tip:~P}; expected id_tip < od_tip"
        )
    tapered = not (np.isclose(od_tip.m_as("m"), seg.od.m_as("m"), rtol=1e-12, atol=0.0)
                   and np.isclose(id_tip.m_as("m"), seg.id.m_as("m"), rtol=1e-12, atol=1e-18))
    if not tapered:
        return None
    if seg.insert is not None:
        if not np.isclose(id_tip.m_as("m"), seg.id.m_as("m"), rtol=1e-12, atol=0.0):
            raise InvalidValueError(
                f"insert: the bore is tapered (id {seg.id:~P} to id_tip {id_tip:~P}); an insert "
                "(a cylindrical shank) needs a uniform bore: give the segment id_tip equal to id, "
                "or split it into a tapered segment without insert and a uniform one with it"
            )
    if seg.flutes is not None and seg.flutes.diameter_ratio * od_tip <= id_tip:
        raise InvalidValueError(
            "flutes.diameter_ratio: the equivalent diameter at the tip "
            f"{seg.flutes.diameter_ratio} * {od_tip:~P} is not larger than the bore {id_tip:~P}"
        )
    return (seg.od.m_as("m"), od_tip.m_as("m"), seg.id.m_as("m"), id_tip.m_as("m"))


def step_count(seg: Segment, omega_max: float) -> int:
    """Number of steps that model a segment (see :meth:`Segment.taper_step_count`).

    Parameters
    ----------
    seg : Segment
        Any segment.
    omega_max : float
        Highest angular frequency the model serves [rad/s]; 0 for the
        geometric criterion alone.

    Returns
    -------
    int
        ``taper_steps`` when given, else from the error bound; 1 for a uniform segment.
    """
    if not seg.is_tapered:
        return 1
    return seg.taper_steps if seg.taper_steps is not None else _auto_steps(taper_si(seg), omega_max)


def piece_sections(seg: Segment, steps: int | None, omega_max: float) -> list[Section]:
    """The equal-length uniform sections of a segment (see :meth:`Segment.piece_sections`).

    Parameters
    ----------
    seg : Segment
        Any segment.
    steps : int or None
        Number of steps; None for :func:`step_count`.
    omega_max : float
        Highest angular frequency [rad/s] for the default count.

    Returns
    -------
    list of Section
        ``2 * steps`` Magnus half-steps of a tapered segment, or ``steps``
        copies of a uniform segment's section; all of the same length.
    """
    n = _steps(steps)
    if n is None:
        n = step_count(seg, omega_max)
    if not seg.is_tapered:
        return [seg.section()] * n
    return _magnus_sections(seg, n)


def mass(seg: Segment) -> float:
    """Exact mass of a tapered segment: ``rho*A`` is quadratic in ``x``, Simpson's rule is exact.

    Parameters
    ----------
    seg : Segment
        A tapered segment.

    Returns
    -------
    float
        Mass in kg, insert included.
    """
    return mass_si(taper_si(seg))


def mass_si(tp: TaperSI) -> float:
    """:func:`mass` of a tapered segment given by its SI numbers.

    Parameters
    ----------
    tp : TaperSI
        The segment.

    Returns
    -------
    float
        Mass in kg, insert included.
    """
    rhoa = _taper_arrays(tp, np.array([0.0, 0.5, 1.0]))[2]
    return float(tp.length * (float(rhoa[0]) + 4.0 * float(rhoa[1]) + float(rhoa[2])) / 6.0)


def section_at(seg: Segment, x) -> Section:
    """Section of a segment at a distance from its base (see :meth:`Segment.section_at`).

    Parameters
    ----------
    seg : Segment
        Any segment.
    x : quantity or str
        Distance from the base, within the segment's length.

    Returns
    -------
    Section
        SI section properties there.
    """
    at = quantity(x, "x", "[length]").m_as("m")
    if not -1e-12 * seg.length_m <= at <= seg.length_m * (1 + 1e-12):
        raise InvalidValueError(f"x: got {x!r}; expected a distance within the segment's length {seg.length:~P}")
    if not seg.is_tapered:
        return seg.section()
    return _taper_sections(seg, np.array([min(max(at / seg.length_m, 0.0), 1.0)]))[0]


def split(seg: Segment, at) -> tuple[Segment, Segment]:
    """A segment cut in two (see :meth:`Segment.split`).

    Parameters
    ----------
    seg : Segment
        Any segment.
    at : quantity or str
        Distance of the cut from the base, strictly inside the segment.

    Returns
    -------
    (Segment, Segment)
        Base part and tip part, diameters continuous at the cut.
    """
    x = quantity(at, "at", "[length]")
    if not 0 < x.m_as("m") < seg.length_m:
        raise InvalidValueError(
            f"at: got {at!r}; expected a distance strictly inside the segment's length {seg.length:~P}"
        )
    if not seg.is_tapered:
        return attrs.evolve(seg, length=x), attrs.evolve(seg, length=seg.length - x)
    t = x.m_as("m") / seg.length_m
    od_tip = seg.od if seg.od_tip is None else seg.od_tip
    id_tip = seg.id if seg.id_tip is None else seg.id_tip
    od_cut = seg.od + (od_tip - seg.od) * t
    id_cut = seg.id + (id_tip - seg.id) * t
    first_steps = rest_steps = None
    if seg.taper_steps is not None:
        first_steps = max(1, round(seg.taper_steps * t))
        rest_steps = max(1, seg.taper_steps - first_steps)
    first = attrs.evolve(seg, length=x, od_tip=od_cut, id_tip=id_cut, taper_steps=first_steps)
    second = attrs.evolve(seg, length=seg.length - x, od=od_cut, id=id_cut, od_tip=od_tip, id_tip=id_tip,
                          taper_steps=rest_steps)
    return first, second


def piecewise_sections(segments: Sequence[Segment], omega_max: float = 0.0,
                        positions: np.ndarray = np.empty(0)) -> tuple[list[Section], np.ndarray]:
    """Uniform sections of a stepped beam and their boundaries from the base (m).

    A uniform segment is one piece; a tapered one is cut at the requested
    ``positions`` inside it (so that they fall on step boundaries, where the
    stepped model is fourth-order accurate) and each part is
    :meth:`Segment.piece_sections` for ``omega_max``.  The segment ends are
    the running sums of the segment lengths, as for a beam without tapers,
    so that ``tip`` is exactly the last boundary.

    Parameters
    ----------
    segments : sequence of Segment
        Base to tip.
    omega_max : float
        Highest angular frequency of the computation [rad/s].
    positions : ndarray
        Requested points, distances from the base in metres.

    Returns
    -------
    sections : list of Section
        The uniform pieces, base to tip.
    bounds : ndarray
        Their ``len(sections) + 1`` boundaries from the base, in metres.
    """
    ends = np.concatenate([[0.0], np.cumsum([s.length_m for s in segments])])
    sections: list[Section] = []
    bounds = [0.0]
    for seg, (arrays, cuts) in zip(segments, pieces([taper_si(s) if s.is_tapered else None for s in segments],
                                                    ends, omega_max, positions)):
        sections.extend([seg.section()] if arrays is None else [Section(*row) for row in zip(*arrays)])
        bounds.extend(cuts)
    return sections, np.array(bounds)


def pieces(tapers: Sequence[TaperSI | None], ends: np.ndarray, omega_max: float, positions=()) -> list[tuple]:
    """The uniform pieces of a stepped beam's segments (:func:`piecewise_sections`, from SI numbers).

    Parameters
    ----------
    tapers : sequence of TaperSI or None
        Per segment, base to tip: its numbers when it is tapered, None when it is uniform.
    ends : ndarray
        The segments' ends from the base [m] (``len(tapers) + 1``, from 0).
    omega_max : float
        Highest angular frequency of the computation [rad/s].
    positions : sequence of float
        Requested points [m from the base]: a tapered segment is cut there.

    Returns
    -------
    list of (tuple or None, list of float)
        Per segment: the arrays ``(EI, kGA, rhoA, rhoI)`` of its pieces (None for a uniform segment, one
        piece) and the pieces' ends from the base.
    """
    positions = sorted(float(p) for p in positions)
    out: list[tuple] = []
    for tp, x0, x1 in zip(tapers, ends[:-1], ends[1:]):
        if tp is None:
            out.append((None, [float(x1)]))
            continue
        tol = 1e-12 * max(x1, 1e-300)
        inner = [p for p in positions if x0 + tol < p < x1 - tol]
        # the parts between the points, as split() cuts them (its share of the steps given, too), as fractions of
        # the segment: their sections without building the parts
        stops = [*inner, x1]
        steps: list = [None] * len(stops)
        if tp.steps is not None:
            rest = tp.steps
            for k, (a, b) in enumerate(zip([x0, *inner], inner)):
                steps[k] = max(1, round(rest * (b - a) / (x1 - a)))
                rest = max(1, rest - steps[k])
            steps[-1] = rest
        length = x1 - x0
        arrays, cuts = [], []
        for a, b, n in zip([x0, *inner], stops, steps):
            part = ((a - x0) / length, (b - x0) / length)
            arrays.append(_magnus_arrays(tp, n if n is not None else _auto_steps(tp, omega_max, part), part))
            m = arrays[-1][0].size
            cuts.extend(a + (b - a) * np.arange(1, m) / m)
            cuts.append(b)
        out.append((tuple(np.concatenate(column) for column in zip(*arrays)), cuts))
    return out


def tapered_column(column: Sequence[Segment], omega_max: float) -> list[tuple[Section, object]]:
    """Intervals of one segment position of a batch where some configuration has a taper.

    Every configuration gets the largest step count of the column, so that the
    chains keep one layout (a uniform segment is cut into as many equal
    pieces); a piece shared by all configurations is one section for the
    kernel.

    Parameters
    ----------
    column : sequence of Segment
        The segment at one position of the chain, one per configuration.
    omega_max : float
        Highest angular frequency of the computation [rad/s].

    Returns
    -------
    list of (Section, length)
        Intervals base to tip; a field (and the length, in metres) is an
        array over configurations where they differ.
    """
    n = max(step_count(seg, omega_max) for seg in column)
    pieces = [_magnus_sections(seg, n) if seg.is_tapered else [seg.section()] * (2 * n) for seg in column]
    first = column[0]
    if all(seg is first or seg == first for seg in column[1:]):
        return [(sec, first.length_m / (2 * n)) for sec in pieces[0]]
    length = np.array([seg.length_m / (2 * n) for seg in column])
    return [(_stack_sections([secs[k] for secs in pieces]), length) for k in range(2 * n)]
