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

Springs to the ground under a free body (suspension bands, a fixture) add resonances the model lacks, with
nothing to shift: their two rigid-body modes sit in a minimum narrower than any grid of stiffnesses and places.
Their starts come from the body instead: its mass, rotary inertia and centre read off the model's receptances
at the component's two ends (:func:`rigid_body`), and the springs that put its two modes at two of the lowest
resonances the model lacks, or either mode at the lowest.
"""

from __future__ import annotations

import itertools

import numpy as np

from ..errors import SubstructureError
from ..frf import FRF
from ..updating.elements import SectionChange
from ..updating.evaluator import Evaluator
from ..updating.fit import from_u, to_u
from .compare import _pairs, pair_modes
from .settings import DEFAULT_SETTINGS, DiagnoseSettings

__all__ = ["mode_starts", "peak_near", "rigid_starts", "rigid_body"]


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


def rigid_starts(lik, current, changes, settings: DiagnoseSettings = DEFAULT_SETTINGS) -> dict:
    """Starts of the changes that hang a free body on springs from the lowest resonances the model lacks, with the
    body's mass, rotary inertia and centre read off the model's receptances at its two ends (:func:`rigid_body`).

    An effect takes part through two class methods: ``body(where)``, the component its springs hold, and
    ``rigid_body_starts(where, length, body, peaks_hz, count)``, its values that put the body's modes at the
    resonances (:class:`~substructure.diagnose.catalogue.SupportSprings`).  The screening searches each start's
    main parameter near it (:func:`substructure.diagnose.scan.sharpen`).

    Parameters
    ----------
    lik : Likelihood
        Every measured FRF on all its lines.
    current : list of (Change, dict)
        The changes already added.
    changes : sequence of Change
        The candidates.
    settings : DiagnoseSettings
        ``rigid_places`` and the thresholds of a resonance.

    Returns
    -------
    dict
        Per candidate key, groups of trial values: the lowest resonance alone, and each two of them (each group's
        best are searched further).
    """
    hooked = [c for c in changes if hasattr(getattr(c, "cls", None), "rigid_body_starts") and hasattr(c.cls, "body")]
    if not hooked:
        return {}
    try:
        predicted = lik.predict(current)
    except SubstructureError:
        return {}
    # the resonances the model lacks in every FRF measured (a mode can hardly show at one point and plainly at
    # another), however low beside the highest (two modes of a body on soft springs can differ by two decades in
    # height), each located on the measured lines by a parabola through its top (the smoothed data's peak can sit
    # a line off); one seen in several FRFs within a line is one
    hz = lik.measured[0].frf.frequency.hz[lik.lines]
    step = float(hz[1] - hz[0]) if hz.size > 1 else 0.0
    found = []
    for m, y in zip(lik.measured, predicted):
        measured = m.frf
        f, h = measured.frequency.hz[lik.lines], measured.data[lik.lines, 0, 0]
        model = FRF(measured.frequency, y[:, None, None], measured.outputs, measured.inputs)
        found += [peak_near(f, h, p.measured_hz, settings.mode_window) or p.measured_hz
                  for p in pair_modes(model, measured, 0.0, noise=m.noise.floor, prominence=settings.mode_prominence,
                                      noise_prominence=settings.mode_prominence_floors,
                                      pairing=settings.mode_pairing) if p.model_hz is None]
    clusters: list[list[float]] = []
    for hz in sorted(found):
        if clusters and hz - clusters[-1][-1] <= step:
            clusters[-1].append(hz)
        else:
            clusters.append([hz])
    lacking_hz = [float(np.median(c)) for c in clusters]
    if not lacking_hz:
        return {}
    # every two of the lowest, the upper one a line or so either way (a peak on noisy lines sits up to a line off,
    # and the two modes' ratio places the springs), and the lowest alone with either mode there (two modes close
    # together can show as one)
    pairs = itertools.combinations(lacking_hz[:settings.rigid_resonances], 2)
    shifted = [[(lo, hi + s * step) for s in settings.rigid_shifts if hi + s * step > lo] for lo, hi in pairs]
    sets = [[(lacking_hz[0],)]] + [group for group in shifted if group]
    out: dict = {}
    group = lik.groups[0]
    for change in hooked:
        try:
            name = change.cls.body(change.where)
            length = group.assembly.component(name).length_m
            body = rigid_body(group.structure_with(current), name, length, settings.rigid_below * lacking_hz[0],
                              settings.rigid_free)
            if body is None:
                continue
            groups = [[t for peaks in peak_sets
                       for t in change.cls.rigid_body_starts(change.where, length, body, peaks,
                                                             settings.rigid_places_alone if len(peaks) == 1
                                                             else settings.rigid_places)]
                      for peak_sets in sets]
            if any(groups):
                out[change.key] = [g for g in groups if g]
        except (SubstructureError, ValueError, FloatingPointError):
            continue
    return out


def rigid_body(structure, name: str, length: float, f_hz: float, free: float = 0.05
               ) -> tuple[float, float, float] | None:
    """A free body's mass [kg], rotary inertia about its centre of mass [kg m^2] and that centre's distance from
    the component's base [m], from the receptances between the component's two ends at ``f_hz`` and ``2 f_hz``
    (well below its first flexible mode).

    There ``-omega^2 H_ij = 1/m + d_i d_j / J`` with ``d`` a point's distance from the centre; three receptances
    give the three numbers.  None where the body is not free (held to the ground, the mass line of ``f_hz`` not
    that of ``2 f_hz`` within ``free``) or the numbers are not physical.

    Parameters
    ----------
    structure : Structure
        The model (SI form).
    name : str
        The component.
    length : float
        Its length [m] (from its base to its tip).
    f_hz : float
        A frequency below the body's first flexible mode [Hz].
    free : float
        The relative tolerance of the two mass lines (default 0.05).

    Returns
    -------
    (float, float, float) or None
    """
    ends = [f"{name}.base", f"{name}.tip"]
    hz = np.array([f_hz, 2.0 * f_hz])
    h = Evaluator(ends, ends, hz)(structure).real
    a = -(2.0 * np.pi * hz[:, None, None]) ** 2 * h
    if not np.allclose(a[0], a[1], rtol=free, atol=0.0):
        return None
    a = a[0]
    curvature = a[0, 0] + a[1, 1] - 2.0 * a[0, 1]
    if not curvature > 0:
        return None
    inertia = length ** 2 / curvature
    centre = inertia * (a[0, 0] - a[0, 1]) / length
    mass = 1.0 / (a[0, 1] + centre * (length - centre) / inertia)
    return (mass, inertia, centre) if mass > 0 and np.isfinite(mass) else None


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
