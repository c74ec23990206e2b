"""Honest evaluation of the surrogates: leave-one-out and leave-one-group-out cross-validation.

Leave-one-out leaves out one tool at a time: the rows with the same
features (repeated tests of one tool) are held out together.  Each fold
refits a clone of the surrogate without the held-out rows and predicts
them; the result gives every fold's true, predicted values and predictive
standard deviations, the mean absolute percent error, and the calibration
of the intervals: the fraction of held-out values inside the 68 % and 95 %
intervals (nominally 0.68 and 0.95).
"""

from __future__ import annotations

import attrs
import numpy as np
from sklearn.base import clone

from .._text import plain_text
from ..errors import InvalidValueError
from .models import JointSurrogate
from .columns import in_si
from .table import JointTable

__all__ = ["CrossValidation", "cross_validate"]


@attrs.frozen(eq=False)
class CrossValidation:
    """Held-out predictions of a cross-validation.

    ``folds`` is a list of dicts ``held_out`` (row indices), ``true``,
    ``predicted``, ``std``, ``lower_68``, ``upper_68``, ``lower_95``, ``upper_95``.

    Parameters
    ----------
    model : str
        The surrogate's class name.
    target : str
        The parameter predicted (``k_yf``).
    unit : str
        Its unit (``N/m``).
    scheme : str
        ``"loo"`` or ``"group:FEATURE"``.
    folds : list of dict
        The held-out predictions, values in ``unit``.
    """

    model: str
    target: str
    unit: str
    scheme: str
    folds: list

    def _all(self, key: str) -> np.ndarray:
        return np.concatenate([np.asarray(f[key], dtype=float) for f in self.folds])

    @property
    def percent_errors(self) -> np.ndarray:
        """Absolute errors of the held-out predictions, in % of the true values."""
        t = self._all("true")
        return 100.0 * np.abs(self._all("predicted") - t) / np.abs(t)

    @property
    def mean_abs_percent_error(self) -> float:
        """Mean absolute percentage error, in %."""
        return float(np.mean(self.percent_errors))

    @property
    def max_abs_percent_error(self) -> float:
        """Largest absolute percentage error, in %."""
        return float(np.max(self.percent_errors))

    def coverage(self, level: float) -> float:
        """Share of the true values inside the held-out predictive intervals.

        Parameters
        ----------
        level : {0.68, 0.95}
            The interval's probability.

        Returns
        -------
        float
            The share, in [0, 1]; an honest surrogate covers about ``level``.
        """
        key = {0.68: "68", 0.95: "95"}[level]
        t = self._all("true")
        return float(np.mean((t >= self._all("lower_" + key)) & (t <= self._all("upper_" + key))))

    def to_json(self) -> dict:
        """The cross-validation for JSON output.

        Returns
        -------
        dict
            The folds (values in SI units, ``unit``; the table's was ``table_unit``), the errors in % and the
            coverages.
        """
        factor, unit = in_si(self.target, self.unit)
        return {
            "model": self.model, "target": self.target, "unit": unit, "table_unit": self.unit, "scheme": self.scheme,
            "folds": [{k: [int(i) for i in f[k]] if k == "held_out" else [factor * float(x) for x in f[k]]
                       for k in ("held_out", "true", "predicted", "std")} for f in self.folds],
            "mean_abs_percent_error": self.mean_abs_percent_error,
            "max_abs_percent_error": self.max_abs_percent_error,
            "coverage_68": self.coverage(0.68),
            "coverage_95": self.coverage(0.95),
        }

    def plot(self, ax=None):
        """Parity plot: predicted against true with 95 % error bars.

        Parameters
        ----------
        ax : Axes, optional
            Where to draw; a new figure when None.

        Returns
        -------
        Figure
            The figure, both axes in ``unit``.
        """
        import matplotlib.pyplot as plt

        if ax is None:
            fig, ax = plt.subplots(figsize=(4.8, 4.5), layout="constrained")
        t, p = self._all("true"), self._all("predicted")
        lo, hi = self._all("lower_95"), self._all("upper_95")
        ax.errorbar(t, p, yerr=[p - lo, hi - p], fmt="o", ms=4, capsize=2, label="held out, 95 % interval")
        ends = [min(t.min(), lo.min()), max(t.max(), hi.max())]
        ax.plot(ends, ends, "k--", lw=0.8, label="parity")
        ax.set_xlabel(plain_text(f"identified {self.target} [{self.unit}]"))
        ax.set_ylabel(plain_text(f"predicted {self.target} [{self.unit}]"))
        ax.set_title(plain_text(f"{self.model}, {self.scheme}: MAPE {self.mean_abs_percent_error:.1f} %, "
                                f"95 % cover {self.coverage(0.95):.0%}"), fontsize="small")
        ax.legend(fontsize="small")
        return ax.figure


def cross_validate(surrogate: JointSurrogate, table: JointTable, target: str, scheme: str = "loo") -> CrossValidation:
    """Cross-validate ``surrogate`` on ``table`` for parameter ``target``.

    Parameters
    ----------
    surrogate : JointSurrogate
        An unfitted surrogate (cloned for every fold).
    table : JointTable
        The joint table.
    target : str
        The parameter to predict (``k_yf``).
    scheme : str
        ``"loo"`` (leave one tool out: every row of one feature set together,
        so that repeated tests of the held-out tool are never in the training
        set) or ``"group:FEATURE"`` (leave out every row of one value of
        FEATURE at a time, e.g. ``group:tool_diameter``).

    Returns
    -------
    CrossValidation
        The held-out predictions, in the table's unit of ``target``.
    """
    table.check_not_empty()
    table._check_parameter(target)
    n = len(table)
    tools = table.feature_groups()
    tool_of = {i: k for k, rows in enumerate(tools) for i in rows}
    if scheme == "loo":
        groups = tools
    elif scheme.startswith("group:"):
        col = table.feature(scheme[6:])
        keys = list(dict.fromkeys(col.tolist()))
        groups = [[i for i in range(n) if col[i] == k] for k in keys]
        if len(groups) < 2:
            raise InvalidValueError(f"{scheme}: the table has one value of {scheme[6:]} only; nothing to hold out")
    else:
        raise InvalidValueError(f"cross-validation: got {scheme!r}; expected 'loo' or 'group:FEATURE'")
    smallest = min(len({tool_of[i] for i in range(n)} - {tool_of[i] for i in g}) for g in groups)
    if smallest < 3:
        rows = "1 row" if n == 1 else f"{n} rows"
        held = "one row" if len(tools) == n else "one tool (every row of its features)"
        if len(tools) < n:
            rows += f" of {len(tools)} distinct tools (feature sets)"
        raise InvalidValueError(
            f"cross-validation ({scheme}): the joint table has {rows}; holding out "
            f"{held if scheme == 'loo' else 'the largest group'} leaves {smallest} to fit, and a surrogate "
            "needs at least 3"
        )
    y = table.values(target)
    folds = []
    for held in groups:
        keep = np.setdiff1d(np.arange(n), held)
        sub = JointTable(table.parameters, table.features, {k: v[keep] for k, v in table.columns.items()})
        model = clone(surrogate).fit(sub, target)
        cols = {f: table.columns[f][held] for f in table.features}
        pred = model._predict_columns(cols, check_range=False)
        lo68, hi68 = pred.interval(target, 0.68)
        lo95, hi95 = pred.interval(target, 0.95)
        folds.append({"held_out": held, "true": y[held], "predicted": pred.value(target), "std": pred.std(target),
                      "lower_68": lo68, "upper_68": hi68, "lower_95": lo95, "upper_95": hi95})
    name = {"MLPSurrogate": "mlp", "GPSurrogate": "gp"}.get(type(surrogate).__name__, type(surrogate).__name__)
    return CrossValidation(name, target, table.parameters[target], scheme, folds)
