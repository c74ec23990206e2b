"""The scan of the screening: where each candidate is tried before any fit.

A candidate's main parameter is tried over its range (log-spaced on a log
scale, at both signs over :data:`SIGNED_DECADES` decades for a cross term
whose range holds zero, linearly otherwise), at each place an element may
sit (:func:`places`); an effect of several log-scale parameters is also
tried with all of them scaled together, and an effect of the catalogue
whose size comes with positions (springs) with both crossed on finer grids.
An element's main parameter is then searched between the grid's values at
every place where some value made the model better (:func:`finer`).
The numbers of values, places and decades are fields of
:class:`~substructure.diagnose.settings.DiagnoseSettings` (``scan_values``,
``body_positions``, ``signed_decades``, ``named_grid``, ...).  :mod:`substructure.diagnose.search` evaluates the
trials on the screening lines and refines the best.
"""

from __future__ import annotations

import itertools
from typing import Callable

import numpy as np

from ..updating.elements import SectionChange
from ..updating.fit import from_u, to_u
from ..updating.parameters import Change
from .effects import EffectChange
from .settings import DEFAULT_SETTINGS, DiagnoseSettings

__all__ = ["trials", "places", "grid", "finer", "sharpen"]


def grid(spec, count: int, settings: DiagnoseSettings = DEFAULT_SETTINGS) -> np.ndarray:
    """``count`` values of a parameter over its range: log-spaced, signed log-spaced magnitudes when the range
    holds zero (``settings.signed_decades`` below the largest), or linear."""
    if spec.log:
        return np.geomspace(spec.lower, spec.upper, count)
    if spec.lower < 0.0 < spec.upper:  # sign-symmetric, log-spaced magnitudes
        top = max(-spec.lower, spec.upper)
        mags = np.geomspace(top * 10.0 ** -settings.signed_decades, top, max(count, settings.signed_values_min))
        return np.clip(np.concatenate([-mags[::-1], mags]), spec.lower, spec.upper)
    return np.linspace(spec.lower, spec.upper, count)


def places(change: Change, settings: DiagnoseSettings = DEFAULT_SETTINGS) -> list[dict]:
    """Where an element may sit, for screening: positions (and ranges) along its component."""
    base = {s.name: s.start for s in change.specs}
    if isinstance(change, SectionChange):
        L = change.length
        return [{**base, "start": float(start), "length": float(length)}
                for length in (share * L for share in settings.section_lengths)
                for start in np.linspace(0.0, L - length, settings.section_starts)]
    position = next((s for s in change.specs if s.name == "position"), None)
    if position is not None:
        return [{**base, "position": float(x)}
                for x in np.linspace(position.lower, position.upper, settings.body_positions)]
    return [base]


def trials(change: Change, first: bool = True, settings: DiagnoseSettings = DEFAULT_SETTINGS) -> list[dict]:
    """Starting points of the screening scan: the main parameter over its range (at each place), and
    for effects of several log-scale parameters, all of them scaled together (``first``: the first step of
    data with a resonance the model lacks, where the sizes and positions of springs are crossed)."""
    main = change.specs[0]
    where = places(change, settings)
    count = settings.scan_values_placed if len(where) > 1 else settings.scan_values
    values = list(grid(main, count, settings))
    if main.nominal is not None:
        values.append(float(np.clip(main.nominal, main.lower, main.upper)))
    values.append(main.start)
    values = list(dict.fromkeys(float(v) for v in values))
    if isinstance(change, SectionChange):
        values = list(settings.section_ratios)
    out = [{**place, main.name: v} for place in where for v in values]
    # an effect of the catalogue at one place whose size (log scale) comes with where it sits (linear, not
    # signed): springs and their positions, crossed in the first step when the data hold a resonance the model
    # lacks (a suspension mode; the positions alike, then apart), since a spring's stiffness and place act
    # together there
    linear = [spec for spec in change.specs[1:] if not spec.log and spec.lower >= 0.0]
    if first and isinstance(change, EffectChange) and len(where) == 1 and main.log and linear:
        place = where[0]
        for v in grid(main, settings.named_grid, settings):
            for w in np.linspace(linear[0].lower, linear[0].upper, settings.named_second):
                out.append({**place, main.name: float(v), **{spec.name: float(w) for spec in linear[:2]}})
        if len(linear) >= 2:
            for v in grid(main, settings.scan_values, settings):
                for combo in itertools.product(*[np.linspace(x.lower, x.upper, settings.named_third)
                                                 for x in linear[:2]]):
                    out.append({**place, main.name: float(v), **{x.name: float(w) for x, w in zip(linear, combo)}})
    out += [{**where[0], **trial} for trial in getattr(change, "trials", ())]  # e.g. known materials
    logs = [s for s in change.specs if s.log]
    if len(logs) >= 2 and len(where) == 1:  # all log parameters scaled together too
        out += [{**where[0], **{s.name: float(np.clip(s.start * factor, s.lower, s.upper)) for s in logs}}
                for factor in np.geomspace(1.0 / settings.scale_span, settings.scale_span, settings.scale_values)]
    return out


GOLDEN = (np.sqrt(5.0) - 1.0) / 2.0
"""The golden ratio's inverse: the share of its interval a golden-section step keeps."""


def finer(change: Change, tried: list[dict], costs: list[float], evaluate: Callable[[list[dict]], list[float]],
          settings: DiagnoseSettings = DEFAULT_SETTINGS, below: float = np.inf) -> tuple[list[dict], list[float]]:
    """An element that sits at several places: its main parameter searched at each of them.

    At every place of :func:`places`, from the value whose trial cost least
    there, a golden-section search of ``settings.place_search`` steps
    between the grid's neighbours of that value (on the parameter's fitted
    scale), the places' trials evaluated together at each step.  The grid
    of an element's size is coarse (``settings.scan_values_placed`` values
    over decades) and a body's minimum is narrow: a 20 g nut at a holder's
    tip sits between the grid's 10 g and 94 g, both far off there, while
    10 g near the holder's base fits fairly; the polish that follows the
    scan refines only the best place, and the fit that starts there stays.

    Parameters
    ----------
    change : Change
        The candidate.
    tried : list of dict
        The trials evaluated (:func:`trials`, and any others).
    costs : list of float
        Their ``chi^2``.
    evaluate : callable
        ``evaluate(trials) -> costs``, for several trials together.
    settings : DiagnoseSettings
        ``scan_values_placed`` (the grid's step) and ``place_search``.
    below : float
        Only the places where a trial cost less than this are searched (the
        model as it is: where every size tried makes it worse, no size does).

    Returns
    -------
    (list of dict, list of float)
        The trials evaluated besides, and their costs (none for a change at one place).
    """
    where = places(change, settings)
    if len(where) < 2 or settings.place_search == 0:
        return [], []
    main = change.specs[0]
    lo, hi = sorted((to_u(main, main.lower), to_u(main, main.upper)))
    step = (hi - lo) / (settings.scan_values_placed - 1)

    def key(values: dict) -> tuple:
        return tuple(sorted((k, v) for k, v in values.items() if k != main.name))

    at_places = {key(place) for place in where}
    best: dict[tuple, tuple[float, dict]] = {}
    for trial, cost in zip(tried, costs):
        k = key(trial)
        if k in at_places and np.isfinite(cost) and cost < below and (k not in best or cost < best[k][0]):
            best[k] = (float(cost), trial)
    if not best:
        return [], []
    starts = [trial for _, trial in best.values()]
    u0 = np.array([to_u(main, t[main.name]) for t in starts])
    return _golden(main, starts, np.maximum(u0 - step, lo), np.minimum(u0 + step, hi), evaluate, settings.place_search)


def sharpen(change: Change, tried: list[dict], costs: list[float], evaluate: Callable[[list[dict]], list[float]],
            settings: DiagnoseSettings = DEFAULT_SETTINGS) -> tuple[list[dict], list[float]]:
    """The main parameter of the best starts searched close to each (starts from a free body's modes).

    The ``settings.rigid_sharpened`` best of ``tried``, each with a
    golden-section search of ``settings.place_search`` steps within
    ``settings.rigid_span`` of its main parameter (on its fitted scale), the
    starts evaluated together.  A start that places the springs right puts
    the body's modes within a line of the measured ones, and a lightly
    damped mode's minimum is narrower than that: 1 % off in stiffness,
    ``chi^2`` 176 becomes 10,789.

    Parameters
    ----------
    change : Change
        The candidate.
    tried, costs : list
        The starts and their ``chi^2``.
    evaluate : callable
        ``evaluate(trials) -> costs``, for several trials together.
    settings : DiagnoseSettings
        ``rigid_sharpened``, ``rigid_span`` and ``place_search``.

    Returns
    -------
    (list of dict, list of float)
        The trials evaluated besides, and their costs.
    """
    order = [i for i in np.argsort(costs) if np.isfinite(costs[i])][:settings.rigid_sharpened]
    if not order or settings.place_search == 0:
        return [], []
    main = change.specs[0]
    lo, hi = sorted((to_u(main, main.lower), to_u(main, main.upper)))
    starts = [tried[i] for i in order]
    u0 = np.array([to_u(main, t[main.name]) for t in starts])
    return _golden(main, starts, np.maximum(u0 - settings.rigid_span, lo), np.minimum(u0 + settings.rigid_span, hi),
                   evaluate, settings.place_search)


def _golden(main, starts: list[dict], a: np.ndarray, b: np.ndarray, evaluate: Callable, steps: int
            ) -> tuple[list[dict], list[float]]:
    """A golden-section search of ``main`` in ``[a, b]`` (fitted scale) for each start, evaluated together."""
    out: list[dict] = []
    got: list[float] = []

    def at(u) -> np.ndarray:
        batch = [{**t, main.name: from_u(main, float(x))} for t, x in zip(starts, u)]
        cost = [float(c) if np.isfinite(c) else np.inf for c in evaluate(batch)]
        out.extend(batch)
        got.extend(cost)
        return np.array(cost)

    c, d = b - GOLDEN * (b - a), a + GOLDEN * (b - a)
    fc, fd = at(c), at(d)
    for _ in range(steps - 1):
        left = fc <= fd  # the minimum lies in [a, d]: d becomes b, c becomes d
        a, b = np.where(left, a, c), np.where(left, d, b)
        c, d, fc_old, fd_old = (np.where(left, b - GOLDEN * (b - a), d), np.where(left, c, a + GOLDEN * (b - a)),
                                fc, fd)
        new = at(np.where(left, c, d))
        fc, fd = np.where(left, new, fd_old), np.where(left, fc_old, new)
    return out, got
