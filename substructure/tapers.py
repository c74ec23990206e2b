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
from typing import TYPE_CHECKING, Sequence

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


def _taper_arrays(seg: Segment, t: np.ndarray, part: tuple[float, float] = (0.0, 1.0)):
    """``EI, kGA, rhoA, rhoI`` arrays of a tapered segment at fractions ``t`` of its length (SI), or of the
    part of it between the fractions ``part`` (as :func:`split` cuts it, without building the parts)."""
    assert seg._taper is not None  # called for tapered segments only
    od0, od1, id0, id1 = seg._taper
    if part != (0.0, 1.0):
        t = part[0] + (part[1] - part[0]) * t
    od = od0 + (od1 - od0) * t
    idd = id0 + (id1 - id0) * t
    if seg.flutes is not None:
        od = od * seg.flutes.diameter_ratio
    mat = seg.material
    area = math.pi / 4.0 * (od**2 - idd**2)
    inertia = math.pi / 64.0 * (od**4 - idd**4)
    kappa = shear_coefficient(mat.nu, idd / od)
    ei = mat.E_si * inertia
    kga = kappa * mat.G_si * area
    rhoa = mat.rho_si * area
    rhoi = mat.rho_si * inertia
    if seg.insert is not None:
        ins = Section.ring(seg.insert.od.m_as("m"), seg.insert.id.m_as("m"), seg.insert.material)
        ei, kga, rhoa, rhoi = ei + ins.EI, kga + ins.kGA, rhoa + ins.rhoA, rhoi + ins.rhoI
    return (np.broadcast_to(np.asarray(ei, dtype=complex), t.shape),
            np.broadcast_to(np.asarray(kga, dtype=complex), t.shape),
            np.broadcast_to(np.asarray(rhoa, dtype=float), t.shape),
            np.broadcast_to(np.asarray(rhoi, dtype=float), t.shape))


def _taper_sections(seg: Segment, t: np.ndarray) -> list[Section]:
    """Sections of a tapered segment at fractions ``t`` of its length."""
    ei, kga, rhoa, rhoi = _taper_arrays(seg, np.asarray(t, dtype=float))
    return [Section(complex(a), complex(b), float(c), float(d)) for a, b, c, d in zip(ei, kga, rhoa, rhoi)]


_GAUSS = math.sqrt(3.0) / 6.0          # Gauss points of a step at its middle -+ GAUSS * step
_CF = (0.5 + math.sqrt(3.0) / 3.0, 0.5 - math.sqrt(3.0) / 3.0)  # commutator-free Magnus weights


def _magnus_sections(seg: Segment, n: int, part: tuple[float, float] = (0.0, 1.0)) -> list[Section]:
    """The ``2 n`` uniform half-steps of the fourth-order commutator-free Magnus scheme.

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
    ei, kga, rhoa, rhoi = _taper_arrays(seg, t, part)
    out = []
    for k in range(n):
        i, j = 2 * k, 2 * k + 1
        for a, b in (_CF, _CF[::-1]):
            out.append(Section(
                EI=1.0 / (a / ei[i] + b / ei[j]), kGA=1.0 / (a / kga[i] + b / kga[j]),
                rhoA=float(a * rhoa[i] + b * rhoa[j]), rhoI=float(a * rhoi[i] + b * rhoi[j]),
            ))
    return out


def _auto_steps(seg: Segment, omega_max: float = 0.0, part: tuple[float, float] = (0.0, 1.0)) -> int:
    """Steps such that no section property changes by more than TAPER_STEP_RATIO over one
    step and, at ``omega_max``, no step is longer than TAPER_STEP_PHASE over the bending wavenumber.

    The largest logarithmic slope of ``|EI|``, ``|kGA|``, ``rhoA`` and ``rhoI``
    along the segment (from 257 samples) times the length over the ratio;
    the largest ``k L`` of the end sections over the phase.  ``part``: of the
    part between these fractions of the segment.
    """
    t = np.linspace(0.0, 1.0, 257)
    slopes = [np.max(np.abs(np.diff(np.log(np.abs(p))))) * (t.size - 1) for p in _taper_arrays(seg, t, part)]
    n = math.ceil(max(slopes) / TAPER_STEP_RATIO - 1e-9)
    if omega_max > 0.0:
        ends = Section(*_taper_arrays(seg, np.array([0.0, 1.0]), part))  # both ends in one kernel call
        n = max(n, math.ceil(_phase(ends, seg.length_m * (part[1] - part[0]), omega_max) / TAPER_STEP_PHASE - 1e-9))
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
    return seg.taper_steps if seg.taper_steps is not None else _auto_steps(seg, omega_max)


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
    ends = _taper_sections(seg, np.array([0.0, 0.5, 1.0]))
    return float(seg.length_m * (ends[0].rhoA + 4.0 * ends[1].rhoA + ends[2].rhoA) / 6.0)


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
    sections: list[Section] = []
    bounds = [0.0]
    ends = np.concatenate([[0.0], np.cumsum([s.length_m for s in segments])])
    for seg, x0, x1 in zip(segments, ends[:-1], ends[1:]):
        if not seg.is_tapered:
            sections.append(seg.section())
            bounds.append(x1)
            continue
        tol = 1e-12 * max(x1, 1e-300)
        inner = [float(p) for p in positions if x0 + tol < p < x1 - tol]
        # the parts between the points, as split() cuts them (its share of the steps given, too), as fractions of
        # the segment: their sections without building the parts
        stops = [*inner, x1]
        steps: list = [None] * len(stops)
        if seg.taper_steps is not None:
            rest = seg.taper_steps
            for k, (a, b) in enumerate(zip([x0, *inner], inner)):
                steps[k] = max(1, round(rest * (b - a) / (x1 - a)))
                rest = max(1, rest - steps[k])
            steps[-1] = rest
        length = x1 - x0
        for a, b, n in zip([x0, *inner], stops, steps):
            part = ((a - x0) / length, (b - x0) / length)
            pieces = _magnus_sections(seg, n if n is not None else _auto_steps(seg, omega_max, part), part)
            sections.extend(pieces)
            n = len(pieces)
            bounds.extend(a + (b - a) * np.arange(1, n) / n)
            bounds.append(b)
    return sections, np.array(bounds)


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
