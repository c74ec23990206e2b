"""The exponential window's damping taken out of a measured tool point FRF, for stability.

A tap test whose response still rings at the end of the record is processed
through the window ``exp(-t/tau)`` on both channels (``substructure tap``,
docs/tap.md section 3).  The FRF it gives is the structure's at the complex
frequency ``omega - i/tau``: every pole moves left by ``1/tau``, so each
mode carries the added damping ratio ``1/(tau omega_n)``.  Stability limits
grow with the damping, so lobes drawn from such an FRF as it is promise
depths of cut the tool cannot take (the added damping of a 30 ms record is
1.2 % at 900 Hz; a mode of 3 % damping looks 40 % more damped).

A mode ``1/(k (1 - r^2 + 2 i zeta r))`` is ``(1/m) / (s^2 + 2 zeta omega_n s
+ omega_n^2)`` at ``s = i omega``; through the window it is the same at
``s + 1/tau``: a mode of the same modal mass ``m`` and damped frequency
``omega_d``, whose decay rate ``sigma = zeta omega_n`` is ``1/tau`` larger.
So a mode fitted to the windowed FRF (``m'``, ``omega_n'``, ``zeta'``) is the
structure's with

```
sigma = zeta' omega_n' - 1/tau,   omega_n^2 = omega_n'^2 - 2 zeta' omega_n' / tau + 1/tau^2,
zeta = sigma / omega_n,   k = m' omega_n^2
```

exactly (:func:`mode_without_window`).  :func:`window_removed` fits the
modes of each direction (:class:`~substructure.stability.modal.ModalFitter`)
and gives the data with every fitted mode's window damping removed: the
measured FRF plus, per fitted mode, the corrected mode less the mode as
fitted; what the modes do not fit (noise, small modes under the
prominence) stays as measured.  A mode whose fitted decay rate is not above
``1/tau`` cannot be corrected (the record says nothing of its own damping)
and is refused with what to do, unless its peak is small: a mode whose
peak in the data is under ``MINOR_PEAK_SHARE`` (10 %) of the direction's
largest, and whose fitted decay rate is not above ``1/tau`` or whose fitted
damping sits at the fit's lower bound (a feature of the data the fit did not
resolve), is left as measured and named (``WindowRemoved.uncorrected``, a
:class:`~substructure.stability.ModalFitWarning`).
"""

from __future__ import annotations

import math
import warnings

import attrs
import numpy as np

from ..errors import InvalidValueError
from ..frf import FRF, Frequency
from ..frf._fields import window_tau
from ..units import Q_
from .modal import FIT_DAMPING_RANGE, ModalFitter, ModalFitWarning, ModalModel, Mode
from .structure import XY_LABELS, xy_receptance

__all__ = ["mode_without_window", "window_removed", "WindowRemoved", "MINOR_PEAK_SHARE"]

MINOR_PEAK_SHARE = 0.1
"""The data's peak at a mode, relative to the direction's largest, under which a mode the window cannot be
taken out of is left as measured (named) rather than refused."""


def mode_without_window(mode: Mode, tau: float) -> Mode:
    """A mode measured through the window ``exp(-t/tau)``, with the window's decay rate ``1/tau`` removed.

    Parameters
    ----------
    mode : Mode
        As fitted to the windowed FRF.
    tau : float
        The window's time constant [s].

    Returns
    -------
    Mode
        The same modal mass and damped frequency, the decay rate less ``1/tau``.

    Raises
    ------
    InvalidValueError
        For a ``tau`` that is not a number > 0, and for a mode whose decay
        rate ``zeta omega_n`` is not above ``1/tau``: the window's damping is
        all the record shows of it.
    """
    tau = window_tau(tau, "tau")
    w1 = 2.0 * math.pi * mode.frequency_hz
    sigma1 = mode.damping_ratio * w1
    sigma = sigma1 - 1.0 / tau
    if not sigma > 0:
        raise InvalidValueError(
            f"the mode at {mode.frequency_hz:.5g} Hz ({mode.direction}): its damping ratio {mode.damping_ratio:.3g} "
            f"is not above the window's 1/(tau omega) = {1.0 / (tau * w1):.3g} (tau = {tau:.4g} s): the record shows "
            "the window's damping, not the structure's; record longer taps (a window with a larger tau, or none) or "
            "give the modes")
    wn2 = w1 * w1 - 2.0 * sigma1 / tau + 1.0 / (tau * tau)
    wn = math.sqrt(wn2)
    mass = mode.stiffness_n_per_m / (w1 * w1)
    return Mode(mode.direction, Q_(wn / (2.0 * math.pi), "Hz"), sigma / wn, Q_(mass * wn2, "N/m"))


@attrs.frozen
class WindowRemoved:
    """A tool point FRF measured through an exponential window, with the window's damping removed.

    Made by :func:`window_removed`.

    Parameters
    ----------
    frf : FRF
        The data labelled ``x``/``y`` with every fitted mode's window damping
        removed (the cross terms as measured).
    modes : ModalModel
        The fitted modes without the window's damping.
    measured : ModalModel
        The modes as fitted to the windowed data.
    tau : dict
        The window's time constant [s] per direction (None: no window).
    modal_error : dict
        Per direction, how far the fitted modes alone miss the windowed data
        (relative, as ``ModalFitter.modal_error_``).
    uncorrected : tuple
        ``(mode as fitted, why)`` of the minor modes left as measured.
    """

    frf: FRF
    modes: ModalModel
    measured: ModalModel
    tau: dict
    modal_error: dict
    uncorrected: tuple = ()

    def describe(self) -> list[str]:
        """One line per mode: its frequency and damping ratio as measured and without the window.

        Returns
        -------
        list of str
            ``"x 400.06 Hz: damping ratio 1.991% measured, 1.000% without the window's 0.991%"``.
        """
        return [f"{m.direction} {m.frequency_hz:.5g} Hz: damping ratio {m.damping_ratio:.3%} measured, "
                f"{c.damping_ratio:.3%} without the window's "
                f"{1.0 / (self.tau[m.direction] * 2 * math.pi * m.frequency_hz):.3%}"
                for m, c in zip(self.measured.modes, self.modes.modes)] + [
            f"{m.direction} {m.frequency_hz:.5g} Hz: left as measured, {why}" for m, why in self.uncorrected]


def window_removed(structure: FRF, tau: float | dict, n_modes: int | None = None, prominence: float = 0.05,
                   max_error: float = 0.2) -> WindowRemoved:
    """Remove an exponential window's damping from tool point receptances, through their fitted modes.

    Parameters
    ----------
    structure : FRF
        One translational receptance (a symmetric tool) or an FRF labelled
        ``x``/``y`` (:func:`~substructure.stability.xy_frf`), measured
        through the window ``exp(-t/tau)`` on both channels, on the lines
        stability will use (crop the rigid-body lines first:
        :func:`~substructure.stability.choose_band`).
    tau : float or dict
        The window's time constant [s] (``TapResult.tau``; the
        ``# window_tau_s`` line of a CSV file that ``substructure tap``
        wrote, ``substructure.io.frf_files.read_csv_window``), or one per
        direction (``{"x": 0.02, "y": None}``: ``y`` measured without a
        window, left as it is).
    n_modes, prominence
        As in :class:`~substructure.stability.ModalFitter`, per direction.
    max_error : float, default 0.2
        Warn (:class:`~substructure.stability.ModalFitWarning`) when the
        fitted modes miss the data by more than this relative error: a
        mode they do not fit keeps the window's damping.

    Returns
    -------
    WindowRemoved
        The corrected FRF (``x``/``y``), the corrected and the fitted modes.

    Raises
    ------
    InvalidValueError
        For a ``tau`` that is not a number > 0, data the modal fit cannot
        take, and a mode whose fitted decay rate is not above ``1/tau``
        (:func:`mode_without_window`).
    """
    if isinstance(tau, dict):
        unknown = set(tau) - set(XY_LABELS)
        if unknown:
            raise InvalidValueError(f"tau: got the directions {sorted(unknown)}; expected 'x' and 'y'")
        taus = {d: None if tau.get(d) is None else window_tau(tau[d], "tau") for d in XY_LABELS}
        if all(t is None for t in taus.values()):
            raise InvalidValueError("tau: no direction has a window; there is nothing to take out")
    else:
        taus = dict.fromkeys(XY_LABELS, window_tau(tau, "tau"))
    if not isinstance(structure, FRF):
        raise InvalidValueError(f"structure: got {type(structure).__name__}; expected the measured FRF (modes given "
                                "as such have no window to take out)")
    hz, g = xy_receptance(structure)
    frequency = Frequency(hz)
    out = np.array(g, dtype=complex)
    fitted, corrected, errors, skipped = [], [], {}, []
    for i, d in enumerate(XY_LABELS):
        if taus[d] is None or not np.any(g[:, i, i]):
            continue  # measured without the window, or a rigid direction
        fit = ModalFitter(n_modes=n_modes, prominence=prominence).fit(
            FRF.single(frequency, g[:, i, i], output=d, input=d), d)
        errors[d] = fit.modal_error_
        mag = np.abs(g[:, i, i])
        for mode in fit.modes_:
            share = float(mag[np.argmin(np.abs(hz - mode.frequency_hz))] / mag.max())
            try:
                if mode.damping_ratio <= FIT_DAMPING_RANGE[0] * (1 + 1e-6):
                    raise InvalidValueError(
                        f"the mode at {mode.frequency_hz:.5g} Hz ({d}): its fitted damping ratio sits at the fit's "
                        f"lower bound {FIT_DAMPING_RANGE[0]:g}: the fit did not resolve it; choose the band (around "
                        "the tool's modes) or the number of modes")
                fixed = mode_without_window(mode, taus[d])
            except InvalidValueError as exc:
                if share >= MINOR_PEAK_SHARE:
                    raise InvalidValueError(f"{exc} (its peak is {share:.0%} of the largest)") from None
                skipped.append((mode, f"its peak {share:.1%} of the largest: {str(exc).split(': ', 1)[1]}"))
                continue
            out[:, i, i] += fixed.receptance(hz) - mode.receptance(hz)
            fitted.append(mode)
            corrected.append(fixed)
    if skipped:
        warnings.warn("window_removed: " + "; ".join(f"the mode at {m.frequency_hz:.5g} Hz ({m.direction}) is left "
                                                     f"as measured, {why}" for m, why in skipped),
                      ModalFitWarning, stacklevel=2)
    if not fitted:
        raise InvalidValueError("structure: no mode the window can be taken out of" +
                                (f" ({len(skipped)} left as measured)" if skipped else
                                 "; every receptance is 0"))
    worst = max(errors.values())
    if worst > max_error:
        warnings.warn(f"window_removed: the fitted modes miss the data by {worst:.0%} (relative); a mode they do not "
                      "fit keeps the window's damping: choose the band or the number of modes", ModalFitWarning,
                      stacklevel=2)
    frf = FRF(frequency, out, XY_LABELS, XY_LABELS)
    return WindowRemoved(frf, ModalModel(corrected), ModalModel(fitted), taus, errors, tuple(skipped))
