"""Which quantity a measured FRF holds, read against the model: a mobility or an accelerance read as a receptance.

A CSV file without units is read as a receptance (docs/file-formats.md), so an accelerance exported without its
units comes in as ``-omega^2`` times what it should be, and a mobility as ``i omega`` times.  No change of the
structure does that: measured over model, the magnitude grows as ``f^n`` over the whole band and the phase is off
by ``n`` quarter turns at every line.  :func:`quantity_signature` fits ``measured = A (i omega)^n s model`` for
``n`` in -2 to 2, ``s`` = +1 or -1 and a free factor ``A`` (a sensor's calibration, a unit), weighted by the noise
of each line, and :func:`quantity_error` words what it finds when another ``n`` fits the data far better than the
quantity read.
"""

from __future__ import annotations

import attrs
import numpy as np

__all__ = ["QuantityFit", "quantity_signature", "quantity_error", "QUANTITY_FACTOR", "QUANTITY_PHASE",
           "QUANTITY_SPAN"]

QUANTITIES = ("receptance", "mobility", "accelerance")
"""In the order of the power of ``i omega`` that takes a receptance to each."""

QUANTITY_FACTOR = 10.0
"""How many times the weighted squared error of another quantity must fall below the quantity read to say so.  A
quantity read wrong is off by a quarter or half turn of phase at every line: its error fell ten thousand times
over the whole band of the FE rig against an exact model, 23 times against a model without the test's 2 g sensor;
over bands of a factor 2 or more (:data:`QUANTITY_SPAN`), 33 cases of missing or wrong structure against three
models of the rig looked like another quantity by a factor of 2.8 at most."""


QUANTITY_SPAN = 2.0
"""The least ratio of the highest to the lowest line weighed for the question to be asked: over a narrow band a
model whose mode sits on the wrong side of the data's is half a turn off with a magnitude that runs like
``f^(+-2)``, which is what another quantity looks like there."""

QUANTITY_PHASE = 0.5
"""The largest RMS phase error [rad] of the other quantity for it to be a fit at all: a model far off fits no
quantity, and nothing is said."""


@attrs.frozen
class QuantityFit:
    """The best power of ``i omega`` (and sign) between a measured FRF and the model.

    Attributes
    ----------
    power : int
        ``n`` in ``measured = A (i omega)^n s model``: 0 for the quantity read.
    sign : int
        ``s``, +1 or -1.
    factor : float
        ``A``, the common factor of the magnitudes.
    error : float
        The weighted mean square error (log magnitude and phase) of that fit.
    as_read : float
        The same for ``n = 0``, ``s = +1`` (the factor free).
    phase_rms : float
        The fit's RMS phase error [rad], weighted.
    """

    power: int
    sign: int
    factor: float
    error: float
    as_read: float
    phase_rms: float


def quantity_signature(measured: np.ndarray, model: np.ndarray, hz: np.ndarray, w_re: np.ndarray,
                       w_im: np.ndarray) -> QuantityFit:
    """Fit ``measured = A (i omega)^n s model`` for ``n`` in -2..2 and ``s`` = +-1 (``A`` free), line by line weights.

    Parameters
    ----------
    measured, model : ndarray of complex
        One FRF each, on the same lines.
    hz : ndarray
        The lines [Hz] (> 0 where weighted).
    w_re, w_im : ndarray
        Inverse noise of the log magnitude and of the phase per line (0: not used).

    Returns
    -------
    QuantityFit
        The best ``n`` and ``s``, and the error of the quantity read (``n = 0``, errors 0, when fewer than four
        lines are weighed or they span less than :data:`QUANTITY_SPAN`).
    """
    with np.errstate(divide="ignore", invalid="ignore"):
        q = measured / model
        mag, phase, log_w = np.log(np.abs(q)), np.angle(q), np.log(2 * np.pi * hz)
    ok = np.isfinite(mag) & np.isfinite(phase) & np.isfinite(log_w) & (w_re > 0) & (w_im > 0)
    if ok.sum() < 4:
        return QuantityFit(0, 1, 1.0, 0.0, 0.0, 0.0)
    if log_w[ok].max() - log_w[ok].min() < np.log(QUANTITY_SPAN):
        return QuantityFit(0, 1, 1.0, 0.0, 0.0, 0.0)
    mag, phase, log_w, a, b = mag[ok], phase[ok], log_w[ok], w_re[ok] ** 2, w_im[ok] ** 2
    total = float(np.sum(a) + np.sum(b))
    fits = []
    for n in range(-2, 3):
        re = mag - n * log_w
        level = float(np.sum(a * re) / np.sum(a))
        mag_err = float(np.sum(a * (re - level) ** 2))
        for s in (1, -1):
            turn = n * np.pi / 2 + (0.0 if s > 0 else np.pi)
            im = np.angle(np.exp(1j * (phase - turn)))
            phase_err = float(np.sum(b * im**2))
            fits.append((n, s, float(np.exp(level)), (mag_err + phase_err) / total,
                         float(np.sqrt(phase_err / np.sum(b)))))
    as_read = next(f[3] for f in fits if f[0] == 0 and f[1] == 1)
    n, s, factor, error, phase_rms = min(fits, key=lambda f: f[3])
    return QuantityFit(n, s, factor, error, as_read, phase_rms)


def quantity_error(fit: QuantityFit, where: str, declared: str = "receptance") -> str | None:
    """The message for an FRF that holds another quantity than the one read, or None.

    Parameters
    ----------
    fit : QuantityFit
        From :func:`quantity_signature`.
    where : str
        The FRF, as messages name it.
    declared : str
        The quantity it was read as.

    Returns
    -------
    str or None
        The message when another power of ``i omega`` fits :data:`QUANTITY_FACTOR` times better with an RMS phase
        error under :data:`QUANTITY_PHASE`; else None.
    """
    if fit.power == 0 or fit.error * QUANTITY_FACTOR > fit.as_read or fit.phase_rms > QUANTITY_PHASE:
        return None
    power = f"(i 2 pi f)^{fit.power}" if fit.power != 1 else "i 2 pi f"
    sign = ", negated," if fit.sign < 0 else ""
    held = QUANTITIES.index(declared) + fit.power if declared in QUANTITIES else -1
    if 0 <= held < len(QUANTITIES):
        what = (f"{_a(QUANTITIES[held])} read as {_a(declared)}"
                f"{' with its sign reversed' if fit.sign < 0 else ''}: give its quantity ({QUANTITIES[held]!r}: "
                "`quantity` in the measurement set, the units in a CSV file's header such as "
                f"{_units(QUANTITIES[held])}, or FRF(..., quantity=...))")
    else:
        what = "check the quantity and the units the file was read with"
    return (f"measured FRF {where}: read as {_a(declared)}, it is {fit.factor:.4g} times the model times {power}{sign} "
            f"over the whole band (a weighted squared error {fit.as_read / max(fit.error, 1e-300):.3g} times smaller "
            f"than as read, the phase within {fit.phase_rms:.2f} rad RMS): {what}")


def _a(quantity: str) -> str:
    return f"{'an' if quantity[0] in 'aeiou' else 'a'} {quantity}"


def _units(quantity: str) -> str:
    return {"receptance": "`real [m/N]`", "mobility": "`real [m/(N s)]`",
            "accelerance": "`real [m/(N s^2)]`"}[quantity]
