"""Elements a model may lack, at fitted places: bodies, springs to the ground, changes of section; and where a
measured point was.

Each is a :class:`~substructure.updating.parameters.Change` on one beam
component with its position fitted along it:

* :class:`AddedMass` (``added-mass``): a rigid body, mass and rotary
  inertia, at a fitted position: a clamping nut, a balancing ring, a sensor
  nobody wrote down.  Written back as a permanent body (``[[masses]]``).
* :class:`GroundSpring` (``ground-spring``): a translational spring to the
  ground at a fitted position: a suspension band, a fixture, a bearing the
  model lacks.  Written back as a ``[[supports]]`` entry.
* :class:`SectionChange` (``section-change``): the outer diameter scaled
  over a fitted length at a fitted position: a neck, a groove, a collar.
  Written back as the component's segments split where it begins and ends.
* :class:`PointPosition` (``point-position``): where a measured point given at
  a distance really was, a few millimetres from its name's place, or where a
  free tip was tested (``tool.tip-2 mm``): a change of the test, not of the
  structure (nothing written back).
* :class:`HitPosition` (``hit-position``): where the hammer hit a measured
  point, apart from where the sensor sat (at another height beside it): the
  point's inputs move, its outputs stay; a change of the test too.

The helper :func:`split_beam` cuts a beam's arrays at positions and scales a
range of it, shared with the diagnosis catalogue's fluted section.
"""

from __future__ import annotations


import numpy as np

from ..errors import InvalidValueError, UnknownPointError
from ..joints import Mass, Support
from ..units import Q_, finite_real, format_quantity
from .parameters import Change, ParamSpec
from .structure import LinkSI

__all__ = ["AddedMass", "GroundSpring", "SectionChange", "PointPosition", "HitPosition", "split_beam", "split_segments",
           "unique_name", "body_bounds", "rear_bounds", "STEEL_DENSITY"]


def _si(value: float, unit: str) -> str:
    return format_quantity(Q_(float(value), unit))


def _mm(x: float) -> str:
    return f"{x * 1e3:.4g} mm"


STEEL_DENSITY = 7850.0
"""Density of the steel a clamped body is assumed made of [kg/m^3] (for the bound on its mass)."""


def body_bounds(assembly, component) -> tuple[float, float, float]:
    """Where on a beam component a body the model lacks may sit, and its largest plausible mass.

    A body nobody modelled is something clamped or glued on a part that can
    be reached: a nut, a ring, a sensor.  Its mass is at most that of a steel
    ring as long as the component's thickest section is wide, from that
    diameter to twice it (a nut is about as long as it is wide), and at most
    the component's own mass.  On a :class:`~substructure.components.Spindle`
    only the nose can be reached (the shaft behind it runs inside the
    housing): from the front-most support on it, or without supports, from
    the start of its last segment, to its tip.

    Parameters
    ----------
    assembly : Assembly
        The model (for the supports on the component).
    component : Beam
        A plain beam component of it.

    Returns
    -------
    (float, float, float)
        Lowest and highest position [m from the base] and the largest mass [kg].
    """
    from ..components import Spindle
    from .paths import _on_beam

    supports = [x for name, x, _ in (_on_beam(assembly, s.at) for s in assembly.supports) if name == component.name]
    length = float(component.length_m)
    od = max(float(s.od.m_as("m")) for s in component.segments)
    ring = STEEL_DENSITY * np.pi / 4.0 * ((2.0 * od) ** 2 - od ** 2) * od
    mass_max = max(min(ring, float(component.mass())), 1e-3)
    lo = 0.0
    if isinstance(component, Spindle):
        lo = max(supports) if len(supports) else length - float(component.segments[-1].length_m)
    return float(lo), length, float(mass_max)


def rear_bounds(assembly, component) -> tuple[float, float] | None:
    """Where on a spindle's rear end a body the model lacks may sit (a pulley, a rotary union, an encoder).

    The shaft between the bearings runs inside the housing; behind the rear-most
    bearing it is reached again: from the base to the rear-most support on it, or
    without supports, the first segment.  None for other components.

    Parameters
    ----------
    assembly : Assembly
        The model (for the supports on the component).
    component : Beam
        A plain beam component of it.

    Returns
    -------
    (float, float) or None
        Lowest and highest position [m from the base].
    """
    from ..components import Spindle
    from .paths import _on_beam

    if not isinstance(component, Spindle):
        return None
    supports = [x for name, x, _ in (_on_beam(assembly, s.at) for s in assembly.supports) if name == component.name]
    hi = min(supports) if supports else float(component.segments[0].length_m)
    return (0.0, float(hi)) if hi > 0 else None


def unique_name(taken, base: str) -> str:
    """``base``, or ``base-2``, ``base-3``, ... : the first not in ``taken``.

    Parameters
    ----------
    taken : iterable of str
        Names in use.
    base : str
        The wanted name.

    Returns
    -------
    str
        A free name.
    """
    taken = set(taken)
    name, n = base, 2
    while name in taken:
        name, n = f"{base}-{n}", n + 1
    return name


def _positive(name: str, value) -> float:
    if not (finite_real(value) and value > 0):
        raise InvalidValueError(f"{name}: got {value!r}; expected a finite number > 0 (SI)")
    return float(value)


class _OnComponent(Change):
    def __init__(self, component: str, length: float):
        if not isinstance(component, str) or not component:
            raise InvalidValueError(f"component: got {component!r}; expected a component's name")
        self.component = component
        self.where = component
        self.length = _positive("length", length)

    def place(self, values) -> str:
        return f"{self.component}@{_mm(values['position'])}"


class AddedMass(_OnComponent):
    """A rigid body at a fitted position along a beam component.

    Fitted as a mass link on the SI form; written back as a permanent
    :class:`~substructure.joints.Mass` named ``diagnosed-COMPONENT-mass``.

    Parameters
    ----------
    component : str
        The component's name.
    length : float
        Its length [m] (the position's bound).
    mass_max : float
        Upper bound of the mass [kg] (see ``body_bounds``).
    position : (float, float), optional
        Where it may sit [m from the base] (default the whole length).
    inertia_max : float, default 1e-3
        Upper bound of its rotary inertia [kg m^2] (a ring of
        ``mass_max`` at the radius of twice the component's widest section).
    where : str, optional
        Its name in reports when several ranges of one component are
        candidates (default the component's name), e.g. ``"spindle rear end"``.
    """

    effect = "added-mass"
    explanation = ("a body on the structure (a clamping nut, a balancing ring, a sensor) lowers the modes in "
                   "proportion to the square of their motion where it sits: the modes that move most there drop most")

    def __init__(self, component: str, length: float, mass_max: float, position: tuple[float, float] | None = None,
                 inertia_max: float = 1e-3, where: str | None = None):
        super().__init__(component, length)
        self.where = where or component
        if _positive("mass_max", mass_max) <= 1e-4:
            raise InvalidValueError(f"mass_max: got {mass_max!r}; expected more than the least mass fitted, 1e-4 kg")
        _positive("inertia_max", inertia_max)
        lo, hi = position if position is not None else (0.0, self.length)
        slack = 1e-12 * self.length
        if not -slack <= lo <= hi <= self.length + slack:
            raise InvalidValueError(f"position: got {position!r}; expected (lo, hi) with 0 <= lo <= hi <= length "
                                    f"({self.length!r} m)")
        self.specs = (
            ParamSpec("mass", "kg", 1e-4, float(mass_max), min(0.01, float(mass_max))),
            ParamSpec("inertia", "kg*m^2", 1e-10, max(float(inertia_max), 1e-9), 1e-8),
            ParamSpec("position", "m", float(lo), float(hi), 0.5 * (lo + hi), log=False),
        )

    def apply_si(self, structure, values):
        link = LinkSI(("added", f"mass-{self.component}-{len(structure.links)}"),
                      (self.component, float(values["position"])),
                      M=np.diag([values["mass"], values["inertia"]]))
        return structure.add_link(link)

    def apply(self, assembly, values):
        if self.component not in assembly.component_names:
            raise UnknownPointError(f"no component {self.component!r}")
        name = unique_name([m.name for m in assembly.masses], f"diagnosed-{self.component}-mass")
        return assembly.attach(Mass(name, f"{self.component}@{_si(values['position'], 'm')}",
                                    _si(values["mass"], "kg"), _si(values["inertia"], "kg*m^2")))


class GroundSpring(_OnComponent):
    """A translational spring to the ground at a fitted position along a beam component.

    Fitted as a link to the ground; written back as a
    :class:`~substructure.joints.Support` named ``diagnosed-COMPONENT-spring``.

    Parameters
    ----------
    component : str
        The component's name.
    length : float
        Its length [m].
    """

    effect = "ground-spring"
    explanation = ("a spring to the ground (a suspension band, a fixture, a bearing) holds the structure: "
                   "rigid-body motion becomes low modes, and modes with motion at the spring rise")

    def __init__(self, component: str, length: float):
        super().__init__(component, length)
        self.specs = (
            ParamSpec("k_yf", "N/m", 1.0, 1e10, 1e5),
            ParamSpec("position", "m", 0.0, self.length, 0.5 * self.length, log=False),
        )

    def apply_si(self, structure, values):
        link = LinkSI(("added", f"spring-{self.component}-{len(structure.links)}"),
                      (self.component, float(values["position"])), K=np.diag([values["k_yf"], 0.0]))
        return structure.add_link(link)

    def apply(self, assembly, values):
        if self.component not in assembly.component_names:
            raise UnknownPointError(f"no component {self.component!r}")
        name = unique_name([s.name for s in assembly.supports if s.name], f"diagnosed-{self.component}-spring")
        return assembly.support(Support(f"{self.component}@{_si(values['position'], 'm')}",
                                        k={"yf": _si(values["k_yf"], "N/m")}, name=name))


class PointPosition(Change):
    """Where a measured point really was: ``shift`` [m] along its component (towards the tip positive) from where
    its name puts it, within ``reach``.  A test-only change: the model is not changed.

    The shift is from where the name puts the point in the structure fitted, so that it holds beside a change of
    the component's length (``tool.tip-20 mm`` of a shorter tool is nearer its base).

    Parameters
    ----------
    point : str
        The point's name as the measurements give it, e.g. ``"tool.tip-20 mm"``.
    component : str
        Its component, a beam.
    x : float
        Where its name puts it on the model as given [m from the component's base].
    length : float
        The component's length on the model as given [m].
    reach : float
        How far from there it may be [m] (within the component).
    """

    effect = "point-position"
    explanation = ("a sensor or a hit a few millimetres from where the record puts it changes that FRF alone: its "
                   "modes stay where they are, its levels and antiresonances move")
    test_only = True

    def __init__(self, point: str, component: str, x: float, length: float, reach: float):
        self.where, self.component = point, component
        self.from_tip = ".tip-" in point  # the name's distance: from the tip, else from the base
        self.tip = point == f"{component}.tip"  # the free tip itself: where the test was, said from the tip
        self.distance = float(length - x if self.from_tip else x)
        self.specs = (ParamSpec("shift", "m", max(0.0, x - reach) - x, min(length, x + reach) - x, 0.0, log=False),)

    def place(self, values) -> str:
        """Where the point was, written as its name is (``tool.tip-22 mm`` for ``tool.tip-20 mm``; ``tool.tip-2 mm``
        for a free tip)."""
        shift = float(values["shift"])
        if self.tip:
            return f"{self.component}.tip-{_mm(-shift)}"
        if self.from_tip:
            return f"{self.component}.tip-{_mm(self.distance - shift)}"
        return f"{self.component}@{_mm(self.distance + shift)}"

    def apply_si(self, structure, values):
        _, x = structure.position(self.where)
        return structure.with_point(self.where, x + float(values["shift"]))

    def apply(self, assembly, values):
        return assembly  # the model is as it was: the test was taken elsewhere


class HitPosition(PointPosition):
    """Where the hammer hit a measured point, apart from where the sensor sat: ``shift`` [m] along its component
    (towards the tip positive) from where its name puts it, within ``reach``.  A test-only change.

    The point's inputs move (every FRF of that hit: its cross FRFs too); its outputs, and a sensor on it, stay
    where the name or a kept ``point-position`` puts them.  The hammer and the sensor on either side of a tool a
    few millimetres apart in height: the driving point alone cannot tell which of the two moved (reciprocity),
    a cross FRF of the same hit can.  Parameters as :class:`PointPosition`.
    """

    effect = "hit-position"
    explanation = ("a hit a few millimetres above or below the sensor changes every FRF of that hit, the cross FRFs "
                   "as much as the driving point's: its modes stay where they are, its levels and antiresonances move")

    def apply_si(self, structure, values):
        _, x = structure.named_position(self.where)
        return structure.with_hit(self.where, x + float(values["shift"]))


def split_beam(beam, start: float, stop: float, od_factor: float = 1.0, flutes: float | None = None):
    """A beam's arrays cut at ``start`` and ``stop`` [m], the part between changed.

    Parameters
    ----------
    beam : BeamArrays
        The beam.
    start, stop : float
        The range [m from the base], ``0 <= start < stop <= length``.
    od_factor : float
        The outer diameter in the range is multiplied by this.
    flutes : float, optional
        The flutes' diameter ratio in the range (replacing any).

    Returns
    -------
    BeamArrays
        The changed beam.
    """
    if beam.has_taper:
        raise UnknownPointError(f"{beam.name!r} has a tapered segment: a range of it is not cut in the arrays")
    ends = np.concatenate([[0.0], np.cumsum(beam.length)])
    total = ends[-1]
    start, stop = max(0.0, float(start)), min(total, float(stop))
    cuts = np.unique(np.concatenate([ends, [start, stop]]))
    cuts = cuts[np.concatenate([[True], np.diff(cuts) > 1e-12 * total])]
    mid = 0.5 * (cuts[:-1] + cuts[1:])
    idx = np.clip(np.searchsorted(ends, mid) - 1, 0, beam.length.size - 1)
    inside = (start - 1e-12 <= mid) & (mid <= stop + 1e-12)
    od = beam.od[idx] * np.where(inside, od_factor, 1.0)
    ratio = beam.ratio[idx].copy()
    if flutes is not None:
        ratio[inside] = flutes
    bore = beam.id[idx]
    od = np.maximum(od, bore * 1.0001 / ratio)
    return beam.evolve(length=np.diff(cuts), od=od, id=bore, ratio=ratio, material=beam.material[idx],
                       material_names=[beam.material_names[i] for i in idx], insert=beam.insert[idx],
                       insert_names=[beam.insert_names[i] for i in idx], od_tip=beam.od_tip[idx],
                       id_tip=beam.id_tip[idx], steps=beam.steps[idx])


_SLIVER = 1e-6  # m: the shortest segment a model holds (sections.py refuses shorter lengths)


def split_segments(component, start: float, stop: float, change):
    """A beam component with its segments cut at ``start`` and ``stop`` [m], ``change(segment)`` between.

    Parameters
    ----------
    component : Beam
        The component.
    start, stop : float
        The range [m from the base].
    change : callable
        Returns the changed segment for a piece inside the range.

    Returns
    -------
    Beam
        A new component (segments as value objects, for files).
    """
    import attrs

    segments, x = [], 0.0
    for seg in component.segments:
        x0, x1 = x, x + seg.length_m
        x = x1
        cuts = []
        for c in (start, stop):  # a cut within a micrometre of a segment's end is at that end (no slivers)
            c = max(x0, min(x1, c))
            cuts.append(x0 if c - x0 < _SLIVER else x1 if x1 - c < _SLIVER else c)
        pieces = [x0, *cuts, x1]
        for a, b in zip(pieces[:-1], pieces[1:]):
            if b - a <= 1e-12 * max(x1, 1e-3):
                continue
            piece = seg if (a, b) == (x0, x1) else attrs.evolve(seg, length=_si(b - a, "m"))
            segments.append(change(piece) if start - 1e-12 <= 0.5 * (a + b) <= stop + 1e-12 else piece)
    return attrs.evolve(component, segments=segments)


class SectionChange(_OnComponent):
    """The outer diameter scaled over a fitted range of a beam component (a neck, a collar).

    Written back with the component's segments split at the range's ends.

    Parameters
    ----------
    component : str
        The component's name.
    length : float
        Its length [m].
    """

    effect = "section-change"
    explanation = ("a part of the component is thinner (a neck, a groove) or thicker (a collar) than the model: "
                   "the bending stiffness there changes with the fourth power of the diameter, the mass with "
                   "its square, so the modes that bend that part move most")

    def __init__(self, component: str, length: float):
        super().__init__(component, length)
        self.specs = (
            ParamSpec("diameter_ratio", "dimensionless", 0.4, 1.5, 1.0, log=False),
            ParamSpec("start", "m", 0.0, self.length, 0.25 * self.length, log=False),
            ParamSpec("length", "m", 0.02 * self.length, self.length, 0.25 * self.length),
        )

    def place(self, values) -> str:
        stop = min(self.length, values["start"] + values["length"])
        return f"{self.component}@{_mm(values['start'])}-{_mm(stop)}"

    def apply_si(self, structure, values):
        beam = structure.beam(self.component)
        start = float(values["start"])
        return structure.with_beam(split_beam(beam, start, start + float(values["length"]),
                                              od_factor=float(values["diameter_ratio"])))

    def apply(self, assembly, values):
        import attrs

        comp = assembly.component(self.component)
        start = float(values["start"])
        ratio = float(values["diameter_ratio"])

        def thinner(seg):
            od = seg.od.m_as("m") * ratio
            if seg.flutes is not None:
                od = max(od, 1.0001 * seg.id.m_as("m") / seg.flutes.diameter_ratio)
            return attrs.evolve(seg, od=_si(max(od, 1.0001 * seg.id.m_as("m")), "m"))

        return assembly.with_component(split_segments(comp, start, start + float(values["length"]), thinner))
