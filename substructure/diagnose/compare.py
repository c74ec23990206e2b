"""Comparing a model FRF with a measured one: the error measure, modes, FRAC, noise floor.

The error measure, ``rms_log_ratio``, is the root mean square over the band of
the complex logarithm of the ratio of model to measurement,

``e = sqrt( mean_f | ln(H_model / H_measured) |^2 )
    = sqrt( mean_f [ (ln|H_model| - ln|H_measured|)^2 + (phase difference)^2 ] )``,

a log-magnitude term plus a phase term in radians.  It weighs every line of
the band alike whatever the FRF's level (resonances and antiresonances
count as much as the flanks), is symmetric in model and measurement, and a
relative error of 1 % on every line gives ``e = 0.01``.

The noise floor is estimated from the measurement alone, line by line
(:mod:`substructure.updating.noise`): the measured FRF is smoothed by a
Savitzky-Golay filter, and the log ratio of the data to its smoothed
version has the scatter of the noise, a relative part plus an additive part
that grows where ``|H|`` is small; the RMS of the per-line standard
deviations is the error a perfect model would still show (:func:`noise_floor`).
"""

from __future__ import annotations

import attrs
import numpy as np

from ..errors import FrequencyAxisMismatchError, InvalidValueError
from ..frf import FRF, frf_checked
from ..smoothing import choose_window, smooth
from .settings import DEFAULT_SETTINGS, DiagnoseSettings

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
    for name, value in (("model", model), ("measured", measured)):
        frf_checked(value, name)
    if model.frequency != measured.frequency:
        raise FrequencyAxisMismatchError(
            "model and measurement are on different frequency axes: compute the model on the "
            "measured grid (or interpolate the measurement explicitly)"
        )
    if model.shape[1:] != measured.shape[1:]:
        raise InvalidValueError(f"model {model.shape[1:]} and measurement {measured.shape[1:]} differ in entries")


def log_ratio(model: FRF, measured: FRF) -> np.ndarray:
    """``ln(H_model / H_measured)`` per line and entry.

    Parameters
    ----------
    model : FRF
        The model on the measured grid (same entries).
    measured : FRF
        The measurement.

    Returns
    -------
    ndarray, shape (n_freq, n_out, n_in)
        Complex log ratios.
    """
    _check(model, measured)
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.log(model.data / measured.data)


def error(model: FRF, measured: FRF, mask: np.ndarray | None = None) -> float:
    """The error measure ``rms_log_ratio`` over all entries (and the lines of ``mask``).

    Parameters
    ----------
    model : FRF
        The model on the measured grid (same entries).
    measured : FRF
        The measurement.
    mask : ndarray of bool, optional
        Lines to use.

    Returns
    -------
    float
        ``sqrt(mean |ln(H_model / H_measured)|^2)``.
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

    The per-line noise model of :func:`substructure.updating.noise.estimate_noise`
    (relative noise plus an additive floor that dominates where ``|H|`` is
    small, estimated from the scatter of the data about a Savitzky-Golay
    smoothing) gives the variances ``v_re``, ``v_im`` of the real and
    imaginary parts of ``ln H`` at every line; the floor is
    ``sqrt(mean(v_re + v_im))``, the expected :func:`error` of a perfect
    model.  With several entries, the RMS of their floors.

    Parameters
    ----------
    measured : FRF
        The measurement, on a uniform grid.
    window : int, optional
        Smoothing window in lines (chosen from the sharpest resonance when
        not given).
    polyorder : int, default 3
        Order of the smoother.

    Returns
    -------
    float
        The noise floor (same scale as :func:`error`).
    """
    from ..updating.noise import estimate_noise

    frf_checked(measured, "measured")
    floors = [estimate_noise(measured.select([o], [i]), window, polyorder).floor ** 2
              for o in measured.outputs for i in measured.inputs]
    return float(np.sqrt(np.mean(floors)))


def frac(model: FRF, measured: FRF) -> float:
    """Frequency response assurance criterion: 1 for FRFs of the same shape, 0 for unrelated.

    Parameters
    ----------
    model : FRF
        The model on the measured grid (same entries).
    measured : FRF
        The measurement.

    Returns
    -------
    float
        FRAC over all lines and entries.
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
        """Model minus measurement [Hz] (None when unpaired)."""
        return None if self.model_hz is None else self.model_hz - self.measured_hz

    @property
    def amplitude_ratio(self) -> float | None:
        """Model peak over measured peak (None when unpaired)."""
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


def pair_modes(model: FRF, measured: FRF, floor: float = 0.02, window: int | None = None,
               noise: float | None = None, prominence: float = 0.1, noise_prominence: float = 5.0,
               pairing: float = 1.5) -> list[ModePair]:
    """Pair each measured resonance with the nearest model resonance (in log frequency).

    Measured peaks are taken on the smoothed data (so that noise ripples are
    not peaks), both above ``floor`` times the highest peak; each model peak
    is used once, nearest first; a measured mode without a model mode within
    a factor ``pairing`` in frequency stays unpaired.  A measured mode must
    stand out of the noise: a prominence in ``ln|H|`` of at least
    ``prominence`` or ``noise_prominence`` noise floors, whichever is larger
    (a model mode: ``prominence``).

    Parameters
    ----------
    model : FRF
        The model on the measured grid (same entries).
    measured : FRF
        The measurement.
    floor : float
        Peaks below this share of the highest are left out.
    window : int, optional
        Smoothing window [lines].
    noise : float, optional
        The measurement's noise floor when known (estimated from it otherwise).
    prominence : float
        Least prominence of a peak in ``ln|H|`` (0.1: 10 %; dimensionless).
    noise_prominence : float
        Least prominence of a measured peak in noise floors.
    pairing : float
        Largest ratio of the frequencies of two modes paired (dimensionless).

    Returns
    -------
    list of ModePair
        One per measured resonance.
    """
    _check(model, measured)
    w = window or _window(measured)
    # a mode must stand out of the noise: a prominence of 0.1 in ln|H| (10 %) or
    # five times the noise floor, whichever is larger
    least = max(prominence, noise_prominence * (noise_floor(measured, window=w) if noise is None else noise))
    fm, hm = _peaks(smooth(measured, window=w), floor, least)
    fo, ho = _peaks(model, floor, prominence)
    candidates = sorted(
        (abs(np.log(a / b)), i, j)
        for i, a in enumerate(fm)
        for j, b in enumerate(fo)
        if abs(np.log(a / b)) < np.log(pairing)
    )
    used_j, match = set(), {}
    for _, i, j in candidates:
        if i not in match and j not in used_j:
            used_j.add(j)
            match[i] = j
    return [
        ModePair(float(fm[i]), float(fo[match[i]]) if i in match else None, float(hm[i]),
                 float(ho[match[i]]) if i in match else None)
        for i in range(len(fm))
    ]


def _pairs(model: FRF, measured: FRF, noise: float, settings: DiagnoseSettings) -> list:
    """:func:`pair_modes` with the settings' thresholds."""
    return pair_modes(model, measured, settings.mode_peak_share, noise=noise, prominence=settings.mode_prominence,
                      noise_prominence=settings.mode_prominence_floors, pairing=settings.mode_pairing)


def error_bands(model: FRF, measured: FRF, share: float = 0.5, width_hz: float | None = None,
                floor: float = 0.0, width_share: float = 0.02,
                floor_factor: float = 2.0) -> list[tuple[float, float, float]]:
    """The frequency bands that carry most of the error: ``[(lo, hi, share_of_error), ...]``.

    The squared log ratio, smoothed over ``width_hz`` (default
    ``width_share``, 2 %, of the band), is cut into contiguous regions above
    its median and above ``floor_factor`` (twice) the noise ``floor`` (noise
    is not a failure of the model); the regions are
    ranked by their share of the total and returned until ``share`` of the
    error is covered.

    Parameters
    ----------
    model : FRF
        The model on the measured grid (same entries).
    measured : FRF
        The measurement.
    share : float
        Share of the error to cover.
    width_hz : float, optional
        Smoothing width [Hz].
    floor : float
        The noise floor.
    width_share : float
        The default smoothing width as a share of the band (dimensionless).
    floor_factor : float
        Regions must lie above this many noise floors (dimensionless).

    Returns
    -------
    list of (float, float, float)
        ``(lo_hz, hi_hz, share)``, largest share first.
    """
    r2 = np.mean(np.abs(log_ratio(model, measured)) ** 2, axis=(1, 2))
    f = model.frequency.hz
    step = np.median(np.diff(f)) if f.size > 1 else 1.0
    width = width_hz or width_share * (f[-1] - f[0])
    n = max(1, int(round(width / step)))
    local = np.convolve(r2, np.ones(n) / n, mode="same")
    above = (local > np.median(local)) & (local > (floor_factor * floor) ** 2)
    total = r2.sum()
    # the contiguous runs of lines above: [start, stop) between the rises and falls of the padded mask
    edges = np.flatnonzero(np.diff(np.concatenate(([0], above[: f.size], [0])).astype(int)))
    regions = [(float(f[i]), float(f[j - 1]), float(r2[i:j].sum() / total)) for i, j in zip(edges[::2], edges[1::2])]
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
        """True when the error is within 1.5 times the noise floor (``DEFAULT_SETTINGS.explained_error_factor``)."""
        return self.error <= DEFAULT_SETTINGS.explained_error_factor * self.noise_floor

    def plot(self, ax=None):
        """Measured and model FRFs overlaid with the residual below, error bands shaded.

        Parameters
        ----------
        ax : sequence of three Axes, optional
            Where to draw (default: a new figure).

        Returns
        -------
        matplotlib.figure.Figure
            The figure (never shown).
        """
        from .plots import plot_comparison

        return plot_comparison(self, ax=ax)


def compare(model: FRF, measured: FRF) -> Comparison:
    """Compare a model FRF with a measurement on the measured grid.

    Parameters
    ----------
    model : FRF
        The model on the measured grid (same entries).
    measured : FRF
        The measurement.

    Returns
    -------
    Comparison
        Error, noise floor, FRAC, modes and error bands.
    """
    floor = noise_floor(measured)
    return Comparison(
        model=model,
        measured=measured,
        error=error(model, measured),
        noise_floor=floor,
        frac=frac(model, measured),
        modes=pair_modes(model, measured, noise=floor),
        bands=error_bands(model, measured, floor=floor),
    )
