"""The sign of a driving-point FRF: :func:`reversed_share`, :data:`REVERSED_SHARE`.

A passive structure takes power from a force at its own point: with the
convention ``x(t) = X exp(i omega t)`` the mean power ``-omega Im(H) |F|^2 / 2``
is never negative, so a driving-point receptance has ``Im H <= 0`` at every
line (a mobility has ``Re >= 0``, an accelerance ``Im >= 0``).  A measured
one whose imaginary part is mostly positive has one channel's sign reversed:
the hammer's or the sensor's polarity, or a sensor mounted facing the other
way (or the data follow the other convention, ``exp(-i omega t)``, and are
the conjugate).
"""

from __future__ import annotations

import numpy as np

from ..errors import InvalidValueError

__all__ = ["reversed_share", "REVERSED_SHARE", "positive_real_share", "driving_point_quantity", "ACCELERANCE_SLOPE"]

REVERSED_SHARE = 0.8
"""A driving point whose :func:`reversed_share` exceeds this has its sign reversed.

The share is weighted by ``|Im H|``, so the resonances decide it, where the sign is clear; lines of noise
alone would give about 0.5, a reversed sign gives nearly 1 (0.999 on simulated tap tests)."""


def reversed_share(receptance) -> float:
    """The share of a driving-point receptance's ``sum |Im H|`` that lies on lines where ``Im H > 0``.

    Parameters
    ----------
    receptance : array_like of complex
        The driving-point receptance, one value per line (non-finite lines
        are left out).

    Returns
    -------
    float
        0 for a passive structure's FRF (noise adds a little near its
        antiresonances), 1 for one whose sign is reversed; NaN when no line
        has an imaginary part.

    Raises
    ------
    InvalidValueError
        For values that are not numbers.
    """
    try:
        values = np.asarray(receptance, dtype=complex).reshape(-1)
    except (TypeError, ValueError):
        raise InvalidValueError(f"receptance: got {type(receptance).__name__}; expected an array of complex values "
                                "(one driving point's receptance per line)") from None
    imag = np.imag(values)
    imag = imag[np.isfinite(imag)]
    total = float(np.sum(np.abs(imag)))
    return float(np.sum(imag[imag > 0.0]) / total) if total > 0.0 else float("nan")


ACCELERANCE_SLOPE = 1.0
"""A driving point with ``Im >= 0`` whose magnitude grows faster than ``f^ACCELERANCE_SLOPE`` over the band (least
squares of ``ln |H|`` on ``ln f``) reads as an accelerance rather than a receptance of reversed sign: an
accelerance is ``-omega^2`` times the receptance, its slope two more."""


def positive_real_share(values) -> float:
    """The share of ``sum |Re H|`` on lines where ``Re H > 0`` (a driving-point mobility's is 1 on a passive structure).

    Parameters
    ----------
    values : array_like of complex
        One driving point's FRF, a value per line (non-finite lines left out).

    Returns
    -------
    float
        In [0, 1]; NaN when no line has a real part.
    """
    real = np.real(np.asarray(values, dtype=complex).reshape(-1))
    real = real[np.isfinite(real)]
    total = float(np.sum(np.abs(real)))
    return float(np.sum(real[real > 0.0]) / total) if total > 0.0 else float("nan")


def driving_point_quantity(values, hz) -> tuple[str, float] | None:
    """The quantity a driving-point FRF read as a receptance holds by its passivity, when that is not a receptance.

    On a passive structure a receptance has ``Im <= 0``, a mobility ``Re >= 0`` and an accelerance ``Im >= 0``.
    A mobility read as a receptance has its real part positive where most of ``|Re|`` lies and an imaginary part
    of both signs; an accelerance has its imaginary part positive, as a receptance of reversed sign has, and a
    magnitude that grows with frequency (:data:`ACCELERANCE_SLOPE`).

    Parameters
    ----------
    values : array_like of complex
        The FRF as read, a value per line.
    hz : array_like
        The lines [Hz].

    Returns
    -------
    (str, float) or None
        ``("mobility", share)`` with the positive real part's share of ``|Re|``, ``("accelerance", slope)`` with
        the magnitude's slope on log scales, ``("reversed", slope)`` for a receptance of reversed sign, or None for
        a receptance.
    """
    values = np.asarray(values, dtype=complex).reshape(-1)
    share = reversed_share(values)
    if not np.isfinite(share):
        return None
    if share > REVERSED_SHARE:
        f = np.asarray(hz, dtype=float).reshape(-1)
        ok = np.isfinite(values) & (values != 0) & (f > 0)
        slope = float(np.polyfit(np.log(f[ok]), np.log(np.abs(values[ok])), 1)[0]) if ok.sum() >= 2 else 0.0
        return ("accelerance" if slope > ACCELERANCE_SLOPE else "reversed"), slope
    real = positive_real_share(values)
    if 1 - REVERSED_SHARE <= share and real > REVERSED_SHARE:
        return "mobility", real
    return None
