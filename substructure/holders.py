"""Standard tool holders as data: approximate geometry of the common families, easy to override.

A catalogue holder is an *interface* (the shank that goes into the spindle:
BT40, CAT40, HSK-A63) combined with a *clamping system* (ER collet chucks with
their nut, shrink-fit, hydraulic), named ``"<interface> <clamp>"``, e.g.
``"BT40 ER32"`` or ``"HSK-A63 shrink-fit"``.  The numbers live in
``substructure/data/holders.toml`` with their sources; they are APPROXIMATE
(public standards for the interfaces, rounded typical catalogue values for
the bodies and noses), and every holder built from them says so in its
``description``.  Any number can be overridden by name.

The holder runs from the *gauge line* (steep tapers: where the taper has its
gauge diameter; HSK: the flange contact face), where it meets the spindle
face, to its nose: ``holder.base`` is the spindle-holder joint, as in the
thesis, whose spindle model includes the part of the holder inside the
spindle.  ``shank_taper=True`` adds the taper shank before the gauge line as
a tapered segment (:mod:`substructure.tapers`); the gauge line is then at
``HolderDesign.gauge_line`` from the base.  The tool shank fills the
bore over the clamped length as an :class:`~substructure.beams.Insert`
(thesis section 2.1: the part of the tool inside the holder is coupled to it
rigidly).  See docs/holders.md.

Examples
--------
>>> from substructure import Holder
>>> holder = Holder.from_catalog("HSK-A63 shrink-fit", bore="16 mm", gauge_length="80 mm")
>>> holder.length
<Quantity(80.0, 'millimeter')>
>>> "APPROXIMATE" in holder.description
True
"""

from __future__ import annotations

# The catalogue lives beside the Holder class it builds (one module: no import circle between them).
from .components.holder import HolderDesign, catalog_names, catalog_parameters, design

__all__ = ["HolderDesign", "catalog_names", "catalog_parameters", "design"]
