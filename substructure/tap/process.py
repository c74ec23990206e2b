"""From tap records to an FRF with coherence: :func:`process_taps` (its result: :mod:`substructure.tap.result`).

Each record is cut into taps (one per record, or several with
``tap_length``), each tap judged (:mod:`substructure.tap.detect`), the kept
taps windowed (a rectangular force window around the pulse, an exponential
window on both channels) and transformed at once (``numpy.fft.rfft`` over a
``(taps, samples)`` array), and the averaged spectra give H1, H2 or Hv with
the ordinary coherence.  The FRF is converted to receptance; its 0 Hz line
is dropped.  See docs/tap.md for the equations.
"""

from __future__ import annotations

import hashlib
from typing import Any, Sequence

import attrs
import numpy as np
import scipy.fft

from ..errors import InvalidValueError
from ..frf import FRF, Frequency
from .detect import (CLIP_RUN, DOUBLE_HIT_FRACTION, NO_HIT_FACTOR, PRE_TRIGGER_S, TRIGGER_FRACTION,
                     check_swapped, double_hit, find_pulse, longest_flat_run, tap_starts)
from .record_end import noise_variance, the_end, told_apart, truncation_variance, window_words
from .records import RESPONSE_QUANTITIES, TapRecord
from .result import Tap, TapResult

__all__ = ["process_taps", "ESTIMATORS", "EXP_WINDOW_END", "FORCE_WINDOW_EXTRA", "FORCE_WINDOW_BEFORE",
           "HAMMER_BAND_DB", "SHORT_TAP_SHARE", "PULSE_SHORTEST_S", "PULSE_LONGEST_S"]

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

PULSE_SHORTEST_S = 5e-6
"""Taps whose median pulse is shorter (s) are refused: a hammer's pulse lasts from about 0.05 ms (a steel tip on a
small hammer) to 10 ms (a soft tip on a heavy one); shorter, the time axis is in other units than read (times in
seconds read as milliseconds make the pulse 1000 times shorter, every frequency 1000 times higher)."""

PULSE_LONGEST_S = 0.05
"""Taps whose median pulse is longer (s) are refused: times in milliseconds read as seconds make the pulse 1000 times
longer, and every frequency 1000 times lower."""

SHORT_TAP_SHARE = 0.25
"""Without ``tap_length`` every tap is cut to the shortest; a tap whose record ends sooner after its start than
this share of the taps' median length (a hit near the record's end) is rejected as cut short instead: its response
is hardly recorded, and cutting every other tap to it would coarsen the grid and window them all."""

HAMMER_BAND_DB = 20.0
"""The hammer's usable band ends where the force spectrum has fallen this many dB below its low-frequency level."""


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
    seen: dict[bytes, int] = {}
    for i, r in enumerate(items):  # one tap given twice is averaged as two: coherence 1, the scatter understated
        digest = hashlib.sha256(np.ascontiguousarray(r.force).tobytes() + b"|"
                                + np.ascontiguousarray(r.response).tobytes()).digest()
        if digest in seen:
            j = seen[digest]
            raise InvalidValueError(f"records[{i}] ({r.source}): the same force and response samples as records[{j}] "
                                    f"({items[j].source}); expected each tap once (a tap given twice is averaged as "
                                    "two, its coherence 1 and its scatter understated)")
        seen[digest] = i
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


_OPTIONAL = ("tap_length", "tau")
"""The settings that may be None (a record a tap, the window's time constant chosen)."""


def _check_settings(**settings: tuple[Any, str, bool]) -> None:
    """Each ``name=(value, unit, zero_allowed)`` a finite number above 0 (or at 0 where allowed), or None where
    :data:`_OPTIONAL` allows."""
    for name, (value, unit, zero) in settings.items():
        if value is None and name in _OPTIONAL:
            continue
        try:
            x = float(value)
        except (TypeError, ValueError, OverflowError):
            x = float("nan")
        if isinstance(value, bool) or not np.isfinite(x) or x < 0 or (x == 0 and not zero):
            expected = "a finite number >= 0" if zero else "a finite number > 0"
            raise InvalidValueError(f"{name}: got {value!r}{' ' + unit if unit else ''}; expected {expected}")


def _check_band(band: Any) -> tuple[float, float] | None:
    """``band`` as ``(lo, hi)`` in Hz, two finite numbers with ``0 <= lo < hi``; None as it is."""
    if band is None:
        return None
    try:
        lo, hi = (float(v) for v in band)
    except (TypeError, ValueError, OverflowError):
        lo = hi = float("nan")
    if not (np.isfinite(lo) and np.isfinite(hi) and 0.0 <= lo < hi) or isinstance(band, str):
        raise InvalidValueError(f"band: got {band!r}; expected (lo, hi) in Hz, two finite numbers with 0 <= lo < hi")
    return lo, hi


def _band_end(power: np.ndarray, hz: np.ndarray, drop_db: float) -> np.ndarray:
    """Per row of ``power`` (lines last, 0 Hz first): the first frequency below the low-frequency level - drop."""
    reference = power[..., 1:4].mean(axis=-1, keepdims=True)
    below = power[..., 1:] < reference * 10.0 ** (-drop_db / 10.0)
    first = np.where(below.any(axis=-1), np.argmax(below, axis=-1) + 1, hz.size - 1)
    return hz[first]


def _check_pulses(kept: list[Tap], rate: float, record: TapRecord) -> None:
    """Refuse taps whose pulses no hammer makes: the time axis read in the wrong unit."""
    width = float(np.median([t.pulse_width_s for t in kept]))
    if width <= PULSE_LONGEST_S and (width >= PULSE_SHORTEST_S or PULSE_SHORTEST_S * rate < 2):
        return  # (a pulse of a sample or two is not judged short: the rate would not show a shorter one)
    raise InvalidValueError(
        f"{record.source}: the hammer's pulse lasts {width * 1e3:.3g} ms (median of the {len(kept)} kept taps) at "
        f"{rate:.6g} samples/s, where a hammer's lasts about 0.05 to 10 ms: the time axis is not in the unit it "
        "was read in (times in ms read as s make the pulse 1000 times longer): check the time column's unit "
        "(e.g. 'time [ms]') or the sample rate the file or the command gives")


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
        ``scipy.fft.prev_fast_len``); a tap whose record ends sooner after
        its start than :data:`SHORT_TAP_SHARE` of the taps' median length is
        rejected as cut short instead (``TapResult.shortest`` names the tap
        that set the length).
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
        For records of different sample rates or quantities, the same tap
        twice, an unknown estimator, an ``exponential`` other than True,
        False or None, a ``tap_length`` not longer than ``pre_trigger``,
        records shorter than one tap, or no tap kept (the reasons listed).
    SwappedChannelsError
        When a record's force looks like a response (naming file and columns).
    """
    items = _records(records)
    band = _check_band(band)
    _check_settings(tap_length=(tap_length, "s", False), pre_trigger=(pre_trigger, "s", True),
                    tau=(tau, "s", False), window_end=(window_end, "", False),
                    force_window_extra=(force_window_extra, "pulse widths", True),
                    hammer_band_db=(hammer_band_db, "dB", False))
    if tap_length is not None and not float(tap_length) > float(pre_trigger):
        raise InvalidValueError(f"tap_length: got {tap_length!r} s, not longer than pre_trigger {pre_trigger!r} s; "
                                "expected a tap longer than the time kept before its hit")
    if exponential is not None and not isinstance(exponential, (bool, np.bool_)):
        raise InvalidValueError(f"exponential: got {exponential!r} ({type(exponential).__name__}); expected True, "
                                "False or None (the window only when the response still rings at the tap's end)")
    exponential = None if exponential is None else bool(exponential)
    if exponential is False and tau is not None:
        raise InvalidValueError(f"tau: got {tau!r} s with exponential=False; a time constant asks for the window")
    if not isinstance(estimator, str) or estimator not in ESTIMATORS:
        raise InvalidValueError(f"estimator: got {estimator!r}; expected one of {', '.join(ESTIMATORS)}")
    rate = items[0].sample_rate
    dt = 1.0 / rate
    pre = max(int(round(float(pre_trigger) * rate)), 0)
    taps: list[Tap] = []
    cuts: list[tuple[TapRecord, int, int]] = []  # record, first sample, tap index in taps
    peaks: dict[int, float] = {}  # without tap_length: per tap index, its peak force in the whole record
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
            peaks[len(taps)] = 0.0 if isinstance(first, str) else first.peak_force
        else:
            starts = tap_starts(record.force, length, pre, trigger_fraction, no_hit_factor)
            if not starts:
                taps.append(Tap(len(taps) + 1, record.source, 0.0,
                                reason=_dead(record.force_column, record.force, "record") or "no hit: the force never "
                                f"exceeds {no_hit_factor:g} times its noise in the record"))
        for s in starts:
            tap = Tap(len(taps) + 1, record.source, float(record.time[s] - record.time[0]))
            if tap_length is not None and s + length > len(record):  # the record ends inside this tap
                tap = attrs.evolve(tap, reason=f"cut short: the record ends {(len(record) - s) / rate:.4g} s into "
                                               f"this tap of {tap_length:g} s")
            else:
                cuts.append((record, s, len(taps)))
            taps.append(tap)
    shortest = None  # without tap_length: the tap whose length all are cut to, in words
    if tap_length is None and len(cuts) > 1:
        spans = np.array([len(r) - s for r, s, _ in cuts])
        median = float(np.median(spans))
        for (r, s, index), span in zip(cuts, spans.tolist()):
            if span < SHORT_TAP_SHARE * median:
                taps[index] = attrs.evolve(taps[index], peak_force=peaks[index], reason=(
                    f"cut short: the record ends {span / rate:.4g} s after this tap's start (t = "
                    f"{taps[index].start_s:.4g} s), under {SHORT_TAP_SHARE:g} of the taps' median {median / rate:.4g} "
                    "s: its response is hardly recorded (every tap is cut to the shortest kept one)"))
        cuts = [c for c in cuts if taps[c[2]].reason is None]
        spans = np.array([len(r) - s for r, s, _ in cuts])
        if cuts and spans.max() > spans.min():
            k = int(np.argmin(spans))
            shortest = (f"tap {taps[cuts[k][2]].number} ({cuts[k][0].source}): its record ends "
                        f"{spans[k] / rate:.4g} s after its start")
    if not cuts:
        reasons = "; ".join(f"tap {t.number} ({t.source}): {t.reason}" for t in taps)
        raise InvalidValueError(f"no tap kept: {reasons}")
    if tap_length is None:  # the longest length all taps have whose FFT is fast (no large prime factor)
        length = scipy.fft.prev_fast_len(min(len(r) - s for r, s, _ in cuts), real=True)
    if length < 16:
        raise InvalidValueError(f"{cuts[0][0].source}: the taps are {length} samples long; expected more")
    force = np.stack([r.force[s:s + length] for r, s, _ in cuts])
    response = np.stack([r.response[s:s + length] for r, s, _ in cuts])
    # the spectra, their products and the mean squares of the end of the taps are formed of the channels each
    # divided by a power of two near its peak (exact: the FRF and coherence do not depend on the channels' scale;
    # squares of 1e160 N overflowed, of 1e-170 N underflowed, to a coherence of 0), the scales undone after
    f_scale, x_scale = _scale(force), _scale(response)
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
            taps[index] = attrs.evolve(tap, reason=_dead(record.force_column, force[row], "tap") or pulse)
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
            if reason is None:
                reason = _dead(name, channel, "tap")
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
    power = np.abs(scipy.fft.rfft((force - baseline[:, None]) / f_scale * force_window, axis=1)) ** 2
    bands = _band_end(power, hz, hammer_band_db)
    for row, (_, _, index) in enumerate(cuts):
        if taps[index].peak_force > 0:
            taps[index] = attrs.evolve(taps[index], band_hz=float(bands[row]))
    if not kept:
        reasons = "; ".join(f"tap {t.number} ({t.source}): {t.reason}" for t in taps)
        raise InvalidValueError(f"no tap kept: {reasons}")
    _check_pulses([taps[cuts[r][2]] for r in kept], rate, cuts[0][0])
    rows = np.array(kept)
    f = (force[rows] - baseline[rows, None]) / f_scale
    x = response[rows] / x_scale
    quiet = np.argmax(force_window[rows] > 0, axis=1)  # the samples before the force window: no pulse yet
    for i, p in enumerate(quiet.tolist()):  # per tap, not per line: the response's offset before the hit
        # from the quiet samples only: what a filter of the acquisition spreads ahead of the pulse (a linear-phase
        # decimation filter rings before it) is no offset; through the exponential window an error c of the
        # offset is c / (1/tau + i omega) on every line, not on the 0 Hz line alone
        if p >= 8:
            x[i] -= x[i, :p].mean()
    f = f * force_window[rows]
    noise_sd = np.array([_noise_outside(force[r] - baseline[r], force_window[r]) for r in rows.tolist()]) / f_scale
    end = the_end(x, quiet, [taps[cuts[r][2]].number for r in rows])
    why: str | None = None  # said by the end of the taps, when the default decides
    response_noise = noise_variance(x, quiet)
    if exponential is None and tau is None:
        exponential = end.needs_window
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
        else:  # total least squares weighs both channels in their own units: the response's scale put back
            ratio = x_scale / f_scale
            a, b, c = gff, gxx * ratio**2, gfx * ratio  # the spectra of the force and the response, both / f_scale
            root = np.hypot(a - b, 2.0 * np.abs(c))  # two forms of one root, each free of cancellation
            h = np.where(a >= b, 2.0 * c / (a - b + root), (b - a + root) / (2.0 * np.conj(c))) / ratio
        coherence = np.abs(gfx) ** 2 / (gff * gxx)
    coherence = np.clip(np.nan_to_num(coherence, nan=0.0), 0.0, 1.0)
    h = np.nan_to_num(h)
    h_scaled, h = h, h * (x_scale / f_scale)
    keep = hz > 0.0
    if band is not None:
        lo, hi = band
        keep &= (hz >= lo) & (hz <= hi)
        if not keep.any():
            raise InvalidValueError(f"band: {lo:g}-{hi:g} Hz holds no line of the taps' grid (0 to {hz[-1]:g} Hz "
                                    f"in steps of {hz[1]:g} Hz)")
    kind = RESPONSE_QUANTITIES[items[0].quantity][1]
    measured = FRF.single(Frequency.from_hz(hz[keep]), h[keep], quantity=kind)
    spectra = 10.0 * np.log10(np.maximum(np.abs(F[:, keep]) ** 2, 1e-300)) + 20.0 * np.log10(f_scale)
    hammer_band = float(_band_end(gff[None, :], hz, hammer_band_db)[0])
    # the noise of the force channel in F: per tap sigma^2 sum(w^2) dt^2, the same on every line; in H1 =
    # sum X F* / sum |F|^2 a relative error whose variance is sum_j n_j |F_j|^2 / (sum_j |F_j|^2)^2
    n_f = noise_sd**2 * np.sum(w_f**2, axis=1) * dt**2
    with np.errstate(divide="ignore", invalid="ignore"):
        v_f = np.sum(n_f[:, None] * np.abs(F) ** 2, axis=0) / np.sum(np.abs(F) ** 2, axis=0) ** 2
    # an H2 is compared as gamma^2 H2, which is this H1 (Measurement.h1_frf): its hammer noise is the same
    v_f = np.where(np.isfinite(v_f), v_f, np.inf)[keep] if estimator != "Hv" else None
    width = float(np.mean(np.sum(w_f, axis=1) ** 2 / np.sum(w_f**2, axis=1))) * dt
    truncation = truncation_variance(x, F, w, response_noise, h_scaled, dt)
    if why is None:
        why = window_words(end, truncation, told_apart(x, response_noise))
    # through the window the taps measured the structure at omega - i/tau: so is its receptance
    receptance = measured.to_receptance(1.0 / tau if tau else 0.0)
    return TapResult(receptance, measured, coherence[keep], estimator, tuple(taps), tau,
                     hammer_band, float(hammer_band_db), spectra, rate, length, why, v_f,
                     float(np.sqrt(np.mean(noise_sd**2)) * f_scale), width,
                     None if truncation is None else truncation[keep], shortest)


def _dead(name: str, channel: np.ndarray, span: str) -> str | None:
    """The reason of a tap whose column ``name`` is one number throughout its ``span`` (nothing was measured: not
    an overload, not a missing hit), else None."""
    if channel.size == 0 or channel.max() != channel.min():
        return None
    return (f"dead channel: column {name!r} is {channel[0]:.4g} throughout the {span} (a sensor not connected, not "
            "powered, or a wrong channel)")


def _scale(channels: np.ndarray) -> float:
    """The power of two nearest above the channels' largest magnitude (1 for channels of zeros): dividing by it
    is exact and brings them to [0.5, 1)."""
    peak = float(np.max(np.abs(channels))) if channels.size else 0.0
    return float(np.ldexp(1.0, int(np.frexp(peak)[1]))) if np.isfinite(peak) and peak > 0 else 1.0


def _noise_outside(force: np.ndarray, window: np.ndarray) -> float:
    """The force channel's noise (standard deviation, robust: from the median absolute deviation) over the
    samples outside the force window, after it where there are enough, else before it."""
    after = force[np.flatnonzero(window)[-1] + 1:]
    rest = after if after.size >= 64 else force[window == 0]
    if rest.size < 8:
        return 0.0
    return float(1.4826 * np.median(np.abs(rest - np.median(rest))))
