"""The noise of a measured FRF, per frequency line, estimated from the data alone.

A model is compared with a measurement through the complex log ratio
``r = ln(H_model / H_measured)``; a perfect model leaves only the noise of
``ln H_measured``.  Tap-test noise has two parts: a relative part
(force and response scatter from tap to tap, the same share on every line)
and an additive part (the analyser's and sensor's floor), which dominates
where ``|H|`` is small, at antiresonances.  For ``H + n`` with complex
additive noise of variance ``b`` the log moves by ``n / H``, so the variance
of the real part (log magnitude) and the imaginary part (phase, rad) of
``ln H`` at line ``k`` is

``v_re,k = a_re + b / (2 |H_k|^2)``,  ``v_im,k = a_im + b / (2 |H_k|^2)``,

each capped at ``pi^2 / 3``, the variance of a phase that noise has made
uniform (a line drowned in noise carries no information, whatever its
level).

The three numbers ``a_re, a_im, b`` are estimated from the measurement
itself.  A Savitzky-Golay smoother ``S`` (window from the sharpest
resonance, :func:`substructure.smoothing.choose_window`) follows the FRF
but not the noise; the log ratio ``q = ln(H / S(H))`` then has, for white
noise, the variance ``(1 - h0) v_k`` (``h0`` the filter's central
coefficient: the share of each line's own noise the smoother keeps).  The
parameters maximise the likelihood of ``q`` with these variances, ``|S|``
standing for ``|H|``: first a Student t likelihood with 4 degrees of
freedom, robust to the lines where the smoother cannot follow a very sharp
resonance, then the Gaussian one with the lines beyond its 1e-4 tail set
aside, repeated until the set settles.  The relative
standard error of the variance scale (:attr:`NoiseModel.scale_error`) comes
from the spread of the normalised ``q^2`` over 16 blocks of lines: it
widens the tests of :mod:`substructure.updating.selection` when the noise
varies along the band more than the model says.
"""

from __future__ import annotations

import warnings

import attrs
import numpy as np
from scipy.optimize import minimize
from scipy.signal import savgol_coeffs

from ..errors import InvalidValueError
from ..frf import FRF
from ..smoothing import choose_window, smooth

__all__ = ["NoiseModel", "estimate_noise", "VARIANCE_CAP"]

VARIANCE_CAP = float(np.pi**2 / 3.0)
"""Largest per-line variance of a part of ``ln H``: that of a uniform phase [rad^2]."""

_TRIM = 18.42  # chi^2 with 2 degrees of freedom: upper 1e-4 tail
_BLOCKS = 16


@attrs.frozen
class NoiseModel:
    """Per-line variances of the real and imaginary parts of ``ln H`` of one measured FRF.

    Parameters
    ----------
    var_re, var_im : ndarray, shape (n_lines,)
        Variances of ``ln|H|`` and of the phase [rad^2] at each line.
    relative : (float, float)
        ``a_re, a_im``: the relative (multiplicative) noise variances.
    additive : float
        ``b``: variance of the additive complex noise, in the FRF's units squared.
    scale_error : float
        Relative standard error of the variance scale (see the module docstring).
    window : int
        The smoothing window used [lines].
    scatter : ndarray, shape (n_lines,)
        Per line, the smoothing residual's squared size relative to the
        model, ``(q_re^2 / v_re + q_im^2 / v_im) / (2 (1 - h0))`` (about 1 on
        average; NaN on the lines set aside): how well the model describes
        the noise locally.
    """

    var_re: np.ndarray = attrs.field(eq=False, repr=False)
    var_im: np.ndarray = attrs.field(eq=False, repr=False)
    relative: tuple[float, float]
    additive: float
    scale_error: float
    window: int
    scatter: np.ndarray = attrs.field(eq=False, repr=False)

    @property
    def floor(self) -> float:
        """The RMS log ratio a perfect model would show: ``sqrt(mean(v_re + v_im))``."""
        return float(np.sqrt(np.mean(self.var_re + self.var_im)))

    def select(self, mask: np.ndarray) -> "NoiseModel":
        """The model on a subset of the lines (a boolean mask or indices).

        Parameters
        ----------
        mask : ndarray
            Lines to keep.

        Returns
        -------
        NoiseModel
            The same noise on those lines.
        """
        return attrs.evolve(self, var_re=self.var_re[mask], var_im=self.var_im[mask], scatter=self.scatter[mask])


def _variances(params, g, h0):
    a_re, a_im, b = np.exp(params)
    return (1.0 - h0) * (a_re + 0.5 * b * g), (1.0 - h0) * (a_im + 0.5 * b * g)


def _nll(params, q_re2, q_im2, g, h0, nu=None):
    """Negative log-likelihood of the smoothing residual (Gaussian, or Student t with ``nu`` dof)."""
    v_re, v_im = _variances(params, g, h0)
    a_re, a_im, b = np.exp(params)
    if nu is None:
        value = np.sum(np.log(v_re) + q_re2 / v_re + np.log(v_im) + q_im2 / v_im)
        d_re = 1.0 / v_re - q_re2 / v_re**2
        d_im = 1.0 / v_im - q_im2 / v_im**2
    else:  # t with variance v: scale^2 = v (nu - 2) / nu; heavy tails bound the outliers' pull
        u_re, u_im = q_re2 / ((nu - 2) * v_re), q_im2 / ((nu - 2) * v_im)
        value = np.sum(np.log(v_re) + (nu + 1) * np.log1p(u_re) + np.log(v_im) + (nu + 1) * np.log1p(u_im))
        d_re = (1.0 - (nu + 1) * u_re / (1 + u_re)) / v_re
        d_im = (1.0 - (nu + 1) * u_im / (1 + u_im)) / v_im
    grad = (1.0 - h0) * np.array([np.sum(d_re) * a_re, np.sum(d_im) * a_im, np.sum((d_re + d_im) * 0.5 * g) * b])
    return value, grad


def _window(frf: FRF, polyorder: int) -> int:
    from ..smoothing import CoarseDataWarning

    n = frf.frequency.n
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", CoarseDataWarning)
        try:
            w = choose_window(frf, polyorder=polyorder)
        except InvalidValueError:  # no resonance: about 2 % of the lines
            w = max(polyorder + 2, min(31, n // 50))
    w = min(w, n if n % 2 else n - 1)
    return w if w % 2 else w - 1


_MAGNITUDE_RANGE = (1e-140, 1e140)
"""|H| outside this range (SI units) has a square or an inverse square that over- or underflows in the
estimate; the file readers refuse receptances above 1 m/N long before."""


def estimate_noise(measured: FRF, window: int | None = None, polyorder: int = 3) -> NoiseModel:
    """The per-line noise of a measured FRF (one entry), estimated from the data.

    Parameters
    ----------
    measured : FRF
        One measured entry on a uniform grid, at least ``polyorder + 8`` lines.
    window : int, optional
        Smoothing window in lines (odd); chosen from the sharpest resonance
        when not given.
    polyorder : int, default 3
        Order of the smoother.

    Returns
    -------
    NoiseModel
        Variances per line, and the fitted parameters.

    Raises
    ------
    InvalidValueError
        For an FRF that is zero (or not finite) on every line, too short, or
        with magnitudes whose square overflows (beyond 1e140 in SI units) or
        underflows (below 1e-140).
    """
    if measured.shape[1:] != (1, 1):
        raise InvalidValueError(f"measured: got {measured.shape[1]}x{measured.shape[2]} entries; expected one")
    h = measured.data[:, 0, 0]
    label = f"{measured.outputs[0]} / {measured.inputs[0]}"
    usable = np.isfinite(h) & (np.abs(h) > 0)
    if not usable.any():
        raise InvalidValueError(f"measured FRF {label}: zero (or not finite) on every line: a dead channel?")
    with np.errstate(over="ignore"):
        magnitude = np.abs(h[usable])
    if not (magnitude.max() < _MAGNITUDE_RANGE[1] and magnitude.min() > _MAGNITUDE_RANGE[0]):
        raise InvalidValueError(f"measured FRF {label}: |H| of {float(magnitude.min()):.3g} to "
                                f"{float(magnitude.max()):.3g} in SI units is beyond any measured structure (its "
                                "square is not a finite positive number); check the units")
    n = h.size
    if n < polyorder + 8:
        raise InvalidValueError(f"measured FRF {label}: {n} lines; the noise estimate needs at least {polyorder + 8}")
    clean = measured if usable.all() else FRF(measured.frequency, np.where(usable, h, 0.0)[:, None, None],
                                             measured.outputs, measured.inputs)
    w = window or _window(clean, polyorder)
    s = smooth(clean, window=w, polyorder=polyorder).data[:, 0, 0]
    h0 = float(savgol_coeffs(w, polyorder)[w // 2])
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        q = np.log(h / s)
        g_all = 1.0 / np.abs(s) ** 2
    ok = usable & np.isfinite(q) & np.isfinite(g_all)
    ok[: w // 2] = False  # the smoother's edges are less reliable
    ok[n - w // 2:] = False
    if ok.sum() < 8:
        ok = usable & np.isfinite(q) & np.isfinite(g_all)
    scale = float(np.median(g_all[ok]))  # numbers of order one for the optimiser
    g = g_all / scale
    q_re2, q_im2 = q.real**2, q.imag**2
    m0 = max(float(np.median(q_re2[ok] + q_im2[ok])) / 1.386, 1e-14)  # chi^2_2 median is 1.386
    bounds = [(np.log(1e-16), np.log(10.0))] * 2 + [(np.log(1e-16), np.log(1e8))]

    def solve(start, keep, nu=None):
        res = minimize(_nll, start, args=(q_re2[keep], q_im2[keep], g[keep], h0, nu), jac=True, method="L-BFGS-B",
                       bounds=bounds, options={"maxiter": 80, "ftol": 1e-10})  # a negligible b is flat: stop
        return res.fun, res.x

    # a robust first fit (Student t, 4 dof: lines where the smoother cannot follow a very
    # sharp resonance pull little), from several starting shares of additive noise; then
    # the Gaussian fit with the lines beyond the 1e-4 tail set aside, until they settle
    params = min((solve(np.log([m0 / 2, m0 / 2, m0 * share]), ok, 4.0) for share in (1e-6, 1e-3, 1e-1, 10.0)),
                 key=lambda r: r[0])[1]
    keep = None
    for _ in range(6):
        v_re, v_im = _variances(params, g, h0)
        new = ok & (q_re2 / v_re + q_im2 / v_im <= _TRIM)
        if keep is not None and np.array_equal(new, keep):
            break
        keep = new
        params = solve(params, keep)[1]
    a_re, a_im, b_rel = (float(v) for v in np.exp(params))
    with np.errstate(divide="ignore", invalid="ignore"):
        var_re = np.minimum(a_re + 0.5 * b_rel * g, VARIANCE_CAP)
        var_im = np.minimum(a_im + 0.5 * b_rel * g, VARIANCE_CAP)
    var_re = np.where(np.isfinite(var_re), var_re, VARIANCE_CAP)
    var_im = np.where(np.isfinite(var_im), var_im, VARIANCE_CAP)
    var_re[~usable] = VARIANCE_CAP
    var_im[~usable] = VARIANCE_CAP
    # the scale's standard error from the spread over blocks of lines
    z = 0.5 * (q_re2 / ((1 - h0) * var_re) + q_im2 / ((1 - h0) * var_im))
    idx = np.flatnonzero(keep)
    blocks = [z[part].mean() for part in np.array_split(idx, min(_BLOCKS, max(2, idx.size // 20))) if part.size]
    spread = float(np.std(blocks, ddof=1) / np.sqrt(len(blocks))) if len(blocks) > 1 else 1.0
    scatter = np.where(keep, z, np.nan)
    return NoiseModel(var_re, var_im, (a_re, a_im), b_rel / scale, max(spread, float(np.sqrt(1.0 / idx.size))), w,
                      scatter)
