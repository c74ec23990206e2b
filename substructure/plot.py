"""Matplotlib figures of the objects of `substructure`, returned and never shown.

:func:`plot_frf` draws FRFs for a person to read: the magnitude on a
logarithmic scale over the phase (``kind="bode"``), the real and imaginary
parts (``kind="real-imag"``) or the Nyquist plane (``kind="nyquist"``), in
um/N by default (``unit=``), with plain-language axis labels and the
technical names in a small note; limits of the value axes are given with
their units (``limits=("0.01 um/N", "1e-3 m/N")``) and converted to the
unit shown.  A free-free FRF's rigid-body (mass) line,
which rises without bound toward 0 Hz, is detected and left out of the
autoscaling (it is still drawn, in a shaded band), so the modes fill the
axes.  Passing the axes of an earlier figure (or the figure itself)
overlays further FRFs, e.g. a model over a measurement.  Library code never
calls ``plt.show()``; scripts save or show the figure.
"""

from __future__ import annotations

import textwrap
from collections.abc import Sequence
from typing import Any

import matplotlib.pyplot as plt
import numpy as np
from matplotlib.axes import Axes
from matplotlib.figure import Figure

from ._text import plain_text
from .errors import InvalidValueError, UnitError
from .frf import FRF
from .units import to_si

__all__ = ["plot_frf", "plot_identification", "plot_taps", "rigid_body_cutoff", "FRF_UNITS"]

PARTS = ("magnitude", "phase", "real", "imag")
KINDS = {"bode": ("magnitude", "phase"), "real-imag": ("real", "imag"), "nyquist": ("nyquist",)}
FRF_UNITS = {"m/N": 1.0, "mm/N": 1e3, "um/N": 1e6, "µm/N": 1e6, "nm/N": 1e9}
"""Display units of translational FRFs (displacement per force) and their factors from m/N."""
_LENGTH = {"m/N": "m", "mm/N": "mm", "um/N": "µm", "µm/N": "µm", "nm/N": "nm"}
_NAMES = {  # plain name, symbol, definition (for the note)
    "receptance": ("receptance", "H", "displacement / force"),
    "mobility": ("mobility", "Y", "velocity / force"),
    "accelerance": ("accelerance", "A", "acceleration / force"),
}
_RIGID_GID = "substructure-rigid-body-region"
_NOTE_GID = "substructure-note"


def _axes_for(ax: Any, parts: Sequence[str]) -> list[Axes]:
    if ax is None:
        if parts == ("nyquist",):
            fig, axis = plt.subplots(figsize=(6.4, 6.4), layout="constrained")
            return [axis]
        fig, axes = plt.subplots(len(parts), 1, sharex=True, squeeze=False,
                                 figsize=(7.0, 2.2 + 1.8 * len(parts)), layout="constrained")
        return list(axes[:, 0])
    if isinstance(ax, Figure):
        ax = ax.axes
    axes = [ax] if isinstance(ax, Axes) else list(np.ravel(np.asarray(ax, dtype=object)))
    if len(axes) != len(parts) or not all(isinstance(a, Axes) for a in axes):
        raise InvalidValueError(
            f"ax: got {len(axes)} axes for the {len(parts)} panel(s) {tuple(parts)}; pass one "
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
    out = []
    for end, value in zip(("lower", "upper"), limits):
        if value is None:
            out.append(None)
            continue
        try:
            out.append(to_si(value, f"limits ({end})", si_units[0]) * factor)
        except UnitError as exc:
            raise UnitError(f"{exc} (the axes show {shown}; write e.g. '100 {shown}')") from None
    return out[0], out[1]


def _autoscale(axes: list[Axes], parts: Sequence[str]) -> None:
    """Limits from every line's data above its rigid-body cutoff (lines keep theirs as an attribute)."""
    for part, axis in zip(parts, axes):
        if part == "phase":
            continue
        lines = [ln for ln in axis.lines if hasattr(ln, "_substructure_freq")]
        if not any(getattr(ln, "_substructure_cutoff", None) for ln in lines):
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


def plot_frf(
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
    """Plot entries of an FRF: Bode (magnitude and phase), real and imaginary parts, or Nyquist.

    Parameters
    ----------
    frf : FRF
        The FRF to draw.
    ax : Axes, sequence of Axes, Figure or None
        Where to draw: one Axes per panel, in the order of the panels (an
        earlier figure or its ``fig.axes`` overlays); ``None`` makes a new
        figure.
    entries : sequence of (output, input), optional
        Entries to draw; all of them by default.
    parts : sequence of {"magnitude", "phase", "real", "imag"}, optional
        Panels from top to bottom, overriding ``kind`` (magnitude on a log
        scale, phase in degrees).
    label : str, optional
        Legend label; with several entries each line gets ``"label out / in"``.
        Without a label, lines are labelled ``"out / in"`` when there are
        several entries.  A legend is drawn on the first panel when any line
        is labelled.
    kind : {"bode", "real-imag", "nyquist"}
        ``"bode"``: magnitude (log scale) over phase against frequency;
        ``"real-imag"``: real and imaginary parts against frequency;
        ``"nyquist"``: imaginary against real part, one panel.
    unit : {"um/N", "m/N", "mm/N", "nm/N"}
        Display unit of translational entries (displacement per force; also
        for mobility and accelerance, whose length unit it sets); rotational
        entries stay in SI (``1/N``, ``1/(N m)``).  Values convert exactly
        (factors 1, 1e3, 1e6, 1e9 from m/N).
    title : str, optional
        Figure title, wrapped to the figure width.
    note : bool
        Add a small note with the technical names (the symbol and its
        definition, the entries, the rigid-body region when one is excluded
        from the scale).
    limits : (lower, upper), optional
        Limits of the value axis of the magnitude, real and imaginary panels
        (of both axes of a Nyquist plot), each a quantity with its unit
        (``"0.01 um/N"``, ``"1e-3 m/N"``, a pint Quantity) or None to keep
        the automatic one; converted to the display unit ``unit``, so that a
        limit means the same whatever unit the axes show.  A bare number is
        refused (its unit would be a guess).  The phase panel keeps its own.
    **line_kw
        Passed to ``Axes.plot`` (``color``, ``linestyle``, ...).

    Returns
    -------
    matplotlib.figure.Figure
        The figure (never shown by the library).

    Notes
    -----
    When an entry starts with a free-free rigid-body (mass) line
    (:func:`rigid_body_cutoff`), the magnitude, real, imaginary and Nyquist
    axes are scaled on the data above it; the line is still drawn, in a
    shaded band.
    """
    if not isinstance(frf, FRF):
        raise InvalidValueError(f"frf: got {type(frf).__name__}; expected an FRF")
    if kind not in KINDS:
        raise InvalidValueError(f"kind: got {kind!r}; expected one of {', '.join(KINDS)}")
    if unit not in FRF_UNITS:
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
    entries = [tuple(e) for e in entries]
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
            line._substructure_freq = hz
            line._substructure_cutoff = cutoff
    plain, symbol, definition = _NAMES[frf.quantity]
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
    fig = axes[0].figure
    if any(line.get_label() and not line.get_label().startswith("_") for line in axes[0].lines):
        axes[0].legend(fontsize="small")
    if title is not None:
        fig.suptitle(plain_text(_wrap(str(title), 0.9 * fig.get_figwidth(), plt.rcParams["figure.titlesize"]
                                      if isinstance(plt.rcParams["figure.titlesize"], (int, float)) else 12.0)))
    if note:
        earlier = [t for t in axes[-1].texts if t.get_gid() == _NOTE_GID]
        text = f"{symbol} = {definition} ({frf.quantity}), time convention x(t) = X exp(i omega t)"
        if len(entries) == 1 and not earlier:
            text += f"; response {entries[0][0]}, excitation {entries[0][1]}"
        found = [ln._substructure_cutoff for a in axes for ln in a.lines
                 if getattr(ln, "_substructure_cutoff", None) is not None]
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


_UNITS = {"k_yf": "N/m", "k_ym": "N", "k_tf": "N/rad", "k_tm": "N m/rad",
          "c_yf": "N s/m", "c_ym": "N s", "c_tf": "N s/rad", "c_tm": "N m s/rad"}


def plot_identification(result, names=("k_yf", "c_yf"), band=None, fitted=None, ax=None,
                        measured: FRF | None = None) -> Figure:
    """Closed-form joint parameters against frequency, with the band and fitted constants.

    Parameters
    ----------
    result : substructure.identify.ClosedFormResult
        The closed form's stiffness at every line.
    names : sequence of str
        Parameters to draw, one panel each.
    band : (lo, hi), optional
        Shaded band (the one the fit used).
    fitted : mapping, optional
        Fitted constant values (SI) drawn as horizontal lines, with
        ``fitted[name + "_std"]`` as a shaded one-sigma strip when given.
    ax : Axes or sequence of Axes, optional
        One Axes per name; a new figure when None.
    measured : FRF, optional
        A measured point FRF drawn on a second axis of each panel, as the
        thesis's figures 2.8-2.9 do, to show where the modes are.

    Returns
    -------
    Figure
        The figure: k in N/m (or N, N/rad, N m/rad), c in N s/m (and so on) against Hz.
    """
    names = list(names)
    if ax is None:
        fig, axes = plt.subplots(len(names), 1, sharex=True, squeeze=False,
                                 figsize=(7.0, 1.5 + 2.2 * len(names)), layout="constrained")
        axes = list(axes[:, 0])
    else:
        axes = [ax] if isinstance(ax, Axes) else list(ax)
        fig = axes[0].figure
    f = result.frequency.hz
    bad = result.ill_conditioned()
    for a, name in zip(axes, names):
        values = result.parameter(name)
        a.plot(f, values, lw=0.8, color="0.35", label="closed form (eq. 2.3)")
        if np.any(bad):
            a.plot(f[bad], values[bad], ".", ms=2, color="tab:red", label="ill-conditioned lines")
        if band is not None:
            a.axvspan(*band, color="tab:green", alpha=0.12, label="fit band")
            inside = result.frequency.band_mask(*band)
            lo, hi = np.percentile(values[inside], [5, 95]) if inside.any() else (values.min(), values.max())
            span = max(hi - lo, abs(hi) * 0.5, 1e-30)
            a.set_ylim(lo - 2 * span, hi + 2 * span)
        if fitted is not None and name in fitted:
            v = fitted[name]
            a.axhline(v, color="tab:blue", lw=1.5, label=f"band fit {v:.4g}")
            sd = fitted.get(name + "_std")
            if sd:
                a.axhspan(v - sd, v + sd, color="tab:blue", alpha=0.15)
        a.set_ylabel(f"{name} [{_UNITS.get(name, '')}]")
        a.grid(True, alpha=0.3)
        if measured is not None:
            twin = a.twinx()
            twin.semilogy(measured.frequency.hz, np.abs(measured.data[:, 0, 0]), color="tab:orange", lw=0.6,
                          alpha=0.7)
            twin.set_ylabel("|H| [m/N]", color="tab:orange")
    axes[0].legend(loc="best", fontsize="small")
    axes[-1].set_xlabel("frequency [Hz]")
    return fig


def plot_taps(result, title: str | None = None, unit: str = "um/N") -> Figure:
    """Four panels for a person to check a tap test (:mod:`substructure.tap`); returns the Figure.

    Top to bottom, on one frequency axis: each kept tap's force spectrum in
    dB with the hammer's usable band marked, the coherence, and the
    receptance's magnitude and phase drawn by :func:`plot_frf` (its units,
    labels and rigid-body line left out of the scale).

    Parameters
    ----------
    result : substructure.tap.TapResult
        The processed taps.
    title : str, optional
        The figure's title (the estimator, the taps and the window follow it).
    unit : {"um/N", "m/N", "mm/N", "nm/N"}
        Unit of the magnitude axis.

    Returns
    -------
    matplotlib.figure.Figure
        The figure, never shown.
    """
    fig, axes = plt.subplots(4, 1, sharex=True, figsize=(7.5, 9.5), layout="constrained",
                             gridspec_kw={"height_ratios": [1.2, 0.8, 1.5, 1.0]})
    ax_f, ax_c, ax_m, ax_p = axes
    hz = result.frf.frequency.hz
    kept = [t for t in result.taps if t.kept]
    for tap, spectrum in zip(kept, result.force_spectra_db):
        ax_f.plot(hz, spectrum, lw=0.8, label=f"tap {tap.number} ({tap.peak_force:.0f} N)")
    ax_f.axvline(result.hammer_band_hz, color="0.4", ls="--", lw=0.8,
                 label=f"usable band: {result.hammer_band_hz:.0f} Hz (-{result.hammer_band_db:g} dB)")
    ax_f.set_ylabel("force spectrum\n[dB re 1 N/Hz]")
    ax_f.legend(fontsize=7, ncol=2, loc="lower left")
    ax_c.plot(hz, result.coherence, color="C2", lw=0.8)
    ax_c.set_ylim(-0.02, 1.02)
    ax_c.set_ylabel("coherence")
    for ax in (ax_f, ax_c):
        ax.grid(True, alpha=0.3)
    plot_frf(result.frf, ax=[ax_m, ax_p], unit=unit, note=False)
    rejected = len(result.rejected)
    about = (f"{result.estimator}, {result.averages} taps averaged" + (f", {rejected} rejected" if rejected else "")
             + (f"; exponential window tau = {result.tau:.4g} s" if result.tau else "; no exponential window"))
    fig.suptitle(plain_text((f"{title}\n" if title else "") + about), fontsize=10)
    return fig
