"""Finding the taps of a record and judging each one: hit, pulse, double hit, clipping, swapped channels.

The thresholds are the module's named constants; :func:`substructure.tap.process_taps`
takes each as a keyword to override it.  Every test works on whole arrays
(no Python loop over samples).
"""

from __future__ import annotations

import attrs
import numpy as np

from ..errors import InvalidValueError

__all__ = ["TRIGGER_FRACTION", "NO_HIT_FACTOR", "DOUBLE_HIT_FRACTION", "CLIP_RUN", "CLIP_TOLERANCE", "CLIP_REACH",
           "PRE_TRIGGER_S", "CREST_FACTOR_PULSE", "Pulse", "SwappedChannelsError", "noise_level", "find_pulse",
           "double_hit", "longest_flat_run", "tap_starts", "crest_factor", "check_swapped"]

TRIGGER_FRACTION = 0.05
"""The trigger level as a fraction of the tap's peak force (the pulse starts where the force first exceeds it)."""

NO_HIT_FACTOR = 10.0
"""A force whose peak does not exceed this many times its noise (robust standard deviation) is no hit."""

DOUBLE_HIT_FRACTION = 0.05
"""A second pulse after the first has ended, above this fraction of the first's peak, is a double hit."""

CLIP_RUN = 4
"""This many consecutive samples at a channel's maximum or minimum are a clipped (overloaded) channel."""

CLIP_TOLERANCE = 1e-9
"""Samples within this fraction of the channel's range from its extreme count as at the extreme."""

CLIP_REACH = 0.5
"""Only an extreme at least this fraction of the channel's largest excursion from its mean can be a clip."""

PRE_TRIGGER_S = 0.005
"""Time kept before the force first crosses its trigger level, in s (less when the record starts later)."""

CREST_FACTOR_PULSE = 10.0
"""A response whose peak exceeds this many times its RMS, and more than the force's, is a pulse: swapped channels."""


class SwappedChannelsError(InvalidValueError):
    """The force column looks like a response and the response like a force."""


def noise_level(values: np.ndarray, median: float | None = None) -> float:
    """The robust standard deviation of a channel: 1.4826 times its median absolute deviation.

    Parameters
    ----------
    values : numpy.ndarray
        The samples, any unit.
    median : float, optional
        Their median, when it is known already.

    Returns
    -------
    float
        The noise level in the unit of the samples (the short pulse of a tap
        does not move it).
    """
    median = float(np.median(values)) if median is None else median
    return float(1.4826 * np.median(np.abs(values - median)))


@attrs.frozen
class Pulse:
    """The force pulse of one tap, in samples of its segment.

    Parameters
    ----------
    start : int
        First sample above the trigger level.
    peak : int
        Sample of the largest force.
    end : int
        First sample after the peak back below the trigger level.
    peak_force : float
        The peak force in N (positive for a push; the sign of the record is kept in ``sign``).
    sign : float
        +1 or -1: the polarity of the hammer's channel.
    noise : float
        The force noise level in N.
    level : float
        The trigger level in N.
    baseline : float
        The force's resting level (its median) in N.
    """

    start: int
    peak: int
    end: int
    peak_force: float
    sign: float
    noise: float
    level: float
    baseline: float = 0.0


def find_pulse(force: np.ndarray, trigger_fraction: float = TRIGGER_FRACTION,
               no_hit_factor: float = NO_HIT_FACTOR) -> Pulse | str:
    """The pulse of a tap's force, or the reason why there is none.

    Parameters
    ----------
    force : numpy.ndarray
        The force in N.
    trigger_fraction : float
        The trigger level as a fraction of the peak (dimensionless).
    no_hit_factor : float
        The peak must exceed this many noise levels (dimensionless).

    Returns
    -------
    Pulse or str
        The pulse, or a reason starting with ``"no hit"``.
    """
    baseline = float(np.median(force))
    centred = force - baseline
    k = int(np.argmax(np.abs(centred)))
    peak = float(abs(centred[k]))
    noise = noise_level(force, baseline)
    if not peak > no_hit_factor * noise:
        return (f"no hit: the force never exceeds {no_hit_factor:g} times its noise (peak {peak:.3g} N, "
                f"noise {noise:.3g} N)")
    sign = 1.0 if centred[k] > 0 else -1.0
    signed = sign * centred
    level = max(trigger_fraction * peak, 0.5 * no_hit_factor * noise)
    above = signed > level
    start = int(np.argmax(above))
    below = ~above[k:]
    end = k + int(np.argmax(below)) if below.any() else force.size
    return Pulse(start, k, end, peak, sign, noise, level, baseline)


def double_hit(force: np.ndarray, pulse: Pulse, fraction: float = DOUBLE_HIT_FRACTION) -> int | None:
    """The first sample of a second pulse after ``pulse`` has ended, or None.

    Parameters
    ----------
    force : numpy.ndarray
        The force in N, the segment ``pulse`` was found in.
    pulse : Pulse
        The first pulse.
    fraction : float
        A second pulse must exceed this fraction of the first's peak (dimensionless).

    Returns
    -------
    int or None
        The sample index.
    """
    after = pulse.sign * (force[pulse.end:] - pulse.baseline)
    level = max(fraction * pulse.peak_force, 0.5 * NO_HIT_FACTOR * pulse.noise)
    hits = after > level
    if not hits.any():
        return None
    return pulse.end + int(np.argmax(hits))


def longest_flat_run(values: np.ndarray, tolerance: float = CLIP_TOLERANCE) -> tuple[int, str]:
    """The longest run of consecutive samples at the channel's maximum or minimum.

    Parameters
    ----------
    values : numpy.ndarray
        The channel.
    tolerance : float
        Fraction of the channel's range within which a sample counts as at the extreme.

    Returns
    -------
    int
        The length of the longest run (samples).
    str
        ``"maximum"`` or ``"minimum"``: where it lies.
    """
    hi, lo = float(values.max()), float(values.min())
    span = hi - lo
    if span == 0.0:
        return int(values.size), "maximum"
    middle = float(np.mean(values))
    reach = max(hi - middle, middle - lo)
    best, where = 0, "maximum"
    for name, mask, extreme in (("maximum", values >= hi - tolerance * span, hi),
                                ("minimum", values <= lo + tolerance * span, lo)):
        if abs(extreme - middle) < CLIP_REACH * reach:  # the resting level (a force between taps) is no overload
            continue
        edges = np.flatnonzero(np.diff(np.concatenate(([0], mask.view(np.int8), [0]))))
        runs = edges[1::2] - edges[::2]
        longest = int(runs.max()) if runs.size else 0
        if longest > best:
            best, where = longest, name
    return best, where


def tap_starts(force: np.ndarray, tap_samples: int, pre_samples: int,
               trigger_fraction: float = TRIGGER_FRACTION, no_hit_factor: float = NO_HIT_FACTOR) -> list[int]:
    """The first samples of the taps of a long record: each trigger crossing after the previous tap ended.

    Parameters
    ----------
    force : numpy.ndarray
        The whole record's force in N.
    tap_samples : int
        The length of one tap in samples; a crossing inside a tap belongs to
        it (a double hit), the next crossing after it starts a new tap.
    pre_samples : int
        Samples kept before each crossing.
    trigger_fraction, no_hit_factor : float
        As for :func:`find_pulse`, with the record's largest force as the peak.

    Returns
    -------
    list of int
        The first sample of each tap (the crossing minus the pre-trigger),
        empty when the record holds no hit.
    """
    centred = force - np.median(force)
    peak = float(np.max(np.abs(centred)))
    noise = noise_level(force)
    if not peak > no_hit_factor * noise:
        return []
    sign = 1.0 if centred[int(np.argmax(np.abs(centred)))] > 0 else -1.0
    level = max(trigger_fraction * peak, 0.5 * no_hit_factor * noise)
    crossings = np.flatnonzero((sign * centred[1:] > level) & (sign * centred[:-1] <= level)) + 1
    if sign * centred[0] > level:
        crossings = np.concatenate(([0], crossings))
    starts: list[int] = []
    end = -1
    for c in crossings.tolist():  # one pass over the crossings, not the samples
        if c >= end:
            start = max(c - pre_samples, 0)
            starts.append(start)
            end = start + tap_samples
    return starts


def crest_factor(values: np.ndarray) -> float:
    """The peak over the RMS of a channel, its mean removed (dimensionless; large for a short pulse).

    Parameters
    ----------
    values : numpy.ndarray
        The channel.

    Returns
    -------
    float
        ``max|v - mean| / rms(v - mean)``; 0 for a constant channel.
    """
    centred = values - np.mean(values)
    peak = float(np.max(np.abs(centred))) if centred.size else 0.0
    if not peak > 0:
        return 0.0
    # relative to the peak: the squares of channels of 1e160 or 1e-170 would overflow or underflow
    return float(1.0 / np.sqrt(np.mean((centred / peak) ** 2)))


def check_swapped(force: np.ndarray, response: np.ndarray, dt: float, source: str, force_column: str,
                  response_column: str) -> None:
    """Refuse a record whose response looks more like a hammer's pulse than its force does.

    A hammer's force is a pulse of a few milliseconds in a long record: its
    peak is many times its RMS (its crest factor is large).  A structure's
    response rings on after the hit: its crest factor is smaller.  When the
    response's crest factor exceeds :data:`CREST_FACTOR_PULSE` (it is a
    pulse, not noise) and the force's, the columns are taken to be swapped.

    Parameters
    ----------
    force, response : numpy.ndarray
        The channels.
    dt : float
        The time step in s.
    source, force_column, response_column : str
        For the message.

    Raises
    ------
    SwappedChannelsError
        Naming the file and both columns.
    """
    if force.size and force.max() == force.min():  # a dead hammer channel is said so by its tap, not swapped
        return
    c_force, c_response = crest_factor(force), crest_factor(response)
    if c_response > CREST_FACTOR_PULSE and c_response > c_force:
        # a hit in the record's last 5 %: the response has hardly begun, and a pulse in both columns says
        # nothing about which is which
        k = int(np.argmax(np.abs(force - np.median(force))))
        if k >= 0.95 * force.size:
            raise InvalidValueError(
                f"{source}: the hit in column {force_column!r} comes at t = {k * dt:.4g} s, "
                f"{(force.size - k) * dt:.3g} s before the record ends: the response after it is not recorded "
                "(record longer after the trigger)"
            )
        raise SwappedChannelsError(
            f"{source}: column {force_column!r} does not look like a hammer's force and column "
            f"{response_column!r} does: the force's peak is {c_force:.3g} times its RMS, the response's "
            f"{c_response:.3g} times (a force is a short pulse, a response rings on); the channels look swapped: "
            "check which column is which"
        )
