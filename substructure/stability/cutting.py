"""Cuts: what the stability methods need to know about milling and turning.

A cut turns a relative displacement of tool and workpiece into a dynamic
cutting force.  Everything is linear and regenerative: the force per unit
axial depth of cut ``a`` is

``F(t) = a * K(t) * (r(t) - r(t - T))``

with ``r = (x, y)`` the displacement of the tool relative to the workpiece
(``x`` the feed direction, ``y`` normal to it in the plane of the cut), ``T``
the regeneration delay (the tooth period in milling, the revolution in
turning) and ``K(t)`` a 2x2 matrix in N/m^2 (a pressure: N per metre of depth
per metre of chip thickness).  :class:`MillingCut` builds ``K`` from the
teeth, the immersion and the cutting coefficients (Altintas & Budak 1995;
Insperger & Stepan 2004), :class:`TurningCut` is the oriented single-direction
case of Tlusty.  Both give the zero-order (time-averaged) matrix
:meth:`~MillingCut.mean_force_matrix` and the averages over angle intervals
that semi-discretization needs (:meth:`~MillingCut.force_matrix_average`).

Spindle speeds are in rpm and go through :func:`spindle_speeds` or
:func:`as_speed_rpm`: a speed in Hz is refused, because pint converts rpm to
Hz as an angular velocity (off by ``2*pi``).

The concepts have modules of their own: ``speeds`` (the spindle speeds),
``milling`` (:class:`MillingCut`), ``turning`` (:class:`TurningCut`) and
``_cut_fields`` (the checks of a cut's fields); every name is imported from
here.
"""

from __future__ import annotations

from ._cut_fields import MILLING_MODES  # noqa: F401 (its old place)
from .milling import MillingCut
from .speeds import MAX_SPEEDS, as_speed_rpm, spindle_speeds, tooth_passing_hz
from .turning import TurningCut

__all__ = ["MillingCut", "TurningCut", "spindle_speeds", "as_speed_rpm", "tooth_passing_hz", "MAX_SPEEDS"]
