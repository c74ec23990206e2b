"""Figures of the diagnosis: where the model fails, and the error falling (returned, never shown)."""

from __future__ import annotations

import matplotlib.pyplot as plt
import numpy as np

from .._text import plain_text
from ..frf.plotting import given_axes

__all__ = ["plot_comparison", "plot_history"]


def plot_comparison(comparison, ax=None):
    """Measured and model ``|H|`` and phase overlaid, the log-ratio residual below.

    The bands that carry most of the error are shaded and the paired modes
    annotated with their shifts (model minus measurement).

    Parameters
    ----------
    comparison : Comparison
        What to draw.
    ax : sequence of three Axes, optional
        Where to draw (default: a new figure).

    Returns
    -------
    matplotlib.figure.Figure
        The figure.
    """
    if ax is None:
        fig, axes = plt.subplots(3, 1, sharex=True, figsize=(8.0, 7.5), layout="constrained",
                                 gridspec_kw={"height_ratios": [3, 1.5, 1.5]})
    else:
        axes = given_axes(ax, ("magnitude", "phase", "residual"))
        fig = axes[0].figure
    meas, model = comparison.measured, comparison.model
    f = meas.frequency.hz
    hm, ho = meas.data[:, 0, 0], model.data[:, 0, 0]
    axes[0].semilogy(f, np.abs(hm), color="0.25", lw=0.8, label="measured")
    axes[0].semilogy(f, np.abs(ho), color="tab:blue", lw=1.2, label="model")
    # phase in (-360, 0]: receptance lags the force, and the mass line at -180 deg
    # does not flip between +180 and -180 on noise
    def lag(h):
        return np.degrees(np.angle(h)) - 360.0 * (np.angle(h) > 0.5 * np.pi)

    axes[1].plot(f, lag(hm), color="0.25", lw=0.8)
    axes[1].plot(f, lag(ho), color="tab:blue", lw=1.2)
    with np.errstate(divide="ignore", invalid="ignore"):
        r = np.log(ho / hm)
    axes[2].plot(f, r.real, color="tab:red", lw=0.8, label="ln|model/measured|")
    axes[2].plot(f, r.imag, color="tab:purple", lw=0.8, label="phase difference [rad]")
    axes[2].axhline(0, color="0.5", lw=0.5)
    for lo, hi, share in comparison.bands:
        for a in axes:
            a.axvspan(lo, hi, color="tab:orange", alpha=0.15)
        axes[2].annotate(f"{share:.0%}", ((lo + hi) / 2, 0), ha="center", va="bottom", fontsize="x-small")
    for m in comparison.modes:
        if m.model_hz is None:
            continue
        axes[0].annotate(f"{m.shift_hz:+.0f} Hz", (m.measured_hz, m.measured_amplitude),
                         textcoords="offset points", xytext=(0, 6), ha="center", fontsize="x-small")
    axes[0].set_ylabel(plain_text(f"|{meas.outputs[0]} / {meas.inputs[0]}| [m/N]"))
    axes[0].legend(fontsize="small")
    axes[0].set_title(f"error {comparison.error:.3g} (noise floor {comparison.noise_floor:.3g}), "
                      f"FRAC {comparison.frac:.3f}; shaded: where the error is")
    axes[1].set_ylabel("phase [deg]")
    axes[2].set_ylabel("residual")
    axes[2].legend(fontsize="x-small", loc="upper right")
    axes[2].set_xlabel("frequency [Hz]")
    for a in axes:
        a.grid(True, alpha=0.3)
    return fig


def plot_history(diagnosis, ax=None):
    """The refinement's error after each step, with the noise floor.

    Parameters
    ----------
    diagnosis : Diagnosis
        What to draw.
    ax : Axes, optional
        Where to draw (default: a new figure).

    Returns
    -------
    matplotlib.figure.Figure
        The figure.
    """
    if ax is None:
        fig, ax = plt.subplots(figsize=(6.5, 3.8), layout="constrained")
    else:
        ax = given_axes(ax, ("history",))[0]
        fig = ax.figure
    steps = diagnosis.refinement
    x = [s.step for s in steps]
    ax.semilogy(x, [s.error for s in steps], "o-", color="tab:blue")
    for s in steps:
        label = "model as given" if s.added is None else f"+ {s.added.name}\n({s.added.where})"
        ax.annotate(plain_text(label), (s.step, s.error), textcoords="offset points", xytext=(6, 6), fontsize="x-small")
    ax.axhline(diagnosis.noise_floor, color="tab:green", ls="--", label="noise floor")
    factor = diagnosis.settings.explained_error_factor
    ax.axhline(factor * diagnosis.noise_floor, color="tab:green", ls=":", label=f"{factor:g} x noise floor")
    ax.set_xticks(x)
    ax.set_xlabel("refinement step")
    ax.set_ylabel(f"error ({diagnosis.metric})")
    ax.set_title("watch the error fall")
    ax.legend(fontsize="small")
    ax.grid(True, alpha=0.3)
    return fig
