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

Real tap-test noise is not of this fixed form everywhere (heavy-tailed,
larger at low frequencies, near the data's own antiresonances and over
bands of low coherence); four more steps follow it, from the data alone:
the coherence of an H1 estimate over ``n`` taps adds the term
``(1 - gamma^2) / (2 n gamma^2)`` with a fitted weight; a local scale
(:data:`LOCAL_LINES` lines, taken only where it lies :data:`LOCAL_Z`
standard errors above the model); a line beyond the tail of even the local
model gets its own squared residual as variance; and the lines where the
additive terms of the log variance (the floor's and the coherence's: the
response's noise is additive) exceed :data:`NOISE_DOMINATED` are read in
the linear domain by :meth:`NoiseModel.line_scores`.  Errors the
smoothing residual cannot see are added when the measurement carries
them: the hammer's noise (smooth over the force window's inverse) and the
truncation of a response that still rang at the end of the taps (which
every tap repeats, so that the coherence does not see it either).  An FRF
measured through an exponential window has its noise correlated over
neighbouring lines (:func:`window_correlation`): the smoother then keeps
more of it, the share ``h0`` is computed for that correlation, and
``NoiseModel.correlation`` tells the fits and tests how many times
fewer lines the data count as.  An FRF that does not say its window (a
file of another analyser) but whose smoothing residual is correlated
between neighbouring lines beyond what independent lines give is treated
as measured through the window that correlates it as much
(``NoiseModel.seen_tau``).  See docs/diagnose.md, "The noise model".
"""

from __future__ import annotations

import warnings

import attrs
import numpy as np
from scipy.optimize import minimize
from scipy.signal import savgol_coeffs

from ..errors import InvalidValueError
from ..frf import FRF, Frequency
from ..frf._fields import window_tau as window_tau_s
from ..smoothing import choose_window, smooth
from .interpolated import interpolated_from, on_every_line

__all__ = ["NoiseModel", "estimate_noise", "window_correlation", "VARIANCE_CAP"]

VARIANCE_CAP = float(np.pi**2 / 3.0)
"""Largest per-line variance of a part of ``ln H``: that of a uniform phase [rad^2]."""

_TRIM = 18.42  # chi^2 with 2 degrees of freedom: upper 1e-4 tail
_BLOCKS = 16
_EULER = 0.5772156649015329  # -E[ln X] for X exponential with mean 1
LOCAL_LINES = 21
"""Width of the window over which the local scale of the noise is estimated [lines]."""
LOCAL_Z = 2.5
"""How many standard errors above the fitted model the local noise must lie to be taken as larger."""
LINEAR_LINES = 101
"""Width of the window of the linear-domain noise of lines drowned in additive noise [lines]."""
NOISE_DOMINATED = 0.1
"""Variance of ``ln H`` from the additive noise above which a line is read linearly [-] (its log is biased)."""
CORRELATION_Z = 4.0
"""How many standard errors above that of independent lines the correlation of neighbouring lines' smoothing
residuals must lie to be taken as the noise's own (:func:`estimate_noise`)."""
DETECT_WINDOW = 13
"""The narrowest smoothing window [lines] whose residual the noise's correlation is read from."""
WINDOW_X_MAX = 20.0
"""The shortest exponential window the data's own correlation is read as, ``T / tau`` (exp(-20) of the response
left at the record's end, about 2e-9); a residual more correlated than that is not noise (:func:`estimate_noise`)."""
COHERENCE_MIN = 1e-3
"""Smallest coherence used in the variance of an H1 estimate (a line below it carries no information)."""


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
    local_scale : ndarray, shape (n_lines,), optional
        The factor (>= 1) by which the data's own scatter shows the noise
        larger around each line than the fitted model.
    outliers : int
        Lines whose variance is their own squared smoothing residual.
    coherence_factor : float or None
        The fitted weight of the coherence term relative to its theory
        (about 1 when the coherence accounts for the scatter); None without
        a coherence.
    linear : tuple, optional
        ``(H / S(H), v_re, v_im)`` on the lines drowned in additive noise
        (NaN elsewhere), for :meth:`line_scores`.
    dof : ndarray, shape (n_lines,), optional
        Per line, the degrees of freedom of the variance (Satterthwaite's):
        ``2 (n - 1) / s^2`` where the share ``s`` of it comes from the
        coherence of ``n`` taps, whose estimate at one line scatters like
        ``chi^2`` with ``2 (n - 1)`` degrees of freedom; infinite where no
        part does.  A line's score then follows ``F(2, dof)`` rather than
        the exponential (:func:`substructure.updating.selection.consistency`).
    correlation : float
        The variance of a sum of neighbouring lines' scores over that of as
        many independent ones (1: independent lines).  An exponential window
        ``exp(-t/tau)`` on records of ``T = 1/df`` seconds makes the noise of
        lines ``k`` apart correlated, ``|rho_k|^2 = 1 / (1 + (pi k tau / T)^2)``,
        and the sum of all lags gives ``(T/tau) coth(T/tau)``
        (:func:`window_correlation`): a fit, a test or a comparison of
        ``chi^2`` counts the data as that many times fewer lines.
    seen_tau : float or None
        When the FRF does not say its window but its own scatter shows its
        noise correlated over neighbouring lines: the time constant [s] of
        the exponential window that would correlate it as much (its
        ``correlation`` is that window's); None otherwise.
    held : ndarray of bool, optional
        For an FRF interpolated from every ``step``-th of its lines
        (:func:`~substructure.updating.interpolated_from`): the
        lines measured, on which the noise was estimated and the model is
        compared (the others carry their nearest measured line's noise);
        None when every line is a measurement.
    interpolated : (int, int) or None
        ``(step, degree)`` of that interpolation (degree 0: a value held,
        1: straight lines, 3: a cubic spline); None without one.
    """

    var_re: np.ndarray = attrs.field(eq=False, repr=False)
    var_im: np.ndarray = attrs.field(eq=False, repr=False)
    relative: tuple[float, float]
    additive: float
    scale_error: float
    window: int
    scatter: np.ndarray = attrs.field(eq=False, repr=False)
    local_scale: np.ndarray | None = attrs.field(default=None, eq=False, repr=False)
    outliers: int = 0
    coherence_factor: float | None = None
    linear: tuple | None = attrs.field(default=None, eq=False, repr=False)
    dof: np.ndarray | None = attrs.field(default=None, eq=False, repr=False)
    correlation: float = 1.0
    seen_tau: float | None = None
    held: np.ndarray | None = attrs.field(default=None, eq=False, repr=False)
    interpolated: tuple[int, int] | None = None

    def seen_note(self, which: str) -> str:
        """The note that the data's own scatter shows the noise correlated (``seen_tau`` set), and what to give.

        Parameters
        ----------
        which : str
            The measurement (``response / excitation``).

        Returns
        -------
        str
            One clause, which the diagnosis and the identification end with what the window does to them.
        """
        return (f"{which}: its noise is correlated over neighbouring lines (seen in its own scatter, as an exponential "
                f"window of tau = {self.seen_tau:.3g} s would correlate it), counted as {self.correlation:.3g} times "
                "fewer lines; if the analyser applied that window, give its time constant (window_tau_s in the "
                "measurement set)")

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
        local = None if self.local_scale is None else self.local_scale[mask]
        linear = None if self.linear is None else tuple(part[mask] for part in self.linear)
        dof = None if self.dof is None else self.dof[mask]
        held = None if self.held is None else self.held[mask]
        return attrs.evolve(self, var_re=self.var_re[mask], var_im=self.var_im[mask], scatter=self.scatter[mask],
                            local_scale=local, linear=linear, dof=dof, held=held)

    def line_scores(self, ratios: np.ndarray, lines=None) -> np.ndarray:
        """Per line, half the squared whitened residual (exponential with mean 1 for noise).

        Where the additive noise is as large as the signal (the data's own
        antiresonances), the residual is read in the linear domain,
        ``(M - H) / S(H)`` with the variances of the model uncapped, rather
        than as ``ln(M / H)``: the log of a noise-dominated line is biased
        and heavy-tailed, its linear residual is not.

        Parameters
        ----------
        ratios : ndarray
            ``ln(model / measured)`` on the lines ``lines``.
        lines : array of int, optional
            The lines of the noise model the ratios are on (default all).

        Returns
        -------
        ndarray
            ``0.5 (Re(r)^2 / v_re + Im(r)^2 / v_im)`` per line.
        """
        sel = slice(None) if lines is None else lines
        r = np.asarray(ratios)
        z = 0.5 * (r.real**2 / self.var_re[sel] + r.imag**2 / self.var_im[sel])
        if self.linear is None:
            return z
        hs, lin_re, lin_im = (part[sel] for part in self.linear)
        use = np.isfinite(lin_re) & np.isfinite(lin_im)
        if use.any():
            e = np.expm1(np.clip(r[use].real, -50.0, 50.0) + 1j * r[use].imag) * hs[use]
            z = z.copy()
            z[use] = 0.5 * (e.real**2 / lin_re[use] + e.imag**2 / lin_im[use])
        return z


def _variances(params, g, h0):
    """``(1 - h0) v`` of the real and imaginary parts: ``a_re``/``a_im`` plus the regressors ``g`` weighted by ``b``."""
    coef = np.exp(params)
    extra = 0.5 * (coef[2:] @ g)
    return (1.0 - h0) * (coef[0] + extra), (1.0 - h0) * (coef[1] + extra)


def _nll(params, q_re2, q_im2, g, h0, nu=None):
    """Negative log-likelihood of the smoothing residual (Gaussian, or Student t with ``nu`` dof)."""
    v_re, v_im = _variances(params, g, h0)
    coef = np.exp(params)
    if nu is None:
        value = np.sum(np.log(v_re) + q_re2 / v_re + np.log(v_im) + q_im2 / v_im)
        d_re = 1.0 / v_re - q_re2 / v_re**2
        d_im = 1.0 / v_im - q_im2 / v_im**2
    else:  # t with variance v: scale^2 = v (nu - 2) / nu; heavy tails bound the outliers' pull
        u_re, u_im = q_re2 / ((nu - 2) * v_re), q_im2 / ((nu - 2) * v_im)
        value = np.sum(np.log(v_re) + (nu + 1) * np.log1p(u_re) + np.log(v_im) + (nu + 1) * np.log1p(u_im))
        d_re = (1.0 - (nu + 1) * u_re / (1 + u_re)) / v_re
        d_im = (1.0 - (nu + 1) * u_im / (1 + u_im)) / v_im
    grad = (1.0 - h0) * np.concatenate(([np.sum(d_re) * coef[0], np.sum(d_im) * coef[1]],
                                         (g @ (d_re + d_im)) * 0.5 * coef[2:]))
    return value, grad


def _running_mean(values: np.ndarray, width: int) -> tuple[np.ndarray, np.ndarray]:
    """The mean of the finite values within ``width`` lines of each line, and how many there were."""
    finite = np.isfinite(values)
    kernel = np.ones(width)
    total = np.convolve(np.where(finite, values, 0.0), kernel, mode="same")
    count = np.convolve(finite.astype(float), kernel, mode="same")
    with np.errstate(divide="ignore", invalid="ignore"):
        return total / count, count


def _local_scale(z: np.ndarray, width: int) -> np.ndarray:
    """How much larger than the fitted model the noise is around each line (1 where not clearly larger).

    ``z`` is the squared smoothing residual over the model (exponential with mean 1 for
    complex Gaussian noise of the model's size).  Its log averaged over ``width`` lines
    estimates ``ln m - EULER``; the noise is taken as larger (``m > 1``) only where that
    estimate exceeds :data:`LOCAL_Z` of its own standard errors (``pi / sqrt(6 count)``),
    so that Gaussian noise of the model's size is not rescaled by chance.
    """
    with np.errstate(divide="ignore"):
        lz = np.where(np.isfinite(z) & (z > 0), np.log(np.maximum(z, 1e-300)), np.nan)
    mean, count = _running_mean(lz, width)
    log_m = mean + _EULER
    se = np.pi / np.sqrt(6.0 * np.maximum(count, 1.0))
    return np.where(np.isfinite(log_m) & (log_m > LOCAL_Z * se), np.exp(np.minimum(log_m, 50.0)), 1.0)


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


def _best_domain_residual(clean: FRF, h, q, usable, window: int, polyorder: int) -> np.ndarray:
    """Per line, the smoothing residual in H or in 1/H, whichever is smaller around the line (5 lines)."""
    with np.errstate(divide="ignore", invalid="ignore"):
        inverse = np.where(usable, 1.0 / h, 0.0)
        s_inv = smooth(FRF(clean.frequency, inverse[:, None, None], clean.outputs, clean.inputs), window=window,
                       polyorder=polyorder).data[:, 0, 0]
        q_inv = np.log(h * s_inv)
    e_direct, _ = _running_mean(np.where(np.isfinite(q), np.abs(q) ** 2, np.nan), 5)
    e_inverse, _ = _running_mean(np.where(np.isfinite(q_inv), np.abs(q_inv) ** 2, np.nan), 5)
    use_inverse = np.isfinite(q_inv) & (e_inverse < e_direct)
    return np.where(use_inverse, q_inv, q)


def _coherence_regressor(coherence, averages, n: int, label: str) -> np.ndarray | None:
    """``(1 - gamma^2) / (2 n gamma^2)`` per line, the relative variance of an H1 estimate, or None."""
    if coherence is None or averages is None:
        return None
    gamma = np.asarray(coherence, dtype=float).reshape(-1)
    if gamma.size != n:
        raise InvalidValueError(f"coherence of {label}: {gamma.size} values for {n} lines; expected one per line")
    if int(averages) < 2:  # one average: the coherence is 1 by construction and says nothing
        return None
    gamma = np.clip(np.where(np.isfinite(gamma), gamma, 0.0), COHERENCE_MIN, 1.0 - 1e-9)
    return (1.0 - gamma) / (2.0 * int(averages) * gamma)


def _hv_bias(coherence, averages, estimator) -> np.ndarray | None:
    """``-ln gamma^2`` per line for an Hv estimate over two taps or more: how far it may lie above H1 (else None)."""
    if estimator != "Hv" or coherence is None or averages is None or int(averages) < 2:
        return None
    gamma = np.asarray(coherence, dtype=float).reshape(-1)
    return -np.log(np.clip(np.where(np.isfinite(gamma), gamma, 0.0), COHERENCE_MIN, 1.0))


def _carried(value, n: int, what: str) -> np.ndarray:
    """A per-line variance the measurement carries, checked: ``n`` values >= 0 (``inf`` allowed)."""
    v = np.asarray(value, dtype=float).reshape(-1)
    if v.size != n or not np.all(v >= 0):
        raise InvalidValueError(f"{what}: expected {n} variances >= 0, one per line")
    return v


def _force_term(force_noise, window_s, hz: np.ndarray, label: str) -> np.ndarray | None:
    """Half the hammer's noise variance per line times the lines its error spans (None without it)."""
    if force_noise is None:
        return None
    v = _carried(force_noise, hz.size, f"force noise of {label}")
    if window_s is None or not np.isfinite(window_s) or window_s <= 0:
        raise InvalidValueError(f"force noise of {label}: the force window's length is needed (force_window_s > 0)")
    spacing = float(np.median(np.diff(hz))) if hz.size > 1 else 1.0
    return 0.5 * v * max(1.0, 1.0 / (float(window_s) * spacing))


def window_correlation(tau: float | None, spacing_hz: float) -> float:
    """How many times a sum of line scores varies more than for independent lines, under an exponential window.

    The noise of a record of ``T`` seconds through the window ``exp(-t/tau)``
    is correlated between lines ``k`` apart (``k / T`` hertz) as the
    transform of the squared window at that distance,
    ``rho_k = 1 / (1 + i pi k tau / T)``; a line's score (the squared
    modulus of a complex Gaussian) correlates with ``|rho_k|^2``, and
    ``1 + 2 sum_k |rho_k|^2 = x coth x`` with ``x = T / tau``.

    Parameters
    ----------
    tau : float or None
        The window's time constant [s]; None for no window (1).
    spacing_hz : float
        The line spacing ``1 / T`` [Hz].

    Returns
    -------
    float
        ``x coth x`` (>= 1; about ``x`` for a window much shorter than the
        record, 1 for none).
    """
    if tau is None or not np.isfinite(spacing_hz) or spacing_hz <= 0:
        return 1.0
    x = 1.0 / (float(tau) * float(spacing_hz))
    return float(x / np.tanh(x)) if x < 350.0 else x


def _kept_share(w: int, polyorder: int, tau: float | None, spacing_hz: float) -> float:
    """``h0``: the share of a line's noise variance the smoother keeps, ``1 - E[q^2] / v``.

    For white noise the filter's central coefficient.  Through an exponential window the noise of
    lines ``k`` apart is correlated, the real and the imaginary parts each by
    ``c_k = 1 / (1 + (pi k tau df)^2)`` (:func:`window_correlation`), and the smoother follows more of
    it: ``E[q^2] / v = 1 - 2 s . c + s^T C s`` (``s`` the filter's coefficients, ``C`` the lines'
    correlations); read as white noise, a windowed FRF's scatter put the coherence's fitted weight at
    0.12 of its theory (records five time constants long).
    """
    s = savgol_coeffs(w, polyorder)
    if tau is None or not spacing_hz > 0:
        return float(s[w // 2])
    lag = np.arange(w) - w // 2
    c = 1.0 / (1.0 + (np.pi * float(tau) * spacing_hz * np.subtract.outer(lag, lag)) ** 2)
    residual = 1.0 - 2.0 * float(s @ c[w // 2]) + float(s @ c @ s)
    return 1.0 - max(residual, 1e-9)


def estimate_noise(measured: FRF, window: int | None = None, polyorder: int = 3, *, coherence=None,
                   averages: int | None = None, force_noise=None, force_window_s: float | None = None,
                   estimator: str | None = None, truncation=None, window_tau: float | None = None) -> NoiseModel:
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
    coherence : array_like, optional
        The ordinary coherence of the measurement, one value per line in
        ``[0, 1]`` (from the tap test's averages).  With ``averages`` of 2 or
        more, the variance of an H1 estimate, ``(1 - gamma^2) / (2 n gamma^2)``
        [Bendat and Piersol], is one more term of the model, its weight
        fitted to the data.
    averages : int, optional
        The number of taps averaged.
    force_noise : array_like, optional
        Per line, the variance of H1's relative error that the hammer's noise
        gives (``substructure.tap.TapResult.force_noise``).  The error
        passes through the force window only, so it is smooth over about
        ``1 / force_window_s`` hertz, which the smoothing residual cannot
        see and the tests would read as independent lines: with
        ``force_window_s`` it is added to each line's variance (half to each
        part) times the lines it spans, ``1 / (force_window_s df)``.
    force_window_s : float, optional
        The force window's effective length [s] (needed with ``force_noise``).
    estimator : {"H1", "H2", "Hv"}, optional
        How the FRF was estimated.  An Hv estimate lies between H1 and
        ``H2 = H1 / gamma^2`` (nearer H2 where the response channel's power
        is the larger), by an amount its coherence alone does not give: with
        a coherence of two taps or more, the bias it may carry, ``-ln gamma^2``
        in the log magnitude (``1 / gamma^2 - 1`` relative, in the linear
        domain), is added to each line's variance.  An H2 is compared as
        ``gamma^2 H2``, which is H1 (``Measurement.h1_frf``): give that FRF
        and ``"H1"``.
    truncation : array_like, optional
        Per line, the variance of the FRF's relative error that the end of
        the taps leaves where the response still rang
        (``substructure.tap.TapResult.truncation``, already counted over the
        lines it spans): an error the taps repeat, which neither the
        coherence nor the smoothing residual sees; added to each line's
        variance, half to each part.
    window_tau : float, optional
        The time constant [s] of the exponential window the FRF was measured
        through: its noise is correlated over neighbouring lines
        (``NoiseModel.correlation``, :func:`window_correlation`).

    Returns
    -------
    NoiseModel
        Variances per line, and the fitted parameters.

    Raises
    ------
    InvalidValueError
        For an FRF that is zero (or not finite) on every line, too short,
        with magnitudes whose square overflows (beyond 1e140 in SI units) or
        underflows (below 1e-140), a coherence or force noise of the wrong
        length, or a force noise without the window's length, a truncation
        of the wrong length or negative.

    Notes
    -----
    An FRF interpolated from every ``step``-th of its lines (straight lines,
    a cubic spline or a value held between them, found in the data by
    :func:`~substructure.updating.interpolated_from`) has its
    noise estimated on those lines alone; ``NoiseModel.held`` marks them,
    and the comparisons keep them.
    """
    lines, n = (coherence, force_noise, truncation), measured.frequency.n
    found = (_interpolated(measured, window_tau) if measured.shape[1:] == (1, 1)
             and all(a is None or np.size(a) == n for a in lines) else None)
    knots = None if found is None else np.arange(found[1], n, found[0])
    if knots is not None and knots.size >= polyorder + 8:  # the noise of the measured lines, which are compared
        coherence, force_noise, truncation = (None if a is None else np.asarray(a)[knots] for a in lines)
        sub = FRF(Frequency.from_hz(measured.frequency.hz[knots]), measured.data[knots], measured.outputs,
                  measured.inputs, measured.quantity)
        model = estimate_noise(sub, window, polyorder, coherence=coherence,
                               averages=averages, force_noise=force_noise, force_window_s=force_window_s,
                               estimator=estimator, truncation=truncation, window_tau=window_tau)
        return on_every_line(model, knots, n, found[0], found[2])
    model, seen = _estimate(measured, window, polyorder, coherence, averages, force_noise, force_window_s,
                            estimator, truncation, window_tau)
    if window_tau is not None or seen is None or force_noise is not None or truncation is not None:
        return model  # a tap test processed here says its window, and counts the smooth errors its taps leave
    tau = _equivalent_tau(*seen)
    if tau is None:
        return model
    model, _ = _estimate(measured, window or seen[2], polyorder, coherence, averages, force_noise, force_window_s,
                         estimator, truncation, tau)
    return attrs.evolve(model, seen_tau=tau)


def _interpolated(measured: FRF, window_tau) -> tuple[int, int, int] | None:
    """:func:`interpolated_from` of the FRF as given, or as the mobility or accelerance a receptance was read from
    (interpolated before it was divided by ``i omega`` or ``-omega^2``, at ``omega - i/tau`` through a window)."""
    try:
        decay = 0.0 if window_tau is None else 1.0 / window_tau_s(window_tau)
    except InvalidValueError:  # said where the window is used
        decay = 0.0
    s = measured.frequency.omega - 1j * decay
    h = measured.data[:, 0, 0]
    for factor in (None, 1j * s, -(s**2)):
        with np.errstate(over="ignore", invalid="ignore"):  # beyond any structure: refused with its range after
            found = interpolated_from(h if factor is None else h * factor)
        if found is not None:
            return found
    return None


def _estimate(measured: FRF, window, polyorder: int, coherence, averages, force_noise, force_window_s,
              estimator, truncation, window_tau) -> tuple[NoiseModel, tuple | None]:
    """The noise model (:func:`estimate_noise`) for noise correlated as through ``window_tau`` (None: independent
    lines), and what :func:`_equivalent_tau` reads of the correlation the data show."""
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
    coh = _coherence_regressor(coherence, averages, n, label)
    clean = measured if usable.all() else FRF(measured.frequency, np.where(usable, h, 0.0)[:, None, None],
                                             measured.outputs, measured.inputs)
    if window is not None and (isinstance(window, (bool, np.bool_)) or not isinstance(window, (int, np.integer))
                               or window < 1):
        raise InvalidValueError(f"window: got {window!r}; expected an odd number of lines (e.g. 11), or None to "
                                "choose it from the sharpest resonance")
    w = window or _window(clean, polyorder)
    s = smooth(clean, window=w, polyorder=polyorder).data[:, 0, 0]
    if window_tau is not None:
        window_tau = window_tau_s(window_tau)
    spacing = float(np.median(np.diff(measured.frequency.hz)))
    h0 = _kept_share(w, polyorder, window_tau, spacing)
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        q = np.log(h / s)
        g_all = 1.0 / np.abs(s) ** 2
    ok = usable & np.isfinite(q) & np.isfinite(g_all)
    ok[: w // 2] = False  # the smoother's edges are less reliable
    ok[n - w // 2:] = False
    if ok.sum() < 8:
        ok = usable & np.isfinite(q) & np.isfinite(g_all)
    scale = float(np.median(g_all[ok]))  # numbers of order one for the optimiser
    regressors = [np.where(np.isfinite(g_all), g_all, 0.0) / scale]
    coh_scale = 1.0
    if coh is not None:
        coh_scale = max(float(np.median(coh[ok])), 1e-30)
        regressors.append(coh / coh_scale)
    g = np.array(regressors)
    q_re2, q_im2 = q.real**2, q.imag**2
    m0 = max(float(np.median(q_re2[ok] + q_im2[ok])) / 1.386, 1e-14)  # chi^2_2 median is 1.386
    bounds = [(np.log(1e-16), np.log(10.0))] * 2 + [(np.log(1e-16), np.log(1e8))] * len(regressors)

    def solve(start, keep, nu=None):
        res = minimize(_nll, start, args=(q_re2[keep], q_im2[keep], g[:, keep], h0, nu), jac=True,
                       method="L-BFGS-B", bounds=bounds, options={"maxiter": 80, "ftol": 1e-10})
        return res.fun, res.x  # (a negligible term is flat: stop early)

    # a robust first fit (Student t, 4 dof: lines where the smoother cannot follow a very
    # sharp resonance pull little), from several starting shares of the line-dependent terms;
    # then the Gaussian fit with the lines beyond the 1e-4 tail set aside, until they settle
    starts = [np.log([m0 / 2, m0 / 2] + [m0 * share] * len(regressors)) for share in (1e-6, 1e-3, 1e-1, 10.0)]
    if coh is not None:  # the coherence alone, as its theory says
        starts.append(np.log([m0 * 1e-3, m0 * 1e-3, m0 * 1e-6, 2.0 * coh_scale]))
    params = min((solve(start, ok, 4.0) for start in starts), key=lambda r: r[0])[1]
    keep = None
    for _ in range(6):
        v_re, v_im = _variances(params, g, h0)
        # lines drowned in additive noise are left to the linear domain below: their log is
        # biased and would pull the fit (unless they are nearly all there is)
        drowned = 0.5 * np.exp(params[2]) * g[0] > NOISE_DOMINATED
        new = ok & (q_re2 / v_re + q_im2 / v_im <= _TRIM)
        if (new & ~drowned).sum() >= max(20, new.sum() // 10):
            new &= ~drowned
        if keep is not None and np.array_equal(new, keep):
            break
        keep = new
        params = solve(params, keep)[1]
    coef = np.exp(params)
    v_re, v_im = (v / (1.0 - h0) for v in _variances(params, g, h0))
    # the noise where it is clearly larger than the fitted model (a band of low coherence, the
    # lines near the data's own antiresonances, a noisy end of the band): a local scale from the
    # smoothing residual of the data alone, never from a model
    # A resonance sharper than the window is not smooth in H but is in 1/H (a dynamic stiffness
    # is a low-order polynomial of frequency near a resonance); noise is smooth in neither.  The
    # local steps read, line by line, the residual of whichever domain follows the data better
    # there, so that a sharp resonance of the data is never taken for noise.
    q_local = _best_domain_residual(clean, h, q, usable, w, polyorder)
    with np.errstate(divide="ignore", invalid="ignore"):
        z = 0.5 * (q_local.real**2 / ((1 - h0) * v_re) + q_local.imag**2 / ((1 - h0) * v_im))
    z = np.where(usable & np.isfinite(z), z, np.nan)
    z[:w] = np.nan  # the smoother's edges (its fits there lean to one side): no domain is reliable
    z[n - w:] = np.nan
    width = min(LOCAL_LINES, n if n % 2 else n - 1)
    local = _local_scale(z, width)
    v_re, v_im = v_re * local, v_im * local
    # a line whose own smoothing residual lies beyond the tail of even the local model is an
    # outlier of the data (a spike, a line the smoother cannot follow): its variance is what
    # the line itself shows, so that a model is neither blamed nor rewarded for it
    with np.errstate(invalid="ignore"):
        spike = usable & np.isfinite(z) & (z / local > _TRIM / 2)
    own = np.abs(q_local) ** 2 / (1.0 - h0) ** 2
    # the residual in units of its noise, for _equivalent_tau: about a smoother of at least DETECT_WINDOW lines (a
    # narrower one follows a correlated noise nearly whole; its misfit of a sharp resonance stays in a few blocks)
    w_seen = max(w, min(DETECT_WINDOW, n if n % 2 else n - 1))
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        q_seen = q_local if w_seen == w else _best_domain_residual(clean, h, np.log(
            h / smooth(clean, window=w_seen, polyorder=polyorder).data[:, 0, 0]), usable, w_seen, polyorder)
        whitened = (q_seen.real / np.sqrt(v_re), q_seen.imag / np.sqrt(v_im))
    v_re, v_im = (np.where(spike, np.maximum(v, own), v) for v in (v_re, v_im))
    # lines where the additive noise (the floor's, and the response's noise that the coherence term
    # carries) is as large as the signal: the log of the data is biased and heavy-tailed there, and
    # the tests read the residual in the linear domain
    additive_share = 0.5 * (coef[2:] @ g) * local
    linear = usable & (additive_share > NOISE_DOMINATED)
    with np.errstate(invalid="ignore", divide="ignore"):
        hs = np.where(linear, h / s, 0.0)
    # their variance in the linear domain from the data's linear smoothing residual H - S(H)
    # around each line (a running median over LINEAR_LINES lines: an exponential's median is
    # ln 2 times its mean), per part and relative to |S|^2
    d2 = np.where(usable, np.abs(h - s) ** 2, np.nan)
    d2[:w] = np.nan
    d2[n - w:] = np.nan
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)  # a window of edges only: NaN, not used
        padded = np.pad(d2, LINEAR_LINES // 2, constant_values=np.nan)
        windows = np.lib.stride_tricks.sliding_window_view(padded, LINEAR_LINES)
        local_d2 = np.nanmedian(windows, axis=1) / np.log(2.0) / (1.0 - h0)
    with np.errstate(divide="ignore", invalid="ignore"):
        v_lin = 0.5 * local_d2 / np.abs(s) ** 2
    if coh is not None:
        # a line's own coherence says how noisy it is, wherever its neighbours stand: its H1 variance (with the
        # fitted weight, as in the log domain) relative to |S|^2, at least (a single line at an antiresonance
        # the grid does not resolve: the smoother does not dip with it, and its neighbours are far less noisy)
        with np.errstate(invalid="ignore", over="ignore"):
            v_lin = np.maximum(v_lin, 0.5 * coef[3] * g[1] * local * np.abs(hs) ** 2)
    linear = linear & np.isfinite(v_lin) & (v_lin > 0)
    lin_re, lin_im = (np.where(linear, np.maximum(v_lin, c), np.nan) for c in coef[:2])
    var_re, var_im = (np.where(usable, np.minimum(np.where(np.isfinite(v), v, VARIANCE_CAP), VARIANCE_CAP),
                               VARIANCE_CAP) for v in (v_re, v_im))
    # the scale's standard error from the spread over blocks of lines
    zf = 0.5 * (q_re2 / ((1 - h0) * var_re) + q_im2 / ((1 - h0) * var_im))
    keep = keep & ~spike
    idx = np.flatnonzero(keep)
    blocks = [zf[part].mean() for part in np.array_split(idx, min(_BLOCKS, max(2, idx.size // 20))) if part.size]
    spread = float(np.std(blocks, ddof=1) / np.sqrt(len(blocks))) if len(blocks) > 1 else 1.0
    scatter = np.where(keep, zf, np.nan)
    coherence_factor = float(0.5 * coef[3] / coh_scale) if coh is not None else None
    extra = _force_term(force_noise, force_window_s, measured.frequency.hz, label)
    if truncation is not None:  # the taps' end: an error repeated by every tap, counted like the hammer's
        cut = 0.5 * _carried(truncation, n, f"truncation of {label}")
        extra = cut if extra is None else extra + cut
    dof = None
    if coh is not None:
        # the share of each line's variance that the coherence of a few taps gives, and the variance's degrees
        # of freedom from it (the other parts are fitted to many lines: known by comparison)
        with np.errstate(divide="ignore", invalid="ignore"):
            share = np.clip(0.5 * coef[3] * g[1] * local / (0.5 * (var_re + var_im)), 0.0, 1.0)
            dof = np.where(usable & (share > 0), 2.0 * (int(averages) - 1) / np.maximum(share, 1e-12) ** 2, np.inf)
        dof = np.where(np.isfinite(dof), dof, np.inf)
    if extra is not None:  # the hammer's noise: a smooth error the smoothing residual does not see (docstring)
        var_re, var_im = (np.minimum(v + extra, VARIANCE_CAP) for v in (var_re, var_im))
    bias = _hv_bias(coherence, averages, estimator)
    if bias is not None:  # Hv's bias towards H2, in the magnitude only (H1, H2 and Hv share their phase)
        var_re = np.minimum(var_re + bias**2, VARIANCE_CAP)
        lin_re = lin_re + np.expm1(bias) ** 2
    model = NoiseModel(var_re, var_im, (float(coef[0]), float(coef[1])), float(coef[2]) / scale,
                       max(spread, float(np.sqrt(1.0 / max(idx.size, 1)))), w, scatter,
                       local_scale=local, outliers=int(spike.sum()), coherence_factor=coherence_factor,
                       linear=(hs, lin_re, lin_im), dof=dof,
                       correlation=window_correlation(window_tau, spacing))
    valid = usable & np.isfinite(z) & ~spike & ~linear
    valid[: w_seen] = valid[n - w_seen:] = False
    return model, (whitened, valid, w_seen, polyorder, spacing)


def _residual_lag1(w: int, polyorder: int, u: float | None) -> float:
    """The correlation of neighbouring lines' smoothing residuals for noise correlated as through an exponential
    window with ``tau df = u`` (None: independent lines): ``r^T C_1 r / r^T C_0 r``, ``r`` the residual's filter."""
    r = -savgol_coeffs(w, polyorder)
    r[w // 2] += 1.0
    lag = np.subtract.outer(np.arange(w), np.arange(w))

    def c(k):
        return (k == 0).astype(float) if u is None else 1.0 / (1.0 + (np.pi * k * u) ** 2)

    return float(r @ c(lag - 1) @ r / (r @ c(lag) @ r))


def _equivalent_tau(whitened, valid: np.ndarray, w: int, polyorder: int, spacing: float) -> float | None:
    """The time constant [s] of the exponential window that would correlate the noise of neighbouring lines as
    much as the data's own smoothing residual shows, or None where it shows no more than independent lines do.

    Real tap-test noise is often correlated over neighbouring lines without a window the FRF records (the
    analyser's exponential window in a file of another system); read as independent, it makes an exact model
    fail the tests.  The residual's lag-1 correlation (both parts, their values clipped at 3.5 noise units
    against heavy tails; the median over :data:`_BLOCKS` blocks of the band, at least 50 pairs of lines each)
    is set against :func:`_residual_lag1` over the family of exponential windows; taken only beyond
    :data:`CORRELATION_Z` standard errors (of the median) of independent lines' value.
    """
    pairs = np.flatnonzero(valid[:-1] & valid[1:])
    if pairs.size < 50 * _BLOCKS or not spacing > 0:
        return None
    parts = [np.clip(np.where(valid, x, 0.0), -3.5, 3.5) for x in whitened]
    num = sum(x[pairs] * x[pairs + 1] for x in parts)
    den = sum(0.5 * (x[pairs] ** 2 + x[pairs + 1] ** 2) for x in parts)
    # the median over blocks of the band: a misfit a few lines wide (a bump the smoother follows in part) is the
    # data's own, not a correlation of the noise everywhere
    blocks = [(float(np.sum(num[b])), float(np.sum(den[b]))) for b in np.array_split(np.arange(pairs.size), _BLOCKS)]
    if not all(d > 0 for _, d in blocks):
        return None
    seen = float(np.median([n / d for n, d in blocks]))
    if seen <= _residual_lag1(w, polyorder, None) + 1.25 * CORRELATION_Z / np.sqrt(pairs.size):
        return None
    us = np.geomspace(1.0 / WINDOW_X_MAX, 30.0, 120)
    lags = np.array([_residual_lag1(w, polyorder, u) for u in us])  # falls as u grows
    if seen > lags[0]:  # more than any window leaves noise: the smoother's own misfit of data without noise
        return None
    u = float(np.exp(np.interp(seen, lags[::-1], np.log(us[::-1]))))
    return u / spacing
