"""The figure of a closed-form identification (internal): :func:`substructure.plot.plot_identification`.

In the ``identify`` package, so that :meth:`ClosedFormResult.plot` draws without importing
``substructure.plot`` (a higher layer); ``substructure.plot`` re-exports the function.
Matplotlib is imported with this module, on the first figure.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import matplotlib.pyplot as plt
import numpy as np
from matplotlib.axes import Axes
from matplotlib.figure import Figure

if TYPE_CHECKING:  # the annotations only
    from ..frf import FRF


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
