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
``_chain_receptance``): one 2x2 inversion per frequency line, singular
only at the beam's own natural frequencies, with the rigid-body ``omega^2``
factor carried exactly, so that the lowest lines are as accurate as the
rest.  The segment dynamic stiffness (for joints of beam pieces and for
teaching) follows from the blocks of ``T``.  The closed form and the chain
formula are evaluated by the compiled kernels of :mod:`substructure._kernels`,
one frequency line at a time (and over configurations in sweeps); this
module prepares their inputs.

Sections (the shear coefficient, composite and fluted sections) live in
``substructure.sections`` and the chain machinery (cutting long chains
into well-conditioned pieces) in ``substructure._chains``; their public
names are importable from here as before.
"""

from __future__ import annotations

import math
from typing import Sequence

import attrs
import numpy as np
import pint

from . import _blocks as bk
from ._blocks import angular_lines
from ._chains import _CHUNK_KL, _chain_receptance, _chain_single, _is_shared, _phase, _stack_sections  # noqa: F401
from .errors import InvalidValueError
from .materials import Material
from .tapers import MAX_TAPER_STEPS, _steps  # noqa: F401 (MAX_TAPER_STEPS: read from here as before)
from .sections import Flutes, Insert, Section, _length, _material, _metres, shear_coefficient
from .units import magnitude_in, quantity

__all__ = [
    "Insert",
    "Flutes",
    "Segment",
    "Section",
    "shear_coefficient",
    "segment_dynamic_stiffness",
    "stepped_beam_receptance",
    "stepped_beam_receptance_batch",
    "stepped_beam_receptance_si",
    "stepped_beam_receptances_si",
]

def _optional_length(field: str, *, allow_zero: bool = False):
    convert = _length(field, allow_zero=allow_zero)

    def optional(value):
        return None if value is None else convert(value)

    return optional


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
        The segment's material (a catalogue name or a :class:`Material`).
    insert : Insert, optional
        A body of another material filling the bore.
    flutes : Flutes, optional
        Fluted section (tools).  On a tapered segment the equivalent
        diameter follows the outer diameter: ``diameter_ratio * od(x)``.
    od_tip : quantity or str, optional
        Outer diameter at the tip end of a tapered (conical) segment; the
        outer diameter varies linearly from ``od`` at the base end to
        ``od_tip``.  Default: ``od`` (no taper).
    id_tip : quantity or str, optional
        Inner diameter at the tip end, likewise from ``id``.  Default: ``id``.
        An ``insert`` needs a uniform bore (``id_tip`` equal to ``id``).
    taper_steps : int, optional
        Number of uniform steps that model a tapered segment.  Default: the
        number chosen from the error bound of :mod:`substructure.tapers` (see
        :meth:`taper_step_count` and docs/beams.md, "Tapered segments").

    Examples
    --------
    A BT40-like 7:24 steep taper, 65.4 mm long, from 25.375 mm to 44.45 mm:

    >>> cone = Segment("65.4 mm", "25.375 mm", od_tip="44.45 mm")
    >>> cone.is_tapered, cone.taper_step_count()
    (True, 11)
    >>> round(cone.mass(), 3)     # kg, exact for the cone
    0.504
    """

    length: pint.Quantity = attrs.field(converter=_length("length"))  # type: ignore[misc]  # attrs plugin: converter factory
    od: pint.Quantity = attrs.field(converter=_length("od"))  # type: ignore[misc]  # attrs plugin: converter factory
    id: pint.Quantity = attrs.field(default="0 mm", converter=_length("id", allow_zero=True))  # type: ignore[misc]  # attrs plugin: converter factory
    material: Material = attrs.field(default="steel", converter=_material)  # type: ignore[assignment]  # via the converter
    insert: Insert | None = attrs.field(default=None)
    flutes: Flutes | None = attrs.field(default=None)
    od_tip: pint.Quantity | None = attrs.field(default=None, kw_only=True, converter=_optional_length("od_tip"))  # type: ignore[misc]  # attrs plugin: converter factory
    id_tip: pint.Quantity | None = attrs.field(
        default=None, kw_only=True, converter=_optional_length("id_tip", allow_zero=True)  # type: ignore[misc]  # attrs plugin: converter factory
    )
    taper_steps: int | None = attrs.field(default=None, kw_only=True, converter=_steps)
    # SI values, derived once (the kernels need them at every call)
    _si: tuple = attrs.field(init=False, eq=False, repr=False)
    # tapered segments: SI end diameters (od, od_tip, id, id_tip); None when uniform
    _taper: tuple | None = attrs.field(init=False, eq=False, repr=False, default=None)

    def __attrs_post_init__(self) -> None:
        length, od, id_ = (magnitude_in(q, "m") for q in (self.length, self.od, self.id))
        if id_ >= od:
            raise InvalidValueError(f"id: got {self.id:~P} with od {self.od:~P}; expected id < od")
        if self.insert is not None:
            if not isinstance(self.insert, Insert):
                raise InvalidValueError(f"insert: got {self.insert!r}; expected an Insert")
            if id_ == 0:
                raise InvalidValueError("insert: the segment is solid (id = 0); an insert needs a bore")
            if self.insert.od_m > id_:
                raise InvalidValueError(
                    f"insert.od: got {self.insert.od:~P}, larger than the bore id {self.id:~P}"
                )
        if self.flutes is not None:
            if not isinstance(self.flutes, Flutes):
                raise InvalidValueError(f"flutes: got {self.flutes!r}; expected Flutes")
            if self.flutes.diameter_ratio * od <= id_:
                raise InvalidValueError(
                    "flutes.diameter_ratio: the equivalent diameter "
                    f"{self.flutes.diameter_ratio} * {self.od:~P} is not larger than the bore {self.id:~P}"
                )
        if self.od_tip is not None or self.id_tip is not None:
            from .tapers import check_taper

            ends = check_taper(self)
            if ends is not None:  # tapered: no single section
                object.__setattr__(self, "_si", (length, None))
                object.__setattr__(self, "_taper", ends)
                return
        if self.flutes is not None:
            od = od * self.flutes.diameter_ratio
        sec = Section.ring(od, id_, self.material)
        if self.insert is not None:
            sec = sec + Section.ring(self.insert.od_m, self.insert.id_m, self.insert.material)
        object.__setattr__(self, "_si", (length, sec))

    @classmethod
    def from_si(cls, length: float, od: float, id: float = 0.0, material="steel",
                insert: Insert | None = None, flutes: Flutes | None = None) -> "Segment":
        """A segment from its dimensions in metres: the fast way to build many variants.

        Parameters
        ----------
        length, od : float
            Length and outer diameter [m].
        id : float, default 0
            Inner diameter [m].
        material : Material or str, default "steel"
            The segment's material (a catalogue name or a :class:`Material`).
        insert : Insert, optional
            A body of another material filling the bore.
        flutes : Flutes, optional
            Fluted section (tools).

        Returns
        -------
        Segment
            The same segment as ``Segment(f"{length} m", f"{od} m", ...)``,
            with the same checks, built without reading any text: a sweep
            over thousands of geometries spends its time in the computation,
            not in parsing units.
        """
        return cls(_metres(length, "length"), _metres(od, "od"), _metres(id, "id"), material, insert, flutes)

    @property
    def length_m(self) -> float:
        """Length in m (a float)."""
        return self._si[0]

    def section(self) -> Section:
        """Section properties in SI units (layers summed).

        Returns
        -------
        Section
            EI in N m^2, kGA in N, rhoA in kg/m, rhoI in kg m.

        Raises
        ------
        InvalidValueError
            For a tapered segment, whose section varies along it: use
            :meth:`section_at` or :meth:`piece_sections`.
        """
        if self._taper is not None:
            raise InvalidValueError(
                f"section: the segment is tapered (od {self.od:~P} to {self._od_tip:~P}, id {self.id:~P} "
                f"to {self._id_tip:~P}); its section varies along it: use section_at(x) or piece_sections()"
            )
        return self._si[1]

    def mass(self) -> float:
        """Mass of the segment (with its insert); exact for a tapered segment.

        Returns
        -------
        float
            The mass in kg.
        """
        if self._taper is not None:
            from .tapers import mass

            return mass(self)
        return float(self.section().rhoA * self.length_m)

    # -- tapered (conical) segments: the stepping is in substructure.tapers ----------
    @property
    def _od_tip(self) -> pint.Quantity:
        return self.od if self.od_tip is None else self.od_tip

    @property
    def _id_tip(self) -> pint.Quantity:
        return self.id if self.id_tip is None else self.id_tip

    @property
    def is_tapered(self) -> bool:
        """True when the outer or inner diameter varies along the segment."""
        return self._taper is not None

    def taper_step_count(self, max_frequency=None) -> int:
        """Number of steps that model this segment (1 when it is uniform).

        ``taper_steps`` when given; otherwise the smallest ``n`` for which no
        section property (``EI``, ``kappa G A``, ``rho A``, ``rho I``) changes by
        more than :data:`~substructure.tapers.TAPER_STEP_RATIO` (relatively)
        over one step and, up to ``max_frequency``, no step is longer than
        :data:`~substructure.tapers.TAPER_STEP_PHASE` over the bending
        wavenumber.  Static compliances and natural frequencies are then
        within :data:`~substructure.tapers.TAPER_ERROR_BOUND` (docs/beams.md,
        "Tapered segments").  The receptance functions pass their highest
        frequency line.

        Parameters
        ----------
        max_frequency : quantity or str, optional
            Highest frequency the model must serve (e.g. ``"5 kHz"``); without
            it only the geometric criterion applies.

        Returns
        -------
        int
            The number of steps, >= 1.
        """
        from .tapers import step_count

        if max_frequency is None:
            return step_count(self, 0.0)
        return step_count(self, 2.0 * math.pi * quantity(max_frequency, "max_frequency", "1 / [time]").m_as("Hz"))

    def section_at(self, x) -> Section:
        """Section properties at a distance from the base (layers summed, SI).

        Parameters
        ----------
        x : quantity or str
            Distance from the base end, within ``[0, length]`` (e.g. ``"10 mm"``).

        Returns
        -------
        Section
            ``EI`` [N m^2], ``kGA`` [N], ``rhoA`` [kg/m], ``rhoI`` [kg m] there.
        """
        from .tapers import section_at

        return section_at(self, x)

    def piece_sections(self, steps: int | None = None, omega_max: float = 0.0) -> list[Section]:
        """The uniform sections that model this segment, base to tip, all of the same length.

        A uniform segment is ``steps`` copies of its section (one by
        default).  A tapered segment of ``n`` steps is ``2 n`` half-steps of
        the fourth-order commutator-free Magnus scheme
        (:mod:`substructure.tapers`): exact in the limit, with an error
        falling as ``1/n^4``.

        Parameters
        ----------
        steps : int, optional
            Number of steps; default: ``taper_steps``, else chosen as
            :meth:`taper_step_count` does for the highest angular frequency
            ``omega_max``.
        omega_max : float
            Highest angular frequency the pieces must serve [rad/s] (0: the
            geometric criterion only).

        Returns
        -------
        list of Section
            Each ``length / len(list)`` long; SI values (``EI`` [N m^2],
            ``kGA`` [N], ``rhoA`` [kg/m], ``rhoI`` [kg m]).
        """
        from .tapers import piece_sections

        return piece_sections(self, steps, omega_max)

    def split(self, at) -> tuple["Segment", "Segment"]:
        """Two segments that together are this one, cut at a distance from the base.

        Parameters
        ----------
        at : quantity or str
            Where to cut, strictly inside the segment (e.g. ``"20 mm"``).

        Returns
        -------
        (Segment, Segment)
            Base part and tip part; a tapered segment's diameters are
            interpolated at the cut, so each part keeps its own taper
            (explicit ``taper_steps`` are shared in proportion).
        """
        from .tapers import split

        return split(self, at)


# ---------------------------------------------------------------------------
# Closed-form segment transfer matrices
#
# The closed form of the module docstring (and docs/beams.md) is evaluated by
# the compiled kernels of substructure._kernels (a C extension built when the
# package is installed), four frequency lines at a time: the squared
# wavenumbers s1, s2 of A^2, C and S and their divided differences (power
# series where |s L^2| < 0.5, exponentials elsewhere), and
# T = alpha I + beta A + gamma A^2 + delta A^3.  The kernels are imported on
# first use, so that a program loads them only when something is computed.


def segment_transfer_matrix(sec: Section, length: float, omega: np.ndarray) -> np.ndarray:
    """Transfer matrix ``T = exp(A L)`` of a uniform segment, shape ``(4, 4, n)``.

    State ``[w, psi, V, M]`` with ``V = kGA (w' - psi)`` and ``M = EI psi'``.
    """
    from . import _kernels

    omega = np.reshape(omega, -1)
    t = _kernels.transfer_matrices(
        omega, np.array([[sec.EI]], dtype=complex), np.array([[sec.kGA]], dtype=complex),
        np.array([[sec.rhoA]], dtype=float), np.array([[sec.rhoI]], dtype=float), np.array([[length]], dtype=float),
    )
    return np.ascontiguousarray(np.moveaxis(t[0], 0, -1))


def segment_dynamic_stiffness(sec: Section, length: float, omega: np.ndarray):
    """Dynamic stiffness blocks ``(D11, D12, D21, D22)`` of a uniform segment.

    Each block has shape ``(2, 2, n)`` and relates the loads ``[f, m]`` applied
    at the ends to the displacements ``[y, theta]`` of the ends (1: base at
    ``x = 0``, 2: tip at ``x = length``).  Exact: no discretisation.

    Parameters
    ----------
    sec : Section
        Section properties, SI.
    length : float
        Length in m.
    omega : ndarray
        Angular frequencies in rad/s.

    Returns
    -------
    tuple of ndarray
        ``(D11, D12, D21, D22)``, complex, each ``(2, 2, n)``: N/m, N/rad, N m/m and N m/rad.
    """
    t = segment_transfer_matrix(sec, length, omega)
    t11, t12, t21, t22 = t[:2, :2], t[:2, 2:], t[2:, :2], t[2:, 2:]
    t12i = bk.inv2(t12)
    d11 = bk.mul2(t12i, t11)
    d12 = -t12i
    d21 = t21 - bk.mul2(t22, d11)
    d22 = bk.mul2(t22, t12i)
    return d11, d12, d21, d22


def stepped_beam_receptance(
    segments: Sequence[Segment], positions: Sequence[float], frequency_hz: np.ndarray, decay: float = 0.0
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
    decay : float, optional
        ``1/tau`` [1/s]: the receptances at the complex frequency
        ``omega - i decay``, as a tap test sees the beam through an
        exponential window ``exp(-t/tau)``; default 0.

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
    omega = angular_lines(frequency_hz, decay)
    from .tapers import piecewise_sections

    sections, ends = piecewise_sections(segments, float(np.abs(omega).max()) if omega.size else 0.0, sorted_pos)
    cuts = np.unique(np.concatenate([ends, sorted_pos]))
    intervals = []
    for x0, x1 in zip(cuts[:-1], cuts[1:]):
        k = int(np.clip(np.searchsorted(ends, 0.5 * (x0 + x1)) - 1, 0, len(sections) - 1))
        intervals.append((sections[k], float(x1 - x0)))
    nodes = [int(i) for i in np.searchsorted(cuts, sorted_pos)]
    return _chain_receptance(intervals, nodes, omega, place=[int(i) for i in order])


_INTERVALS: dict = {}
_INTERVALS_KEPT = 256


def _intervals(lengths: np.ndarray, positions) -> tuple:
    """The intervals of a stepped beam between its steps and the positions: ``(order, widths (k, 1), segment of
    each, node of each sorted position)``, kept for the layouts seen last (a fit changes sizes, not places)."""
    key = (lengths.tobytes(), tuple(float(x) for x in positions))
    found = _INTERVALS.get(key)
    if found is not None:
        return found
    # checked here, once per layout kept: a length or a position the beam does not have gave numbers silently
    if lengths.ndim != 1 or lengths.size == 0 or not (np.isfinite(lengths).all() and (lengths > 0).all()):
        raise InvalidValueError(f"lengths: got {lengths.tolist()!r}; expected the segment lengths in m, each finite "
                                "and > 0")
    pos = np.asarray(positions, dtype=float).reshape(-1)
    total = float(lengths.sum())
    outside = ~np.isfinite(pos) | (pos < 0.0) | (pos > total * (1.0 + 1e-12))
    if pos.size == 0 or outside.any():
        raise InvalidValueError(f"positions: got {pos.tolist()!r}; expected at least one position in m from the base, "
                                f"each within the beam (0 to {total!r} m)")
    order = np.argsort(pos)
    sorted_pos = pos[order]
    if np.any(np.diff(sorted_pos) <= 0):
        raise InvalidValueError("positions: expected distinct positions")
    ends = np.concatenate([[0.0], np.cumsum(lengths)])
    cuts = np.unique(np.concatenate([ends, sorted_pos]))
    widths = np.diff(cuts)
    seg = np.clip(np.searchsorted(ends, 0.5 * (cuts[:-1] + cuts[1:])) - 1, 0, lengths.size - 1)
    nodes = np.searchsorted(cuts, sorted_pos).astype(np.int64)
    found = (order.astype(np.int64), widths.reshape(-1, 1), seg, nodes)
    for a in found:
        a.flags.writeable = False  # shared between calls
    if len(_INTERVALS) >= _INTERVALS_KEPT:
        _INTERVALS.pop(next(iter(_INTERVALS)))
    _INTERVALS[key] = found
    return found


def _checked_si(ei, kga, rhoa, rhoi, n_seg: int, frequency_hz, finite: bool = True) -> None:
    """The SI arrays of :func:`stepped_beam_receptance_si` (shape ``(n_seg, 1)``) and of
    :func:`stepped_beam_receptances_si` (``(n_seg, beams)``) checked: one value per segment, sections a beam has
    (``EI`` and ``kappa G A`` of positive real part, ``rho A`` > 0, ``rho I`` >= 0, finite; with ``finite``
    False a value that is not a number passes, for the batch to fall back on single calls), lines above 0 Hz (a
    free-free beam has no static receptance: 0 Hz gave infinite values)."""
    for name, v in (("ei", ei), ("kga", kga), ("rhoa", rhoa), ("rhoi", rhoi)):
        if v.shape[0] != n_seg:
            raise InvalidValueError(f"{name}: got {v.shape[0]} values for {n_seg} segments; expected one per segment")
    bad = (ei.real <= 0) | (kga.real <= 0) | (rhoa <= 0) | (rhoi < 0)
    if finite:
        bad |= ~(np.isfinite(ei) & np.isfinite(kga) & np.isfinite(rhoa) & np.isfinite(rhoi))
    if bad.any():
        k, b = (int(i) for i in np.argwhere(bad)[0])
        raise InvalidValueError(f"segment {k}: got EI = {complex(ei[k, b])!r}, kGA = {complex(kga[k, b])!r}, "
                                f"rhoA = {float(rhoa[k, b])!r}, rhoI = {float(rhoi[k, b])!r}; expected EI and kGA of "
                                "positive real part, rhoA > 0 and rhoI >= 0, each finite (SI)")
    f = np.asarray(frequency_hz, dtype=float)
    if f.size and not (f.min() > 0 and f.max() < np.inf):
        raise InvalidValueError("frequency_hz: expected lines above 0 Hz, each finite (a free-free beam has no "
                                "static receptance)")


def stepped_beam_receptance_si(
    ei: np.ndarray, kga: np.ndarray, rhoa: np.ndarray, rhoi: np.ndarray, lengths: np.ndarray,
    positions: Sequence[float], frequency_hz: np.ndarray, decay: float = 0.0,
) -> np.ndarray:
    """Free-free receptances of a stepped beam given by SI arrays (no Segment objects).

    The same closed form as :func:`stepped_beam_receptance`, for callers that
    change section properties many times (model updating): no units are
    parsed and no value objects are built.

    Parameters
    ----------
    ei, kga : ndarray of complex, shape (n_seg,)
        Bending stiffness [N m^2] and shear stiffness ``kappa G A`` [N] of each
        segment, base to tip (complex with a loss factor; real parts > 0).
    rhoa, rhoi : ndarray of float, shape (n_seg,)
        Mass per length [kg/m] (> 0) and rotary inertia per length [kg m] (>= 0).
    lengths : ndarray of float, shape (n_seg,)
        Segment lengths [m], all > 0.
    positions : sequence of float
        Distinct positions from the base [m], within ``[0, sum(lengths)]``.
    frequency_hz : ndarray
        Frequency lines [Hz], all > 0.
    decay : float, optional
        ``1/tau`` [1/s]: at the complex frequency ``omega - i decay``.

    Returns
    -------
    ndarray, shape (2p, 2p, n_freq)
        Frequency-last receptances; DOFs ``(y, theta)`` per position in the
        order given.

    Raises
    ------
    InvalidValueError
        For arrays not of one value per segment, a section, a length or a
        line outside those ranges (or not a number), or a position off the
        beam: they gave numbers without a word.
    """
    lengths = np.asarray(lengths, dtype=float)
    from . import _kernels

    ei, kga = (_kernels.c_array(np.asarray(v, complex).reshape(-1, 1), complex) for v in (ei, kga))
    rhoa, rhoi = (_kernels.c_array(np.asarray(v, float).reshape(-1, 1), float) for v in (rhoa, rhoi))
    _checked_si(ei, kga, rhoa, rhoi, lengths.size, frequency_hz)
    order, widths, seg, nodes = _intervals(lengths, positions)
    omega = angular_lines(frequency_hz, decay)
    _, k_max = _kernels.segment_coefficients(  # every segment's largest wavenumber, in one call
        ei.reshape(1, -1), kga.reshape(1, -1), rhoa.reshape(1, -1), rhoi.reshape(1, -1),
        float(np.max(np.abs(omega))) if omega.size else 0.0)
    phases = k_max[0, seg] * widths[:, 0]
    if phases.max() <= _CHUNK_KL and np.cumsum(phases)[-1] <= _CHUNK_KL:
        # one transfer-matrix chain (the usual case): the kernel takes the arrays as they are
        return _kernels.chain_receptance(
            omega, ei[seg], kga[seg], rhoa[seg], rhoi[seg], widths,
            np.zeros(seg.size, dtype=bool), np.arange(seg.size, dtype=np.int64), nodes, order)
    widths = widths[:, 0]
    sections = [Section(complex(a), complex(b), float(c), float(d))
                for a, b, c, d in zip(ei[:, 0], kga[:, 0], rhoa[:, 0], rhoi[:, 0])]
    intervals = [(sections[k], float(w)) for k, w in zip(seg, widths)]
    return _chain_receptance(intervals, [int(i) for i in nodes], omega, [float(x) for x in phases],
                             place=[int(i) for i in order])


def stepped_beam_receptances_si(
    sections: Sequence[tuple], lengths: np.ndarray, positions: Sequence[float], frequency_hz: np.ndarray,
    decay: float = 0.0,
) -> list[np.ndarray] | None:
    """:func:`stepped_beam_receptance_si` of several beams of the same segment lengths at the same positions.

    One call of the chain kernel over the beams (its configurations): the
    intervals that are the same in every beam (most of them, in a scan that
    changes one segment's section) are computed once per line.  Every
    beam's receptances are the numbers :func:`stepped_beam_receptance_si`
    gives it alone.

    Parameters
    ----------
    sections : sequence of (ei, kga, rhoa, rhoi)
        Each beam's section arrays, as :func:`stepped_beam_receptance_si`
        takes them.
    lengths : ndarray of float, shape (n_seg,)
        The segment lengths [m], the same for every beam.
    positions, frequency_hz, decay
        As :func:`stepped_beam_receptance_si`.

    Returns
    -------
    list of ndarray or None
        ``(2p, 2p, n_freq)`` per beam; None when a beam is long enough at the
        highest line that its chain must be cut, or a section is not a number
        (then call :func:`stepped_beam_receptance_si` for each, which cuts the
        chain or raises as for that beam alone).

    Raises
    ------
    InvalidValueError
        As :func:`stepped_beam_receptance_si` (but for a section that is not
        a number), and for no beams or beams of other numbers of segments.
    """
    from . import _kernels

    lengths = np.asarray(lengths, dtype=float)
    if len(sections) == 0:
        raise InvalidValueError("sections: got none; expected the section arrays of at least one beam")
    omega = angular_lines(frequency_hz, decay)
    try:
        ei, kga = (np.ascontiguousarray(np.stack([np.asarray(s[k], complex).reshape(-1) for s in sections], axis=1))
                   for k in (0, 1))
        rhoa, rhoi = (np.ascontiguousarray(np.stack([np.asarray(s[k], float).reshape(-1) for s in sections], axis=1))
                      for k in (2, 3))
    except ValueError as exc:  # beams of other numbers of segments
        raise InvalidValueError(f"sections: {exc}; expected (ei, kga, rhoa, rhoi) of {lengths.size} values each, "
                                "for every beam") from None
    _checked_si(ei, kga, rhoa, rhoi, lengths.size, frequency_hz, finite=False)
    order, widths, seg, nodes = _intervals(lengths, positions)
    _, k_max = _kernels.segment_coefficients(ei.T, kga.T, rhoa.T, rhoi.T,
                                             float(np.max(np.abs(omega))) if omega.size else 0.0)
    phases = k_max[:, seg] * widths[:, 0]
    # a chain to cut, or a section that is not a number (refused by the single call): each beam alone
    if not np.isfinite(phases).all() or phases.max() > _CHUNK_KL or np.cumsum(phases, axis=1)[:, -1].max() > _CHUNK_KL:
        return None
    ei, kga, rhoa, rhoi = (np.ascontiguousarray(v[seg]) for v in (ei, kga, rhoa, rhoi))
    shared = ((ei == ei[:, :1]).all(axis=1) & (kga == kga[:, :1]).all(axis=1)
              & (rhoa == rhoa[:, :1]).all(axis=1) & (rhoi == rhoi[:, :1]).all(axis=1))
    out = _kernels.chain_receptance(omega, ei, kga, rhoa, rhoi, np.repeat(widths, len(sections), axis=1), shared,
                                    np.arange(seg.size, dtype=np.int64), nodes, order)
    n = omega.size
    return [out[..., c * n:(c + 1) * n] for c in range(len(sections))]


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
    The same closed form as :func:`stepped_beam_receptance`, in one kernel
    call for all configurations: a segment that is the same in every
    configuration (e.g. the fluted length in an overhang sweep) is computed
    once per frequency line, the others per configuration and line.
    """
    n_seg = len(configurations[0])
    if any(len(c) != n_seg for c in configurations):
        raise InvalidValueError("configurations: every beam of a batch needs the same number of segments")
    if not ends or any(e not in ("base", "tip") for e in ends) or len(set(ends)) != len(ends):
        raise InvalidValueError(f"ends: got {ends!r}; expected 'base' and/or 'tip'")
    f = np.asarray(frequency_hz, dtype=float).reshape(-1)
    omega = 2.0 * np.pi * f
    omega_max = 2.0 * np.pi * float(f.max())
    intervals, phases = [], []
    for j in range(n_seg):
        column = [cfg[j] for cfg in configurations]
        first = column[0]
        if any(seg.is_tapered for seg in column):  # the same number of steps in every configuration
            from .tapers import tapered_column

            for sec, length in tapered_column(column, omega_max):
                intervals.append((sec, length))
                phases.append(_phase(sec, length, omega_max))
            continue
        if all(seg is first or seg == first for seg in column[1:]):
            sec, length = first.section(), first.length_m
        else:
            sec = _stack_sections([seg.section() for seg in column])
            length = np.array([seg.length_m for seg in column])
        intervals.append((sec, length))
        phases.append(_phase(sec, length, omega_max))
    nodes = sorted({"base": 0, "tip": len(intervals)}[e] for e in ends)
    place = [list(ends).index(e) for e in sorted(ends, key=lambda e: e != "base")]  # base first
    return _chain_receptance(intervals, nodes, omega, phases, n_config=len(configurations), place=place)
