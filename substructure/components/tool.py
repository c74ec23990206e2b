"""Cutting tools as components: :class:`Tool`, with teeth, helix and cutting diameter.

A tool is a beam whose base is at the shank end and whose tip cuts; the
optional ``teeth``, ``helix`` and ``diameter`` are checked on entry and used
by the stability commands.  :meth:`Tool.end_mill` builds a fluted end mill
with a plain shank from its catalogue dimensions.
"""

from __future__ import annotations

import attrs
import numpy as np
import pint

from ..beams import Flutes, Segment
from ..errors import InvalidValueError, UnitError
from ..units import Q_, check_number_text, quantity, show_value, teeth_count, ureg
from .beam import Beam
from .protocol import register_component

__all__ = ["Tool"]


def _tool_teeth(value):
    return None if value is None else teeth_count(value)


def _tool_helix(value):
    if value is None:
        return None
    if isinstance(value, str):  # "3,5 deg" is 35 deg to pint: refused, as every value's text
        check_number_text(value, "helix", "the helix angle with its unit, e.g. '30 deg'")
    try:
        q = Q_(value) if isinstance(value, str) else value
    except Exception:
        q = None
    if not isinstance(q, pint.Quantity) or q.units == ureg.dimensionless or not q.dimensionless \
            or np.ndim(q.magnitude) != 0:
        raise UnitError(f"helix: got {value!r}; expected the helix angle with its unit, e.g. '30 deg'")
    if dict(q.to_root_units()._units).get("radian", 0) != 1:  # "30 %" is 0.3, which pint would take as 0.3 rad
        raise UnitError(f"helix: got {value!r}; expected an angle (deg or rad), e.g. '30 deg'")
    deg = float(q.m_as("deg"))
    if not 0.0 <= deg < 90.0:
        raise InvalidValueError(f"helix: got {value!r}; expected a helix angle in [0, 90) deg")
    return q.to("deg")


def _tool_diameter(value):
    if value is None:
        return None
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
        d = quantity(diameter, "diameter", "[length]")
        total = quantity(overhang, "overhang", "[length]")
        flutes = None if flute_length is None else quantity(flute_length, "flute_length", "[length]")
        for field, value, q in (("diameter", diameter, d), ("overhang", overhang, total)):
            if q.magnitude <= 0:
                raise InvalidValueError(f"{field}: got {show_value(value)}; expected a positive length")
        if flutes is not None and flutes.magnitude < 0:
            raise InvalidValueError(f"flute_length: got {show_value(flute_length)}; expected a length >= 0")
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
