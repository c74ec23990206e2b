"""The figures of a report, drawn by the library's own plots and embedded as PNG data (base64).

Each function takes the results and returns a ``data:image/png;base64,...``
address: the page carries its figures in itself and fetches nothing.  Figures
are closed after encoding.  Matplotlib is imported here only.
"""

from __future__ import annotations

import base64
import io
from typing import Any

__all__ = ["png_data", "tool_point_figure", "lobes_figure", "diagnosis_figures", "identification_figure",
           "FIGURE_DPI"]

FIGURE_DPI = 100
"""Resolution of the embedded figures (pixels per inch): about 800 pixels wide for the library's figures."""


def png_data(fig: Any, dpi: int = FIGURE_DPI) -> str:
    """A figure as a PNG ``data:`` address (base64), the figure then closed.

    Parameters
    ----------
    fig : matplotlib.figure.Figure
        The figure.
    dpi : int
        Pixels per inch.

    Returns
    -------
    str
        ``"data:image/png;base64,..."``.
    """
    import matplotlib.pyplot as plt

    buffer = io.BytesIO()
    try:
        fig.savefig(buffer, format="png", dpi=dpi, metadata={"Software": None})
    finally:
        plt.close(fig)
    return "data:image/png;base64," + base64.b64encode(buffer.getvalue()).decode("ascii")


def tool_point_figure(report: Any) -> str:
    """The tool point receptance, magnitude in um/N over phase (the rigid-body line out of the scale).

    Parameters
    ----------
    report : Report
        The results.

    Returns
    -------
    str
        The PNG ``data:`` address.
    """
    fig = report.frf.plot(kind="bode", unit="um/N", title=f"Tool point receptance at {report.at}: how far the "
                          "tool tip moves per newton of force")
    band = report.structure_band
    if band is not None and band.excluded_hz is not None:
        for ax in fig.axes[:2]:
            ax.axvline(band.lo_hz, color="tab:green", lw=0.8, ls="--")
        fig.axes[0].annotate(f"stability uses {band.lo_hz:.4g} Hz and above", (band.lo_hz, 1.0),
                             xycoords=("data", "axes fraction"), xytext=(4, -12), textcoords="offset points",
                             fontsize="x-small", color="tab:green")
    return png_data(fig)


def lobes_figure(report: Any) -> str:
    """The stability lobes with the recommendation, its safe window and its runners-up.

    Parameters
    ----------
    report : Report
        The results (with lobes).

    Returns
    -------
    str
        The PNG ``data:`` address.
    """
    import numpy as np

    lobes = report.lobes
    milling = hasattr(report.cut, "radial_depth")
    answer = getattr(report, "band_recommendation", None) or report.recommendation  # the band's when there is one
    fig = lobes.plot(lobes=lobes.method == "zoa", recommendation=answer,
                     title=f"Chatter-free axial depth against spindle speed: {report.cut.describe()}",
                     limits=report.limits if milling else None, cut=report.cut if milling else None)
    ax = fig.axes[0]
    band = getattr(report, "band", None)
    if band is not None:  # the joints within their stated uncertainty
        lo, hi = (np.where(np.isfinite(m), m, np.nan) * 1e3 for m in (band.lower_m, band.upper_m))
        ax.fill_between(band.spindle_speed_rpm, lo, hi, color="tab:purple", alpha=0.12, lw=0,
                        label=f"stability band ({len(band.members)} variants of the joints)")
        ax.plot(band.spindle_speed_rpm, lo, color="tab:purple", lw=1.0, label="lowest limit of the variants")
    handles, labels = ax.get_legend_handles_labels()
    if ax.get_legend() is not None:  # beside the axes: never over the recommendation and its window
        ax.get_legend().remove()
        fig.legend(handles, labels, loc="outside right upper", fontsize="small")
    fig.set_size_inches(10.2, 5.0)  # 1020 pixels: shown at its own size on the page (1030 wide)
    return png_data(fig)


def diagnosis_figures(diagnosis: Any) -> tuple[str, str]:
    """The diagnosis's figures: where the model fails, and the error falling.

    Parameters
    ----------
    diagnosis : Diagnosis
        The diagnosis (its public plots are used).

    Returns
    -------
    (str, str)
        The PNG ``data:`` addresses.
    """
    return png_data(diagnosis.plot_where()), png_data(diagnosis.plot_history())


def identification_figure(identification: Any) -> str:
    """The identification's figure: the measured FRF with the model's before and after the fit.

    Parameters
    ----------
    identification : IdentificationReport
        One identified joint.

    Returns
    -------
    str
        The PNG ``data:`` address.
    """
    return png_data(identification.plot())
