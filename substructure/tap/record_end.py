"""The end of a tap: whether the response died out within it, and what its truncation leaves in the FRF.

A response that still rings when the tap ends is cut there: the FRF lacks
the transform of the rest, ``-int_L^inf x(t) exp(-i omega t) dt / F``.  The
taps repeat that error (the same response, scaled), so the coherence does
not see it; where it exceeds the noise, an exact model is refused.
:func:`truncation_variance` estimates it from the taps' own last samples.
The last segment (:data:`TRUNCATION_SEGMENT` of the tap) and the one before
it each contribute a part to the FRF averaged over the taps, less their
noise (from the taps' scatter: averaging reduces the noise, not the
repeated tail), their powers averaged over three times the ``1 / TRUNCATION_SEGMENT``
lines a segment resolves and kept where they stand out of the noise
(:data:`TRUNCATION_SIGNIFICANCE`).  Their ratio ``r`` at each line is the decay of
the modes that ring there; for one decaying mode the rest beyond the end is
at most ``r / (1 - r)`` times the last segment's part (reached at the
mode's frequency), which is the estimate.  On the shipped real records cut
short (0.5 to 0.05 s, against the FRF of the whole 1 s) the actual error is
a median 0.1 to 0.2 of it, within it (with the noise) on 95 % of the lines.
See docs/tap.md, "The end of a tap".
"""

from __future__ import annotations

import attrs
import numpy as np
import scipy.fft
from scipy.stats import chi2
from scipy.stats import f as f_dist

__all__ = ["DECAYED_SHARE", "WINDOW_SHARE", "TRUNCATION_SEGMENT", "TRUNCATION_RATIO_MAX", "TRUNCATION_SIGNIFICANCE",
           "TRUNCATION_NEGLIGIBLE", "End", "the_end", "window_words", "told_apart",
           "noise_variance", "truncation_variance"]

DECAYED_SHARE = 3e-3
"""A response has died out by the end of a tap when its RMS over the tap's last 5 % is at most this share of its
peak, or at most three times its RMS before the hit (its noise)."""

WINDOW_SHARE = 0.1
"""The exponential window is applied by default only when the response's RMS over a tap's last 5 % exceeds this
share of its peak (and three times its noise).  Below it the truncation's error is estimated and counted
(``TapResult.truncation``) rather than traded for the damping ``1 / (tau omega)`` the window adds to every mode,
which no model compared with the FRF has."""

TRUNCATION_SIGNIFICANCE = 1e-3
"""A segment's part counts where its power, averaged over the lines it resolves, exceeds its noise's by more than
noise does with this probability, over all the independent lines of the band (the lines of a segment's
spectrum are correlated over ``1 / TRUNCATION_SEGMENT`` lines)."""

TRUNCATION_NEGLIGIBLE = 1e-6
"""A truncation whose relative error is below this on every line is none (a response rung down to rounding)."""

TRUNCATION_SEGMENT = 0.1
"""The share of a tap whose response estimates the truncation's error, and the segment before it its decay."""

TRUNCATION_RATIO_MAX = 0.9
"""The largest decay ratio from one segment to the next that is used: a response that does not decay over the
tap's last fifth is bounded as if it did by this much (the rest is then at most nine times the last segment's)."""


@attrs.frozen
class End:
    """How the responses of the kept taps end: ``state`` is ``"died"`` (every tap's RMS over its last
    ``tail`` samples at most :data:`DECAYED_SHARE` of its peak, or three times its noise), ``"rang"`` (above
    that, at most :data:`WINDOW_SHARE`) or ``"ringing"`` (above it: the exponential window is needed);
    ``share`` is that RMS over the peak (the largest, or that of tap ``tap``, the one that rang most)."""

    state: str
    share: float
    tail: int
    tap: int | None = None

    @property
    def needs_window(self) -> bool:
        """Whether the exponential window is needed (by default)."""
        return self.state == "ringing"


def the_end(x: np.ndarray, pre: np.ndarray, numbers: list[int]) -> End:
    """How the responses ``x`` (one kept tap a row, numbered ``numbers``) end; ``pre``: the samples before each hit."""
    tail = max(16, x.shape[1] // 20)
    end = np.sqrt(np.mean(x[:, -tail:] ** 2, axis=1))
    peak = np.max(np.abs(x), axis=1)
    noise = np.sqrt(noise_variance(x, pre))
    share = end / np.maximum(peak, 1e-300)
    alive = end > np.maximum(DECAYED_SHARE * peak, 3.0 * noise)
    if not alive.any():
        return End("died", float(share.max()), tail)
    k = int(np.argmax(np.where(alive, share, -1.0)))
    return End("rang" if share[k] <= WINDOW_SHARE else "ringing", float(share[k]), tail, numbers[k])


def window_words(end: End, truncation: np.ndarray | None, told: bool = True) -> str:
    """Why the exponential window was (or was not) applied by default, with what the end of the taps leaves.

    ``truncation`` is what :func:`truncation_variance` found; ``told`` is False when it could not tell an
    error of the end from the noise (one tap, no samples before the hit to measure the noise on).
    """
    if end.state == "died":
        words = (f"none: the response {'died' if truncation is None else 'nearly died'} out within every tap (its "
                 f"RMS over the last {end.tail} samples at most {end.share:.2g} of its peak)")
    else:
        where = f"by the end of tap {end.tap} ({end.share:.2g} of its peak over its last {end.tail} samples)"
        if end.needs_window:
            return f"the response had not died out {where}: a longer record would need none"
        words = f"none: the response still rang {where}"
    if truncation is not None:
        return words + ("; what still rang leaves an error, counted as noise (the truncation)" if end.state == "died"
                        else "; its truncation is counted as noise rather than traded for the window's damping (a "
                             "longer record would be better)")
    if not told:
        return words + ("; with one tap and no samples before the hit, an error of its end cannot be told from its "
                        "noise and is not counted (record a pre-trigger, or more taps)")
    return words + ("" if end.state == "died" else "; no error of its end stands out of the noise")


def told_apart(x: np.ndarray, noise: np.ndarray) -> bool:
    """Whether an error of the taps' end can be told from their noise: two taps or more (their scatter), or
    one with its noise measured before the hit."""
    return x.shape[0] > 1 or bool(noise[0] > 0)


def noise_variance(x: np.ndarray, pre: np.ndarray) -> np.ndarray:
    """Per tap, the response's mean square before the hit (its noise; 0 with fewer than 8 samples there)."""
    return np.array([np.mean(row[:p] ** 2) if p >= 8 else 0.0 for row, p in zip(x, pre.tolist())])


def truncation_variance(x: np.ndarray, F: np.ndarray, w: np.ndarray, noise: np.ndarray, h: np.ndarray,
                        dt: float) -> np.ndarray | None:
    """Per line, the variance of the FRF's relative error that the taps' end leaves.

    Parameters
    ----------
    x : numpy.ndarray
        The responses as transformed (offset removed, windowed), one kept tap a row.
    F : numpy.ndarray
        Their forces' transforms (times ``dt``), one row a tap.
    w : numpy.ndarray
        The exponential window of each row (ones without it; broadcast to ``x``).
    noise : numpy.ndarray
        Per tap, the response's noise variance before the window (:func:`noise_variance`).
    h : numpy.ndarray
        The FRF estimated from the taps on every line of ``F``.
    dt : float
        The time step (s).

    Returns
    -------
    numpy.ndarray or None
        ``|E / H|^2`` per line, ``E`` the bound of the module docstring,
        counted as ``TapResult.force_noise`` is (half in the log magnitude,
        half in the phase); None when the response's end holds nothing
        above its noise (it died out), when the two cannot be told apart
        (:func:`told_apart`), or nothing above
        :data:`TRUNCATION_NEGLIGIBLE` on any line.
    """
    n = x.shape[1]
    seg = max(16, int(TRUNCATION_SEGMENT * n))
    if 2 * seg > n or not told_apart(x, noise):
        return None
    w2 = np.broadcast_to(w, x.shape) ** 2
    power = np.sum(np.abs(F) ** 2, axis=0)

    def part(stop: int) -> tuple[np.ndarray, np.ndarray]:
        """The FRF's part from the segment ending ``stop`` samples before the end, and its noise's variance.

        The noise's variance from the taps' scatter about the part they share (a response repeated by every
        tap is proportional to its force; noise is not, whatever its spectrum): ``sum_i |P_i - F_i m|^2 /
        ((n - 1) sum_i |F_i|^2)``; from the noise before the hit for one tap.
        """
        piece = np.zeros_like(x)
        where = slice(n - stop - seg, n - stop)
        # less its mean: an offset left by the one removed before the hit (a mean of a few noisy samples)
        # is no ringing, and it would stand out of the noise, the same on the segment's lowest lines
        piece[:, where] = x[:, where] - np.mean(x[:, where], axis=1, keepdims=True)
        spectrum = scipy.fft.rfft(piece, axis=1) * dt
        with np.errstate(divide="ignore", invalid="ignore"):
            mean = np.sum(np.conj(F) * spectrum, axis=0) / power
            if x.shape[0] > 1:
                var = np.sum(np.abs(spectrum - F * mean) ** 2, axis=0) / ((x.shape[0] - 1) * power)
            else:
                var = noise[0] * np.sum(w2[0, where]) * dt**2 / power
        return np.where(np.isfinite(mean), mean, 0.0), np.where(np.isfinite(var), var, 0.0)

    # what the two segments bring to the averaged FRF, less their noise (which averaging reduces; the
    # response's repeated tail it does not); a segment's spectrum dips every n / seg lines (its length's),
    # the rest of the response does not: the powers averaged over that width (before they are made
    # relative: |H| has nulls of its own, its antiresonances, where the same absolute error is a large
    # relative one), and taken only where they stand out of the noise (SIGNIFICANCE, over all the band's
    # independent lines) as the noise's own scatter allows: over three widths, three independent lines
    # of a segment, the F distribution of the two averaged chi^2 (the noise's variance estimated from the
    # taps' scatter), or the chi^2 of the one (from the noise before the hit)
    width = max(1, int(round(n / seg))) | 1
    kernel = np.ones(3 * width) / (3 * width)  # three of the segment's independent lines
    taps = x.shape[0]
    alpha = TRUNCATION_SIGNIFICANCE / max(1.0, F.shape[1] / width)  # over the band's independent lines
    quantile = float(f_dist.isf(alpha, 6, 6 * (taps - 1)) if taps > 1 else chi2.isf(alpha, 6) / 6)

    def excess(stop: int) -> np.ndarray:
        mean, var = part(stop)
        power_s, var_s = (np.convolve(v, kernel, mode="same") for v in (np.abs(mean) ** 2, var))
        return np.where(power_s > quantile * var_s, power_s - var_s, 0.0)

    excess_last, excess_before = excess(0), excess(seg)
    if not (excess_last.sum() > 0.0 and excess_before.sum() > 0.0):
        return None
    # the decay per line, of the modes that ring there (over the whole band where a line's segment before
    # holds nothing)
    overall = min(float(np.sqrt(excess_last.sum() / excess_before.sum())), TRUNCATION_RATIO_MAX)
    with np.errstate(divide="ignore", invalid="ignore"):
        r = np.where(excess_before > 0, np.sqrt(excess_last / excess_before), overall)
    r = np.minimum(np.where(np.isfinite(r), r, overall), TRUNCATION_RATIO_MAX)
    size = excess_last * (r / (1.0 - r)) ** 2
    with np.errstate(divide="ignore", invalid="ignore"):
        v = np.where(np.abs(h) > 0, size / np.abs(h) ** 2, np.inf)
    return v if np.max(v) > TRUNCATION_NEGLIGIBLE**2 else None
