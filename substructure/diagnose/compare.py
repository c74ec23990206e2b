"""Comparing a model FRF with a measured one: the error measure, modes, FRAC, noise floor.

The error measure, ``rms_log_ratio``, is the root mean square over the band of
the complex logarithm of the ratio of model to measurement,

``e = sqrt( mean_f | ln(H_model / H_measured) |^2 )
    = sqrt( mean_f [ (ln|H_model| - ln|H_measured|)^2 + (phase difference)^2 ] )``,

a log-magnitude term plus a phase term in radians.  It weighs every line of
the band alike whatever the FRF's level (resonances and antiresonances
count as much as the flanks), is symmetric in model and measurement, and a
relative error of 1 % on every line gives ``e = 0.01``.

The noise floor is estimated from the measurement alone: the measured FRF
is smoothed by a Savitzky-Golay filter, and the log ratio of the data to its
smoothed version has the scatter of the noise; corrected for the share of
the noise the filter keeps, its RMS is the error a perfect model would still
show (:func:`noise_floor`).
"""

from __future__ import annotations

import attrs
import numpy as np
from scipy.signal import savgol_coeffs

from ..errors import FrequencyAxisMismatchError, InvalidValueError
from ..frf import FRF
from ..smoothing import choose_window, smooth

__all__ = [
    "METRIC",
    "log_ratio",
    "error",
    "noise_floor",
    "frac",
    "ModePair",
    "pair_modes",
    "error_bands",
    "Comparison",
    "compare",
]

METRIC = "rms_log_ratio"
"""Name of the error measure in reports and JSON."""


def _check(model: FRF, measured: FRF) -> None:
    if model.frequency != measured.frequency:
        raise FrequencyAxisMismatchError(
            "model and measurement are on different frequency axes: compute the model on the "
            "measured grid (or interpolate the measurement explicitly)"
        )
    if model.shape[1:] != measured.shape[1:]:
        raise InvalidValueError(f"model {model.shape[1:]} and measurement {measured.shape[1:]} differ in entries")


def log_ratio(model: FRF, measured: FRF) -> np.ndarray:
    """``ln(H_model / H_measured)`` per line and entry, shape ``(n_freq, n_out, n_in)``."""
    _check(model, measured)
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.log(model.data / measured.data)


def error(model: FRF, measured: FRF, mask: np.ndarray | None = None) -> float:
    """The error measure ``rms_log_ratio`` over all entries (and the lines of ``mask``).

    Parameters
    ----------
    model : FRF
        The model's FRF (m/N for a tool point H).
    measured : FRF
        The measured FRF, on the same lines and labels.
    mask : ndarray of bool, optional
        The lines to use (``(n_freq,)``); default all.

    Returns
    -------
    float
        ``sqrt(mean |ln(model / measured)|^2)``: dimensionless, 0.01 for 1 % off on every line.
    """
    r = log_ratio(model, measured)
    if mask is not None:
        r = r[mask]
    return float(np.sqrt(np.mean(np.abs(r) ** 2)))


def _window(measured: FRF, polyorder: int = 3) -> int:
    """A smoothing window for noise estimation (no warning: peak bias does not matter here)."""
    import warnings

    from ..smoothing import CoarseDataWarning

    with warnings.catch_warnings():
        warnings.simplefilter("ignore", CoarseDataWarning)
        try:
            return choose_window(measured, polyorder=polyorder)
        except InvalidValueError:  # no resonance in the band: a window of ~2 % of the lines
            n = len(measured.frequency)
            w = max(polyorder + 2, min(31, n // 50))
            return w + 1 if w % 2 == 0 else w


def noise_floor(measured: FRF, window: int | None = None, polyorder: int = 3) -> float:
    """The error a perfect model would show on these data, estimated from the data.

    ``r = ln(H / S(H))`` with ``S`` a Savitzky-Golay smoother of window ``w``:
    for white relative noise of RMS ``sigma`` the filter keeps the share
    ``h0`` (its central coefficient) of each line's noise, so
    ``var(r) = sigma^2 (1 - 2 h0 + sum(h^2)) = sigma^2 (1 - h0)``.  The scatter
    of ``r`` is taken robustly (1.4826 times the median absolute deviation, of
    the real and imaginary parts), so that the few lines where the smoother
    cannot follow the FRF (very sharp resonances, antiresonances in a noise
    floor) do not inflate it; the floor is ``sigma``.

    Parameters
    ----------
    measured : FRF
        The measured FRF.
    window : int, optional
        Odd window of the smoother, in lines; default chosen from the narrowest resonance.
    polyorder : int
        Order of the smoother's polynomial.

    Returns
    -------
    float
        The floor, on the scale of the error measure (dimensionless).
    """
    w = window or _window(measured, polyorder)
    smoothed = smooth(measured, window=w, polyorder=polyorder)
    with np.errstate(divide="ignore", invalid="ignore"):
        r = np.log(measured.data / smoothed.data)
    r = r[w // 2 : -(w // 2) or None]  # the filter's edges are less reliable
    r = r[np.isfinite(r)]
    h0 = float(savgol_coeffs(w, polyorder)[w // 2])

    def mad(x):
        return 1.4826 * np.median(np.abs(x - np.median(x)))

    return float(np.sqrt((mad(r.real) ** 2 + mad(r.imag) ** 2) / (1.0 - h0)))


def frac(model: FRF, measured: FRF) -> float:
    """Frequency response assurance criterion: 1 for FRFs of the same shape, 0 for unrelated.

    Parameters
    ----------
    model : FRF
        The model's FRF (m/N for a tool point H).
    measured : FRF
        The measured FRF, on the same lines and labels.

    Returns
    -------
    float
        The criterion, in [0, 1].
    """
    _check(model, measured)
    a, b = model.data.ravel(), measured.data.ravel()
    return float(np.abs(np.vdot(a, b)) ** 2 / (np.vdot(a, a).real * np.vdot(b, b).real))


@attrs.frozen
class ModePair:
    """A measured resonance and the model's resonance paired with it."""

    measured_hz: float
    model_hz: float | None
    measured_amplitude: float
    model_amplitude: float | None

    @property
    def shift_hz(self) -> float | None:
        """Model minus measurement, Hz."""
        return None if self.model_hz is None else self.model_hz - self.measured_hz

    @property
    def amplitude_ratio(self) -> float | None:
        return None if self.model_amplitude is None else self.model_amplitude / self.measured_amplitude


def _peaks(frf: FRF, floor: float, prominence: float) -> tuple[np.ndarray, np.ndarray]:
    """Resonances of the first entry of a (smoothed) FRF.

    Peaks of ``ln|H|`` with a prominence of at least ``prominence`` (so that
    noise ripples are not modes) and at least ``floor`` times the highest.
    """
    from scipy.signal import find_peaks

    h = np.abs(frf.data[:, 0, 0])
    f = frf.frequency.hz
    with np.errstate(divide="ignore"):
        idx, _ = find_peaks(np.log(h), prominence=prominence)
    if idx.size:
        idx = idx[h[idx] >= floor * h[idx].max()]
    return f[idx], h[idx]


def pair_modes(model: FRF, measured: FRF, floor: float = 0.02, window: int | None = None) -> list[ModePair]:
    """Pair each measured resonance with the nearest model resonance (in log frequency).

    Measured peaks are taken on the smoothed data (so that noise ripples are
    not peaks), both above ``floor`` times the highest peak; each model peak
    is used once, nearest first; a measured mode without a model mode within
    a factor 1.5 in frequency stays unpaired.

    Parameters
    ----------
    model : FRF
        The model's FRF (m/N for a tool point H).
    measured : FRF
        The measured FRF, on the same lines and labels.
    floor : float
        Peaks below this fraction of the highest one are ignored.
    window : int, optional
        Smoothing window in lines; default chosen from the data.

    Returns
    -------
    list of ModePair
        One per measured peak, with the model's frequency (Hz) when paired.
    """
    _check(model, measured)
    w = window or _window(measured)
    # a mode must stand out of the noise: a prominence of 0.1 in ln|H| (10 %) or
    # five times the noise floor, whichever is larger
    prominence = max(0.1, 5.0 * noise_floor(measured, window=w))
    fm, hm = _peaks(smooth(measured, window=w), floor, prominence)
    fo, ho = _peaks(model, floor, 0.1)
    candidates = sorted(
        (abs(np.log(a / b)), i, j) for i, a in enumerate(fm) for j, b in enumerate(fo) if abs(np.log(a / b)) < np.log(1.5)
    )
    used_i, used_j, match = set(), set(), {}
    for _, i, j in candidates:
        if i not in used_i and j not in used_j:
            used_i.add(i)
            used_j.add(j)
            match[i] = j
    return [
        ModePair(float(fm[i]), float(fo[match[i]]) if i in match else None, float(hm[i]),
                 float(ho[match[i]]) if i in match else None)
        for i in range(len(fm))
    ]


def error_bands(model: FRF, measured: FRF, share: float = 0.5, width_hz: float | None = None,
                floor: float = 0.0) -> list[tuple[float, float, float]]:
    """The frequency bands that carry most of the error: ``[(lo, hi, share_of_error), ...]``.

    The squared log ratio, smoothed over ``width_hz`` (default 2 % of the
    band), is cut into contiguous regions above its median and above twice
    the noise ``floor`` (noise is not a failure of the model); the regions are
    ranked by their share of the total and returned until ``share`` of the
    error is covered.  None when the model is within the noise everywhere.
    """
    r2 = np.mean(np.abs(log_ratio(model, measured)) ** 2, axis=(1, 2))
    f = model.frequency.hz
    step = np.median(np.diff(f)) if f.size > 1 else 1.0
    width = width_hz or 0.02 * (f[-1] - f[0])
    n = max(1, int(round(width / step)))
    local = np.convolve(r2, np.ones(n) / n, mode="same")
    above = (local > np.median(local)) & (local > (2.0 * floor) ** 2)
    total = r2.sum()
    regions = []
    i = 0
    while i < f.size:
        if above[i]:
            j = i
            while j + 1 < f.size and above[j + 1]:
                j += 1
            regions.append((float(f[i]), float(f[j]), float(r2[i : j + 1].sum() / total)))
            i = j + 1
        else:
            i += 1
    regions.sort(key=lambda r: -r[2])
    out, covered = [], 0.0
    for reg in regions:
        out.append(reg)
        covered += reg[2]
        if covered >= share:
            break
    return out


@attrs.frozen
class Comparison:
    """Model against measurement: the numbers a report needs.

    Parameters
    ----------
    model : FRF
        The model's FRF (m/N for a tool point H).
    measured : FRF
        The measured FRF, on the same lines and labels.
    error : float
        The error measure (:data:`METRIC`).
    noise_floor : float
        The error a perfect model would show (estimated from the data).
    frac : float
        Frequency response assurance criterion, in [0, 1] (1: same shape).
    modes : list of ModePair
        Measured and model peaks paired, with their shifts in Hz and height ratios.
    bands : list of (lo, hi, share)
        Where the error is.
    """

    model: FRF
    measured: FRF
    error: float
    noise_floor: float
    frac: float
    modes: list
    bands: list

    @property
    def as_good_as_data(self) -> bool:
        """True when the error is within 1.5 times the noise floor."""
        return self.error <= 1.5 * self.noise_floor

    def plot(self, ax=None):
        """Measured and model FRFs overlaid with the residual below, error bands shaded.

        Parameters
        ----------
        ax : sequence of Axes, optional
            Where to draw; a new figure when None.

        Returns
        -------
        Figure
            The figure (never shown by the library).
        """
        from .plots import plot_comparison

        return plot_comparison(self, ax=ax)


def compare(model: FRF, measured: FRF) -> Comparison:
    """Compare a model FRF with a measurement on the measured grid.

    Parameters
    ----------
    model : FRF
        The model's FRF (m/N for a tool point H).
    measured : FRF
        The measured FRF, on the same lines and labels.

    Returns
    -------
    Comparison
        The error, the noise floor, FRAC, paired modes and error bands.
    """
    floor = noise_floor(measured)
    return Comparison(
        model=model,
        measured=measured,
        error=error(model, measured),
        noise_floor=floor,
        frac=frac(model, measured),
        modes=pair_modes(model, measured),
        bands=error_bands(model, measured, floor=floor),
    )
