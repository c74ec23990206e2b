"""A plain stepped beam as SI arrays over its segments: :class:`BeamArrays`, the beams of the fits' SI form.

Its segments' geometry (tapers too: their tip diameters and step counts) and material constants, from which
the section properties ``EI``, ``kappa G A``, ``rho A``, ``rho I`` follow; changed by returning a new
beam that shares every array it did not change.  :class:`~substructure.updating.structure.Structure` holds
one per plain beam component.
"""

from __future__ import annotations

import itertools
import math
from typing import Sequence

import attrs
import numpy as np

from .._blocks import angular_lines
from ..beams import Flutes, Insert, Segment, shear_coefficient, stepped_beam_receptance_si
from ..components import Beam
from ..materials import Material
from ..tapers import TaperSI, mass_si, pieces
from ..units import Q_

__all__ = ["BeamArrays"]

_TOKENS = itertools.count(1)


def _ring(od, id_, E, nu, rho, eta):
    """Section properties of rings (arrays over segments), as ``beams.Section.ring``."""
    area = math.pi / 4.0 * (od**2 - id_**2)
    inertia = math.pi / 64.0 * (od**4 - id_**4)
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = np.where(od > 0, id_ / np.where(od > 0, od, 1.0), 0.0)
    kappa = shear_coefficient(np.atleast_1d(np.asarray(nu, dtype=float)), np.atleast_1d(np.asarray(ratio, dtype=float)))
    damp = 1.0 + 1j * eta
    return E * damp * inertia, kappa * (E / (2.0 * (1.0 + nu))) * damp * area, rho * area, rho * inertia


def _segment_sections(od, ratio, id_, material, insert) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """``(EI, kGA, rhoA, rhoI)`` of segments given as :class:`BeamArrays` holds them (rows of its arrays)."""
    E, nu, rho, eta = material.T
    parts = _ring(od * ratio, id_, E, nu, rho, eta)
    has = insert[:, 0] > 0
    if has.any():
        io, ii, iE, inu, irho, ieta = insert.T
        safe_od = np.where(has, io, 1.0)
        extra = _ring(safe_od, np.where(has, ii, 0.0), iE, np.where(has, inu, 0.3), irho, ieta)
        parts = tuple(p + np.where(has, e, 0.0) for p, e in zip(parts, extra))
    return (np.asarray(parts[0], complex), np.asarray(parts[1], complex), np.asarray(parts[2], float),
            np.asarray(parts[3], float))


class BeamArrays:
    """A plain stepped beam as SI arrays over its segments (base to tip).

    Attributes
    ----------
    name : str
        The component's name.
    length, od, id, ratio : ndarray, shape (n_seg,)
        Lengths, outer and inner diameters [m], and the flutes' diameter
        ratio (1 where a segment has no flutes).
    material : ndarray, shape (n_seg, 4)
        ``E`` [Pa], ``nu``, ``rho`` [kg/m^3], loss factor of each segment.
    material_names : tuple of str
        The segments' material names.
    insert : ndarray, shape (n_seg, 6)
        ``od``, ``id`` [m], ``E``, ``nu``, ``rho``, loss factor of each
        segment's insert (``od = 0``: none).
    insert_names : tuple of str or None
        The inserts' material names.
    od_tip, id_tip : ndarray, shape (n_seg,)
        Outer and inner diameters at the segments' tip ends [m]; NaN where
        none is given (the segment's ``od``, ``id``: uniform).  A segment
        whose ends differ is tapered (:mod:`substructure.tapers`).
    steps : ndarray of int, shape (n_seg,)
        A tapered segment's ``taper_steps``; 0 for the error bound's count.
    token : int
        Identifies the arrays: a changed beam gets a new token, so that the
        evaluator recomputes only what changed.
    """

    __slots__ = ("name", "length", "od", "id", "ratio", "material", "material_names", "insert", "insert_names",
                 "od_tip", "id_tip", "steps", "token", "_sections", "_total", "_component", "_parent", "_tapered",
                 "_no_tips")

    def __init__(self, name, length, od, id, ratio, material, material_names, insert, insert_names, od_tip=None,
                 id_tip=None, steps=None):
        self.name = name
        self.length = np.asarray(length, dtype=float)
        self.od = np.asarray(od, dtype=float)
        self.id = np.asarray(id, dtype=float)
        self.ratio = np.asarray(ratio, dtype=float)
        self.material = np.asarray(material, dtype=float)
        self.material_names = tuple(material_names)
        self.insert = np.asarray(insert, dtype=float)
        self.insert_names = tuple(insert_names)
        none = np.full(self.length.shape, np.nan)
        self.od_tip = none if od_tip is None else np.asarray(od_tip, dtype=float)
        self.id_tip = none if id_tip is None else np.asarray(id_tip, dtype=float)
        self.steps = np.zeros(self.length.shape, dtype=int) if steps is None else np.asarray(steps, dtype=int)
        self._tapered: np.ndarray | None = None
        self._no_tips: bool | None = None  # no tip diameter given: every segment uniform, whatever its sizes
        self.token = next(_TOKENS)
        self._sections = None
        self._total = None
        self._component: tuple | None = None  # (template, the component): as_component's last answer
        self._parent: BeamArrays | None = None  # the beam this one was evolved from, its sections computed

    @classmethod
    def from_beam(cls, beam: Beam) -> "BeamArrays":
        """The arrays of a :class:`~substructure.components.Beam` whose segments are plain ``Segment``.

        Parameters
        ----------
        beam : Beam
            The component.

        Returns
        -------
        BeamArrays
            Its segments as SI arrays.
        """
        segs = beam.segments
        mat = [(s.material.E.m_as("Pa"), s.material.nu, s.material.rho_si, s.material.loss_factor) for s in segs]
        ins, ins_names = [], []
        for s in segs:
            if s.insert is None:
                ins.append((0.0, 0.0, 0.0, 0.0, 0.0, 0.0))
                ins_names.append(None)
            else:
                m = s.insert.material
                ins.append((s.insert.od.m_as("m"), s.insert.id.m_as("m"), m.E.m_as("Pa"), m.nu, m.rho_si,
                            m.loss_factor))
                ins_names.append(m.name)
        return cls(beam.name, [s.length_m for s in segs], [s.od.m_as("m") for s in segs],
                   [s.id.m_as("m") for s in segs],
                   [1.0 if s.flutes is None else s.flutes.diameter_ratio for s in segs],
                   mat, [s.material.name for s in segs], ins, ins_names,
                   [np.nan if s.od_tip is None else s.od_tip.m_as("m") for s in segs],
                   [np.nan if s.id_tip is None else s.id_tip.m_as("m") for s in segs],
                   [s.taper_steps or 0 for s in segs])

    def as_component(self, template: Beam) -> Beam:
        """The component whose segments these arrays hold, with every change they carry (sizes, materials,
        inserts, flutes, segments split by an added element); its type and other numbers are ``template``'s.

        Parameters
        ----------
        template : Beam
            The component the arrays were made from (the assembly's).

        Returns
        -------
        Beam
            A copy of ``template`` with the arrays' segments.
        """
        if self._component is not None and self._component[0] is template:  # the arrays are never changed
            return self._component[1]

        def material(name, values):
            E, nu, rho, eta = (float(v) for v in values)
            return Material(name, Q_(E, "Pa"), nu, Q_(rho, "kg/m^3"), eta)

        segs = []
        for i in range(self.length.size):
            od_in, id_in = (float(v) for v in self.insert[i, :2])
            insert = None if not od_in > 0 else Insert(Q_(od_in, "m"), material(self.insert_names[i],
                                                                                 self.insert[i, 2:]), Q_(id_in, "m"))
            ratio = float(self.ratio[i])
            tips = {k: Q_(float(v[i]), "m") for k, v in (("od_tip", self.od_tip), ("id_tip", self.id_tip))
                    if not np.isnan(v[i])}
            segs.append(Segment(Q_(float(self.length[i]), "m"), Q_(float(self.od[i]), "m"),
                                Q_(float(self.id[i]), "m"), material(self.material_names[i], self.material[i]), insert,
                                None if ratio == 1.0 else Flutes(ratio), taper_steps=int(self.steps[i]) or None,
                                **tips))
        self._component = (template, attrs.evolve(template, segments=segs))
        return self._component[1]

    def evolve(self, **changes) -> "BeamArrays":
        """A copy with some arrays replaced (a new token).

        Parameters
        ----------
        **changes
            Fields to replace (``length``, ``od``, ``material``, ...).

        Returns
        -------
        BeamArrays
            The changed beam.
        """
        fields = {k: getattr(self, k) for k in ("name", "length", "od", "id", "ratio", "material", "material_names",
                                               "insert", "insert_names", "od_tip", "id_tip", "steps")}
        fields.update(changes)
        beam = BeamArrays(**fields)
        if "od_tip" not in changes and "id_tip" not in changes:
            beam._no_tips = self._no_tips
        if self._sections is not None:  # the sections of the segments that did not change are taken from here
            beam._parent = self
        return beam

    @property
    def total_length(self) -> float:
        """Length of the beam [m]."""
        if self._total is None:  # the arrays are not changed in place (a change makes a new BeamArrays)
            self._total = float(self.length.sum())
        return self._total

    @property
    def tips(self) -> tuple[np.ndarray, np.ndarray]:
        """The outer and inner diameters at the segments' tip ends [m] (their ``od``, ``id`` where none is given)."""
        return (np.where(np.isnan(self.od_tip), self.od, self.od_tip),
                np.where(np.isnan(self.id_tip), self.id, self.id_tip))

    @property
    def no_tips(self) -> bool:
        """True when no segment has a tip diameter given: none is tapered (the usual beam; quick to tell)."""
        if self._no_tips is None:
            self._no_tips = bool(np.isnan(self.od_tip).all() and np.isnan(self.id_tip).all())
        return self._no_tips

    @property
    def has_taper(self) -> bool:
        """True when a segment is tapered."""
        return not self.no_tips and bool(self.tapered.any())

    @property
    def tapered(self) -> np.ndarray:
        """Which segments are tapered: their ends' diameters differ (as :func:`substructure.tapers.check_taper`
        tells)."""
        if self._tapered is None and self.no_tips:
            self._tapered = np.zeros(self.length.shape, dtype=bool)
        if self._tapered is None:
            od1, id1 = self.tips
            self._tapered = ~(np.isclose(od1, self.od, rtol=1e-12, atol=0.0)
                              & np.isclose(id1, self.id, rtol=1e-12, atol=1e-18))
        return self._tapered

    def _taper(self, k: int) -> TaperSI:
        """Segment ``k``'s numbers, for :mod:`substructure.tapers`."""
        od1, id1 = self.tips
        E, nu, rho, eta = (float(v) for v in self.material[k])
        insert = None
        if self.insert[k, 0] > 0:
            io, ii, iE, inu, irho, ieta = (np.array([v]) for v in self.insert[k])
            insert = tuple(complex(v[0]) if j < 2 else float(v[0])
                           for j, v in enumerate(_ring(io, ii, iE, inu, irho, ieta)))
        damp = 1.0 + 1j * eta
        return TaperSI(float(self.length[k]), (float(self.od[k]), float(od1[k]), float(self.id[k]), float(id1[k])),
                       float(self.ratio[k]), E * damp, E / (2.0 * (1.0 + nu)) * damp, nu, rho, insert,
                       int(self.steps[k]) or None)

    def sections(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """``(EI, kGA, rhoA, rhoI)`` per segment, layers (inserts) summed (of a tapered segment: at its base).

        Returns
        -------
        tuple of ndarray
            Complex ``EI`` [N m^2] and ``kappa G A`` [N], ``rho A`` [kg/m], ``rho I`` [kg m].
        """
        if self._sections is None:
            parent, self._parent = self._parent, None
            if parent is None or parent.length.size != self.length.size:
                self._sections = _segment_sections(self.od, self.ratio, self.id, self.material, self.insert)
            else:  # the segments that changed computed, the others as the parent's (the same numbers)
                rows = ((self.od != parent.od) | (self.id != parent.id) | (self.ratio != parent.ratio)
                        | (self.material != parent.material).any(axis=1) | (self.insert != parent.insert).any(axis=1))
                if not rows.any():
                    self._sections = parent.sections()
                else:
                    new = _segment_sections(self.od[rows], self.ratio[rows], self.id[rows], self.material[rows],
                                    self.insert[rows])
                    self._sections = tuple(np.array(p) for p in parent.sections())
                    for whole, part in zip(self._sections, new):
                        whole[rows] = part
            for a in self._sections:
                a.flags.writeable = False  # shared with the beams evolved from this one
        return self._sections

    def mass(self) -> float:
        """Mass of the beam.

        Returns
        -------
        float
            [kg].
        """
        rhoa = self.sections()[2] * self.length
        for k in np.flatnonzero(self.tapered) if self.has_taper else ():
            rhoa[k] = mass_si(self._taper(k))
        return float(np.sum(rhoa))

    def receptance(self, positions: Sequence[float], frequency_hz: np.ndarray, decay: float = 0.0) -> np.ndarray:
        """Free-free receptances between positions.

        Parameters
        ----------
        positions : sequence of float
            Distinct positions [m from the base].
        frequency_hz : ndarray
            Frequency lines [Hz], > 0.
        decay : float, optional
            ``1/tau`` [1/s]: at the complex frequency ``omega - i decay``.

        Returns
        -------
        ndarray, shape (2p, 2p, n)
            Frequency-last receptances, DOFs ``(y, theta)`` per position.
        """
        ei, kga, rhoa, rhoi = self.sections()
        if not self.has_taper:
            return stepped_beam_receptance_si(ei, kga, rhoa, rhoi, self.length, positions, frequency_hz, decay)
        # the tapered segments as their uniform pieces (cut at the positions within them), as the objects do
        omega = angular_lines(np.asarray(frequency_hz, dtype=float), decay)
        ends = np.concatenate([[0.0], np.cumsum(self.length)])
        columns: list[list] = [[], [], [], []]
        bounds = [0.0]
        parts = pieces([self._taper(k) if t else None for k, t in enumerate(self.tapered)], ends,
                       float(np.abs(omega).max()) if omega.size else 0.0, positions)
        for k, (arrays, cuts) in enumerate(parts):
            for column, whole, part in zip(columns, (ei, kga, rhoa, rhoi), arrays or (None,) * 4):
                column.append(whole[k:k + 1] if part is None else part)
            bounds.extend(cuts)
        return stepped_beam_receptance_si(*(np.concatenate(c) for c in columns), np.diff(bounds), positions,
                                          frequency_hz, decay)
