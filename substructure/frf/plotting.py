"""The drawing of FRFs (internal): :func:`substructure.plot.plot_frf` and :meth:`FRF.plot`.

In the ``frf`` layer, so that ``FRF.plot`` draws without importing ``substructure.plot`` (a module
of a higher layer, which imports ``frf``); ``substructure.plot`` checks its input and calls
:func:`draw_frf`, and its figures of other objects use the helpers here.  Matplotlib is imported
with this module, which ``FRF.plot`` imports on first use.
"""

from __future__ import annotations

import textwrap
from collections.abc import Sequence
from typing import TYPE_CHECKING, Any, cast

import matplotlib.pyplot as plt
import numpy as np
from matplotlib.axes import Axes
from matplotlib.figure import Figure

from .._text import plain_text
from ..errors import InvalidValueError, UnitError
from ..units import to_si

if TYPE_CHECKING:  # response imports this module (FRF.plot); the annotations only
    from .response import FRF


PARTS = ("magnitude", "phase", "real", "imag")
KINDS = {"bode": ("magnitude", "phase"), "real-imag": ("real", "imag"), "nyquist": ("nyquist",)}
FRF_UNITS = {"m/N": 1.0, "mm/N": 1e3, "um/N": 1e6, "µm/N": 1e6, "nm/N": 1e9}
"""Display units of translational FRFs (displacement per force) and their factors from m/N."""
_LENGTH = {"m/N": "m", "mm/N": "mm", "um/N": "µm", "µm/N": "µm", "nm/N": "nm"}
_NAMES = {"receptance": ("receptance", "H"), "mobility": ("mobility", "Y"), "accelerance": ("accelerance", "A")}
"""Plain name and symbol of each quantity (the note's definition follows the DOFs drawn: :func:`_definition`)."""
_MOTIONS = {"receptance": ("displacement", "rotation"), "mobility": ("velocity", "angular velocity"),
            "accelerance": ("acceleration", "angular acceleration")}


def _definition(quantity: str, entries: Sequence[tuple[str, str]]) -> str:
    """What the entries drawn are, per their DOFs: ``displacement / force``, ``rotation / moment``, or both words
    where the entries mix them (a label without ``:theta`` is a translation)."""
    def words(labels, pair) -> str:
        kinds = sorted({pair[1] if str(label).endswith(":theta") else pair[0] for label in labels},
                       key=pair.index)
        return " or ".join(kinds) if kinds else pair[0]

    return (f"{words([o for o, _ in entries], _MOTIONS[quantity])} / "
            f"{words([i for _, i in entries], ('force', 'moment'))}")


_RIGID_GID = "substructure-rigid-body-region"
_NOTE_GID = "substructure-note"


def _axes_for(ax: Any, parts: Sequence[str]) -> list[Axes]:
    if ax is None:
        if parts == ("nyquist",):
            return [plt.subplots(figsize=(6.4, 6.4), layout="constrained")[1]]
        _, grid = plt.subplots(len(parts), 1, sharex=True, squeeze=False,
                               figsize=(7.0, 2.2 + 1.8 * len(parts)), layout="constrained")
        return list(grid[:, 0])
    return given_axes(ax, parts)


def given_axes(ax: Any, panels: Sequence[str]) -> list[Axes]:
    """The Axes a caller gave to draw ``panels`` on: one Axes, a Figure (its axes) or a sequence of Axes, one per
    panel; anything else is refused naming ``ax`` (before any drawing).

    Parameters
    ----------
    ax : matplotlib Axes, Figure or sequence of Axes
        What was given.
    panels : sequence of str
        The panels to draw, for the count and the message.

    Returns
    -------
    list of Axes
        One per panel.
    """
    if isinstance(ax, Figure):
        ax = ax.axes
    axes = [ax] if isinstance(ax, Axes) else list(np.ravel(np.asarray(ax, dtype=object)))
    if len(axes) != len(panels) or not all(isinstance(a, Axes) for a in axes):
        raise InvalidValueError(
            f"ax: got {len(axes)} axes for the {len(panels)} panel(s) {tuple(panels)}; pass one "
            "Axes per panel (e.g. fig.axes of an earlier plot) or choose parts to match"
        )
    return axes


def rigid_body_cutoff(frequency_hz: np.ndarray, magnitude: np.ndarray) -> float | None:
    """Upper end of a free-free FRF's rigid-body (mass) line, or None when there is none.

    A free body's receptance is ``-1/(m omega^2)``: from the lowest line the
    magnitude falls with a log-log slope near -2 down to the first
    antiresonance, where the flexible modes take over.  When the first lines
    fall like that (slope between -2.5 and -1.5), the region ends at the
    first local minimum of the magnitude; a structure on supports (flat,
    static compliance at low frequency) has none.

    Parameters
    ----------
    frequency_hz : ndarray
        Increasing frequencies in Hz, > 0.
    magnitude : ndarray
        ``|FRF|`` at those frequencies.

    Returns
    -------
    float or None
        The frequency in Hz of the first minimum after the mass line, or None.
    """
    f = np.asarray(frequency_hz, dtype=float)
    m = np.asarray(magnitude, dtype=float)
    if f.size < 5 or f[0] <= 0 or np.any(m <= 0) or not np.all(np.isfinite(m)):
        return None
    slope = np.diff(np.log(m)) / np.diff(np.log(f))
    if not -2.5 < float(np.median(slope[:3])) < -1.5:
        return None
    rising = np.nonzero(slope > 0)[0]
    if rising.size == 0 or rising[0] == 0:
        return None
    return float(f[rising[0]])


def _scaled(frf: FRF, output: str, input_: str, unit: str) -> tuple[float, str]:
    """Factor from SI and the display unit of one entry (translational outputs scale, rotations stay SI)."""
    si = frf.unit(output, input_)
    if si.startswith("m/"):
        return FRF_UNITS[unit], _LENGTH[unit] + si[1:]
    return 1.0, si


def _wrap(text: str, width_in: float, fontsize: float = 12.0) -> str:
    """Text wrapped to about ``width_in`` inches at ``fontsize`` points (average glyph 0.55 em)."""
    width = max(20, int(width_in * 72 / (0.55 * fontsize)))
    return "\n".join(textwrap.wrap(text, width))


def _limits(values: list[np.ndarray], log: bool) -> tuple[float, float] | None:
    data = np.concatenate([v[np.isfinite(v)] for v in values]) if values else np.empty(0)
    if log:
        data = data[data > 0]
    if data.size == 0:
        return None
    lo, hi = float(data.min()), float(data.max())
    if log:
        return lo / 2.0, hi * 2.0
    pad = 0.08 * (hi - lo) if hi > lo else max(abs(hi), 1e-300) * 0.1
    return lo - pad, hi + pad


def _display_limits(limits: Any, si_units: list[str], factor: float, shown: str) -> tuple[Any, Any]:
    """``limits`` (quantities or None) as numbers in the display unit of the axes."""
    if isinstance(limits, (str, bytes)) or not isinstance(limits, Sequence) or len(limits) != 2:
        raise InvalidValueError(
            f"limits: got {limits!r}; expected a pair (lower, upper) of quantities with their units, "
            "e.g. ('0.01 um/N', '100 um/N'), either of them None"
        )
    if len(set(si_units)) != 1:
        raise InvalidValueError(
            f"limits: the entries drawn have different units ({', '.join(sorted(set(si_units)))}); "
            "draw them in separate figures to set limits"
        )
    out: list[float | None] = []
    for end, value in zip(("lower", "upper"), limits):
        if value is None:
            out.append(None)
            continue
        try:
            out.append(to_si(value, f"limits ({end})", si_units[0]) * factor)
        except UnitError as exc:
            raise UnitError(f"{exc} (the axes show {shown}; write e.g. '100 {shown}')") from None
    return out[0], out[1]


def _mark(line: Any, hz: np.ndarray, cutoff: float | None) -> None:
    """Keep a line's frequencies and rigid-body cutoff on it, for later autoscaling of overlays."""
    line._substructure_freq = hz
    line._substructure_cutoff = cutoff


def _cutoff(line: Any) -> float | None:
    return getattr(line, "_substructure_cutoff", None)


def _autoscale(axes: list[Axes], parts: Sequence[str]) -> None:
    """Limits from every line's data above its rigid-body cutoff (lines keep theirs as an attribute)."""
    for part, axis in zip(parts, axes):
        if part == "phase":
            continue
        lines: list[Any] = [ln for ln in axis.lines if hasattr(ln, "_substructure_freq")]
        if not any(_cutoff(ln) for ln in lines):
            continue
        if part == "nyquist":
            keep = [ln._substructure_freq > (ln._substructure_cutoff or -np.inf) for ln in lines]
            xs = _limits([np.asarray(ln.get_xdata())[k] for ln, k in zip(lines, keep)], False)
            ys = _limits([np.asarray(ln.get_ydata())[k] for ln, k in zip(lines, keep)], False)
            if xs and ys:
                axis.set_xlim(*xs)
                axis.set_ylim(*ys)
            continue
        keep = [np.asarray(ln.get_xdata()) > (ln._substructure_cutoff or -np.inf) for ln in lines]
        lim = _limits([np.asarray(ln.get_ydata())[k] for ln, k in zip(lines, keep)], part == "magnitude")
        if lim:
            axis.set_ylim(*lim)
        cutoff = max(ln._substructure_cutoff or 0.0 for ln in lines)
        if not any(p.get_gid() == _RIGID_GID for p in axis.patches):
            x0 = min(float(np.min(ln.get_xdata())) for ln in lines)
            axis.axvspan(x0, cutoff, color="0.5", alpha=0.08, lw=0, gid=_RIGID_GID)


def draw_frf(
    frf: FRF,
    ax: Any = None,
    entries: Sequence[tuple[str, str]] | None = None,
    parts: Sequence[str] | None = None,
    label: str | None = None,
    *,
    kind: str = "bode",
    unit: str = "um/N",
    title: str | None = None,
    note: bool = True,
    limits: Sequence[Any] | None = None,
    **line_kw: Any,
) -> Figure:
    """Draw entries of an FRF (the options of :func:`substructure.plot.plot_frf`); returns the Figure."""
    if not isinstance(kind, str) or kind not in KINDS:
        raise InvalidValueError(f"kind: got {kind!r}; expected one of {', '.join(KINDS)}")
    if not isinstance(unit, str) or unit not in FRF_UNITS:
        raise InvalidValueError(f"unit: got {unit!r}; expected one of {', '.join(FRF_UNITS)}")
    if parts is None:
        parts = KINDS[kind]
    else:
        parts = tuple(parts)
        unknown = [p for p in parts if p not in PARTS]
        if kind == "nyquist" or not parts or unknown:
            raise InvalidValueError(
                f"parts: got {parts!r}; expected a non-empty subset of {PARTS} (and no parts with kind='nyquist')"
            )
    if entries is None:
        entries = [(o, i) for o in frf.outputs for i in frf.inputs]
    entries = [cast("tuple[str, str]", tuple(e)) for e in entries]
    values = [frf.entry(o, i) for o, i in entries]  # raises UnknownPointError for bad labels
    scales = [_scaled(frf, o, i, unit) for o, i in entries]
    units = sorted({u for _, u in scales})
    shown = units[0] if len(units) == 1 else "mixed units"
    if limits is not None:
        limits = _display_limits(limits, [frf.unit(o, i) for o, i in entries], scales[0][0], shown)
        low = [v for v in limits if v is not None and v <= 0]
        if "magnitude" in parts and low:
            raise InvalidValueError(
                f"limits: got {low[0]:g} {shown}; the magnitude axis is logarithmic: its limits must be > 0"
            )
    axes = _axes_for(ax, parts)
    hz = frf.frequency.hz
    for (output, input_), y, (factor, _) in zip(entries, values, scales):
        name = f"{output} / {input_}"
        text = (label if len(entries) == 1 else f"{label} {name}") if label else (
            name if len(entries) > 1 else None)
        text = None if text is None else plain_text(text)  # names are plain text, never mathtext
        cutoff = rigid_body_cutoff(hz, np.abs(y))
        re, im = y.real * factor, y.imag * factor   # the SI values times an exact factor
        for part, axis in zip(parts, axes):
            if part == "magnitude":
                (line,) = axis.semilogy(hz, np.abs(y) * factor, label=text, **line_kw)
            elif part == "phase":
                (line,) = axis.plot(hz, np.angle(y, deg=True), label=text, **line_kw)
            elif part == "nyquist":
                (line,) = axis.plot(re, im, label=text, **line_kw)
            else:
                (line,) = axis.plot(hz, re if part == "real" else im, label=text, **line_kw)
            _mark(line, hz, cutoff)
    plain, symbol = _NAMES[frf.quantity]
    ylabels = {
        "magnitude": f"{plain} |{symbol}| ({shown})",
        "phase": "phase (deg)",
        "real": f"{plain}, real part ({shown})",
        "imag": f"{plain}, imaginary part ({shown})",
    }
    for part, axis in zip(parts, axes):
        axis.grid(True, which="both", alpha=0.3)
        if part == "nyquist":
            axis.set_xlabel(f"{plain}, real part ({shown})")
            axis.set_ylabel(f"{plain}, imaginary part ({shown})")
            axis.axhline(0.0, color="0.6", lw=0.5)
            axis.axvline(0.0, color="0.6", lw=0.5)
            continue
        axis.set_ylabel(ylabels[part])
        if part == "phase":
            axis.set_yticks([-180, -90, 0, 90, 180])
    if parts != ("nyquist",):
        axes[-1].set_xlabel("frequency (Hz)")
    _autoscale(axes, parts)
    if limits is not None:
        for part, axis in zip(parts, axes):
            if part != "phase":
                axis.set_ylim(*limits)
            if part == "nyquist":
                axis.set_xlim(*limits)
    fig = cast(Figure, axes[0].figure)  # the axes of a figure (a subfigure's have no width to wrap text in)
    if any(line.get_label() and not str(line.get_label()).startswith("_") for line in axes[0].lines):
        axes[0].legend(fontsize="small")
    if title is not None:
        fig.suptitle(plain_text(_wrap(str(title), 0.9 * fig.get_figwidth(), plt.rcParams["figure.titlesize"]
                                      if isinstance(plt.rcParams["figure.titlesize"], (int, float)) else 12.0)))
    if note:
        earlier = [t for t in axes[-1].texts if t.get_gid() == _NOTE_GID]
        text = (f"{symbol} = {_definition(frf.quantity, entries)} ({frf.quantity}), time convention "
                "x(t) = X exp(i omega t)")
        if len(entries) == 1 and not earlier:
            text += f"; response {entries[0][0]}, excitation {entries[0][1]}"
        found = [c for a in axes for ln in a.lines if (c := _cutoff(ln)) is not None]
        if found:
            where = "below" if parts == ("nyquist",) else "shaded, below"
            text += f"; {where} {max(found):.4g} Hz: rigid-body (mass) line, drawn but left out of the scale"
        for t in earlier:  # an overlay: one note for the figure
            t.remove()
        width = axes[-1].get_position().width * fig.get_figwidth()
        axes[-1].annotate(plain_text(_wrap(text, width, 8.5)), xy=(0.0, 0.0), xycoords="axes fraction", xytext=(0, -44),
                          textcoords="offset points", va="top", ha="left", fontsize="x-small", color="0.35",
                          annotation_clip=False, gid=_NOTE_GID)
    return fig
