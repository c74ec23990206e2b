"""Components: the substructures an assembly is made of.

A component knows its points and produces its free-free receptances between
them; it knows nothing of assemblies.  Three kinds ship with the package:

* :class:`Beam` and its kinds :class:`Spindle`, :class:`Holder`,
  :class:`Tool`: stepped Timoshenko beams from :mod:`substructure.beams`;
* :class:`MeasuredComponent`: receptances given as data (a tap test, or a
  computed subassembly), at the points its FRF names;
* :class:`substructure.assembly.Assembly` itself, so that a subassembly can be
  coupled like any other component (thesis eq. 2.2).

The protocol a component satisfies (duck-typed, nothing to inherit):

``name``
    Its name.
``component_names``
    The component names whose points it answers for (its own name; all
    inner names for a subassembly).
``node_key(ref) -> hashable``
    A key identifying the physical point of a :class:`~substructure.points.PointRef`
    (two names of the same place give the same key); raises
    :class:`~substructure.errors.UnknownPointError` for a point it lacks.
``receptance_matrix(refs, frequency_hz) -> ndarray``
    The receptances between the points, shape ``(2p, 2p, n_freq)``
    (frequency last), DOFs ``(y, theta)`` per point.

One optional member lets batched computations take a shortcut:

``plain_beam`` (bool, default False)
    True when the receptances are exactly those of the stepped beam of the
    component's ``segments`` between its ends (``base``, ``tip``): a sweep
    then evaluates many such components in one call of the beam kernel from
    their segments, without calling ``receptance_matrix``.  :class:`Beam`
    says True; a subclass that overrides ``receptance_matrix`` or
    ``position`` says False unless it sets ``plain_beam = True`` itself (see
    :func:`is_plain_beam`).

New component types are registered with :func:`register_component` so that
assembly files can name them by their ``type``.
"""

from __future__ import annotations

from typing import Any, ClassVar, Iterable, Sequence

import attrs
import numpy as np
import pint

from .beams import Flutes, Segment, stepped_beam_receptance
from .errors import FrequencyAxisMismatchError, InvalidValueError, UnknownPointError
from .frf import FRF, Frequency
from .points import DOFS, PointRef, check_name, parse_point

__all__ = [
    "Beam",
    "Spindle",
    "Holder",
    "Tool",
    "MeasuredComponent",
    "COMPONENT_TYPES",
    "register_component",
    "as_frequency",
    "dof_labels",
    "is_plain_beam",
]

COMPONENT_TYPES: dict[str, type] = {}
"""Registered component types by their ``type`` name in assembly files."""


def register_component(kind: str):
    """Class decorator registering a component type under ``kind``.

    Parameters
    ----------
    kind : str
        The name of the type in assembly files (``type = "shrink-fit-holder"``).

    Returns
    -------
    callable
        The decorator: it sets ``cls.kind``, adds the class to
        :data:`COMPONENT_TYPES` and returns the class unchanged.

    Raises
    ------
    InvalidValueError
        When another class is already registered under ``kind``.

    Examples
    --------
    >>> @register_component("shrink-fit-holder")          # doctest: +SKIP
    ... @attrs.frozen
    ... class ShrinkFitHolder(Holder): ...
    """

    def decorate(cls):
        if kind in COMPONENT_TYPES and COMPONENT_TYPES[kind] is not cls:
            raise InvalidValueError(f"component type {kind!r} is already registered")
        cls.kind = kind
        COMPONENT_TYPES[kind] = cls
        return cls

    return decorate


def as_frequency(frequency) -> Frequency:
    """A :class:`Frequency` from a Frequency, an FRF, an array of frequencies in Hz or a quantity.

    A quantity in angular units is converted explicitly, as everywhere
    (:func:`substructure.units.frequency_hz`): rad/s divided by ``2*pi``,
    rpm by 60.

    Parameters
    ----------
    frequency : Frequency, FRF, pint.Quantity or array_like
        The frequency lines: a Frequency, the axis of an FRF, a quantity in Hz
        (rad/s and rpm converted: divided by 2*pi and by 60), or plain numbers in Hz.

    Returns
    -------
    Frequency
        The frequency axis, in Hz.
    """
    if isinstance(frequency, Frequency):
        return frequency
    if isinstance(frequency, FRF):
        return frequency.frequency
    if isinstance(frequency, pint.Quantity):
        from .units import cycles_per_second, ureg

        q = frequency if frequency._REGISTRY is ureg else ureg.Quantity(frequency.magnitude, str(frequency.units))
        if not q.check("1 / [time]"):
            raise InvalidValueError(
                f"frequency: got a quantity in {q.units}; expected frequencies (Hz, or rad/s and rpm, "
                "which are divided by 2*pi and by 60)"
            )
        return Frequency.from_hz(np.atleast_1d(np.asarray(cycles_per_second(q, "frequency"), dtype=float)))
    if isinstance(frequency, str):
        raise InvalidValueError(
            f"frequency: got {frequency!r}; expected a Frequency (e.g. Frequency.from_range('20 Hz', "
            "'5000 Hz', '2 Hz')) or an array of frequencies in Hz"
        )
    return Frequency.from_hz(np.atleast_1d(np.asarray(frequency, dtype=float)))


def dof_labels(points: Iterable[str]) -> tuple[str, ...]:
    """DOF labels ``("p:y", "p:theta", ...)`` of point names.

    Parameters
    ----------
    points : iterable of str
        Point names (``"tool.tip"``).

    Returns
    -------
    tuple of str
        Two labels per point: the displacement ``y`` (m) and the slope ``theta`` (rad).
    """
    return tuple(f"{p}:{d}" for p in points for d in DOFS)


def _positive_frequencies(f: np.ndarray, who: str) -> None:
    if np.any(f <= 0):
        raise InvalidValueError(
            f"frequency: {who} is free-free and has no static receptance; "
            f"expected frequencies > 0 Hz, got {float(f.min())} Hz"
        )


def _segments(value) -> tuple[Segment, ...]:
    if isinstance(value, Segment):
        value = (value,)
    try:
        segs = tuple(value)
    except TypeError:
        raise InvalidValueError(f"segments: got {value!r}; expected a sequence of Segment") from None
    if not segs:
        raise InvalidValueError("segments: got none; expected at least one Segment (base to tip)")
    for i, s in enumerate(segs):
        if not isinstance(s, Segment):
            raise InvalidValueError(f"segments[{i}]: got {s!r}; expected a Segment")
    return segs


def _text(field: str):
    def check(instance, attribute, value) -> None:
        if not isinstance(value, str):
            raise InvalidValueError(f"{field}: got {value!r}; expected a text")

    return check


_BEAM_METHODS = ("receptance_matrix", "position")
"""Methods whose override makes a Beam subclass something else than its segments (plain_beam False)."""


def is_plain_beam(component: Any) -> bool:
    """Whether a component's receptances are those of its ``segments`` alone (the ``plain_beam`` member).

    Parameters
    ----------
    component : object
        Any component.

    Returns
    -------
    bool
        True only when the component says so with ``plain_beam = True`` and
        has a sequence of :class:`~substructure.beams.Segment` as
        ``segments``; batched paths (sweeps) may then compute it from the
        segments.  Everything else is computed through its
        ``receptance_matrix``.
    """
    if getattr(component, "plain_beam", False) is not True:
        return False
    segments = getattr(component, "segments", None)
    return isinstance(segments, tuple) and bool(segments) and all(isinstance(s, Segment) for s in segments)


@register_component("beam")
@attrs.frozen
class Beam:
    """A free-free stepped Timoshenko beam (the base class of spindles, holders and tools).

    Parameters
    ----------
    name : str
        Name used in point names (``"tool"`` gives ``"tool.tip"``).
    segments : sequence of Segment
        Base to tip (lengths and diameters with units, see :class:`Segment`).
    description : str, optional
        What the component is and where its numbers come from (keyword only;
        shown in summaries, kept in assembly files).  Catalogue holders say
        here that their geometry is approximate.

    Examples
    --------
    >>> from substructure import Tool, Segment
    >>> tool = Tool("tool", [Segment("60 mm", "12 mm", material="carbide")])
    >>> frf = tool.receptance([500.0, 1000.0], points=["tip"])
    >>> frf.outputs
    ('tool.tip:y', 'tool.tip:theta')
    """

    kind: ClassVar[str] = "beam"
    plain_beam: ClassVar[bool] = True
    """The receptances are those of ``segments`` alone (see :func:`is_plain_beam`).

    A subclass that overrides ``receptance_matrix`` or ``position`` (a
    lumped mass, a different point layout) gets False, so that sweeps call
    its own ``receptance_matrix``; it may set ``plain_beam = True`` in its
    class body when its receptances are still exactly the segments'.
    """

    name: str = attrs.field(converter=check_name)
    segments: tuple[Segment, ...] = attrs.field(converter=_segments)
    description: str = attrs.field(default="", kw_only=True, validator=_text("description"))

    def __init_subclass__(cls, **kwargs: Any) -> None:
        super().__init_subclass__(**kwargs)
        if "plain_beam" not in cls.__dict__ and any(m in cls.__dict__ for m in _BEAM_METHODS):
            cls.plain_beam = False

    @property
    def component_names(self) -> frozenset[str]:
        """The component names whose points this beam answers for: its own name."""
        return frozenset({self.name})

    @property
    def length(self) -> pint.Quantity:
        """Total length."""
        total = self.segments[0].length
        for s in self.segments[1:]:
            total = total + s.length
        return total.to(self.segments[0].length.units)

    @property
    def length_m(self) -> float:
        """Total length in m (a float)."""
        return float(sum(s.length_m for s in self.segments))

    def mass(self) -> float:
        """Total mass (inserts included).

        Returns
        -------
        float
            The mass in kg.
        """
        return float(sum(s.mass() for s in self.segments))

    def position(self, ref: PointRef | str) -> float:
        """Distance of a point from the base.

        Parameters
        ----------
        ref : PointRef or str
            A point of this beam: ``"tool.tip"``, ``"base"``, ``"@30 mm"``, ``"tip-15 mm"``.

        Returns
        -------
        float
            The distance from the base, in m.

        Raises
        ------
        UnknownPointError
            When the point is not on this beam or lies outside it.
        """
        if isinstance(ref, str):
            ref = self._ref(ref)
        if ref.component != self.name:
            raise UnknownPointError(f"point {ref}: not on component {self.name!r}")
        total = self.length_m
        if ref.where == "base":
            x = 0.0
        elif ref.where == "tip":
            x = total
        elif ref.where == "at":
            x = float(ref.distance.m_as("m"))
        elif ref.where == "from_tip":
            x = total - float(ref.distance.m_as("m"))
        else:
            raise UnknownPointError(
                f"point {ref}: {self.name!r} has points base, tip, @X and tip-X, not {ref.where!r}"
            )
        tol = 1e-12 * total
        if x < -tol or x > total + tol:
            raise UnknownPointError(
                f"point {ref}: lies outside {self.name!r}, whose length is {self.length:~P}"
            )
        return min(max(x, 0.0), total)

    def node_key(self, ref: PointRef):
        """A key of the physical point: two names of the same place give the same key.

        Parameters
        ----------
        ref : PointRef
            A point of this beam.

        Returns
        -------
        tuple
            ``(name, position in m rounded to 1e-12)``.
        """
        return (self.name, round(self.position(ref), 12))

    def receptance_matrix(self, refs: Sequence[PointRef], frequency_hz: np.ndarray) -> np.ndarray:
        """The free-free receptances between points, frequency last (the component protocol).

        Parameters
        ----------
        refs : sequence of PointRef
            The p points.
        frequency_hz : ndarray
            Frequencies in Hz, all > 0 (a free-free beam has no static receptance).

        Returns
        -------
        ndarray
            Complex, shape ``(2p, 2p, n_freq)``, DOFs ``(y, theta)`` per point: m/N, m/(N m),
            rad/N and rad/(N m).
        """
        f = np.asarray(frequency_hz, dtype=float)
        _positive_frequencies(f, f"component {self.name!r}")
        return stepped_beam_receptance(self.segments, [self.position(r) for r in refs], f)

    def _ref(self, point: str) -> PointRef:
        text = point if point.startswith(self.name + ".") or point.startswith(self.name + "@") else (
            f"{self.name}{point}" if point.startswith("@") else f"{self.name}.{point}"
        )
        return parse_point(text, allow_dof=False)

    def receptance(self, frequency, points: Sequence[str] = ("tip",)) -> FRF:
        """Free-free receptance matrix between points of this beam.

        Parameters
        ----------
        frequency : Frequency or array_like
            The frequency lines (plain numbers are in Hz), all > 0.
        points : sequence of str
            Point names, full (``"tool.tip"``) or local (``"tip"``, ``"base"``,
            ``"@30 mm"``, ``"tip-15 mm"``).

        Returns
        -------
        FRF
            Outputs and inputs ``(p:y, p:theta)`` per point: H in m/N, L in m/(N m),
            N in rad/N, P in rad/(N m).
        """
        freq = as_frequency(frequency)
        refs = [self._ref(p) for p in points]
        data = np.moveaxis(self.receptance_matrix(refs, freq.hz), -1, 0)
        labels = dof_labels(str(r) for r in refs)
        return FRF(freq, data, labels, labels)


@register_component("spindle")
@attrs.frozen
class Spindle(Beam):
    """A spindle: base at its rear end, tip at its nose.

    Parameters
    ----------
    name : str
        Name used in point names (``"spindle"`` gives ``"spindle.tip"``).
    segments : sequence of Segment
        Base to tip.
    description : str, optional
        What the component is and where its numbers come from (keyword only).
    """


@register_component("holder")
@attrs.frozen
class Holder(Beam):
    """A tool holder: base at the taper end, tip at its face.

    Parameters
    ----------
    name : str
        Name used in point names (``"holder"`` gives ``"holder.tip"``).
    segments : sequence of Segment
        Base to tip.
    description : str, optional
        What the component is and where its numbers come from (keyword only).

    Notes
    -----
    The part of the tool inside the holder is usually modelled as an
    :class:`~substructure.beams.Insert` of the holder's bore segment
    (thesis section 2.1).  Standard holders (BT40, CAT40, HSK-A63 with ER
    collet chucks, shrink-fit or hydraulic noses) come from
    :meth:`from_catalog`.
    """

    @classmethod
    def from_catalog(cls, entry: str, *, name: str = "holder", **parameters) -> "Holder":
        """A standard holder of approximate geometry from the catalogue, with overrides.

        Parameters
        ----------
        entry : str
            ``"<interface> <clamp>"``, e.g. ``"HSK-A63 shrink-fit"``, ``"BT40 ER32"``,
            ``"CAT40 hydraulic"`` (:func:`substructure.holders.catalog_names`).
        name : str
            Component name.
        **parameters
            ``bore`` (the tool shank diameter, required), ``gauge_length``,
            ``clamp_length``, ``material``, ``tool_material``, ``shank_taper``
            and any geometric value of the catalogue by name, e.g.
            ``nose_diameter="27 mm"`` (:func:`substructure.holders.design`).

        Returns
        -------
        Holder
            From the gauge line (its base, the spindle-holder joint) to the
            nose, the tool shank as an insert over the clamped length; its
            ``description`` says it is approximate and cites the sources.

        Examples
        --------
        >>> h = Holder.from_catalog("BT40 ER32", bore="12 mm", gauge_length="70 mm", nut_diameter="48 mm")
        >>> round(h.mass(), 2)
        1.11
        """
        from .holders import design

        return design(entry, **parameters).holder(name, cls)


def _tool_teeth(value):
    if value is None:
        return None
    if isinstance(value, bool) or not (isinstance(value, (int, np.integer)) or (
            isinstance(value, float) and value.is_integer())):
        raise InvalidValueError(f"teeth: got {value!r}; expected a whole number of teeth (flutes) >= 1")
    if value < 1:
        raise InvalidValueError(f"teeth: got {value!r}; expected a whole number of teeth (flutes) >= 1")
    return int(value)


def _tool_helix(value):
    if value is None:
        return None
    from .errors import UnitError
    from .units import Q_, ureg

    try:
        q = Q_(value) if isinstance(value, str) else value
    except Exception:
        q = None
    if not isinstance(q, pint.Quantity) or q.units == ureg.dimensionless or not q.dimensionless \
            or np.ndim(q.magnitude) != 0:
        raise UnitError(f"helix: got {value!r}; expected the helix angle with its unit, e.g. '30 deg'")
    deg = float(q.m_as("deg"))
    if not 0.0 <= deg < 90.0:
        raise InvalidValueError(f"helix: got {value!r}; expected a helix angle in [0, 90) deg")
    return q.to("deg")


def _tool_diameter(value):
    if value is None:
        return None
    from .units import quantity

    q = quantity(value, "diameter", "[length]")
    if not q.magnitude > 0:
        raise InvalidValueError(f"diameter: got {value!r}; expected a positive cutting diameter")
    return q


@register_component("tool")
@attrs.frozen
class Tool(Beam):
    """A cutting tool: base at the shank end, tip at the cutting end.

    Parameters
    ----------
    name : str
        Name used in point names (``"tool"`` gives ``"tool.tip"``).
    segments : sequence of Segment
        Base to tip.
    description : str, optional
        What the component is and where its numbers come from (keyword only).
    teeth : int, optional
        Number of teeth (flutes); stability lobes take it from the tool.
    helix : quantity or str, optional
        Helix angle, e.g. ``"30 deg"`` (recorded; the straight-tooth
        stability models do not use it).
    diameter : quantity or str, optional
        Cutting diameter; default: the outer diameter of the tip segment
        (:attr:`cutting_diameter`).
    """

    teeth: int | None = attrs.field(default=None, kw_only=True, converter=_tool_teeth)
    helix: pint.Quantity | None = attrs.field(default=None, kw_only=True, converter=_tool_helix)
    diameter: pint.Quantity | None = attrs.field(default=None, kw_only=True, converter=_tool_diameter)

    @property
    def cutting_diameter(self) -> pint.Quantity:
        """The cutting diameter: ``diameter`` when given, else the tip segment's outer diameter."""
        return self.diameter if self.diameter is not None else self.segments[-1].od

    @property
    def flute_length(self) -> pint.Quantity | None:
        """Length of the fluted segments at the tip (``None`` when none is fluted)."""
        total = None
        for seg in reversed(self.segments):
            if seg.flutes is None:
                break
            total = seg.length if total is None else total + seg.length
        return total

    @classmethod
    def end_mill(
        cls,
        diameter,
        overhang,
        flute_length=None,
        *,
        material="carbide",
        diameter_ratio: float = 0.8,
        name: str = "tool",
        teeth: int | None = None,
        helix=None,
    ) -> "Tool":
        """An end mill sticking out of its holder by ``overhang``.

        The shank inside the holder belongs to the holder (as an insert); this
        tool is the overhang: a solid shank, then ``flute_length`` of flutes
        modelled by the equivalent diameter ``diameter_ratio * diameter``.

        Parameters
        ----------
        diameter : str or pint.Quantity
            Shank and cutting diameter, a length (``"12 mm"``).
        overhang : str or pint.Quantity
            Length out of the holder, a length.
        flute_length : str or pint.Quantity, optional
            Length of the fluted part at the tip, a length no longer than the
            overhang; None (default) or zero for a plain rod.
        material : str or Material
            Material name in the catalogue or a :class:`Material`; default carbide.
        diameter_ratio : float
            Equivalent diameter of the fluted section over the diameter, in (0, 1]
            (dimensionless); default 0.8.
        name : str
            Component name; default ``"tool"``.
        teeth : int, optional
            Number of teeth (flutes).
        helix : str or pint.Quantity, optional
            Helix angle, e.g. ``"30 deg"``.

        Returns
        -------
        Tool
            The overhang: a solid shank segment (if any), then the fluted segment.
        """
        from .units import quantity

        d = quantity(diameter, "diameter", "[length]")
        total = quantity(overhang, "overhang", "[length]")
        flutes = None if flute_length is None else quantity(flute_length, "flute_length", "[length]")
        extra = {"teeth": teeth, "helix": helix}
        if flutes is None or flutes.magnitude == 0:
            return cls(name, [Segment(total, d, material=material)], **extra)
        if flutes > total:
            raise InvalidValueError(
                f"flute_length: got {flutes:~P}, longer than the overhang {total:~P}"
            )
        shank = total - flutes
        segs = [Segment(flutes, d, material=material, flutes=Flutes(diameter_ratio))]
        if shank.magnitude > 0:
            segs.insert(0, Segment(shank, d, material=material))
        return cls(name, segs, **extra)


def _measured_frf(value) -> FRF:
    if not isinstance(value, FRF):
        raise InvalidValueError(f"frf: got {value!r}; expected an FRF")
    if value.outputs != value.inputs:
        raise InvalidValueError(
            "frf: a measured component needs a square receptance matrix with the same "
            f"outputs and inputs; got outputs {value.outputs} and inputs {value.inputs}"
        )
    return value.to_receptance()


@register_component("measured")
@attrs.frozen
class MeasuredComponent:
    """A substructure known by its receptances (measured, or computed elsewhere).

    Parameters
    ----------
    name : str
        Name of the component in messages.
    frf : FRF
        Square receptance matrix whose labels are point names with DOFs,
        e.g. ``"holder.tip:y"``, ``"holder.tip:theta"``.  Both DOFs of a point
        are needed for coupling at that point (estimate rotational FRFs by
        finite differences when only ``y`` was measured).

    Notes
    -----
    The points answer to the component names in the labels, so that a
    measured spindle-holder subassembly keeps the point names of the model
    (``"holder.tip"``) and couples to a tool like the modelled one.
    """

    name: str = attrs.field(converter=check_name)
    frf: FRF = attrs.field(converter=_measured_frf)

    @property
    def component_names(self) -> frozenset[str]:
        """The component names in the FRF's labels: the points this component answers for."""
        return frozenset(parse_point(lbl).component for lbl in self.frf.outputs)

    @property
    def points(self) -> tuple[str, ...]:
        """The point names of the FRF's labels, in order."""
        seen: dict[str, None] = {}
        for lbl in self.frf.outputs:
            seen[str(parse_point(lbl).point)] = None
        return tuple(seen)

    def node_key(self, ref: PointRef):
        """A key of the physical point, after checking that both DOFs were measured.

        Parameters
        ----------
        ref : PointRef
            A point named in the FRF's labels.

        Returns
        -------
        tuple
            ``(name, point name)``.

        Raises
        ------
        UnknownPointError
            When the point, or one of its DOFs ``y`` and ``theta``, is not in the FRF.
        """
        point = str(ref.point)
        missing = [f"{point}:{d}" for d in DOFS if f"{point}:{d}" not in self.frf.outputs]
        if len(missing) == 2:
            raise UnknownPointError(
                f"point {point}: not in measured component {self.name!r}, which has {', '.join(self.points)}"
            )
        if missing:
            raise UnknownPointError(
                f"point {point}: measured component {self.name!r} lacks {', '.join(missing)}; "
                "coupling needs both y and theta (estimate rotational FRFs by finite differences)"
            )
        return (self.name, point)

    def receptance_matrix(self, refs: Sequence[PointRef], frequency_hz: np.ndarray) -> np.ndarray:
        """The measured receptances between points, frequency last (the component protocol).

        Parameters
        ----------
        refs : sequence of PointRef
            The p points.
        frequency_hz : ndarray
            Frequencies in Hz: a contiguous run of the FRF's own lines (never interpolated).

        Returns
        -------
        ndarray
            Complex, shape ``(2p, 2p, n_freq)``, DOFs ``(y, theta)`` per point, in m/N, m/(N m),
            rad/N and rad/(N m).

        Raises
        ------
        FrequencyAxisMismatchError
            When the frequencies are not lines of the FRF.
        """
        f = np.asarray(frequency_hz, dtype=float)
        hz = self.frf.frequency.hz
        start = int(np.searchsorted(hz, f[0])) if f.size else 0
        if f.size == 0 or not np.array_equal(hz[start : start + f.size], f):
            raise FrequencyAxisMismatchError(
                f"measured component {self.name!r} is known on {self.frf.frequency!r}; the request "
                "uses another grid: interpolate the FRF or compute on its grid"
            )
        for r in refs:
            self.node_key(r)
        labels = [f"{r.point}:{d}" for r in refs for d in DOFS]
        index = [self.frf.outputs.index(lbl) for lbl in labels]
        data = self.frf.data[start : start + f.size]
        return np.moveaxis(data[:, index][:, :, index], 0, -1)


def component_info(component: Any) -> str:
    """One line describing a component, for summaries."""
    kind = getattr(component, "kind", type(component).__name__)
    if isinstance(component, Beam):
        text = f"{component.name} ({kind}, {len(component.segments)} segments, {component.length:~P}, {component.mass():.3g} kg)"
        if component.description:  # its first sentence: catalogue holders carry their sources after it
            text += ": " + component.description.split(". ")[0].rstrip(".")
        return text
    return f"{component.name} ({kind})"
