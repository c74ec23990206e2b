"""The built-in effects of the diagnosis: the physical effects the catalogue names.

A sensor's mass on a measured point, a joint's stiffness, damping and
cross-coupling, a rigid joint made elastic, a fluted section of a tool,
springs of a free-free test's suspension and a tool that tapers.  Each is an
:class:`~substructure.diagnose.effects.Effect` registered by name when the
package is imported, in this order (the built-in answer does not depend on
the order, but ties between candidates are broken by it); each also gives
its change on the SI form of the model (``apply_si``), so that fits do not
rebuild objects.  The methods follow the protocol documented on
:class:`~substructure.diagnose.effects.Effect` (``places``, ``bounds``,
``starting_values``, ``apply``, ``apply_si``); only what differs from it is
written here.
"""

from __future__ import annotations

from typing import ClassVar

import attrs
import numpy as np

from ..beams import Flutes
from ..components import Beam, Tool
from ..errors import InvalidValueError, UnknownPointError
from ..joints import Joint, Sensor, Support
from ..points import parse_point
from ..units import Q_, format_quantity, ureg
from ..updating.elements import split_beam, split_segments
from ..updating.paths import apply_path_si, set_parameters
from ..updating.structure import LinkSI
from .effects import Effect, Parameter, register_effect

__all__: list[str] = []  # the effects are reached by name through the registry

PASSIVE_SHARE = 0.999
"""A joint's cross terms are searched up to this share of their passivity bound (``k_ym^2 < k_yf k_tm``), so that
every value of the search is a passive joint.  A bound of the effect's parameters, as the ranges of the catalogue
are, not a setting of the diagnosis."""


def _si(value: float, unit: str) -> str:
    return format_quantity(ureg.Quantity(float(value), unit))


SENSOR_MASS_MAX = 0.05
"""The heaviest body ``sensor-mass`` fits [kg]: a tap test's accelerometer with its mounting (tens of grams at
most); a heavier body on a measured point is a body of the structure (a nut, a ring), ``added-mass``."""


@register_effect
class SensorMass(Effect):
    """A body on a measured point (an accelerometer, a magnet) that the model lacks: ``mass``, ``inertia``.

    Written back as a sensor ``diagnosed-<point>`` that is on in every test (``always_on``), since the
    records the diagnosis was fitted on do not list it.
    """

    name = "sensor-mass"
    test_only: ClassVar[bool] = True  # a sensor is on the tested points only (see Change.test_only)
    parameters = (
        Parameter("mass", "kg", 1e-4, SENSOR_MASS_MAX, 2e-3),
        Parameter("inertia", "kg*m^2", 1e-10, 1e-4, 1e-8),
    )
    explanation = (
        "a body on the structure (an accelerometer, a magnet) lowers every mode in proportion to "
        "the square of its modal displacement at that point: the mode with most motion there "
        "(the tool mode, for a tool-tip sensor) drops most, the others barely move"
    )

    @classmethod
    def places(cls, assembly, measured_points):
        return list(dict.fromkeys(str(parse_point(p).point) for p in measured_points))

    @classmethod
    def starting_values(cls, assembly, where, shift):
        """From the main mode's relative shift: a tip mode drops as ``sqrt(1 + dm / m_eff)``
        with a quarter of the component's mass moving (model above measurement: a tip mass)."""
        out = {p.name: p.start for p in cls.parameters}
        try:
            body = assembly.component(parse_point(where).component)
            m_eff = 0.25 * body.mass()  # a cantilever's tip mode: about a quarter of its mass moves
        except (AttributeError, UnknownPointError):
            return out
        if shift > 0:  # f_model / f_measured - 1 = sqrt(1 + dm / m_eff) - 1
            out["mass"] = float(np.clip(m_eff * ((1 + shift) ** 2 - 1), 1e-4, SENSOR_MASS_MAX))
        return out

    def apply(self, assembly):
        base = f"diagnosed-{self.where.replace('.', '-').replace('@', '-at-').replace(' ', '')}"
        taken = {s.name for s in assembly.sensors}
        name, n = base, 2
        while name in taken:  # a model improved before may carry one already
            name, n = f"{base}-{n}", n + 1
        sensor = Sensor(name, self.where, _si(self.values["mass"], "kg"), _si(self.values["inertia"], "kg*m^2"),
                        always_on=True)
        return assembly.attach(sensor)

    def apply_si(self, structure):
        return structure.add_link(LinkSI(("added", f"sensor-mass-{self.where}"), self.where,
                                         M=np.diag([self.values["mass"], self.values["inertia"]])))


class _JointEffect(Effect):
    kind: ClassVar[str] = "k"
    entries: ClassVar[tuple[str, ...]] = ()

    @classmethod
    def places(cls, assembly, measured_points):
        return [j.name for j in assembly.joints if not getattr(j, "rigid", False) and isinstance(j, Joint)]

    @classmethod
    def starting_values(cls, assembly, where, shift):
        joint = assembly.joint(where)
        out = {}
        for p in cls.parameters:
            entry = p.name.split("_", 1)[1]
            nominal = (joint.k if p.name[0] == "k" else joint.c).get(entry)
            out[p.name] = float(np.clip(nominal if nominal > 0 else p.start, p.lower, p.upper))
        return out

    def _paths(self) -> dict:
        """The values as parameter paths of the joint (``k_ym`` sets ``k.ym`` and ``k.tf``: one number)."""
        return {f"joints.{self.where}.{name[0]}.{name.split('_', 1)[1]}": value for name, value in self.values.items()}

    def apply(self, assembly):
        return set_parameters(assembly, self._paths())

    def apply_si(self, structure):
        _, link = structure.link(("joints", self.where))
        if link.rigid or link.custom is not None:
            raise UnknownPointError(f"joint {self.where!r} has no stiffness matrix here")
        for path, value in self._paths().items():
            structure = apply_path_si(structure, path, float(value))
        return structure


@register_effect
class JointStiffness(_JointEffect):
    """A joint's stiffness ``k_yf``, ``k_tm`` off."""

    name = "joint-stiffness"
    parameters = (
        Parameter("k_yf", "N/m", 1e4, 1e11, 1e7),
        Parameter("k_tm", "N*m/rad", 1e2, 1e9, 1e5),
    )
    explanation = (
        "a joint's stiffness sets the frequency of the mode it dominates: a softer joint lowers "
        "that mode (and raises its peak), leaving modes far from the joint alone"
    )


@register_effect
class JointDamping(_JointEffect):
    """A joint's damping ``c_yf``, ``c_tm`` off."""

    name = "joint-damping"
    parameters = (
        Parameter("c_yf", "N*s/m", 1e-2, 1e5, 50.0),
        Parameter("c_tm", "N*m*s/rad", 1e-4, 1e3, 1.0),
    )
    explanation = (
        "a joint's damping sets the height and width of the peak of the mode it dominates, "
        "not its frequency"
    )


@register_effect
class JointCrossCoupling(_JointEffect):
    """A joint's cross terms ``k_ym = k_tf`` and ``c_ym = c_tf`` missing (within passivity)."""

    name = "joint-cross-coupling"
    parameters = (
        Parameter("k_ym", "N", -1e9, 1e9, 0.0, log=False),
        Parameter("c_ym", "N*s", -1e4, 1e4, 0.0, log=False),
    )
    explanation = (
        "off-diagonal joint terms (k_ym = k_tf) couple the joint's translation and rotation: they "
        "shift the joint's modes like a change of its stiffness, but differently at the tip and at "
        "points further back"
    )

    @classmethod
    def starting_values(cls, assembly, where, shift):
        joint = assembly.joint(where)
        scale = np.sqrt(max(joint.k.get("yf") * joint.k.get("tm"), 1.0))
        return {"k_ym": 0.3 * scale * (-1 if shift < 0 else 1), "c_ym": 0.0}

    @classmethod
    def bounds(cls, assembly, where):
        """Passive cross terms: ``k_ym^2 < k_yf k_tm`` and ``c_ym^2 < c_yf c_tm``."""
        joint = assembly.joint(where)
        k = PASSIVE_SHARE * np.sqrt(max(joint.k.get("yf") * joint.k.get("tm"), 0.0))
        c = PASSIVE_SHARE * np.sqrt(max(joint.c.get("yf") * joint.c.get("tm"), 0.0))
        return {"k_ym": (-k, k), "c_ym": (-c, c) if c > 0 else (-1e-12, 1e-12)}


@register_effect
class RigidJointFlexibility(_JointEffect):
    """A joint modelled as rigid is elastic: ``k_yf``, ``k_tm``."""

    name = "rigid-joint-flexibility"
    parameters = (
        Parameter("k_yf", "N/m", 1e4, 1e12, 1e8),
        Parameter("k_tm", "N*m/rad", 1e2, 1e10, 1e6),
    )
    explanation = (
        "a connection modelled as rigid is elastic: the modes it takes part in are lower than the "
        "model says"
    )

    @classmethod
    def places(cls, assembly, measured_points):
        return [j.name for j in assembly.joints if getattr(j, "rigid", False)]

    @classmethod
    def starting_values(cls, assembly, where, shift):
        return {p.name: p.start for p in cls.parameters}

    def apply(self, assembly):
        joint = assembly.joint(self.where)
        elastic = Joint(joint.name, joint.between, k={"yf": _si(self.values["k_yf"], "N/m"),
                                                      "tm": _si(self.values["k_tm"], "N*m/rad")})
        return assembly.with_joint(elastic)

    def apply_si(self, structure):
        i, link = structure.link(("joints", self.where))
        return structure.with_link(i, link.evolve(rigid=False, custom=None,
                                                  K=np.diag([self.values["k_yf"], self.values["k_tm"]]),
                                                  C=np.zeros((2, 2))))


@register_effect
class FlutedSection(Effect):
    """A tool's flutes: its last ``length`` fluted at ``diameter_ratio`` (equivalent diameter), none before.

    On a tool the model gives flutes, the effect says where they really
    begin and how deep they are (it starts from the model's); on a tool
    without, that it has them.
    """

    name = "fluted-section"
    parameters = (
        Parameter("diameter_ratio", "dimensionless", 0.5, 1.0, 0.8, log=False),
        Parameter("length", "m", 1e-3, 0.2, 0.03),
    )
    explanation = (
        "flutes take stiffness and mass from the tool's last part: the tool modes drop (bending "
        "stiffness falls faster than mass), the spindle and holder modes hardly move"
    )

    @classmethod
    def places(cls, assembly, measured_points):
        return [t.name for t in assembly.components if isinstance(t, Tool)]

    @classmethod
    def starting_values(cls, assembly, where, shift):
        tool = assembly.component(where)
        length, ratio = fluted_tip(tool)
        if length:
            return {"diameter_ratio": ratio, "length": length}
        return {"diameter_ratio": 0.8, "length": min(0.03, 0.5 * tool.length_m)}

    @classmethod
    def scan_starts(cls, assembly, where):
        # length and depth act together (deeper and shorter flutes lower the tool modes alike): crossed
        length = cls.starting_values(assembly, where, 0.0)["length"]
        return [{"diameter_ratio": ratio, "length": factor * length}
                for ratio in (0.7, 0.8, 0.9) for factor in (0.5, 0.75, 1.25, 1.5, 2.0)]

    @classmethod
    def bounds(cls, assembly, where):
        tool = assembly.component(where)
        return {"diameter_ratio": (0.5, 1.0), "length": (1e-3, tool.length_m)}

    def apply(self, assembly):
        tool = assembly.component(self.where)
        if any(seg.flutes for seg in tool.segments):
            tool = attrs.evolve(tool, segments=tuple(attrs.evolve(seg, flutes=None) for seg in tool.segments))
        return assembly.with_component(flute_tip(tool, self.values["length"], self.values["diameter_ratio"]))

    def apply_si(self, structure):
        beam = structure.beam(self.where)
        if np.any(beam.ratio != 1.0):
            beam = beam.evolve(ratio=np.ones_like(beam.ratio))
        total = beam.total_length
        return structure.with_beam(split_beam(beam, total - min(self.values["length"], total), total,
                                              flutes=self.values["diameter_ratio"]))


def fluted_tip(tool: Beam) -> tuple[float, float]:
    """The length [m] of a tool's fluted tip (the fluted segments next to its tip) and their ratio.

    Parameters
    ----------
    tool : Beam
        The tool.

    Returns
    -------
    (float, float)
        ``(0.0, 1.0)`` for a tool whose last segment has no flutes; else the
        fluted tip's length and its last segment's ``diameter_ratio``.
    """
    last = tool.segments[-1]
    if last.flutes is None:
        return 0.0, 1.0
    length = 0.0
    for seg in reversed(tool.segments):
        if seg.flutes is None:
            break
        length += seg.length_m
    return length, last.flutes.diameter_ratio


def flute_tip(tool: Beam, length_m: float, ratio: float) -> Beam:
    """The tool with its last ``length_m`` fluted at ``ratio`` (segments split as needed).

    Parameters
    ----------
    tool : Beam
        The tool.
    length_m : float
        Fluted length [m] (at most the tool's).
    ratio : float
        The flutes' diameter ratio.

    Returns
    -------
    Beam
        A new tool.
    """
    total = tool.length_m
    length_m = min(length_m, total)

    def fluted(seg):
        bore = seg.id.m_as("m")
        if bore >= ratio * seg.od.m_as("m"):  # flutes do not cut into a bore: the SI form's rule (split_beam)
            seg = attrs.evolve(seg, od=_si(1.0001 * bore / ratio, "m"))
        return attrs.evolve(seg, flutes=Flutes(ratio))

    # a cut within a micrometre of a segment's end is at that end: no sliver the beam model refuses
    return split_segments(tool, total - length_m, total, fluted)


@register_effect
class SupportSprings(Effect):
    """Springs to the ground near both ends of the heaviest component: ``k_yf`` per spring, ``inset`` from the
    first end and ``inset_tip`` from the second (as fractions of its length; ``inset_tip`` defaults to
    ``inset``: bands rarely hang symmetrically)."""

    name = "support-springs"
    parameters = (
        Parameter("k_yf", "N/m", 1e1, 1e8, 1e5),
        Parameter("inset", "dimensionless", 0.0, 0.45, 0.15, log=False),
        Parameter("inset_tip", "dimensionless", 0.0, 0.45, 0.15, log=False),
    )

    def __init__(self, where: str, **values: float):
        if "inset" in values and "inset_tip" not in values:
            values["inset_tip"] = values["inset"]
        super().__init__(where, **values)
    explanation = (
        "springs to the ground (suspension bands of a 'free-free' test, a fixture) turn the "
        "rigid-body motion into low modes, tens of Hz for bands: the low end of the FRF rises "
        "from the mass line into peaks"
    )

    @classmethod
    def places(cls, assembly, measured_points):
        beams = [c for c in assembly.components if isinstance(c, Beam)]
        if not beams:
            return []
        heaviest = max(beams, key=lambda b: b.mass())
        return [f"{heaviest.name}.base,{heaviest.name}.tip"]

    def apply(self, assembly):
        """Two equal springs (``k_yf`` each) near the two points of ``where`` (the ends of a component in
        either order, ``"spindle.base,spindle.tip"``), ``inset`` of its length in from the first end named
        and ``inset_tip`` from the second.
        """
        name, first, second = self._places(self.where, assembly.component(self._ends(self.where)[0]).length_m)
        k = {"yf": _si(self.values["k_yf"], "N/m")}
        return assembly.support(Support(f"{name}@{_si(first, 'm')}", k=k, name=f"diagnosed-{name}-1")).support(
            Support(f"{name}@{_si(second, 'm')}", k=k, name=f"diagnosed-{name}-2"))

    @classmethod
    def body(cls, where: str) -> str:
        """The component the springs hold (``where`` checked)."""
        return cls._ends(where)[0]

    @classmethod
    def rigid_body_starts(cls, where: str, length: float, body: tuple[float, float, float],
                          peaks_hz: tuple[float, ...], count: int) -> list[dict]:
        """Values that put the two modes of the free body on its springs at two measured resonances.

        Below its first flexible mode the body moves as a rigid one: with
        mass ``m``, rotary inertia ``J`` about its centre of mass and springs
        ``k`` at distances ``d1``, ``d2`` from that centre, the modes are
        ``omega^2 = k mu`` with ``mu`` the eigenvalues of
        ``[[2/m, (d1+d2)/m], [(d1+d2)/J, (d1^2+d2^2)/J]]``.  On a grid of
        ``count`` values of each inset, the places where the ratio of the two
        ``mu`` is the ratio of the two resonances' ``omega^2`` (a curve, found
        by linear interpolation along rows and columns) each give one start,
        ``k`` from the lower resonance.  With one resonance alone, every place
        of the grid gives two starts: either mode there.

        Parameters
        ----------
        where : str
            The place (the component's two ends).
        length : float
            The component's length [m].
        body : (float, float, float)
            Mass [kg], rotary inertia about the centre of mass [kg m^2] and the
            centre's distance from the component's base [m].
        peaks_hz : (float, float) or (float,)
            The two resonances [Hz], lower first, or one.
        count : int
            Values of each inset.

        Returns
        -------
        list of dict
            Starting values (``k_yf``, ``inset``, ``inset_tip``) within the bounds.
        """
        _, base_first = cls._ends(where)
        mass, inertia, centre = body
        specs = {p.name: p for p in cls.parameters}
        u = np.linspace(specs["inset"].lower, specs["inset"].upper, count)
        a, b = np.meshgrid(u, u, indexing="ij")  # a: inset from the first end named, b: from the second
        first, second = (a * length, (1.0 - b) * length) if base_first else ((1.0 - a) * length, b * length)
        d1, d2 = first - centre, second - centre
        trace = 2.0 / mass + (d1 ** 2 + d2 ** 2) / inertia
        root = np.sqrt(np.maximum(trace ** 2 - 4.0 * (d1 - d2) ** 2 / (mass * inertia), 0.0))
        low, high = 0.5 * (trace - root), 0.5 * (trace + root)
        lam = (2.0 * np.pi * peaks_hz[0]) ** 2
        k_spec = specs["k_yf"]
        out = []
        if len(peaks_hz) == 1:  # the other mode unseen: either mode there
            for mu in (low, high):
                with np.errstate(divide="ignore"):
                    k = lam / mu
                keep = (k >= k_spec.lower) & (k <= k_spec.upper)
                out += [{"k_yf": float(x), "inset": float(y), "inset_tip": float(z)}
                        for x, y, z in zip(k[keep], a[keep], b[keep])]
            return out
        with np.errstate(divide="ignore", invalid="ignore"):
            g = np.log(high / low) - 2.0 * np.log(peaks_hz[1] / peaks_hz[0])
        for grid_g, grid_low, along in ((g, low, 1), (g.T, low.T, 0)):
            j = np.nonzero(np.isfinite(grid_g[:, :-1]) & np.isfinite(grid_g[:, 1:])
                           & (grid_g[:, :-1] * grid_g[:, 1:] <= 0.0) & (grid_g[:, :-1] != grid_g[:, 1:]))
            t = grid_g[j] / (grid_g[j] - grid_g[j[0], j[1] + 1])
            mu = grid_low[j] + t * (grid_low[j[0], j[1] + 1] - grid_low[j])
            moving = u[j[1]] + t * (u[1] - u[0])
            fixed = u[j[0]]
            for f, m, value in zip(fixed, moving, mu):
                k = lam / value if value > 0 else np.inf
                if k_spec.lower <= k <= k_spec.upper:
                    inset, inset_tip = (f, m) if along == 1 else (m, f)
                    out.append({"k_yf": float(k), "inset": float(inset), "inset_tip": float(inset_tip)})
        return out

    @staticmethod
    def _ends(where: str) -> tuple[str, bool]:
        """The component and whether the first end named is its base (``where`` checked)."""
        texts = [p.strip() for p in where.split(",")]
        points = [parse_point(p) for p in texts] if len(texts) == 2 else []
        if len(points) != 2 or len({p.component for p in points}) != 1 or {p.where for p in points} != {"base", "tip"}:
            raise InvalidValueError(
                f"support-springs: where = {where!r}; expected the two ends of one component in either order, "
                "e.g. 'spindle.base,spindle.tip' (inset from the base) or 'spindle.tip,spindle.base' (inset from "
                "the tip)"
            )
        return points[0].component, points[0].where == "base"

    def _places(self, where: str, total: float) -> tuple[str, float, float]:
        """The component and the two springs' places from its base [m]: ``inset`` from the first end named,
        ``inset_tip`` from the second."""
        name, base_first = self._ends(where)
        a, b = self.values["inset"] * total, self.values["inset_tip"] * total
        return (name, a, total - b) if base_first else (name, total - a, b)

    def apply_si(self, structure):
        name = self._ends(self.where)[0]
        _, first, second = self._places(self.where, structure.beam(name).total_length)
        k = np.diag([self.values["k_yf"], 0.0])
        near = LinkSI(("added", f"springs-{name}-1"), (name, first), K=k)
        far = LinkSI(("added", f"springs-{name}-2"), (name, second), K=k)
        return structure.add_link(near).add_link(far)


def _taperable(tool) -> bool:
    """A tool the ``tapered-tool`` effect can act on: a plain beam of uniform segments, one without flutes."""
    return (isinstance(tool, Tool) and not any(s.is_tapered for s in tool.segments)
            and any(s.flutes is None and s.insert is None for s in tool.segments))


@register_effect
class TaperedTool(Effect):
    """A tool whose diameter falls linearly along it, to ``tip_ratio`` times at its tip (a tapered end mill)."""

    name = "tapered-tool"
    parameters = (Parameter("tip_ratio", "dimensionless", 0.5, 1.0, 0.9, log=False),)
    explanation = (
        "a tool that tapers towards its tip (a tapered end mill, one reground or necked along its length) "
        "is softer and lighter than the cylinder of the model, more so near the tip: the tool modes drop, "
        "the spindle and holder modes hardly move"
    )

    @classmethod
    def places(cls, assembly, measured_points):
        return [t.name for t in assembly.components if _taperable(t)]

    def apply(self, assembly):
        return assembly.with_component(taper_tool(assembly.component(self.where), self.values["tip_ratio"]))

    def apply_si(self, structure):
        if self.where in structure.opaque:  # a tool of a type of one's own
            return structure.with_opaque(taper_tool(structure.component(self.where), self.values["tip_ratio"]))
        beam = structure.beam(self.where)
        base, tip = _tapered_diameters(beam.length, beam.od, beam.id, self.values["tip_ratio"])
        changed = (beam.ratio == 1.0) & ~(beam.insert[:, 0] > 0) & ~beam.tapered
        return structure.with_beam(beam.evolve(od=np.where(changed, base, beam.od),
                                               od_tip=np.where(changed, tip, beam.od_tip)))


def _tapered_diameters(length, od, bore, tip_ratio: float) -> tuple[np.ndarray, np.ndarray]:
    """The outer diameters at the base and tip ends of each segment [m] of a tool tapered to ``tip_ratio``
    (:func:`taper_tool`'s rule, for the objects and the arrays alike): ``od (1 - (1 - tip_ratio) x / L)`` at a
    distance ``x`` from the tool's base, kept above the bore."""
    length, od, bore = (np.asarray(v, dtype=float) for v in (length, od, bore))
    ends = np.concatenate([[0.0], np.cumsum(length)])
    base, tip = (od * (1.0 - (1.0 - tip_ratio) * x / float(length.sum())) for x in (ends[:-1], ends[1:]))
    bored = bore > 0  # the bore stays inside the section as it narrows
    return (np.where(bored, np.maximum(base, 1.0001 * bore), base),
            np.where(bored, np.maximum(tip, 1.0001 * bore), tip))


def taper_tool(tool: Beam, tip_ratio: float) -> Beam:
    """The tool with its diameters falling linearly along it, from as they are at its base to ``tip_ratio``
    times at its tip.

    Each segment without flutes or insert becomes tapered: its outer diameter at a distance ``x`` from the
    tool's base is ``od (1 - (1 - tip_ratio) x / L)`` (``L`` the tool's length); its bore stays.  Fluted
    segments (their equivalent diameter is the flutes' ratio of ``od``) and segments with an insert stay as
    they are.

    Parameters
    ----------
    tool : Beam
        A tool of uniform segments.
    tip_ratio : float
        The outer diameter at the tip over the one the tool has there (0 to 1).

    Returns
    -------
    Beam
        A new tool.
    """
    segs = list(tool.segments)
    bases, tips = _tapered_diameters([s.length_m for s in segs], [s.od.m_as("m") for s in segs],
                                     [s.id.m_as("m") for s in segs], tip_ratio)
    for i, (seg, base, tip) in enumerate(zip(segs, bases.tolist(), tips.tolist())):
        if seg.flutes is None and seg.insert is None and not seg.is_tapered:
            segs[i] = attrs.evolve(seg, od=seg.od if base == seg.od.m_as("m") else Q_(base, "m"), od_tip=Q_(tip, "m"))
    return attrs.evolve(tool, segments=segs)
