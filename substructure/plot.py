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

from collections.abc import Sequence
from typing import Any

import matplotlib.pyplot as plt
from matplotlib.figure import Figure

from ._text import plain_text
from .frf import FRF, frf_checked
from .frf.plotting import FRF_UNITS, KINDS, PARTS, draw_frf, rigid_body_cutoff  # noqa: F401 (their public place)
from .identify.plotting import plot_identification  # noqa: F401 (its public place)

__all__ = ["plot_frf", "plot_identification", "plot_taps", "rigid_body_cutoff", "FRF_UNITS"]


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
    frf_checked(frf)
    return draw_frf(frf, ax, entries, parts, label, kind=kind, unit=unit, title=title, note=note, limits=limits,
                    **line_kw)


def plot_taps(result, title: str | None = None, unit: str = "um/N") -> Figure:
    """Four panels for a person to check a tap test (:mod:`substructure.tap`); returns the Figure.

    Top to bottom, on one frequency axis: each kept tap's force spectrum in
    dB with the hammer's usable band marked, the coherence, and the
    receptance's magnitude and phase drawn by :func:`plot_frf` (its units,
    labels and rigid-body line left out of the scale), with the error the
    end of the taps may leave where the response still rang there
    (``TapResult.truncation``).

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
    if result.truncation is not None:  # the end of the taps: the error it leaves, on the magnitude's scale
        import numpy as np

        size = np.abs(result.frf.data[:, 0, 0]) * np.sqrt(result.truncation) * FRF_UNITS[unit]
        ax_m.plot(hz, np.where(np.isfinite(size), size, np.nan), color="C3", lw=0.7, ls=":",
                  label="error the taps' end may leave")
        ax_m.legend(fontsize=7, loc="lower left")
    rejected = len(result.rejected)
    about = (f"{result.estimator}, {result.averages} taps averaged" + (f", {rejected} rejected" if rejected else "")
             + (f"; exponential window tau = {result.tau:.4g} s" if result.tau else "; no exponential window"))
    fig.suptitle(plain_text((f"{title}\n" if title else "") + about), fontsize=10)
    return fig
