"""The assembly graph: components connected by joints, with sensors and supports.

Nodes are components, edges are joints; sensors and supports hang on points.
The assembly owns its bookkeeping (which DOF is where), so one component can
sit in many assemblies and sweeps at once.  It is immutable: ``add``,
``connect``, ``attach``, ``support`` and friends return new assemblies.

The coupled receptance between any points is computed by the one generic
engine of :mod:`substructure.coupling`: the free-free receptances of the
components at the points that matter (outputs, joint ends, sensor and
support points) are stacked block-diagonally, and every joint, support and
sensor is applied as a connection.  Any number of components and any
topology (chain, branch, loop) work the same way.

An assembly is itself a component: it can be added to a larger assembly,
which is how a spindle-holder subassembly (modelled or measured) is coupled
to a tool (thesis eq. 2.2).

The package holds one concept per module: ``graph`` (:class:`Assembly`),
``plan`` (:func:`expand_points`, the plan of a computation and the coupling
of one chunk of lines), ``prepared`` (:class:`PreparedFRF`) and ``_fields``
(the checks of an assembly's fields); every name is imported from here.

Examples
--------
>>> from substructure import Assembly, Holder, Tool, Segment
>>> holder = Holder("holder", [Segment("60 mm", "40 mm")])
>>> tool = Tool("tool", [Segment("50 mm", "12 mm", material="carbide")])
>>> asm = (Assembly("demo").add(holder, tool)
...        .connect("holder.tip", "tool.base", k={"yf": "4e7 N/m", "tm": "6e4 N*m/rad"}))
>>> frf = asm.receptance("tool.tip", frequency=[1000.0, 2000.0])
>>> frf.outputs
('tool.tip:y', 'tool.tip:theta')
"""

from __future__ import annotations

from .graph import Assembly
from .plan import expand_points
from .prepared import PreparedFRF

__all__ = ["Assembly", "PreparedFRF", "expand_points"]
