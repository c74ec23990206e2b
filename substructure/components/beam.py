"""Stepped Timoshenko beams as components: :class:`Beam` and its kind :class:`Spindle`.

:class:`~substructure.components.Holder` is in ``components.holder``, with the holder catalogue.

A beam is a name and its segments from base to tip; its points are the ends
and positions along it (``tip-15 mm``), its receptances those of the stepped
beam of :mod:`substructure.beams`.  :func:`component_info` writes the one
line of a component in summaries.
"""

from __future__ import annotations

import re
from typing import Any, ClassVar, Sequence

import attrs
import numpy as np
import pint

from ..beams import Segment, stepped_beam_receptance
from ..errors import InvalidValueError, UnknownPointError
from ..frf import FRF
from ..points import PointRef, check_name, parse_point
from .protocol import _positive_frequencies, as_frequency, dof_labels, register_component

__all__ = ["Beam", "Spindle", "component_info"]


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


MAX_BEAM_PIECES = 2000
"""The most pieces a beam is cut into for one computation (at its highest frequency line).

The exact beam receptances are a chain cut where its ``k L`` exceeds 8 (and
a tapered segment into steps of ``k h <= 0.6``), ``k`` the largest
wavenumber at the highest line.  Machine-tool parts need a few pieces up to
tens of kHz; a line at 1e8 Hz (a frequency in the wrong unit) would need
hundreds of thousands and gigabytes of memory, and is refused before.
"""


def check_reach(beam: Any, frequency_hz: np.ndarray) -> None:
    """Refuse frequency lines so high that ``beam`` would be cut into more than :data:`MAX_BEAM_PIECES` pieces.

    Parameters
    ----------
    beam : Beam
        A component with ``segments`` (base to tip).
    frequency_hz : ndarray
        The frequency lines [Hz], finite and > 0.

    Raises
    ------
    InvalidValueError
        Naming the component, the highest line and the pieces it would need.
    """
    from .._chains import _CHUNK_KL, _phases
    from ..tapers import TAPER_STEP_PHASE, _taper_sections

    f_max = float(np.max(frequency_hz)) if np.size(frequency_hz) else 0.0
    if f_max <= 0.0:
        return
    # k L of each segment at the highest line (of both end sections of a tapered one), in one kernel call
    ends = [_taper_sections(s, np.array([0.0, 1.0])) if s.is_tapered else [s.section()] for s in beam.segments]
    phases = iter(_phases([(sec, s.length_m) for s, e in zip(beam.segments, ends) for sec in e], 2.0 * np.pi * f_max))
    pieces = 0.0
    for s, e in zip(beam.segments, ends):
        phase = max(next(phases) for _ in e)
        pieces += phase / (TAPER_STEP_PHASE if s.is_tapered else _CHUNK_KL)
    if not pieces <= MAX_BEAM_PIECES:  # beyond float range (1e100 Hz) the wavenumbers are NaN: as many pieces
        raise InvalidValueError(
            f"frequency: got a line at {f_max:g} Hz, where component {beam.name!r} would be cut into about "
            f"{pieces if np.isfinite(pieces) else np.inf:.3g} pieces (its bending waves are that short), more than "
            f"{MAX_BEAM_PIECES} "
            "(components.beam.MAX_BEAM_PIECES); the beam model is meant for the vibrations of machine-tool parts, "
            "up to some 100 kHz: check the unit of the frequencies (plain numbers are in Hz)"
        )


_LOCAL = re.compile(r"^(tip|base)\s*($|-|:)")  # a local point name: tip, base, tip-X (and @X)

_BEAM_METHODS = ("receptance_matrix", "position")
"""Methods whose override makes a Beam subclass something else than its segments (plain_beam False)."""


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
        total = sum((s.length for s in self.segments[1:]), self.segments[0].length)
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
        if not isinstance(ref, PointRef):
            ref = self._ref(ref)
        if ref.component != self.name:
            raise UnknownPointError(f"point {ref}: not on component {self.name!r}")
        total = self.length_m
        if ref.where == "base":
            x = 0.0
        elif ref.where == "tip":
            x = total
        elif ref.where == "at" and ref.distance is not None:  # "at" and "from_tip" always have a distance
            x = float(ref.distance.m_as("m"))
        elif ref.where == "from_tip" and ref.distance is not None:
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

    def receptance_matrix(self, refs: Sequence[PointRef], frequency_hz: np.ndarray, decay: float = 0.0) -> np.ndarray:
        """The free-free receptances between points, frequency last (the component protocol).

        Parameters
        ----------
        refs : sequence of PointRef
            The p points.
        frequency_hz : ndarray
            Frequencies in Hz, all > 0 (a free-free beam has no static receptance).
        decay : float, optional
            ``1/tau`` [1/s]: at the complex frequency ``omega - i decay`` (a tap
            test seen through an exponential window); default 0.

        Returns
        -------
        ndarray
            Complex, shape ``(2p, 2p, n_freq)``, DOFs ``(y, theta)`` per point: m/N, m/(N m),
            rad/N and rad/(N m).
        """
        f = np.asarray(frequency_hz, dtype=float)
        _positive_frequencies(f, f"component {self.name!r}")
        check_reach(self, f)
        return stepped_beam_receptance(self.segments, [self.position(r) for r in refs], f, decay)

    def _ref(self, point: str | PointRef) -> PointRef:
        if isinstance(point, PointRef):
            return parse_point(point, allow_dof=False)
        if not isinstance(point, str) or not point.strip():
            raise UnknownPointError(
                f"point: got {point!r}; expected a point of {self.name!r}: 'tip', 'base', '@30 mm', 'tip-15 mm' "
                f"or a full name such as '{self.name}.tip'"
            )
        text = point.strip()
        if text.startswith("@"):
            text = f"{self.name}{text}"
        elif _LOCAL.match(text):
            text = f"{self.name}.{text}"
        ref = parse_point(text, allow_dof=False)
        if ref.component != self.name:
            raise UnknownPointError(f"point {ref}: not on component {self.name!r}")
        return ref

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
        names = [points] if isinstance(points, str) else list(points)  # "tip" is one point, not t, i, p
        refs = [self._ref(p) for p in names]
        places: dict = {}
        for i, r in enumerate(refs):
            first = places.setdefault(self.node_key(r), i)
            if first != i:
                raise InvalidValueError(f"points: {names[first]!r} and {names[i]!r} are the same place of "
                                        f"{self.name!r}; expected each point once")
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


def component_info(component: Any) -> str:
    """One line describing a component, for summaries."""
    kind = getattr(component, "kind", type(component).__name__)
    if isinstance(component, Beam):
        text = (f"{component.name} ({kind}, {len(component.segments)} segments, {component.length:~P}, "
                f"{component.mass():.3g} kg)")
        if component.description:  # its first sentence: catalogue holders carry their sources after it
            text += ": " + component.description.split(". ")[0].rstrip(".")
        return text
    return f"{component.name} ({kind})"
