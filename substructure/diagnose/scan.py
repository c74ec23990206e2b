"""The scan of the screening: where each candidate is tried before any fit.

A candidate's main parameter is tried over its range (log-spaced on a log
scale, at both signs over :data:`SIGNED_DECADES` decades for a cross term
whose range holds zero, linearly otherwise), at each place an element may
sit (:func:`places`); an effect of several log-scale parameters is also
tried with all of them scaled together, and an effect of the catalogue
whose size comes with positions (springs) with both crossed on finer grids
(:data:`NAMED_GRID`).  :mod:`substructure.diagnose.search` evaluates the
trials on the screening lines and refines the best.
"""

from __future__ import annotations

import itertools

import numpy as np

from ..updating.elements import SectionChange
from ..updating.parameters import Change
from .effects import EffectChange

__all__ = ["trials", "places", "grid", "SIGNED_DECADES", "NAMED_GRID", "NAMED_SECOND", "NAMED_THIRD"]


SIGNED_DECADES = 3.0
"""A linear parameter whose range holds zero (a cross term) is scanned at both signs over this many decades
below its largest magnitude: its physically typical values are small next to its passivity bound, and a
start at zero (where the model is as given) hides it."""


NAMED_GRID = 33
"""Values (in the first step, on data with a resonance the model lacks) of the size of an effect of the
catalogue at one place that comes with positions (springs), crossed with them: near the edge of the band such
effects have narrow minima (suspension springs whose modes sit just below the first line change the lowest lines
only within a few tens of per cent of their stiffness)."""
NAMED_SECOND = 10
"""Positions (all alike) crossed with each size on that grid."""
NAMED_THIRD = 4
"""Values of each of two positions crossed with nine sizes."""


def grid(spec, count: int) -> np.ndarray:
    if spec.log:
        return np.geomspace(spec.lower, spec.upper, count)
    if spec.lower < 0.0 < spec.upper:  # sign-symmetric, log-spaced magnitudes
        top = max(-spec.lower, spec.upper)
        mags = np.geomspace(top * 10.0 ** -SIGNED_DECADES, top, max(count, 7))
        return np.clip(np.concatenate([-mags[::-1], mags]), spec.lower, spec.upper)
    return np.linspace(spec.lower, spec.upper, count)


def places(change: Change) -> list[dict]:
    """Where an element may sit, for screening: positions (and ranges) along its component."""
    base = {s.name: s.start for s in change.specs}
    if isinstance(change, SectionChange):
        L = change.length
        return [{**base, "start": float(start), "length": float(length)}
                for length in (0.12 * L, 0.3 * L, 0.6 * L) for start in np.linspace(0.0, L - length, 5)]
    position = next((s for s in change.specs if s.name == "position"), None)
    if position is not None:
        return [{**base, "position": float(x)} for x in np.linspace(position.lower, position.upper, 9)]
    return [base]


def trials(change: Change, first: bool = True) -> list[dict]:
    """Starting points of the screening scan: the main parameter over its range (at each place), and
    for effects of several log-scale parameters, all of them scaled together (``first``: the first step of
    data with a resonance the model lacks, where the sizes and positions of springs are crossed)."""
    main = change.specs[0]
    count = 5 if len(places(change)) > 1 else 9
    values = list(grid(main, count))
    if main.nominal is not None:
        values.append(float(np.clip(main.nominal, main.lower, main.upper)))
    values.append(main.start)
    values = list(dict.fromkeys(float(v) for v in values))
    if isinstance(change, SectionChange):
        values = [0.7, 0.85, 1.2]
    out = [{**place, main.name: v} for place in places(change) for v in values]
    # an effect of the catalogue at one place whose size (log scale) comes with where it sits (linear, not
    # signed): springs and their positions, crossed in the first step when the data hold a resonance the model
    # lacks (a suspension mode; the positions alike, then apart), since a spring's stiffness and place act
    # together there
    linear = [spec for spec in change.specs[1:] if not spec.log and spec.lower >= 0.0]
    if first and isinstance(change, EffectChange) and len(places(change)) == 1 and main.log and linear:
        place = places(change)[0]
        for v in grid(main, NAMED_GRID):
            for w in np.linspace(linear[0].lower, linear[0].upper, NAMED_SECOND):
                out.append({**place, main.name: float(v), **{spec.name: float(w) for spec in linear[:2]}})
        if len(linear) >= 2:
            for v in grid(main, 9):
                for combo in itertools.product(*[np.linspace(x.lower, x.upper, NAMED_THIRD) for x in linear[:2]]):
                    out.append({**place, main.name: float(v), **{x.name: float(w) for x, w in zip(linear, combo)}})
    out += [{**places(change)[0], **trial} for trial in getattr(change, "trials", ())]  # e.g. known materials
    logs = [s for s in change.specs if s.log]
    if len(logs) >= 2 and len(places(change)) == 1:  # all log parameters scaled together too
        for factor in np.geomspace(0.01, 100.0, 9):
            trial = dict(places(change)[0])
            for spec in logs:
                trial[spec.name] = float(np.clip(spec.start * factor, spec.lower, spec.upper))
            out.append(trial)
    return out
