"""Weighted nonlinear least squares on whitened residuals, with standard deviations.

:func:`fit` minimises ``chi^2`` of a :class:`~substructure.updating.likelihood.Likelihood`
over the parameters of a list of changes with scipy's bounded
trust-region reflective method.  Parameters that span decades are fitted as
logarithms (``u = ln v``), the others scaled to order one
(``u = v / s``, ``s`` a tenth of their range).

Standard deviations and correlations come from the Jacobian ``J`` of the
whitened residual at the optimum: ``Cov(u) = s^2 (J^T J)^-1`` with
``s^2 = max(1, chi^2 / (n - p))``.  When the residual is consistent with the
noise ``s^2`` is about one and the covariance is the Cramer-Rao bound; when
it is not (the model misses something), the covariance is inflated by the
misfit, as if the noise were that much larger (the quasi-likelihood
correction), so that a wrong model does not report tight values.  Values
follow by the delta method: ``std(v) = v std(u)`` on the log scale.
"""

from __future__ import annotations

from typing import Callable, Mapping, Sequence

import attrs
import numpy as np
from scipy.optimize import least_squares

from .._kernels import one_blas_thread
from ..errors import InvalidValueError, SubstructureError
from ..units import finite_real, whole_number
from .parameters import Change, ParamSpec

__all__ = ["Fit", "fit", "scan", "FTOL", "XTOL", "INFEASIBLE"]

FTOL = 1e-7
"""Relative change of ``chi^2`` at which a fit stops: well below one unit of ``chi^2`` for any data set
of fewer than ten million residuals, so that likelihood ratios are not blurred by unconverged fits."""
XTOL = 1e-7
"""Relative change of the fitted variables at which a fit stops."""
INFEASIBLE = 1e4
"""Every whitened residual of a trial the model cannot hold (values a library check refuses, such as a
segment shorter than a micrometre): a misfit far above any the data give, so that the optimiser steps back."""


def _scale(spec: ParamSpec) -> float:
    return max((spec.upper - spec.lower) / 10.0, 1e-300)


def to_u(spec: ParamSpec, value: float) -> float:
    """The fitted variable of a value: ``ln v`` on a log scale, ``v / s`` on a linear one.

    Parameters
    ----------
    spec : ParamSpec
        The parameter.
    value : float
        Its value (SI).

    Returns
    -------
    float
        The fitted variable.
    """
    return float(np.log(value)) if spec.log else float(value) / _scale(spec)


def from_u(spec: ParamSpec, u: float) -> float:
    """The value of a fitted variable, within the parameter's bounds.

    Parameters
    ----------
    spec : ParamSpec
        The parameter.
    u : float
        The fitted variable.

    Returns
    -------
    float
        The value (SI).
    """
    # min and max, not np.clip: the same values, and this runs at every trial of every fit
    if spec.log:
        v = float(np.exp(min(max(float(u), float(np.log(spec.lower))), float(np.log(spec.upper)))))
    else:
        v = float(u) * _scale(spec)
    return float(min(max(v, spec.lower), spec.upper))


def _bounds_u(spec: ParamSpec) -> tuple[float, float]:
    if spec.log:
        if spec.lower <= 0:
            raise InvalidValueError(f"parameter {spec.name}: a log-scale parameter needs lower > 0, got {spec.lower}")
        return float(np.log(spec.lower)), float(np.log(spec.upper))
    return spec.lower / _scale(spec), spec.upper / _scale(spec)


@attrs.frozen
class Fit:
    """The result of :func:`fit`.

    Parameters
    ----------
    changes : tuple of (Change, dict)
        The changes with their fitted values (SI, by parameter name).
    std : tuple of dict
        Standard deviations per change and parameter (inflated by the misfit).
    correlation : ndarray
        Correlations between all fitted parameters, in the order of ``names``.
    names : tuple of (int, str)
        ``(change index, parameter name)`` of each fitted parameter.
    chi2 : float
        ``chi^2`` at the optimum.
    n : int
        Number of residuals.
    nfev : int
        Model evaluations used.
    at_bound : tuple of bool
        Per fitted parameter, whether it ended on a bound.
    """

    changes: tuple = attrs.field(eq=False)
    std: tuple
    correlation: np.ndarray = attrs.field(eq=False, repr=False)
    names: tuple
    chi2: float
    n: int
    nfev: int
    at_bound: tuple

    @property
    def p(self) -> int:
        """Number of fitted parameters."""
        return len(self.names)

    @property
    def dof(self) -> int:
        """Degrees of freedom ``n - p``."""
        return max(self.n - self.p, 1)

    @property
    def chi2_reduced(self) -> float:
        """``chi^2 / (n - p)``: about 1 when the residual is noise."""
        return self.chi2 / self.dof


def _checked_changes(changes) -> list:
    """``(Change, values)`` pairs checked and copied: values by the change's parameter names, finite numbers."""
    out = []
    for k, item in enumerate(changes):
        if not (isinstance(item, (tuple, list)) and len(item) == 2 and hasattr(item[0], "specs")
                and isinstance(item[1], Mapping)):
            raise InvalidValueError(f"changes[{k}]: got {item!r}; expected a pair (Change, dict of its values)")
        change, values = item
        names = [spec.name for spec in change.specs]
        for name, value in values.items():
            if name not in names:
                raise InvalidValueError(f"changes[{k}]: {change.effect} has no parameter {name!r}; expected some of "
                                        f"{', '.join(names)}")
            real = isinstance(value, (int, float, np.integer, np.floating))
            if isinstance(value, (bool, np.bool_, str, bytes)) or (real and not finite_real(value)):
                raise InvalidValueError(f"changes[{k}]: {change.effect} {name} = {value!r}; expected a finite "
                                        "number (SI)")
        out.append((change, dict(values)))
    return out


def fit(likelihood, changes: Sequence[tuple], free: Sequence[bool] | None = None, max_nfev: int | None = None,
        progress: Callable[[str], None] | None = None) -> Fit:
    """Fit the parameters of changes to the data of a likelihood.

    Parameters
    ----------
    likelihood : Likelihood
        The data and the model evaluation.
    changes : sequence of (Change, dict)
        The changes in the order they apply, each with its starting values
        (SI, by parameter name; missing ones start at the spec's ``start``).
    free : sequence of bool, optional
        Which changes are fitted (default all); the others keep their values.
    max_nfev : int, optional
        Most residual evaluations of the optimiser (default ``30 (p + 1)``).
    progress : callable, optional
        Called with a line of text when the fit ends.

    Returns
    -------
    Fit
        Values, standard deviations (inflated by the misfit), correlations.
    """
    changes = _checked_changes(changes)
    free = [True] * len(changes) if free is None else list(free)
    if len(free) != len(changes) or not all(isinstance(x, (bool, np.bool_)) for x in free):
        raise InvalidValueError(f"free: got {free!r}; expected one True or False per change ({len(changes)})")
    if max_nfev is not None:
        whole_number(max_nfev, "max_nfev", 1)  # None: the default
    slots = []  # (change index, spec)
    for i, ((change, values), is_free) in enumerate(zip(changes, free)):
        for spec in change.specs:
            values[spec.name] = float(np.clip(values.get(spec.name, spec.start), spec.lower, spec.upper))
            if is_free:
                slots.append((i, spec))

    def model_of(u):
        current = [(c, dict(v)) for c, v in changes]
        for (i, spec), ui in zip(slots, u):
            current[i][1][spec.name] = from_u(spec, ui)
        return current

    size = []

    def residual(u):
        # a trial the model cannot hold (a library check refuses the values the optimiser tried) is a large
        # misfit, never the user's error; a fit whose start cannot be evaluated still raises
        try:
            r = likelihood.residual(model_of(u))
        except (SubstructureError, ValueError, FloatingPointError):
            if not size:
                raise
            return np.full(size[0], INFEASIBLE)
        if not size:
            size.append(r.size)
        return r

    def together(_fun, points):
        # scipy's finite-difference steps, evaluated together (``Likelihood.residuals``: the same numbers as one
        # by one, in one coupling where the steps keep the model's layout); one by one when a step cannot be held
        us = list(points)
        try:
            return likelihood.residuals([model_of(u) for u in us])
        except (SubstructureError, ValueError, FloatingPointError):
            return [residual(u) for u in us]

    if not slots:
        r = likelihood.residual(changes)
        return Fit(tuple(changes), tuple({} for _ in changes), np.zeros((0, 0)), (), float(r @ r), r.size, 1, ())
    bounds = np.array([_bounds_u(s) for _, s in slots])
    lo, hi = bounds[:, 0], bounds[:, 1]
    u0 = np.array([to_u(s, changes[i][1][s.name]) for i, s in slots])
    span = np.maximum(hi - lo, 1e-12)
    u0 = np.clip(u0, lo + 1e-9 * span, hi - 1e-9 * span)
    with one_blas_thread():  # a tall, narrow Jacobian: faster on one thread (``_kernels.one_blas_thread``)
        result = least_squares(residual, u0, bounds=(lo, hi), method="trf", x_scale=1.0, diff_step=1e-6,
                               ftol=FTOL, xtol=XTOL, max_nfev=max_nfev or 30 * (len(slots) + 1), workers=together)
    u, f0, jac = result.x, result.fun, result.jac
    chi2 = float(f0 @ f0)
    n, p = f0.size, len(slots)
    s2 = max(1.0, chi2 / max(n - p, 1))
    cov = s2 * np.linalg.pinv(jac.T @ jac)
    sd_u = np.sqrt(np.clip(np.diag(cov), 0.0, None))
    with np.errstate(divide="ignore", invalid="ignore"):
        corr = cov / np.outer(sd_u, sd_u)
    corr = np.where(np.isfinite(corr), corr, 0.0)
    final = model_of(u)
    std = [dict() for _ in changes]
    for (i, spec), sd in zip(slots, sd_u):
        v = final[i][1][spec.name]
        std[i][spec.name] = float(abs(v) * sd) if spec.log else float(_scale(spec) * sd)
    width = 1e-6 * (hi - lo)
    at_bound = ((u <= lo + width) | (u >= hi - width)).tolist()
    if progress:
        progress(f"fitted {', '.join(f'{c.effect} at {c.where}' for c, _ in final)}: chi^2/n = {chi2 / n:.4g}")
    return Fit(tuple(final), tuple(std), corr, tuple((i, s.name) for i, s in slots), chi2, n,
               int(result.nfev) + int(result.njev) * p, tuple(at_bound))


def scan(likelihood, fixed: Sequence[tuple], change: Change, values: dict, name: str,
         grid: Sequence[float]) -> tuple[float, float]:
    """The best value of one parameter on a grid, others held: ``(chi2, value)``.

    Parameters
    ----------
    likelihood : Likelihood
        The data.
    fixed : sequence of (Change, dict)
        Changes applied first, with their values.
    change : Change
        The change scanned.
    values : dict
        Its other parameters' values.
    name : str
        The parameter scanned.
    grid : sequence of float
        Values to try.

    Returns
    -------
    (float, float)
        The lowest ``chi^2`` and its value.
    """
    best = (np.inf, float(values.get(name, np.nan)))
    for v in grid:
        trial = {**values, name: float(v)}
        try:
            chi2 = likelihood.chi2(list(fixed) + [(change, trial)])
        except (SubstructureError, ValueError, FloatingPointError):  # a trial the model cannot hold
            continue
        if chi2 < best[0]:
            best = (chi2, float(v))
    return best
