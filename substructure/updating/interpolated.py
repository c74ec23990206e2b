"""Data interpolated onto a finer grid: which lines were measured, read from the data themselves.

An FRF measured every ``step``-th line and interpolated onto a grid ``step``
times finer (:meth:`substructure.FRF.interpolate`, ``numpy.interp``, a cubic
spline, a value held to the next) has ``step`` times as many lines as
measurements: the lines between are the interpolant's, a fixed function of
the measured ones.  Read as measured, they count the same noise several times
over, and a smooth interpolant hides the noise from the smoothing residual
that estimates it (on the independent FE rig, an exact model was called
unexplained on data interpolated from a grid 4 times coarser by a cubic
spline, and from one 8 times coarser by straight lines, in 8 of 8 tests).

An interpolant of degree ``p`` between its knots leaves its ``(p+1)``-th
differences zero, but for rounding, on every ``p + 2`` neighbouring lines
within one stretch between two knots, and not across a knot where the data
are noisy.  :func:`interpolated_from` finds the step, the knots' offset and
the degree (0: held, 1: straight lines, 3: a cubic spline) that make it so;
:func:`substructure.updating.estimate_noise` then estimates the noise on the
knots alone, and the comparisons keep those lines (``NoiseModel.held``).
"""

from __future__ import annotations

import attrs
import numpy as np

__all__ = ["DEGREES", "MOST_STEP", "EXACT", "ROUNDING", "interpolated_from", "on_every_line"]

DEGREES = (0, 1, 3)
"""The interpolants looked for, by degree: a value held to the next line, straight lines, a cubic spline."""
MOST_STEP = 32
"""The largest step between measured lines looked for."""
EXACT = 1e-5
"""A difference below this share of the values it combines (weighed as it weighs them) is zero but for rounding:
values written with 6 significant digits or more."""
ROUNDING = 1e-9
"""The same for values as computed (double precision, not written to a file)."""
_FEWEST_STRETCHES = 4  # stretches between knots the data must show to be read as interpolated
_ACROSS_SHARE = 0.5  # of the differences across a knot, at least this share must not be zero


def interpolated_from(values: np.ndarray) -> tuple[int, int, int] | None:
    """How the lines of an FRF were interpolated from every ``step``-th of them, if they were.

    Parameters
    ----------
    values : ndarray
        The FRF's values on its (uniform) lines, complex.

    Returns
    -------
    (int, int, int) or None
        ``(step, offset, degree)``: the lines ``offset, offset + step, ...``
        were measured, the others are a polynomial of ``degree`` between
        them; None for lines that are each a measurement (or too few, or
        not finite, to tell).
    """
    h = np.asarray(values, dtype=complex).ravel()
    if h.size < 3 or not np.all(np.isfinite(h)):
        return None
    with np.errstate(over="ignore", invalid="ignore"):  # values beyond any structure: no interpolant read
        size = np.abs(h)
        for exact in (ROUNDING, EXACT):  # values as computed (a smooth spline's knots show only there), as written
            found = _interpolant(h, size, exact)
            if found is not None:
                return found
    return None


def _interpolant(h: np.ndarray, size: np.ndarray, exact: float) -> tuple[int, int, int] | None:
    for degree in DEGREES:
        order = degree + 1
        span = order + 1  # the lines one difference combines
        if h.size < span * _FEWEST_STRETCHES:
            continue
        weights = np.abs(np.diff(np.eye(span)[::-1], order, axis=0))[0]  # |binomial coefficients| of the difference
        zero = np.abs(np.diff(h, order)) <= exact * np.convolve(size, weights, "valid")
        if zero.mean() < 1.0 / MOST_STEP:  # not even one stretch in MOST_STEP lines: no interpolant of this degree
            continue
        start = np.arange(zero.size)
        # a stretch: from a knot to the next one (a held value: to the line before it)
        last = 1 if degree == 0 else 0
        for step in range(order + last, MOST_STEP + 1):
            if zero.size < step * _FEWEST_STRETCHES:
                break
            for offset in range(step):
                inside = (start - offset) % step + order <= step - last  # the difference's lines in one stretch
                if inside.all() or not zero[inside].all():
                    continue
                if np.mean(~zero[~inside]) > _ACROSS_SHARE:
                    return step, offset, degree
    return None


def on_every_line(model, knots: np.ndarray, n: int, step: int, degree: int):
    """A noise model estimated on the measured lines ``knots``, on all ``n`` lines.

    Parameters
    ----------
    model : NoiseModel
        The noise of the FRF on the measured lines alone.
    knots : ndarray of int
        Those lines, every ``step``-th from the first.
    n : int
        All the lines.
    step, degree : int
        As :func:`interpolated_from` found them.

    Returns
    -------
    NoiseModel
        Each line with its nearest measured line's noise, ``held`` marking
        the measured ones and ``interpolated`` set to ``(step, degree)``.
    """
    nearest = np.clip(np.rint((np.arange(n) - knots[0]) / step).astype(int), 0, knots.size - 1)
    held = np.zeros(n, dtype=bool)
    held[knots] = True

    def spread(a):
        return None if a is None else a[nearest]

    return attrs.evolve(model, var_re=spread(model.var_re), var_im=spread(model.var_im),
                        scatter=spread(model.scatter), local_scale=spread(model.local_scale),
                        linear=None if model.linear is None else tuple(spread(a) for a in model.linear),
                        dof=spread(model.dof), held=held, interpolated=(step, degree))
