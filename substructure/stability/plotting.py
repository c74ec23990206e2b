"""Matplotlib figures of stability lobes, returned and never shown.

:func:`plot_lobes` draws the depth limit (mm) against spindle speed (rpm) for
one or several results on one axes, so that lobes from different FRFs (a
measurement and a model, with and without a sensor) can be compared;
:func:`plot_band` shades the spread of a :class:`~substructure.stability.result.LobesBand`;
:func:`plot_recommendation` marks a recommended speed and depth with its
safe window.  Depths below a curve are stable.  Labels are plain language
("zero-order", "semi-discretization"), with the technical name in a small
note; titles wrap; the depth axis always shows the recommendation.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import textwrap

import matplotlib.pyplot as plt
import numpy as np
from matplotlib.axes import Axes
from matplotlib.figure import Figure

from ..errors import InvalidValueError
from .._text import plain_text

__all__ = ["plot_lobes", "plot_band", "plot_recommendation", "plot_machine_limits", "METHOD_NAMES"]

METHOD_NAMES = {
    "zoa": ("zero-order", "zero-order approximation (Altintas & Budak 1995), 'zoa'"),
    "sdm": ("semi-discretization", "semi-discretization (Insperger & Stepan 2004), 'sdm'"),
}
"""Plain-language legend name and the technical note of each method."""


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
    ax.set_ylabel("axial depth of cut [mm]\n(stable below the curve)")
    ax.set_ylim(bottom=0.0)
    ax.grid(True, alpha=0.3)
    if any(not str(line.get_label()).startswith("_") for line in ax.lines + ax.collections):
        ax.legend(fontsize="small")


def wrap_title(ax: Axes, text: str, width: int = 95, **kw: Any) -> None:
    """Set a title wrapped to lines of at most ``width`` characters (nothing is cut off).

    Parameters
    ----------
    ax : Axes
    text : str
        The title, as plain text (a ``$`` is a dollar sign, not mathematics).
    width : int, default 95
        Characters per line.
    **kw
        Passed to ``Axes.set_title``.
    """
    ax.set_title(plain_text("\n".join(textwrap.wrap(" ".join(str(text).split()), width))), fontsize="small", **kw)


def _label(r: Any) -> str:
    return plain_text(r.label or METHOD_NAMES.get(r.method, (r.method, ""))[0])


def plot_lobes(results: Sequence[Any], ax: Any = None, lobes: bool = False, ylim_factor: float = 3.0,
               recommendation: Any = None, title: str | None = None, limits: Any = None, cut: Any = None,
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
        that the near-vertical lobe flanks do not flatten the plot; it is
        raised to show the recommendation and its window.
    recommendation : Recommendation, optional
        Mark it with its safe window (:func:`plot_recommendation`).
    title : str, optional
        Wrapped to the width of the figure.
    limits : MachineLimits, optional
        Draw the machine's limits (:func:`plot_machine_limits`).
    cut : MillingCut, optional
        With ``limits`` and a feed per tooth: the depth the spindle's power
        and torque allow is drawn too.
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
        (line,) = ax.plot(r.spindle_speed_rpm, depth, label=_label(r), **line_kw)
        if lobes:
            for n, a in r.lobes:
                ax.plot(n, a * 1e3, lw=0.5, alpha=0.35, color=line.get_color(), label="_lobe")
        if r.absolute_limit_m is not None and np.isfinite(r.absolute_limit_m):
            ax.axhline(r.absolute_limit_m * 1e3, lw=0.8, ls=":", color=line.get_color(),
                       label="stable at every speed" if not overlay and r is results[0] else "_absolute")
        finite = depth[np.isfinite(depth)]
        if finite.size:
            top = max(top, ylim_factor * float(np.median(finite)))
    ax.set_xlim(min([left] + [r.spindle_speed_rpm[0] for r in results]),
                max([right] + [r.spindle_speed_rpm[-1] for r in results]))
    if top > 0:
        ax.set_ylim(0.0, top)
    notes = sorted({METHOD_NAMES[r.method][1] for r in results if r.method in METHOD_NAMES})
    bands = [r.band for r in results if getattr(r, "band", None) is not None and r.band.excluded_hz is not None]
    if bands:
        notes.append(f"FRF lines below {bands[0].lo_hz:.4g} Hz ({bands[0].kind}: rigid-body/suspension) left out")
    if notes and not overlay:
        ax.text(0.0, -0.2, "; ".join(notes), transform=ax.transAxes, fontsize="x-small", color="0.35",
                va="top", wrap=True)
    if limits is not None:
        plot_machine_limits(limits, cut=cut, ax=ax)
    if recommendation is not None:
        plot_recommendation(recommendation, ax=ax)
    if title is not None:
        wrap_title(ax, title)
    _finish(ax)
    return ax.figure


def plot_machine_limits(limits: Any, cut: Any = None, ax: Any = None) -> Figure:
    """Draw what the machine allows on a lobe plot: the speeds outside its range shaded, the largest depth, and
    (with a cut that has a feed per tooth) the depth its power and torque allow at each speed.

    Parameters
    ----------
    limits : MachineLimits
        The machine's limits.
    cut : MillingCut, optional
        For the power and torque limit: the cut with ``feed_per_tooth``.
    ax : Axes or Figure, optional
        Usually the axes of :func:`plot_lobes` (its speed axis is used).

    Returns
    -------
    matplotlib.figure.Figure
        The figure; the depth axis is left as it was.
    """
    from .machine import cut_power, cut_torque

    ax = _axes(ax)
    left, right = ax.get_xlim()
    bottom, top = ax.get_ylim()
    grey = {"color": "0.5", "alpha": 0.18, "lw": 0}
    if limits.max_speed is not None and limits.max_speed < right:
        ax.axvspan(limits.max_speed, right, label=f"above the machine's {limits.max_speed:,.0f} rpm", **grey)
    if limits.min_speed is not None and limits.min_speed > left:
        ax.axvspan(left, limits.min_speed, label=f"below the machine's {limits.min_speed:,.0f} rpm", **grey)
    if np.isfinite(limits.max_depth_m) and limits.max_depth_m * 1e3 < top:
        ax.axhline(limits.max_depth_m * 1e3, color="0.3", lw=0.9, ls="-.", label="largest depth")
    has_feed = cut is not None and getattr(cut, "feed_per_tooth", None) is not None
    if has_feed and (limits.power is not None or limits.torque is not None):
        n = np.linspace(max(left, 1.0), right, 400)
        with np.errstate(divide="ignore", invalid="ignore"):
            by_power = limits.power_w(n) / cut_power(cut, 1.0, n)
            by_torque = limits.torque_nm(n) / cut_torque(cut, 1.0, n)
        depth = np.minimum(by_power, by_torque) * 1e3
        if np.any(depth < top):
            ax.plot(n, np.where(np.isfinite(depth), depth, np.nan), color="tab:red", lw=1.0, ls="--",
                    label="depth the spindle's power/torque allow")
    ax.set_xlim(left, right)
    ax.set_ylim(bottom, top)
    _finish(ax)
    return ax.figure


def plot_recommendation(recommendation: Any, ax: Any = None, runners_up: bool = True) -> Figure:
    """Mark a recommended speed and depth, its speed window and the limit it keeps a margin from.

    Parameters
    ----------
    recommendation : Recommendation
    ax : Axes or Figure, optional
        Usually the axes of :func:`plot_lobes`.
    runners_up : bool, default True
        Also mark the runners-up (smaller, numbered).

    Returns
    -------
    matplotlib.figure.Figure
        The depth axis is raised, where needed, so that the point, its window
        and the limit are inside it.
    """
    ax = _axes(ax)
    r = recommendation
    n, a = r.spindle_speed_rpm, r.depth_m * 1e3
    lo, hi = r.window_rpm
    ax.fill_between([lo, hi], 0.0, a, color="tab:green", alpha=0.18, lw=0,
                    label=f"safe window: +-{r.speed_tolerance:.0%} speed, {r.margin:.0%} depth margin")
    if np.isfinite(r.limit_depth_m):
        ax.plot([lo, hi], [r.limit_depth_m * 1e3] * 2, color="tab:green", lw=1.0, ls="--", label="_limit")
    ax.plot([n], [a], marker="*", ms=14, color="tab:green", mec="k", ls="none",
            label=f"recommended: {n:,.0f} rpm, {a:.3g} mm")
    top = a
    if runners_up:
        for k, other in enumerate(r.runners_up, 1):
            ax.plot([other.spindle_speed_rpm], [other.depth_m * 1e3], marker="o", ms=6, color="tab:olive",
                    mec="k", ls="none", label="runners-up" if k == 1 else "_runner")
            ax.annotate(str(k), (other.spindle_speed_rpm, other.depth_m * 1e3), textcoords="offset points",
                        xytext=(5, 5), fontsize="x-small")
            top = max(top, other.depth_m * 1e3)
    limit = r.limit_depth_m * 1e3 if np.isfinite(r.limit_depth_m) else a
    needed = 1.25 * max(top, limit, r.limit_at_speed_m * 1e3 if np.isfinite(r.limit_at_speed_m) else 0.0)
    bottom, current = ax.get_ylim()
    if needed > current:
        ax.set_ylim(0.0, needed)
    left, right = ax.get_xlim()
    if lo < left or hi > right:
        ax.set_xlim(min(left, lo), max(right, hi))
    _finish(ax)
    return ax.figure


def plot_band(band: Any, ax: Any = None, color: str | None = None, alpha: float = 0.25, **line_kw: Any) -> Figure:
    """Shade ``band.lower_m .. band.upper_m`` and draw ``band.nominal`` as a line."""
    ax = _axes(ax)
    n = band.spindle_speed_rpm
    lo = np.where(np.isfinite(band.lower_m), band.lower_m, np.nan) * 1e3
    hi = np.where(np.isfinite(band.upper_m), band.upper_m, np.nan) * 1e3
    fill = ax.fill_between(n, lo, hi, color=color, alpha=alpha, lw=0, label=plain_text(band.label or "band"))
    if band.nominal is not None:
        plot_lobes([band.nominal], ax=ax, color=fill.get_facecolor()[0][:3], **line_kw)
    else:
        ax.set_xlim(n[0], n[-1])
        finite = hi[np.isfinite(hi)]
        if finite.size:
            ax.set_ylim(0.0, max(ax.get_ylim()[1], 3.0 * float(np.median(finite))))
    _finish(ax)
    return ax.figure
