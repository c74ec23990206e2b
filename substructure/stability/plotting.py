"""Matplotlib figures of stability lobes, returned and never shown.

:func:`plot_lobes` draws the depth limit (mm) against spindle speed (rpm) for
one or several results on one axes, so that lobes from different FRFs (a
measurement and a model, with and without a sensor) can be compared;
:func:`plot_band` shades the spread of a :class:`~substructure.stability.result.LobesBand`.
Depths below a curve are stable.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import matplotlib.pyplot as plt
import numpy as np
from matplotlib.axes import Axes
from matplotlib.figure import Figure

from ..errors import InvalidValueError

__all__ = ["plot_lobes", "plot_band"]


def _axes(ax: Any) -> Axes:
    if ax is None:
        _, ax = plt.subplots(figsize=(7.5, 4.2), layout="constrained")
        return ax
    if isinstance(ax, Figure):
        if not ax.axes:
            return ax.add_subplot()
        ax = ax.axes[0]
    if not isinstance(ax, Axes):
        raise InvalidValueError(f"ax: got {type(ax).__name__}; expected a matplotlib Axes or Figure")
    return ax


def _finish(ax: Axes) -> None:
    ax.set_xlabel("spindle speed [rpm]")
    ax.set_ylabel("axial depth of cut limit [mm]")
    ax.set_ylim(bottom=0.0)
    ax.grid(True, alpha=0.3)
    if any(not str(line.get_label()).startswith("_") for line in ax.lines + ax.collections):
        ax.legend(fontsize="small")


def plot_lobes(results: Sequence[Any], ax: Any = None, lobes: bool = False, ylim_factor: float = 3.0,
               **line_kw: Any) -> Figure:
    """Depth limit against spindle speed for one or more :class:`Lobes`.

    Parameters
    ----------
    results : sequence of Lobes
    ax : Axes or Figure, optional
        Draw onto these axes (overlay); a new figure when None.
    lobes : bool, default False
        Also draw the individual zero-order lobes, thin and faint.
    ylim_factor : float, default 3.0
        The depth axis ends at this multiple of the median finite limit, so
        that the near-vertical lobe flanks do not flatten the plot.
    **line_kw
        Passed to ``Axes.plot`` for every result (``color``, ``linestyle``).

    Returns
    -------
    matplotlib.figure.Figure
    """
    ax = _axes(ax)
    overlay = bool(ax.lines)
    top = ax.get_ylim()[1] if overlay else 0.0
    left, right = ax.get_xlim() if overlay else (np.inf, -np.inf)
    for r in results:
        depth = np.where(np.isfinite(r.depth_limit_m), r.depth_limit_m, np.nan) * 1e3
        (line,) = ax.plot(r.spindle_speed_rpm, depth, label=r.label or r.method, **line_kw)
        if lobes:
            for n, a in r.lobes:
                ax.plot(n, a * 1e3, lw=0.5, alpha=0.35, color=line.get_color(), label="_lobe")
        if r.absolute_limit_m is not None and np.isfinite(r.absolute_limit_m):
            ax.axhline(r.absolute_limit_m * 1e3, lw=0.8, ls=":", color=line.get_color(), label="_absolute")
        finite = depth[np.isfinite(depth)]
        if finite.size:
            top = max(top, ylim_factor * float(np.median(finite)))
    ax.set_xlim(min([left] + [r.spindle_speed_rpm[0] for r in results]),
                max([right] + [r.spindle_speed_rpm[-1] for r in results]))
    if top > 0:
        ax.set_ylim(0.0, top)
    _finish(ax)
    return ax.figure


def plot_band(band: Any, ax: Any = None, color: str | None = None, alpha: float = 0.25, **line_kw: Any) -> Figure:
    """Shade ``band.lower_m .. band.upper_m`` and draw ``band.nominal`` as a line."""
    ax = _axes(ax)
    n = band.spindle_speed_rpm
    lo = np.where(np.isfinite(band.lower_m), band.lower_m, np.nan) * 1e3
    hi = np.where(np.isfinite(band.upper_m), band.upper_m, np.nan) * 1e3
    fill = ax.fill_between(n, lo, hi, color=color, alpha=alpha, lw=0, label=band.label or "band")
    if band.nominal is not None:
        plot_lobes([band.nominal], ax=ax, color=fill.get_facecolor()[0][:3], **line_kw)
    else:
        ax.set_xlim(n[0], n[-1])
        finite = hi[np.isfinite(hi)]
        if finite.size:
            ax.set_ylim(0.0, max(ax.get_ylim()[1], 3.0 * float(np.median(finite))))
    _finish(ax)
    return ax.figure
