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

__all__ = ["reversed_share", "REVERSED_SHARE"]

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
