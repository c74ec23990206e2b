"""The figure to check a tap test: force spectra per tap, coherence, FRF magnitude and phase."""

from __future__ import annotations

from typing import Any

import numpy as np

from .process import TapResult

__all__ = ["plot_taps"]


def plot_taps(result: TapResult, title: str | None = None, unit: str = "um/N") -> Any:
    """Four panels for a person to check a tap test; returns the Figure (never shown).

    Top to bottom: each kept tap's force spectrum in dB (the hammer's usable
    band marked), the coherence, the receptance's magnitude (log scale) and
    its phase, on one frequency axis.

    Parameters
    ----------
    result : TapResult
        The processed taps.
    title : str, optional
        The figure's title.
    unit : {"m/N", "mm/N", "um/N", "nm/N"}
        Unit of the magnitude axis.

    Returns
    -------
    matplotlib.figure.Figure
        The figure.
    """
    import matplotlib.pyplot as plt

    factors = {"m/N": 1.0, "mm/N": 1e3, "um/N": 1e6, "nm/N": 1e9}
    if unit not in factors:
        from ..errors import InvalidValueError

        raise InvalidValueError(f"unit: got {unit!r}; expected one of {', '.join(factors)}")
    hz = result.frf.frequency.hz
    values = result.frf.data[:, 0, 0] * factors[unit]
    fig, axes = plt.subplots(4, 1, figsize=(8, 10), sharex=True,
                             gridspec_kw={"height_ratios": [1.2, 0.8, 1.5, 1.0]})
    ax_f, ax_c, ax_m, ax_p = axes
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
    ax_m.semilogy(hz, np.abs(values), color="C0", lw=1.0)
    ax_m.set_ylabel(f"|receptance| [{unit.replace('um', 'µm')}]")
    ax_p.plot(hz, np.degrees(np.angle(values)), color="C0", lw=0.8)
    ax_p.set_ylim(-185, 185)
    ax_p.set_yticks([-180, -90, 0, 90, 180])
    ax_p.set_ylabel("phase [deg]")
    ax_p.set_xlabel("frequency [Hz]")
    for ax in axes:
        ax.grid(True, alpha=0.3)
    rejected = len(result.rejected)
    note = (f"{result.estimator}, {result.averages} taps averaged" + (f", {rejected} rejected" if rejected else "")
            + (f"; exponential window tau = {result.tau:.4g} s" if result.tau else "; no exponential window"))
    fig.suptitle((title + "\n" if title else "") + note, fontsize=10)
    fig.tight_layout()
    return fig
