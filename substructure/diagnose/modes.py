"""Starting values from mode shifts: where a candidate's main parameter must go to move the modes.

The complex log ratio of a model with a resonance a few bandwidths off is
flat in the parameter far from its minimum, so a scan on a coarse grid can
miss a narrow minimum (a tool 4 mm longer moves its modes by ten
bandwidths).  Mode frequencies, in contrast, move smoothly with every
parameter.  :func:`mode_starts` pairs the measured resonances of the first
FRF with the model's (:func:`substructure.diagnose.compare.pair_modes`),
takes their relative shifts ``d_i = ln(f_measured,i / f_model,i)``, and for
each candidate the sensitivities ``s_i = d ln f_i / d u`` of the model's
modes to its main parameter ``u`` (a finite difference of the model FRF,
each peak located by a parabola through its top three lines, and followed
from one value to the next); the least squares step
``u + (s . d) / (s . s)`` is where the candidate would put the modes.
Mode frequencies are smooth in ``u`` but not linear (a stiff joint's modes
hardly move until it is soft enough), so the step is repeated three times
with secant slopes (steps limited to a factor ``e^1.5`` on log scales); the
iterates become extra starting points of the screening scan.  When every paired mode is within two lines of the
model's, there is nothing to predict from and no extra start is made.  Elements are linearised at every other
screening place from where they do nothing (a zero mass, a zero spring), with three trials around the
prediction; a section change's three parameters are left to its scan.  The windows, steps and factors are
fields of :class:`~substructure.diagnose.settings.DiagnoseSettings`.
"""

from __future__ import annotations

import numpy as np

from ..errors import SubstructureError
from ..frf import FRF
from ..updating.elements import SectionChange
from ..updating.fit import from_u, to_u
from .compare import _pairs
from .settings import DEFAULT_SETTINGS, DiagnoseSettings

__all__ = ["mode_starts", "peak_near"]


def peak_near(f: np.ndarray, h: np.ndarray, near: float, width: float = 0.12) -> float | None:
    """The resonance of ``|h|`` nearest ``near`` within ``width`` (relative), by a parabola in ``ln|h|``.

    Parameters
    ----------
    f : ndarray
        Frequency lines [Hz] (uniform).
    h : ndarray
        The FRF.
    near : float
        Where to look [Hz].
    width : float
        Relative half-width of the search window.

    Returns
    -------
    float or None
        The peak frequency [Hz], or None when there is no interior maximum.
    """
    window = np.flatnonzero((f > (1 - width) * near) & (f < (1 + width) * near))
    if window.size < 3:
        return None
    with np.errstate(divide="ignore"):
        a = np.log(np.abs(h[window]))
    inner = np.flatnonzero((a[1:-1] >= a[:-2]) & (a[1:-1] >= a[2:])) + 1
    if inner.size == 0:
        return None
    i = int(inner[np.argmin(np.abs(f[window[inner]] - near))])
    y0, y1, y2 = a[i - 1], a[i], a[i + 1]
    den = y0 - 2 * y1 + y2
    shift = 0.0 if den == 0 or not np.isfinite(den) else float(np.clip(0.5 * (y0 - y2) / den, -0.5, 0.5))
    return float(f[window[i]] + shift * (f[window[1]] - f[window[0]]))


def _null(change) -> dict | None:
    """Values at which an element does nothing (None for other changes)."""
    values = {s.name: s.start for s in change.specs}
    if isinstance(change, SectionChange):
        values["diameter_ratio"] = 1.0
        return values
    if change.effect in ("added-mass", "ground-spring"):
        values[change.specs[0].name] = 0.0
        if change.effect == "added-mass":
            values["inertia"] = 0.0
        return values
    return None


def mode_starts(lik0, current, changes, places, settings: DiagnoseSettings = DEFAULT_SETTINGS) -> dict:
    """Extra starting points of the screening scan, predicted from the mode shifts.

    Parameters
    ----------
    lik0 : Likelihood
        The first measured FRF on all its lines.
    current : list of (Change, dict)
        The changes already added.
    changes : sequence of Change
        The candidates.
    places : callable
        ``places(change) -> list of dict``: the screening places of a change.
    settings : DiagnoseSettings
        The windows, steps and factors of the starts.

    Returns
    -------
    dict
        Per candidate key, a list of trial values.
    """
    measured = lik0.measured[0].frf
    f = measured.frequency.hz[lik0.lines]
    try:
        base = lik0.predict(current)[0]
    except SubstructureError:
        return {}
    model = FRF(measured.frequency, base[:, None, None], measured.outputs, measured.inputs)
    pairs = [p for p in _pairs(model, measured, lik0.measured[0].noise.floor, settings) if p.model_hz is not None]
    f0 = np.array([peak_near(f, base, p.model_hz, settings.mode_locate) or p.model_hz for p in pairs])
    if f0.size == 0:
        return {}
    measured_hz = np.array([p.measured_hz for p in pairs])
    step = float(f[1] - f[0]) if f.size > 1 else 1.0
    if np.all(np.abs(measured_hz - f0) < settings.in_place_lines * step):
        return {}  # the modes sit where the model has them: nothing to predict from
    out: dict = {}
    for change in changes:
        if isinstance(change, SectionChange):  # three parameters: its scan covers it
            continue
        trials = []
        null = _null(change)
        main = change.specs[0]
        where = places(change)
        if len(where) > settings.mode_start_places:  # elements: every other screening place
            where = where[::2]
        for place in where:
            values = dict(place)
            try:
                if null is not None:  # an element: linear in its main value, from zero
                    zero = {**values, **{k: v for k, v in null.items() if k not in ("position", "start", "length")}}
                    f_ref = _modes(lik0, list(current) + [(change, zero)], f, f0, settings.mode_follow)
                    step = settings.element_probe_linear * (main.upper - main.lower) if not main.log \
                        else main.upper * settings.element_probe_log
                    probe = {**zero, main.name: zero[main.name] + step}
                    f1 = _modes(lik0, list(current) + [(change, probe)], f, f_ref, settings.mode_follow)
                    s = (np.log(f1) - np.log(f_ref)) / step
                    dd = np.log(measured_hz / f_ref)
                    ok = np.isfinite(s) & np.isfinite(dd)
                    if not ok.any() or float(s[ok] @ s[ok]) <= 0:
                        continue
                    value = zero[main.name] + float(s[ok] @ dd[ok]) / float(s[ok] @ s[ok])
                    for factor in settings.element_factors:
                        v = zero[main.name] + factor * (value - zero[main.name])
                        if main.lower <= v <= main.upper:
                            trials.append({**values, main.name: float(v)})
                else:
                    trials += _secant(lik0, current, change, values, f, f0, measured_hz, settings)
            except (SubstructureError, ValueError, FloatingPointError):
                continue
        if trials:
            out[change.key] = trials
    return out


def _modes(lik0, changes, f, previous, width=0.12):
    h = lik0.predict(changes)[0]
    return np.array([peak_near(f, h, v, width) or np.nan if np.isfinite(v) else np.nan for v in previous])


def _secant(lik0, current, change, values, f, f0, measured_hz, settings: DiagnoseSettings) -> list[dict]:
    """Where the main parameter puts the modes: secant iterations on ``ln f`` (mode frequencies move
    smoothly but not linearly: a stiff joint's modes hardly move until it is soft enough)."""
    main = change.specs[0]
    u_prev = to_u(main, values[main.name])
    first = settings.secant_first_step
    f_prev = _modes(lik0, list(current) + [(change, values)], f, f0, settings.mode_follow)
    u = u_prev + first
    out = []
    lo, hi = (np.log(main.lower), np.log(main.upper)) if main.log else (main.lower / (0.1 * (main.upper - main.lower)),
                                                                        main.upper / (0.1 * (main.upper - main.lower)))
    for _ in range(settings.secant_iterations + 1):
        trial = {**values, main.name: from_u(main, u)}
        f_now = _modes(lik0, list(current) + [(change, trial)], f, f_prev, settings.mode_window)
        if out or u != u_prev + first:
            out.append(trial)
        s = (np.log(f_now) - np.log(f_prev)) / (u - u_prev)
        d = np.log(measured_hz / f_now)
        ok = np.isfinite(s) & np.isfinite(d)
        if not ok.any() or float(s[ok] @ s[ok]) <= 0:
            break
        a = float(s[ok] @ d[ok]) / float(s[ok] @ s[ok])
        a = float(np.clip(a, -settings.secant_max_step, settings.secant_max_step)) if main.log else a
        if abs(a) < settings.secant_tolerance:
            break
        u_prev, f_prev = u, f_now
        u = float(np.clip(u + a, lo, hi))
        if u == u_prev:
            break
    return out
