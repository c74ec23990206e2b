"""Every panel of every figure an example saves shows data: no empty axes.

A panel is empty when none of its data (lines, collections, images,
patches drawn in data coordinates) lies within the axes' limits.  Data
that are all outside the limits count as empty: limits set in the wrong
unit (m/N on an axis drawn in um/N) leave a panel with its grid and labels
but no curve, and that is what a reader sees.  Reference lines and spans
that are drawn in axes coordinates in one direction (``axhline``,
``axvspan``, the shaded rigid-body band of ``plot_frf``) do not count:
they show on any limits.  A panel with its axis turned off that holds text,
a table or a legend is a text panel, not an empty plot.

:func:`install` wraps :meth:`matplotlib.figure.Figure.savefig` so that every
figure is checked as it is saved (the docs build does this around each
example, docs/_ext/gallery_support.py, and ``tests/test_examples.py`` in its
subprocesses); :func:`empty_axes` is the check itself.
"""

from __future__ import annotations

import functools

import numpy as np
from matplotlib.axes import Axes
from matplotlib.collections import Collection
from matplotlib.figure import Figure
from matplotlib.image import AxesImage
from matplotlib.lines import Line2D
from matplotlib.patches import Patch
from matplotlib.path import Path
from matplotlib.transforms import Bbox


class EmptyAxesError(ValueError):
    """A saved figure has a panel that shows no data within its limits."""


def _in_data_coordinates(transform, ax: Axes) -> bool:
    """True when ``transform`` maps data coordinates in both directions (not a span or an axhline)."""
    return transform == ax.transData or transform.contains_branch(ax.transData)


#: A line shows when this share of its segments, or of the panel's width, is within the limits:
#: less is a sliver (a steep flank crossing a panel whose limits miss the curve).
MIN_SHARE = 0.2
MIN_WIDTH = 0.05


def _clip_segments(verts: np.ndarray, box: Bbox) -> tuple[int, np.ndarray]:
    """Segments of a polyline (display coordinates) and the x of their parts within ``box``.

    Liang-Barsky clipping of every segment with finite ends at once.
    Returns the number of such segments and the x coordinates of the ends
    of the visible parts.
    """
    p0, p1 = verts[:-1], verts[1:]
    ok = np.all(np.isfinite(p0), axis=1) & np.all(np.isfinite(p1), axis=1)
    p0, p1 = p0[ok], p1[ok]
    d = p1 - p0
    lo, hi = np.zeros(len(d)), np.ones(len(d))
    with np.errstate(divide="ignore", invalid="ignore"):
        for axis, (a, b) in enumerate(((box.x0, box.x1), (box.y0, box.y1))):
            for bound, sign in ((a, -1.0), (b, 1.0)):
                p, q = sign * d[:, axis], sign * (bound - p0[:, axis])
                t = q / p
                parallel_out = (p == 0) & (q < 0)
                lo = np.where(p < 0, np.maximum(lo, t), lo)
                hi = np.where(p > 0, np.minimum(hi, t), hi)
                hi = np.where(parallel_out, -1.0, hi)
    seen = lo <= hi
    xs = np.concatenate([p0[seen, 0] + lo[seen] * d[seen, 0], p0[seen, 0] + hi[seen] * d[seen, 0]])
    return int(ok.sum()), xs


def _line_shows(verts: np.ndarray, box: Bbox, markers_only: bool) -> bool:
    """A polyline (or markers) shows when a fair share of it, or of the panel's width, is visible."""
    verts = np.asarray(verts, dtype=float).reshape(-1, 2)
    finite = verts[np.all(np.isfinite(verts), axis=1)]
    if markers_only or len(verts) < 2:
        inside = ((finite[:, 0] >= box.x0) & (finite[:, 0] <= box.x1)
                  & (finite[:, 1] >= box.y0) & (finite[:, 1] <= box.y1))
        count, xs = len(finite), finite[inside, 0]
        shown = int(inside.sum())
    else:
        count, xs = _clip_segments(verts, box)
        shown = xs.size // 2
    if shown == 0:
        return False
    width = (xs.max() - xs.min()) / max(box.width, 1e-9)
    return shown >= MIN_SHARE * count or width >= MIN_WIDTH


def _path_meets(path: Path, box: Bbox) -> bool:
    """Whether a filled path in display coordinates has a finite piece inside or across ``box``."""
    verts = np.asarray(path.vertices, dtype=float)
    if verts.size == 0 or not np.all(np.isfinite(verts)):
        verts = verts[np.all(np.isfinite(verts), axis=1)] if verts.size else verts
        if verts.size == 0:
            return False
        return Path(verts).intersects_bbox(box, filled=True)
    return path.intersects_bbox(box, filled=True)


def _shows(artist, ax: Axes, box: Bbox) -> bool | None:
    """True or False whether a data artist shows within the limits; None for decorations."""
    if not artist.get_visible() or artist.get_alpha() == 0:
        return None
    if isinstance(artist, Line2D):
        transform = artist.get_transform()
        if not _in_data_coordinates(transform, ax):
            return None
        path = transform.transform_path(artist.get_path())
        return _line_shows(path.vertices, box, artist.get_linestyle() in ("None", "none", " ", ""))
    if isinstance(artist, AxesImage):
        if not _in_data_coordinates(artist.get_transform(), ax):
            return None
        x0, x1, y0, y1 = artist.get_extent()
        corners = ax.transData.transform([[x0, y0], [x1, y1]])
        if not np.all(np.isfinite(corners)):
            return False
        return Bbox(corners).overlaps(box)
    if isinstance(artist, Collection):
        offsets = np.asarray(artist.get_offsets())
        if offsets.size and _in_data_coordinates(artist.get_offset_transform(), ax):
            return _line_shows(artist.get_offset_transform().transform(offsets), box, markers_only=True)
        transform = artist.get_transform()
        if not _in_data_coordinates(transform, ax):
            return None
        return any(_path_meets(transform.transform_path(p), box) for p in artist.get_paths())
    if isinstance(artist, Patch):
        if not _in_data_coordinates(artist.get_data_transform(), ax):
            return None
        return _path_meets(artist.get_transform().transform_path(artist.get_path()), box)
    return None


def _data_range(ax: Axes) -> str:
    """The extent of the panel's lines in data coordinates, for the message."""
    xs, ys = [], []
    for line in ax.lines:
        if _in_data_coordinates(line.get_transform(), ax):
            x = np.asarray(line.get_xdata(), dtype=float)
            y = np.asarray(line.get_ydata(), dtype=float)
            xs.append(x[np.isfinite(x)])
            ys.append(y[np.isfinite(y)])
    x, y = (np.concatenate(v) if v else np.empty(0) for v in (xs, ys))
    if not x.size or not y.size:
        return "no data lines"
    return f"its lines span x {x.min():.3g} to {x.max():.3g}, y {y.min():.3g} to {y.max():.3g}"


def _name(ax: Axes, index: int, count: int) -> str:
    words = [w for w in (ax.get_title(), ax.get_ylabel()) if w]
    return f"panel {index + 1} of {count}" + (f" ({' / '.join(words)})" if words else "")


def empty_axes(fig: Figure) -> list[str]:
    """Describe every visible panel of ``fig`` that shows no data within its limits.

    Parameters
    ----------
    fig : Figure
        The figure, drawn or not (its limits are brought up to date).

    Returns
    -------
    list of str
        One sentence per empty panel (its place, its limits and where its
        lines are); empty when every panel shows data.
    """
    fig.draw_without_rendering()  # final limits and layout, as in the saved file
    axes = [ax for ax in fig.axes if ax.get_visible()]
    problems = []
    for index, ax in enumerate(axes):
        artists = [*ax.lines, *ax.collections, *ax.images, *ax.patches]
        if not ax.axison and (ax.texts or ax.tables or ax.get_legend() is not None) :
            continue  # a text panel
        box = ax.bbox.frozen().padded(1.0)
        found = [_shows(a, ax, box) for a in artists]
        if any(found):
            continue
        xlim, ylim = ax.get_xlim(), ax.get_ylim()
        what = ("draws nothing" if not any(f is not None for f in found)
                else "shows no data within its limits, or only a sliver of them")
        problems.append(f"{_name(ax, index, len(axes))} {what}: limits x {xlim[0]:.3g} to {xlim[1]:.3g}, "
                        f"y {ylim[0]:.3g} to {ylim[1]:.3g}; {_data_range(ax)}")
    return problems


def check_figure(fig: Figure, name: str = "a figure") -> None:
    """Raise :class:`EmptyAxesError` when a panel of ``fig`` shows no data within its limits.

    Parameters
    ----------
    fig : Figure
        The figure.
    name : str
        How the message names it (its file name).
    """
    problems = empty_axes(fig)
    if problems:
        raise EmptyAxesError(f"{name}: " + "; ".join(problems)
                             + " (limits in another unit than the axis shows, e.g. m/N on a um/N axis?)")


_original_savefig = Figure.savefig


@functools.wraps(_original_savefig)
def _checked_savefig(self, fname, *args, **kwargs):
    result = _original_savefig(self, fname, *args, **kwargs)
    check_figure(self, str(getattr(fname, "name", fname)))
    return result


def install() -> None:
    """Check every figure when it is saved (``Figure.savefig``; ``pyplot.savefig`` goes through it)."""
    Figure.savefig = _checked_savefig


def uninstall() -> None:
    """Save figures without the check again."""
    Figure.savefig = _original_savefig
