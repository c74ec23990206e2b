"""From tap records to an FRF with coherence: :func:`process_taps` and :class:`TapResult`.

Each record is cut into taps (one per record, or several with
``tap_length``), each tap judged (:mod:`substructure.tap.detect`), the kept
taps windowed (a rectangular force window around the pulse, an exponential
window on both channels) and transformed at once (``numpy.fft.rfft`` over a
``(taps, samples)`` array), and the averaged spectra give H1, H2 or Hv with
the ordinary coherence.  The FRF is converted to receptance; its 0 Hz line
is dropped.  See docs/tap.md for the equations.
"""

from __future__ import annotations

from typing import Any, Sequence

import attrs
import numpy as np
import scipy.fft

from ..errors import InvalidValueError
from ..frf import FRF, Frequency
from .detect import (CLIP_RUN, DOUBLE_HIT_FRACTION, NO_HIT_FACTOR, PRE_TRIGGER_S, TRIGGER_FRACTION,
                     check_swapped, double_hit, find_pulse, longest_flat_run, tap_starts)
from .record_end import TRUNCATION_SEGMENT, end_words, noise_variance, truncation_variance, window_needed
from .records import RESPONSE_QUANTITIES, TapRecord

__all__ = ["process_taps", "TapResult", "Tap", "ESTIMATORS", "EXP_WINDOW_END", "FORCE_WINDOW_EXTRA",
           "FORCE_WINDOW_BEFORE", "HAMMER_BAND_DB", "PEAK_PROMINENCE", "HALF_POWER_LINES",
           "added_damping"]

ESTIMATORS = ("H1", "H2", "Hv")
"""The FRF estimators: H1 = Gfx/Gff (noise on the response), H2 = Gxx/Gxf (noise on the force), Hv (both)."""

EXP_WINDOW_END = 0.01
"""The exponential window's value at the end of the tap when its time constant is not given."""

FORCE_WINDOW_EXTRA = 1.0
"""The force window stays open this many pulse widths after the pulse ends."""

FORCE_WINDOW_BEFORE = 1.0
"""The force window opens this many pulse widths before the force crosses the trigger level (the pulse's rise
below that level is kept; the pre-trigger's noise before it is not: left in, it is a smooth random error of H1
over hundreds of hertz, largest relative to the response's noise at the resonances)."""

HALF_POWER_LINES = 3
"""A half-power bandwidth narrower than this many lines gives no damping ratio (the grid cannot resolve it)."""

PEAK_PROMINENCE = 0.02
"""The peaks a result reports stand out by at least this fraction of the largest magnitude in the band."""

HAMMER_BAND_DB = 20.0
"""The hammer's usable band ends where the force spectrum has fallen this many dB below its low-frequency level."""


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
            The peak frequencies in Hz, ascending.
        """
        hz = self.measured.frequency.hz
        lo = hz[0] if lo is None else lo
        hi = min(self.hammer_band_hz, hz[-1]) if hi is None else hi
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
            None), ``per_tap``.
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
            "per_tap": [{"tap": t.number, "file": t.source, "start_s": t.start_s, "peak_force_n": t.peak_force,
                         "pulse_width_s": t.pulse_width_s, "band_hz": t.band_hz, "kept": t.kept}
                        for t in self.taps],
        }


def _records(records: Any) -> tuple[TapRecord, ...]:
    if isinstance(records, TapRecord):
        records = (records,)
    try:
        items = tuple(records)
    except TypeError:
        raise InvalidValueError(f"records: got {type(records).__name__}; expected TapRecord objects") from None
    if not items:
        raise InvalidValueError("records: got none; expected at least one TapRecord")
    for i, r in enumerate(items):
        if not isinstance(r, TapRecord):
            raise InvalidValueError(f"records[{i}]: got {type(r).__name__}; expected a TapRecord")
    first = items[0]
    for r in items[1:]:
        if abs(r.sample_rate - first.sample_rate) > 1e-6 * first.sample_rate:
            raise InvalidValueError(f"{r.source}: sampled at {r.sample_rate:g} Hz, {first.source} at "
                                    f"{first.sample_rate:g} Hz; the taps of one FRF need one sample rate")
        if r.quantity != first.quantity:
            raise InvalidValueError(f"{r.source}: column {r.response_column!r} is a {r.quantity}, "
                                    f"{first.source}'s {first.response_column!r} a {first.quantity}; the taps "
                                    "of one FRF need one response quantity")
    return items


def _check_settings(**settings: tuple[Any, str, bool]) -> None:
    """Each ``name=(value, unit, zero_allowed)`` a finite number above 0 (or at 0 where allowed), or None."""
    for name, (value, unit, zero) in settings.items():
        if value is None:
            continue
        try:
            x = float(value)
        except (TypeError, ValueError):
            x = float("nan")
        if isinstance(value, bool) or not np.isfinite(x) or x < 0 or (x == 0 and not zero):
            expected = "a finite number >= 0" if zero else "a finite number > 0"
            raise InvalidValueError(f"{name}: got {value!r}{' ' + unit if unit else ''}; expected {expected}")


def _band_end(power: np.ndarray, hz: np.ndarray, drop_db: float) -> np.ndarray:
    """Per row of ``power`` (lines last, 0 Hz first): the first frequency below the low-frequency level - drop."""
    reference = power[..., 1:4].mean(axis=-1, keepdims=True)
    below = power[..., 1:] < reference * 10.0 ** (-drop_db / 10.0)
    first = np.where(below.any(axis=-1), np.argmax(below, axis=-1) + 1, hz.size - 1)
    return hz[first]


def process_taps(
    records: TapRecord | Sequence[TapRecord],
    estimator: str = "H1",
    *,
    tap_length: Any = None,
    pre_trigger: float = PRE_TRIGGER_S,
    exponential: bool | None = None,
    tau: float | None = None,
    window_end: float = EXP_WINDOW_END,
    force_window_extra: float = FORCE_WINDOW_EXTRA,
    trigger_fraction: float = TRIGGER_FRACTION,
    no_hit_factor: float = NO_HIT_FACTOR,
    double_hit_fraction: float = DOUBLE_HIT_FRACTION,
    clip_run: int = CLIP_RUN,
    hammer_band_db: float = HAMMER_BAND_DB,
    band: tuple[float, float] | None = None,
) -> TapResult:
    """Estimate an FRF with its coherence from the time records of taps.

    Parameters
    ----------
    records : TapRecord or sequence of TapRecord
        One record per tap, or long records holding several taps (give
        ``tap_length``); one sample rate and one response quantity.
    estimator : {"H1", "H2", "Hv"}
        H1 = Gfx/Gff (unbiased with noise on the response), H2 = Gxx/Gxf
        (unbiased with noise on the force), Hv (total least squares).
    tap_length : float, optional
        The length of one tap in s: a record is then cut into taps at every
        trigger crossing after the previous tap ended.  Default: one tap per
        record, from the pre-trigger to the end of the shortest record
        (shortened to the nearest length below whose FFT is fast:
        ``scipy.fft.prev_fast_len``).
    pre_trigger : float
        Time kept before the trigger crossing, in s.
    exponential : bool or None
        Whether to apply the exponential window to both channels; None
        (default): only when the response still rings at the end of a tap
        above :data:`WINDOW_SHARE` of its peak: a window adds the damping
        ratio ``1 / (tau omega)`` to every mode, which a comparison with a
        model sees; below it, the truncation's error is counted
        (``TapResult.truncation``).
    tau : float, optional
        Its time constant in s (given: the window is applied unless
        ``exponential`` is False); default such that it falls to
        ``window_end`` at the end of the tap.
    window_end : float
        See ``tau`` (dimensionless, in (0, 1)).
    force_window_extra : float
        The force window closes this many pulse widths after the pulse
        (dimensionless); the force is zero after it.
    trigger_fraction, no_hit_factor, double_hit_fraction : float
        Thresholds of :mod:`substructure.tap.detect` (dimensionless).
    clip_run : int
        Samples at a channel's extreme that make it clipped.
    hammer_band_db : float
        The drop of the force spectrum (dB) that ends the hammer's usable band.
    band : (float, float), optional
        Keep only these lines (Hz).

    Returns
    -------
    TapResult
        The receptance, coherence, taps and windows.

    Raises
    ------
    InvalidValueError
        For records of different sample rates or quantities, an unknown
        estimator, records shorter than one tap, or no tap kept (the
        reasons listed).
    SwappedChannelsError
        When a record's force looks like a response (naming file and columns).
    """
    items = _records(records)
    _check_settings(tap_length=(tap_length, "s", False), pre_trigger=(pre_trigger, "s", True),
                    tau=(tau, "s", False), window_end=(window_end, "", False),
                    force_window_extra=(force_window_extra, "pulse widths", True),
                    hammer_band_db=(hammer_band_db, "dB", False))
    if exponential is False and tau is not None:
        raise InvalidValueError(f"tau: got {tau!r} s with exponential=False; a time constant asks for the window")
    if estimator not in ESTIMATORS:
        raise InvalidValueError(f"estimator: got {estimator!r}; expected one of {', '.join(ESTIMATORS)}")
    rate = items[0].sample_rate
    dt = 1.0 / rate
    pre = max(int(round(float(pre_trigger) * rate)), 0)
    taps: list[Tap] = []
    cuts: list[tuple[TapRecord, int, int]] = []  # record, first sample, tap index in taps
    if tap_length is not None:
        length = int(round(float(tap_length) * rate))
        if length < 16:
            raise InvalidValueError(f"tap_length: got {tap_length!r} s, {length} samples; expected a longer tap")
    for record in items:
        check_swapped(record.force, record.response, dt, record.source, record.force_column,
                      record.response_column)
        if tap_length is None:
            first = find_pulse(record.force, trigger_fraction, no_hit_factor)
            starts = [0 if isinstance(first, str) else max(first.start - pre, 0)]
        else:
            starts = tap_starts(record.force, length, pre, trigger_fraction, no_hit_factor)
            if not starts:
                taps.append(Tap(len(taps) + 1, record.source, 0.0,
                                reason="no hit: the force never exceeds "
                                       f"{no_hit_factor:g} times its noise in the record"))
        for s in starts:
            tap = Tap(len(taps) + 1, record.source, float(record.time[s] - record.time[0]))
            if tap_length is not None and s + length > len(record):  # the record ends inside this tap
                tap = attrs.evolve(tap, reason=f"cut short: the record ends {(len(record) - s) / rate:.4g} s into "
                                               f"this tap of {tap_length:g} s")
            else:
                cuts.append((record, s, len(taps)))
            taps.append(tap)
    if not cuts:
        reasons = "; ".join(f"tap {t.number} ({t.source}): {t.reason}" for t in taps)
        raise InvalidValueError(f"no tap kept: {reasons}")
    if tap_length is None:  # the longest length all taps have whose FFT is fast (no large prime factor)
        length = scipy.fft.prev_fast_len(min(len(r) - s for r, s, _ in cuts), real=True)
    if length < 16:
        raise InvalidValueError(f"{cuts[0][0].source}: the taps are {length} samples long; expected more")
    force = np.stack([r.force[s:s + length] for r, s, _ in cuts])
    response = np.stack([r.response[s:s + length] for r, s, _ in cuts])
    hz = np.fft.rfftfreq(length, dt)
    # judge each tap; the windows of the kept ones
    force_window = np.zeros_like(force)
    kept: list[int] = []
    trigger = np.zeros(len(cuts))
    baseline = np.zeros(len(cuts))
    for row, (record, s, index) in enumerate(cuts):
        tap = taps[index]
        pulse = find_pulse(force[row], trigger_fraction, no_hit_factor)
        if isinstance(pulse, str):
            taps[index] = attrs.evolve(tap, reason=pulse)
            continue
        width = (pulse.end - pulse.start) * dt
        tap = attrs.evolve(tap, peak_force=pulse.peak_force, pulse_width_s=width)
        reason = None
        second = double_hit(force[row], pulse, double_hit_fraction)
        if second is not None:
            t = float(record.time[s + second] - record.time[0])
            size = abs(force[row][second] - pulse.baseline)
            reason = (f"double hit at t = {t:.5g} s (a second pulse of {size:.3g} N after the first of "
                      f"{pulse.peak_force:.3g} N had ended)")
        for name, channel in ((record.force_column, force[row]), (record.response_column, response[row])):
            run, where = longest_flat_run(channel)
            if reason is None and channel.max() == channel.min():  # not an overload: nothing was measured
                reason = (f"dead channel: column {name!r} is {channel[0]:.4g} throughout the tap (a sensor not "
                          "connected, not powered, or a wrong channel)")
            if reason is None and run >= clip_run:
                value = channel.max() if where == "maximum" else channel.min()
                reason = (f"clipped: column {name!r} stays at its {where} ({value:.4g}) for {run} samples "
                          "(an overload: a larger range, or a softer tap)")
        taps[index] = attrs.evolve(tap, reason=reason)
        close = min(pulse.end + int(np.ceil(force_window_extra * (pulse.end - pulse.start))) + 1, length)
        open_ = max(pulse.start - int(np.ceil(FORCE_WINDOW_BEFORE * (pulse.end - pulse.start))) - 1, 0)
        force_window[row, open_:close] = 1.0
        trigger[row] = pulse.start * dt
        baseline[row] = pulse.baseline
        if reason is None:
            kept.append(row)
    # the usable band per tap (kept or not), from the force in its window
    power = np.abs(scipy.fft.rfft((force - baseline[:, None]) * force_window, axis=1)) ** 2
    bands = _band_end(power, hz, hammer_band_db)
    for row, (_, _, index) in enumerate(cuts):
        if taps[index].peak_force > 0:
            taps[index] = attrs.evolve(taps[index], band_hz=float(bands[row]))
    if not kept:
        reasons = "; ".join(f"tap {t.number} ({t.source}): {t.reason}" for t in taps)
        raise InvalidValueError(f"no tap kept: {reasons}")
    rows = np.array(kept)
    f = force[rows] - baseline[rows, None]
    x = response[rows].copy()
    pre_rows = (trigger[rows] / dt).astype(int)
    for i, p in enumerate(pre_rows.tolist()):  # per tap, not per line: the response's offset before the hit
        if p >= 8:
            x[i] -= x[i, :p].mean()
    f = f * force_window[rows]
    noise_sd = np.array([_noise_outside(force[r] - baseline[r], force_window[r]) for r in rows.tolist()])
    quiet = np.argmax(force_window[rows] > 0, axis=1)  # the samples before the force window: no pulse yet
    needed, why = window_needed(x, quiet, [taps[cuts[r][2]].number for r in rows])
    response_noise = noise_variance(x, quiet)
    if exponential is None and tau is None:
        exponential = needed
    elif exponential is False:
        why = "none: not asked for"
    else:  # asked for: exponential=True, or a time constant given
        exponential, why = True, "asked for"
    if exponential:
        if tau is None:
            if not 0.0 < window_end < 1.0:
                raise InvalidValueError(f"window_end: got {window_end!r}; expected a value in (0, 1)")
            tau = (length * dt - float(trigger[rows].max())) / np.log(1.0 / window_end)
        tau = float(tau)
        if not tau > 0:
            raise InvalidValueError(f"tau: got {tau!r} s; expected a positive time constant")
        t = np.arange(length) * dt
        w = np.exp(-(t[None, :] - trigger[rows][:, None]) / tau)
        f, x = f * w, x * w
    else:
        tau, w = None, np.ones((1, length))
    w_f = force_window[rows] * w  # the windows the force's noise passes through
    F = scipy.fft.rfft(f, axis=1) * dt
    X = scipy.fft.rfft(x, axis=1) * dt
    gff = np.mean(np.abs(F) ** 2, axis=0)
    gxx = np.mean(np.abs(X) ** 2, axis=0)
    gfx = np.mean(np.conj(F) * X, axis=0)
    with np.errstate(divide="ignore", invalid="ignore"):
        if estimator == "H1":
            h = gfx / gff
        elif estimator == "H2":
            h = gxx / np.conj(gfx)
        else:
            root = np.hypot(gff - gxx, 2.0 * np.abs(gfx))  # two forms of one root, each free of cancellation
            h = np.where(gff >= gxx, 2.0 * gfx / (gff - gxx + root), (gxx - gff + root) / (2.0 * np.conj(gfx)))
        coherence = np.abs(gfx) ** 2 / (gff * gxx)
    coherence = np.clip(np.nan_to_num(coherence, nan=0.0), 0.0, 1.0)
    h = np.nan_to_num(h)
    keep = hz > 0.0
    if band is not None:
        lo, hi = band
        keep &= (hz >= lo) & (hz <= hi)
        if not keep.any():
            raise InvalidValueError(f"band: {lo:g}-{hi:g} Hz holds no line of the taps' grid (0 to {hz[-1]:g} Hz "
                                    f"in steps of {hz[1]:g} Hz)")
    kind = RESPONSE_QUANTITIES[items[0].quantity][1]
    measured = FRF.single(Frequency.from_hz(hz[keep]), h[keep], quantity=kind)
    spectra = 10.0 * np.log10(np.maximum(np.abs(F[:, keep]) ** 2, 1e-300))
    hammer_band = float(_band_end(gff[None, :], hz, hammer_band_db)[0])
    # the noise of the force channel in F: per tap sigma^2 sum(w^2) dt^2, the same on every line; in H1 =
    # sum X F* / sum |F|^2 a relative error whose variance is sum_j n_j |F_j|^2 / (sum_j |F_j|^2)^2
    n_f = noise_sd**2 * np.sum(w_f**2, axis=1) * dt**2
    with np.errstate(divide="ignore", invalid="ignore"):
        v_f = np.sum(n_f[:, None] * np.abs(F) ** 2, axis=0) / np.sum(np.abs(F) ** 2, axis=0) ** 2
    # an H2 is compared as gamma^2 H2, which is this H1 (Measurement.h1_frf): its hammer noise is the same
    v_f = np.where(np.isfinite(v_f), v_f, np.inf)[keep] if estimator != "Hv" else None
    width = float(np.mean(np.sum(w_f, axis=1) ** 2 / np.sum(w_f**2, axis=1))) * dt
    truncation = truncation_variance(x, F, w, response_noise, h, dt)
    why = end_words(why, truncation)
    return TapResult(measured.to_receptance(), measured, coherence[keep], estimator, tuple(taps), tau,
                     hammer_band, float(hammer_band_db), spectra, rate, length, why, v_f,
                     float(np.sqrt(np.mean(noise_sd**2))), width, None if truncation is None else truncation[keep])


def _noise_outside(force: np.ndarray, window: np.ndarray) -> float:
    """The force channel's noise (standard deviation, robust: from the median absolute deviation) over the
    samples outside the force window, after it where there are enough, else before it."""
    after = force[np.flatnonzero(window)[-1] + 1:]
    rest = after if after.size >= 64 else force[window == 0]
    if rest.size < 8:
        return 0.0
    return float(1.4826 * np.median(np.abs(rest - np.median(rest))))
