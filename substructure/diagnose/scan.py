"""The scan of the screening: where each candidate is tried before any fit.

A candidate's main parameter is tried over its range (log-spaced on a log
scale, at both signs over :data:`SIGNED_DECADES` decades for a cross term
whose range holds zero, linearly otherwise), at each place an element may
sit (:func:`places`); an effect of several log-scale parameters is also
tried with all of them scaled together, and an effect of the catalogue
whose size comes with positions (springs) with both crossed on finer grids.
The numbers of values, places and decades are fields of
:class:`~substructure.diagnose.settings.DiagnoseSettings` (``scan_values``,
``body_positions``, ``signed_decades``, ``named_grid``, ...).  :mod:`substructure.diagnose.search` evaluates the
trials on the screening lines and refines the best.
"""

from __future__ import annotations

import itertools

import numpy as np

from ..updating.elements import SectionChange
from ..updating.parameters import Change
from .effects import EffectChange
from .settings import DEFAULT_SETTINGS, DiagnoseSettings

__all__ = ["trials", "places", "grid"]


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
