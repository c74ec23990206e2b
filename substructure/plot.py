"""Matplotlib figures of the objects of `substructure`, returned and never shown.

:func:`plot_frf` draws FRFs as stacked panels sharing the frequency axis:
``|FRF|`` on a logarithmic scale over the phase in degrees by default, real
and imaginary parts on request.  Passing the axes of an earlier figure (or
the figure itself) overlays further FRFs, e.g. a model over a measurement.
Library code never calls ``plt.show()``; scripts save or show the figure.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import matplotlib.pyplot as plt
import numpy as np
from matplotlib.axes import Axes
from matplotlib.figure import Figure

from .errors import InvalidValueError
from .frf import FRF

__all__ = ["plot_frf", "plot_identification"]

PARTS = ("magnitude", "phase", "real", "imag")


def _axes_for(ax: Any, parts: Sequence[str]) -> list[Axes]:
    if ax is None:
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


def plot_frf(
    frf: FRF,
    ax: Any = None,
    entries: Sequence[tuple[str, str]] | None = None,
    parts: Sequence[str] = ("magnitude", "phase"),
    label: str | None = None,
    **line_kw: Any,
) -> Figure:
    """Plot entries of an FRF against frequency in Hz.

    Parameters
    ----------
    frf : FRF
        The FRF to draw.
    ax : Axes, sequence of Axes, Figure or None
        Where to draw: one Axes per panel, in the order of ``parts`` (an
        earlier figure or its ``fig.axes`` overlays); ``None`` makes a new
        figure.
    entries : sequence of (output, input), optional
        Entries to draw; all of them by default.
    parts : sequence of {"magnitude", "phase", "real", "imag"}
        Panels from top to bottom.  Magnitude is on a log scale; phase in
        degrees.
    label : str, optional
        Legend label; with several entries each line gets ``"label out / in"``.
        Without a label, lines are labelled ``"out / in"`` when there are
        several entries.  A legend is drawn on the first panel when any line
        is labelled.
    **line_kw
        Passed to ``Axes.plot`` (``color``, ``linestyle``, ...).

    Returns
    -------
    matplotlib.figure.Figure
    """
    if not isinstance(frf, FRF):
        raise InvalidValueError(f"frf: got {type(frf).__name__}; expected an FRF")
    parts = tuple(parts)
    unknown = [p for p in parts if p not in PARTS]
    if not parts or unknown:
        raise InvalidValueError(f"parts: got {parts!r}; expected a non-empty subset of {PARTS}")
    if entries is None:
        entries = [(o, i) for o in frf.outputs for i in frf.inputs]
    entries = [tuple(e) for e in entries]
    values = [frf.entry(o, i) for o, i in entries]  # raises UnknownPointError for bad labels
    units = sorted({frf.unit(o, i) for o, i in entries})
    unit = units[0] if len(units) == 1 else "mixed units"
    axes = _axes_for(ax, parts)
    hz = frf.frequency.hz
    for (output, input_), y in zip(entries, values):
        name = f"{output} / {input_}"
        text = (label if len(entries) == 1 else f"{label} {name}") if label else (
            name if len(entries) > 1 else None)
        for part, axis in zip(parts, axes):
            if part == "magnitude":
                axis.semilogy(hz, np.abs(y), label=text, **line_kw)
            elif part == "phase":
                axis.plot(hz, np.angle(y, deg=True), label=text, **line_kw)
            else:
                axis.plot(hz, y.real if part == "real" else y.imag, label=text, **line_kw)
    ylabels = {
        "magnitude": f"|{frf.quantity}| [{unit}]",
        "phase": "phase [deg]",
        "real": f"Re {frf.quantity} [{unit}]",
        "imag": f"Im {frf.quantity} [{unit}]",
    }
    for part, axis in zip(parts, axes):
        axis.set_ylabel(ylabels[part])
        if part == "phase":
            axis.set_yticks([-180, -90, 0, 90, 180])
        axis.grid(True, which="both", alpha=0.3)
    axes[-1].set_xlabel("frequency [Hz]")
    if any(line.get_label() and not line.get_label().startswith("_") for line in axes[0].lines):
        axes[0].legend(fontsize="small")
    return axes[0].figure


_UNITS = {"k_yf": "N/m", "k_ym": "N", "k_tf": "N/rad", "k_tm": "N m/rad",
          "c_yf": "N s/m", "c_ym": "N s", "c_tf": "N s/rad", "c_tm": "N m s/rad"}


def plot_identification(result, names=("k_yf", "c_yf"), band=None, fitted=None, ax=None,
                        measured: FRF | None = None) -> Figure:
    """Closed-form joint parameters against frequency, with the band and fitted constants.

    Parameters
    ----------
    result : substructure.identify.ClosedFormResult
    names : sequence of str
        Parameters to draw, one panel each.
    band : (lo, hi), optional
        Shaded band (the one the fit used).
    fitted : mapping, optional
        Fitted constant values (SI) drawn as horizontal lines, with
        ``fitted[name + "_std"]`` as a shaded one-sigma strip when given.
    measured : FRF, optional
        A measured point FRF drawn on a second axis of each panel, as the
        thesis's figures 2.8-2.9 do, to show where the modes are.
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
