"""One self-contained HTML report of a tool: the model, how the tool vibrates, the tap test, the cut to use.

:func:`report` computes, with the library's workflows, everything a
machinist or an engineer asks of a spindle-holder-tool assembly, and
:class:`Report` presents it as one HTML page that opens in any browser
with no server and no network (figures embedded, style inline, no script):

* the model: parts, segments, materials, joints, supports, sensors, and the
  descriptions (approximate catalogue geometry);
* the tool point receptance and its modes;
* with tap tests: the diagnosis (the verdict, where the model fails, what it
  misses, the error falling) and the joints identified with their
  standard deviations;
* with a cut: the stability lobes, the recommended spindle speed and depth
  with their margin, the runners-up, what limits them, removal rate and power;
* the assumptions behind all of it.

Plain words come first, the technical names in small notes, units everywhere.
``substructure report`` runs the same from the command line; see
``docs/report.md``.
"""

from .build import DEFAULT_SPEEDS, SUMMARY_KEYS, Report, ToolMode, report, tool_point
from .shop import depth_order

__all__ = ["Report", "ToolMode", "report", "tool_point", "depth_order", "SUMMARY_KEYS", "DEFAULT_SPEEDS"]
