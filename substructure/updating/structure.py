"""The SI form of an assembly, and its fast evaluation for model updating.

A fit evaluates one model hundreds of times with a few numbers changed.
:class:`Structure` holds an assembly as plain SI arrays: per beam component
its segments' geometry and material constants (from which the section
properties ``EI``, ``kappa G A``, ``rho A``, ``rho I`` follow), and per link
(joint, support, sensor, permanent mass, or an element a fit adds) its
stiffness, damping and mass matrices.  Changing a number returns a new
structure that shares every array it did not change; no units are parsed
and no value objects are rebuilt.

Its evaluation is :class:`~substructure.updating.evaluator.Evaluator`'s.
"""

from __future__ import annotations

import functools

import numpy as np

from .._blocks import angular_lines, takes_decay
from ..assembly import Assembly
from ..assembly.plan import check_connected
from ..beams import Segment
from ..components import Beam, is_plain_beam
from ..errors import InvalidValueError, UnknownPointError
from ..joints import Joint, dynamic_stiffness
from ..points import parse_point
from .beam_arrays import BeamArrays, _segment_sections  # noqa: F401  (kept importable here)

__all__ = ["BeamArrays", "LinkSI", "Structure", "si_beam", "uniform_beam"]


def assembly_checked(assembly, where: str = "assembly"):
    """``assembly`` when it is an :class:`~substructure.assembly.Assembly`; else a clear error (a name or a path
    for the model gave an AttributeError deep inside)."""
    if not isinstance(assembly, Assembly):
        raise InvalidValueError(f"{where}: got {type(assembly).__name__}; expected an Assembly (load_assembly(path) "
                                "for a file, default_assembly() for the built-in one)")
    return assembly


@functools.lru_cache(maxsize=4096)
def _parse(point: str):
    """Point names parsed once (parsing a distance goes through the unit registry)."""
    return parse_point(point)


@functools.lru_cache(maxsize=4096)
def _at(component: str, x: float, length: float):
    """The point at ``x`` metres from a component's base (its ``base`` and ``tip`` by those names)."""
    if x <= 0.0:
        return _parse(f"{component}.base").point
    if x >= length:
        return _parse(f"{component}.tip").point
    return _parse(f"{component}@{x * 1e3!r} mm").point


@functools.lru_cache(maxsize=4096)
def _distance_m(point: str) -> float:
    ref = _parse(point)
    return 0.0 if ref.distance is None else float(ref.distance.m_as("m"))


class LinkSI:
    """A joint, support, body or added element, as SI matrices.

    Attributes
    ----------
    key : tuple
        What it is in the assembly: ``("joints", name)``, ``("supports", i)``,
        ``("sensors", name)``, ``("masses", name)`` or ``("added", label)``.
    a, b : str
        Its points (``b`` None for a link to the ground or a body).
    K, C, M : ndarray, shape (2, 2)
        Stiffness, damping and mass matrices (SI); the dynamic stiffness is
        ``K + i omega C - omega^2 M``.
    rigid : bool
        A rigid joint (no matrices).
    custom : object or None
        A joint model with its own ``dynamic_stiffness`` (used as is).
    """

    __slots__ = ("key", "a", "b", "K", "C", "M", "rigid", "custom")

    def __init__(self, key, a, b=None, K=None, C=None, M=None, rigid=False, custom=None):
        self.key, self.a, self.b = key, a, b
        z = np.zeros((2, 2))
        self.K = z if K is None else np.asarray(K, dtype=float)
        self.C = z if C is None else np.asarray(C, dtype=float)
        self.M = z if M is None else np.asarray(M, dtype=float)
        self.rigid, self.custom = rigid, custom

    def evolve(self, **changes) -> "LinkSI":
        """A copy with some fields replaced.

        Parameters
        ----------
        **changes
            Fields to replace (``K``, ``C``, ``M``, ``a``, ``rigid``, ...).

        Returns
        -------
        LinkSI
            The changed link.
        """
        fields = {k: getattr(self, k) for k in self.__slots__}
        fields.update(changes)
        return LinkSI(**fields)

    def dynamic_stiffness(self, frequency_hz: np.ndarray, decay: float = 0.0) -> np.ndarray | None:
        """``K + i omega C - omega^2 M``, frequency last.

        Parameters
        ----------
        frequency_hz : ndarray
            Frequency lines [Hz].
        decay : float, optional
            ``1/tau`` [1/s]: at the complex frequency ``omega - i decay``.

        Returns
        -------
        ndarray or None
            ``(2, 2, n)``; None for a rigid joint.
        """
        if self.rigid:
            return None
        if self.custom is not None:
            return dynamic_stiffness(self.custom, frequency_hz, decay)
        w = angular_lines(frequency_hz, decay)
        return self.K[:, :, None] + 1j * w * self.C[:, :, None] - (w * w) * self.M[:, :, None]


def _along(component) -> float | None:
    """The length of a component whose points lie along it (a :class:`Beam` of any kind), else None."""
    return float(component.length_m) if isinstance(component, Beam) else None


def si_beam(component) -> bool:
    """Whether a component can be held as SI arrays: a plain beam of segments (tapered ones too).

    Parameters
    ----------
    component : object
        Any component.

    Returns
    -------
    bool
        True for a component whose receptances are those of its segments
        (:func:`substructure.components.is_plain_beam`); other components
        take part through their own methods.
    """
    return (is_plain_beam(component) and isinstance(component, Beam)
            and all(type(s) is Segment for s in component.segments))


def uniform_beam(component) -> bool:
    """Whether a component is a plain beam of uniform segments: one whose materials the ``materials.NAME.X``
    paths change (:func:`si_beam`, no segment tapered).

    Parameters
    ----------
    component : object
        Any component.

    Returns
    -------
    bool
        :func:`si_beam` without tapers.
    """
    return si_beam(component) and not any(s.is_tapered for s in component.segments)


class Structure:
    """An assembly as SI arrays (one test configuration), changed without rebuilding objects.

    Build it with :meth:`from_assembly`; :meth:`with_beam`, :meth:`with_link`,
    :meth:`add_link` and :meth:`with_point` return changed copies.

    Parameters
    ----------
    assembly : Assembly
        The assembly it was made from (the configuration, before any change).
    beams : dict of str to BeamArrays
        The plain stepped beams as arrays, by name.
    opaque : dict of str to object
        The other components (used through their own ``receptance_matrix``).
    links : tuple of LinkSI
        Joints, supports, sensors, masses and added elements, in order.
    order : tuple of str
        The components' names in the assembly's order.
    sources : dict of str to object, optional
        The component objects the beams were made from (to share arrays).
    moved : dict of str to (str, float), optional
        Points placed elsewhere than their names say, ``(component, x)``
        (:meth:`with_point`: where a measured point really was).
    hits : dict of str to (str, float), optional
        Points hit elsewhere than where they are measured, ``(component,
        x)`` (:meth:`with_hit`: the hammer beside the sensor, at another
        height); they place the inputs of that name only.
    """

    __slots__ = ("assembly", "beams", "opaque", "links", "order", "sources", "moved", "hits", "_positions")

    def __init__(self, assembly, beams: dict, opaque: dict, links: tuple, order: tuple, sources: dict | None = None,
                 moved: dict | None = None, hits: dict | None = None):
        self.assembly = assembly
        self.beams = beams
        self.opaque = opaque
        self.links = links
        self.order = order
        self.sources = sources or {}
        self.moved = moved or {}  # point name -> (component, x): a measured point where a fit placed it
        self.hits = hits or {}  # point name -> (component, x): where the hammer hit it, apart from the sensor
        self._positions: dict = {}  # point name -> (component, x): a structure is never changed in place

    def _copy(self, **fields) -> "Structure":
        kept = {"assembly": self.assembly, "beams": self.beams, "opaque": self.opaque, "links": self.links,
                "order": self.order, "sources": self.sources, "moved": self.moved,
                "hits": self.hits}
        return Structure(**{**kept, **fields})

    @classmethod
    def from_assembly(cls, assembly, like: "Structure | None" = None) -> "Structure":
        """The SI form of an assembly (plain beams as arrays, everything else as given).

        Parameters
        ----------
        assembly : Assembly
            The configuration.
        like : Structure, optional
            A structure of the same assembly: the arrays of components that
            are the same objects in both are shared (so that their
            receptances are not computed again).

        Returns
        -------
        Structure
            The SI form.
        """
        check_connected(assembly_checked(assembly))
        beams, opaque, order, sources = {}, {}, [], {}
        for comp in assembly.components:
            order.append(comp.name)
            sources[comp.name] = comp
            if like is not None and like.sources.get(comp.name) is comp and comp.name in like.beams:
                beams[comp.name] = like.beams[comp.name]
            elif si_beam(comp):
                beams[comp.name] = BeamArrays.from_beam(comp)
            else:
                opaque[comp.name] = comp
        links = []
        for kind, bodies in (("sensors", assembly.sensors), ("masses", assembly.masses)):
            links += [LinkSI((kind, b.name), b.at, M=np.diag([b.mass_kg, b.inertia_si])) for b in bodies]
        for i, s in enumerate(assembly.supports):
            links.append(LinkSI(("supports", i), s.at, K=s.k.values, C=s.c.values))
        for j in assembly.joints:
            if type(j) is Joint:
                link = (LinkSI(("joints", j.name), j.between[0], j.between[1], rigid=True) if j.rigid else
                        LinkSI(("joints", j.name), j.between[0], j.between[1], K=j.k.values, C=j.c.values))
            else:
                link = LinkSI(("joints", j.name), j.between[0], j.between[1], rigid=bool(getattr(j, "rigid", False)),
                              custom=j)
            links.append(link)
        return cls(assembly, beams, opaque, tuple(links), tuple(order), sources)

    def not_at_complex_frequency(self) -> list[str]:
        """What cannot be evaluated at a complex frequency (a tap test seen through an exponential window).

        The package's beams, joints, supports and bodies can; a component or
        joint model of one's own can when its ``receptance_matrix`` or
        ``dynamic_stiffness`` takes ``decay``; a measured component cannot
        (its FRF is known on the real lines only).

        Returns
        -------
        list of str
            ``"component 'name' (Type)"`` or ``"joint 'name' (Type)"`` for each
            one that cannot; empty when the whole structure can.
        """
        out = [f"component {name!r} ({type(c).__name__})" for name, c in self.opaque.items()
               if not takes_decay(c.receptance_matrix)]
        out += [f"{link.key[0][:-1]} {link.key[1]!r} ({type(link.custom).__name__})" for link in self.links
                if link.custom is not None and not takes_decay(link.custom.dynamic_stiffness)]
        return out

    # -- lookup and changes --------------------------------------------------------

    def has_component(self, name: str) -> bool:
        """True when a component of that name takes part.

        Parameters
        ----------
        name : str
            The component's name.

        Returns
        -------
        bool
            Whether it is in this configuration.
        """
        return name in self.beams or any(name in getattr(c, "component_names", ()) for c in self.opaque.values())

    def component(self, name: str):
        """A component as it stands in this structure, as an object: the one evaluated by its own methods, the
        assembly's own while its arrays are unchanged, else the component its arrays hold
        (``BeamArrays.as_component``).

        Parameters
        ----------
        name : str
            The component's name.

        Returns
        -------
        object
            The component, with every change made to it.

        Raises
        ------
        UnknownPointError
            When no component has that name here.
        """
        if name in self.opaque:
            return self.opaque[name]
        source = self.sources.get(name)  # dropped when the arrays change
        return source if source is not None else self.beam(name).as_component(self.assembly.component(name))

    def beam(self, name: str) -> BeamArrays:
        """The arrays of a plain beam.

        Parameters
        ----------
        name : str
            The component's name.

        Returns
        -------
        BeamArrays
            Its arrays.

        Raises
        ------
        UnknownPointError
            When it is not a plain beam of this configuration.
        """
        try:
            return self.beams[name]
        except KeyError:
            raise UnknownPointError(f"no plain beam {name!r} in this configuration") from None

    def link(self, key: tuple) -> tuple[int, LinkSI]:
        """The link with a key.

        Parameters
        ----------
        key : tuple
            E.g. ``("joints", "holder-tool")`` or ``("supports", 2)``.

        Returns
        -------
        (int, LinkSI)
            Its index and the link.

        Raises
        ------
        UnknownPointError
            When there is none in this configuration.
        """
        for i, link in enumerate(self.links):
            if link.key == key:
                return i, link
        raise UnknownPointError(f"no {key[0][:-1]} {key[1]!r} in this configuration")

    def with_beam(self, beam: BeamArrays) -> "Structure":
        """The structure with one beam's arrays replaced (by name).

        Parameters
        ----------
        beam : BeamArrays
            The new arrays.

        Returns
        -------
        Structure
            A new structure sharing everything else.
        """
        self.beam(beam.name)
        sources = {k: v for k, v in self.sources.items() if k != beam.name}
        return self._copy(beams={**self.beams, beam.name: beam}, sources=sources)

    def with_opaque(self, component) -> "Structure":
        """The structure with one component evaluated by its own methods replaced (by name).

        Parameters
        ----------
        component : object
            The new component (a changed copy of one in ``opaque``, or of a
            beam in ``beams``, which it then replaces: a taper).

        Returns
        -------
        Structure
            A new structure sharing everything else.
        """
        name = component.name
        if name in self.beams:  # a beam that takes a change its arrays cannot hold (a taper)
            beams = {k: v for k, v in self.beams.items() if k != name}
            sources = {k: v for k, v in self.sources.items() if k != name}
            return self._copy(beams=beams, opaque={**self.opaque, name: component}, sources=sources)
        if name not in self.opaque:
            raise UnknownPointError(f"no component {name!r} evaluated by its own methods here")
        return self._copy(opaque={**self.opaque, name: component})

    def with_link(self, index: int, link: LinkSI) -> "Structure":
        """The structure with one link replaced.

        Parameters
        ----------
        index : int
            Its index.
        link : LinkSI
            The new link.

        Returns
        -------
        Structure
            A new structure sharing everything else.
        """
        links = list(self.links)
        links[index] = link
        return self._copy(links=tuple(links))

    def add_link(self, link: LinkSI) -> "Structure":
        """The structure with one more link (applied after the others).

        Parameters
        ----------
        link : LinkSI
            The link (its point must exist).

        Returns
        -------
        Structure
            A new structure.
        """
        self.position(link.a)
        return self._copy(links=self.links + (link,))

    def with_point(self, point: str, x: float) -> "Structure":
        """The structure with a point (a measured one) placed at ``x`` along its component instead.

        Parameters
        ----------
        point : str
            The point's name, e.g. ``"tool.tip-20 mm"``, on a beam.
        x : float
            Where it is [m from the component's base], on the component.

        Returns
        -------
        Structure
            A new structure: the point's outputs, and the sensors and bodies on it, sit at ``x``.
        """
        comp, at = self.position(point)
        if at is None:
            raise UnknownPointError(f"point {point}: {comp!r} has no length to place a point along")
        return self._copy(moved={**self.moved, str(_parse(point).point): self.position((comp, float(x)))})

    def with_hit(self, point: str, x: float) -> "Structure":
        """The structure with a point hit at ``x`` along its component: its inputs there, its outputs kept.

        Parameters
        ----------
        point : str
            The point's name as the measurements give the excitation, e.g. ``"tool.tip"``, on a beam.
        x : float
            Where the hammer hit [m from the component's base], on the component.

        Returns
        -------
        Structure
            A new structure: the point's inputs sit at ``x``; its outputs, and the sensors and bodies on it, stay
            where :meth:`position` puts them.
        """
        comp, at = self.position(point)
        if at is None:
            raise UnknownPointError(f"point {point}: {comp!r} has no length to place a hit along")
        return self._copy(hits={**self.hits, str(_parse(point).point): self.position((comp, float(x)))})

    def named_position(self, point: str) -> tuple[str, float | None]:
        """``(component, x)`` where a point's name puts it, whatever :meth:`with_point` moved (a hit's reference).

        Parameters
        ----------
        point : str
            A point name.

        Returns
        -------
        (str, float or None)
            The component's name and the position.
        """
        return self._copy(moved={}).position(point) if self.moved else self.position(point)

    def hit_position(self, point: str) -> tuple[str, float | None]:
        """``(component, x)`` of a point as an input: where :meth:`with_hit` put it, else :meth:`position`.

        Parameters
        ----------
        point : str
            A point name.

        Returns
        -------
        (str, float or None)
            The component's name and the position.
        """
        if self.hits:
            found = self.hits.get(str(_parse(point).point))
            if found is not None:
                return found
        return self.position(point)

    def position(self, point) -> tuple[str, float | None]:
        """``(component, x)`` of a point: ``x`` in metres from the base on a plain beam, else None.

        Parameters
        ----------
        point : str or (str, float)
            A point name, or ``(component, x)`` on a plain beam.

        Returns
        -------
        (str, float or None)
            The component's name and the position.

        Raises
        ------
        UnknownPointError
            When the point is not on a component of this configuration.
        """
        if isinstance(point, tuple):
            comp, x = point
            total = _along(self.opaque[comp]) if comp in self.opaque else self.beam(comp).total_length
            if total is None:
                raise UnknownPointError(f"point {comp}@{x} m: {comp!r} has no length to place a point along")
            if not -1e-9 * total <= x <= total * (1 + 1e-9):
                raise UnknownPointError(f"point {comp}@{x} m: lies outside {comp!r} ({total * 1e3:.6g} mm long)")
            return comp, min(max(float(x), 0.0), total)
        found = self._positions.get(point)
        if found is None:
            found = self._positions[point] = self._named_position(point)
        return found

    def _named_position(self, point: str) -> tuple[str, float | None]:
        """:meth:`position` of a point name (kept by :meth:`position`)."""
        ref = _parse(point)
        if self.moved and str(ref.point) in self.moved:
            return self.moved[str(ref.point)]
        if ref.component in self.beams:
            beam = self.beams[ref.component]
            total = beam.total_length
            if ref.where == "base":
                x = 0.0
            elif ref.where == "tip":
                x = total
            elif ref.where == "at":
                x = _distance_m(point)
            elif ref.where == "from_tip":
                x = total - _distance_m(point)
            else:
                raise UnknownPointError(f"point {ref}: {ref.component!r} has points base, tip, @X and tip-X")
            if x < -1e-9 * total or x > total * (1 + 1e-9):
                raise UnknownPointError(f"point {ref}: lies outside {ref.component!r} ({total * 1e3:.6g} mm long)")
            return ref.component, min(max(x, 0.0), total)
        for comp in self.opaque.values():
            if ref.component in getattr(comp, "component_names", ()):
                comp.node_key(ref.point)
                if _along(comp) is not None and ref.component == comp.name:  # a beam with physics of its own
                    return comp.name, float(comp.position(ref.point))
                return comp.name, None
        raise UnknownPointError(f"point {ref}: there is no component {ref.component!r} in this configuration")
