"""What the processing of taps gives: :class:`TapResult` (the FRF, its coherence, the taps, the windows) and
:class:`Tap`, with what a result says of itself (its peaks, their damping, the hammer's noise, the end of
the taps).  Made by :func:`substructure.tap.process_taps`; see docs/tap.md, section 5.
"""

from __future__ import annotations

from typing import Any

import attrs
import numpy as np

from ..frf import FRF
from .record_end import TRUNCATION_SEGMENT

__all__ = ["TapResult", "Tap", "PEAK_PROMINENCE", "HALF_POWER_LINES", "added_damping"]

HALF_POWER_LINES = 3
"""A half-power bandwidth narrower than this many lines gives no damping ratio (the grid cannot resolve it)."""

PEAK_PROMINENCE = 0.02
"""The peaks a result reports stand out by at least this fraction of the largest magnitude in the band."""


def added_damping(tau: float | None, frequency_hz: Any) -> np.ndarray:
    """The damping ratio an exponential window ``exp(-t/tau)`` adds to a mode at ``frequency_hz``.

    The window multiplies every free decay ``exp(-zeta omega t)`` by
    ``exp(-t/tau)``: the decay rate grows by ``1/tau``, i.e. the damping
    ratio by ``1 / (tau omega)``.

    Parameters
    ----------
    tau : float or None
        The window's time constant in s (None: no window, nothing added).
    frequency_hz : float or array of float
        Natural frequencies in Hz.

    Returns
    -------
    numpy.ndarray
        The added damping ratios (dimensionless).
    """
    f = np.asarray(frequency_hz, dtype=np.float64)
    if tau is None:
        return np.zeros_like(f)
    return 1.0 / (tau * 2.0 * np.pi * f)


@attrs.frozen
class Tap:
    """One tap found in a record, kept or rejected.

    Parameters
    ----------
    number : int
        1-based, over all records in the order given.
    source : str
        The record's file (or name).
    start_s : float
        The time of the tap's first sample in its record (s).
    peak_force : float
        The peak force in N (0 when there is no hit).
    pulse_width_s : float
        The time the force stays above the trigger level (s).
    band_hz : float
        Where this tap's force spectrum falls the hammer-band limit below
        its low-frequency level (Hz; the Nyquist frequency when it never does).
    reason : str or None
        Why the tap was rejected; None for a kept tap.
    """

    number: int
    source: str
    start_s: float
    peak_force: float = 0.0
    pulse_width_s: float = 0.0
    band_hz: float = 0.0
    reason: str | None = None

    @property
    def kept(self) -> bool:
        """Whether the tap is averaged into the FRF."""
        return self.reason is None


@attrs.frozen(eq=False)
class TapResult:
    """An FRF estimated from taps, with its coherence and what was done to get it.

    Parameters
    ----------
    frf : FRF
        The receptance (m/N), one entry, 0 Hz line dropped.
    measured : FRF
        The FRF as measured (accelerance, mobility or receptance), same lines.
    coherence : numpy.ndarray
        The ordinary coherence per line of ``frf`` (dimensionless).
    estimator : str
        ``"H1"``, ``"H2"`` or ``"Hv"``.
    taps : tuple of Tap
        Every tap found, kept and rejected.
    tau : float or None
        The exponential window's time constant in s (None: no window).
    hammer_band_hz : float
        The usable band's upper end of the averaged force spectrum (Hz).
    hammer_band_db : float
        The drop that defines it (dB).
    force_spectra_db : numpy.ndarray
        Per kept tap, the force spectrum ``20 log10(|F| dt)`` in dB re 1 N/Hz
        on the lines of ``frf``; shape ``(averages, n_lines)``.
    sample_rate : float
        Samples per second (Hz).
    tap_samples : int
        Samples per tap.
    window : str
        Why the exponential window was (or was not) applied, in words.
    force_noise : numpy.ndarray or None
        Per line of ``frf``, the variance of the relative error of H1 that
        the hammer channel's noise gives (``E|dH / H|^2``; half of it in the
        log magnitude, half in the phase): each kept tap's noise, measured
        outside its force window, through the force window and the
        exponential one. It is smooth in frequency, over about
        ``1 / force_window_s`` hertz.  For H2 too, which is compared as the
        H1 of the same taps, ``gamma^2 H2``
        (:attr:`Measurement.h1_frf <substructure.measurements.Measurement.h1_frf>`);
        None for Hv.
    force_noise_rms : float
        The hammer channel's noise outside the pulse, RMS over the kept taps
        (N).
    force_window_s : float
        The force window's effective length (s): the width of the window that
        holds the same noise, ``(sum w)^2 / sum w^2`` samples.
    truncation : numpy.ndarray or None
        Per line of ``frf``, the variance of the FRF's relative error that
        the end of the taps leaves where the response still rings there,
        counted over the lines it spans
        (``substructure.tap.record_end.truncation_variance``); None
        when the response died out.  The diagnosis's noise model adds it as
        it adds ``force_noise``.
    shortest : str or None
        Without ``tap_length``, when the kept taps' records ended at different
        times after their starts: the tap that set ``tap_samples`` (every tap
        is cut to it), in words; None otherwise.
    """

    frf: FRF
    measured: FRF
    coherence: np.ndarray
    estimator: str
    taps: tuple[Tap, ...]
    tau: float | None
    hammer_band_hz: float
    hammer_band_db: float
    force_spectra_db: np.ndarray
    sample_rate: float
    tap_samples: int
    window: str = ""
    force_noise: np.ndarray | None = None
    force_noise_rms: float = 0.0
    force_window_s: float = 0.0
    truncation: np.ndarray | None = None
    shortest: str | None = None

    @property
    def averages(self) -> int:
        """The number of taps averaged."""
        return sum(t.kept for t in self.taps)

    @property
    def rejected(self) -> tuple[Tap, ...]:
        """The rejected taps, each with its reason."""
        return tuple(t for t in self.taps if not t.kept)

    def peaks(self, lo: float | None = None, hi: float | None = None,
              prominence: float = PEAK_PROMINENCE) -> np.ndarray:
        """Frequencies (Hz) of the prominent peaks of the FRF as measured, within a band.

        The peaks are those of the measured quantity (an accelerance for an
        accelerometer), whose modes stand out evenly over the band, found by
        :meth:`substructure.frf.FRF.peaks` with a prominence.

        Parameters
        ----------
        lo, hi : float, optional
            The band in Hz (default: the FRF's first line to the hammer's usable band).
        prominence : float
            The least prominence as a fraction of the largest magnitude in the band (dimensionless).

        Returns
        -------
        numpy.ndarray
            The peak frequencies in Hz, ascending; none when the FRF's lines
            (its ``band``) lie above the hammer's usable band and ``hi`` is not given.
        """
        hz = self.measured.frequency.hz
        lo = hz[0] if lo is None else lo
        if hi is None:
            hi = min(self.hammer_band_hz, hz[-1])
            if hi < lo:  # every line above the hammer's usable band: no peak to trust
                return np.zeros(0)
        frf = self.measured.crop(lo, hi)
        if frf.frequency.n < 3:
            return np.zeros(0)
        return np.asarray(frf.peaks(prominence=prominence), dtype=np.float64)

    def added_damping(self, frequency_hz: Any) -> np.ndarray:
        """The damping ratio the exponential window added at ``frequency_hz`` (see :func:`added_damping`).

        Parameters
        ----------
        frequency_hz : float or array of float
            Frequencies in Hz.

        Returns
        -------
        numpy.ndarray
            Dimensionless added damping ratios.
        """
        return added_damping(self.tau, frequency_hz)

    def damping(self, peaks: Any = None) -> list[dict]:
        """The damping ratio of each peak by its half-power bandwidth, and with the window's share taken out.

        The exponential window moves every pole by ``-1/tau`` (docs/tap.md,
        section 3): a mode's decay rate ``zeta omega_n`` grows by ``1/tau``
        exactly.  The half-power bandwidth of the windowed peak gives
        ``zeta_measured = (f_2 - f_1) / (2 f_peak)`` (the crossings of
        ``|H|^2 = max/2`` interpolated between lines, on the receptance);
        ``zeta_corrected = zeta_measured - 1/(tau omega_peak)``.  It needs a
        peak several lines wide and apart from its neighbours; a peak whose
        half-power points are not found on both sides within half the
        distance to the next peak, or lie fewer than :data:`HALF_POWER_LINES`
        lines apart, gets None.

        Parameters
        ----------
        peaks : array of float, optional
            Peak frequencies in Hz (default: :meth:`peaks`).

        Returns
        -------
        list of dict
            Per peak: ``frequency_hz``, ``damping_ratio`` (half-power, as
            measured, with the window's), ``added_damping_ratio`` and
            ``damping_ratio_corrected`` (dimensionless; None where the
            half-power points are not found).
        """
        peaks = self.peaks() if peaks is None else np.atleast_1d(np.asarray(peaks, dtype=np.float64))
        hz = self.frf.frequency.hz
        power = np.abs(self.frf.data[:, 0, 0]) ** 2
        out = []
        for j, f in enumerate(peaks.tolist()):  # per peak (a handful), not per line
            k = int(np.argmin(np.abs(hz - f)))
            lo_edge = 0.5 * (peaks[j - 1] + f) if j > 0 else hz[0]
            hi_edge = 0.5 * (peaks[j + 1] + f) if j + 1 < peaks.size else hz[-1]
            half = 0.5 * power[k]
            left = np.flatnonzero((power[:k] < half) & (hz[:k] >= lo_edge))
            right = np.flatnonzero((power[k:] < half) & (hz[k:] <= hi_edge)) + k
            zeta = None
            if left.size and right.size:
                i, r = left[-1], right[0]
                f1 = np.interp(half, [power[i], power[i + 1]], [hz[i], hz[i + 1]])
                f2 = np.interp(half, [power[r], power[r - 1]], [hz[r], hz[r - 1]])
                if f2 - f1 >= HALF_POWER_LINES * (hz[1] - hz[0]):
                    zeta = float((f2 - f1) / (2.0 * hz[k]))
            added = float(added_damping(self.tau, hz[k]))
            out.append({"frequency_hz": float(hz[k]), "damping_ratio": zeta, "added_damping_ratio": added,
                        "damping_ratio_corrected": None if zeta is None else zeta - added})
        return out

    def force_scatter(self) -> float | None:
        """The largest relative scatter of H1 that the hammer's noise gives within the usable band.

        Returns
        -------
        float or None
            ``sqrt(force_noise)`` at its largest over the lines up to
            ``hammer_band_hz`` (0.01: 1 %); None for Hv.
        """
        if self.force_noise is None:
            return None
        usable = self.frf.frequency.hz <= self.hammer_band_hz
        values = self.force_noise[usable] if usable.any() else self.force_noise
        values = values[np.isfinite(values)]  # a line without force has no finite variance
        return float(np.sqrt(np.max(values))) if values.size else None

    def truncation_error(self) -> tuple[float, float] | None:
        """The largest relative error the end of the taps leaves within the usable band, and where.

        Returns
        -------
        (float, float) or None
            ``(error, frequency_hz)``: the bound of
            ``substructure.tap.record_end.truncation_variance`` at its
            largest over the finite lines up to ``hammer_band_hz`` (0.01: 1 %),
            without the count of lines it spans; None when the response
            died out.
        """
        if self.truncation is None:
            return None
        hz = self.frf.frequency.hz
        usable = (hz <= self.hammer_band_hz) & np.isfinite(self.truncation)
        if not usable.any():
            return None
        k = int(np.argmax(np.where(usable, self.truncation, -1.0)))
        return float(np.sqrt(self.truncation[k] * TRUNCATION_SEGMENT)), float(hz[k])

    def summary(self) -> dict:
        """The result as plain data (the JSON of ``substructure tap``).

        Returns
        -------
        dict
            Keys ``taps``, ``rejected``, ``estimator``, ``averages``, ``frequency_hz``,
            ``real``, ``imag``, ``coherence``, ``tau_s``, ``window`` (why the window was or was
            not applied), ``hammer_band_hz``, ``force_noise_rms_n``, ``force_window_s``,
            ``force_scatter`` (:meth:`force_scatter`), ``truncation_error``
            (:meth:`truncation_error` as ``{"error", "frequency_hz"}``, or
            None), ``shortest`` (the tap that set the taps' length, or None), ``per_tap``.
        """
        values = self.frf.data[:, 0, 0]
        return {
            "taps": self.averages,
            "averages": self.averages,
            "rejected": [{"tap": t.number, "file": t.source, "reason": t.reason} for t in self.rejected],
            "estimator": self.estimator,
            "frequency_hz": self.frf.frequency.hz.tolist(),
            "real": values.real.tolist(),
            "imag": values.imag.tolist(),
            "coherence": self.coherence.tolist(),
            "tau_s": self.tau,
            "window": self.window,
            "hammer_band_hz": self.hammer_band_hz,
            "hammer_band_db": self.hammer_band_db,
            "force_noise_rms_n": self.force_noise_rms,
            "force_window_s": self.force_window_s,
            "force_scatter": self.force_scatter(),
            "truncation_error": None if (cut := self.truncation_error()) is None else
            {"error": cut[0], "frequency_hz": cut[1]},
            "shortest": self.shortest,
            "per_tap": [{"tap": t.number, "file": t.source, "start_s": t.start_s, "peak_force_n": t.peak_force,
                         "pulse_width_s": t.pulse_width_s, "band_hz": t.band_hz, "kept": t.kept}
                        for t in self.taps],
        }
