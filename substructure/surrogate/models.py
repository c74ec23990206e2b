"""Surrogates that predict joint parameters from features: a neural network and a Gaussian process.

Both follow the scikit-learn estimator conventions: hyperparameters in
``__init__``, ``fit(table, targets)`` returns ``self``, fitted attributes end
in ``_``.  Numeric features are standardised, categorical ones one-hot
encoded; the parameters are learnt as logarithms (they are positive and span
decades), so predictions are log-normal: ``predict`` gives the median and a
standard deviation, and :meth:`Prediction.interval` exact log-space intervals.

* :class:`MLPSurrogate`: a small ensemble of scikit-learn ``MLPRegressor``
  networks (as the thesis's network, chapter 4.5) trained from different
  seeds; its spread plus the training residual give the uncertainty.
* :class:`GPSurrogate`: scikit-learn's ``GaussianProcessRegressor`` with an
  anisotropic RBF kernel and a white-noise term; its predictive standard
  deviation includes the scatter of the data.

Predicting far outside the features of the table warns
(:class:`ExtrapolationWarning`) and says how far; the prediction records
every feature outside the table's range (:meth:`Prediction.outside`, and
``extrapolation`` in its JSON).
"""

from __future__ import annotations

import warnings
from typing import Any, Iterable, Mapping, Sequence

import attrs
import numpy as np
from scipy.stats import norm
from sklearn.base import BaseEstimator
from sklearn.exceptions import ConvergenceWarning
from sklearn.gaussian_process import GaussianProcessRegressor
from sklearn.gaussian_process.kernels import RBF, ConstantKernel, WhiteKernel
from sklearn.neural_network import MLPRegressor

from ..errors import InvalidValueError, SubstructureWarning
from ..units import MAX_REPEATS, whole_number
from .columns import in_si
from .table import JointTable

__all__ = ["ExtrapolationWarning", "Prediction", "JointSurrogate", "MLPSurrogate", "GPSurrogate", "make_surrogate"]


class ExtrapolationWarning(SubstructureWarning):
    """A prediction for features far outside those of the training table."""


@attrs.frozen(eq=False)
class Prediction:
    """Predicted joint parameters for one or more feature sets.

    ``log_mean[p]`` and ``log_std[p]`` (arrays over the feature sets) are the
    mean and standard deviation of the natural logarithm of parameter ``p``
    (in ``units[p]``); ``value`` is the median ``exp(log_mean)`` and ``std``
    the standard deviation of the log-normal distribution.

    Parameters
    ----------
    log_mean : dict
        ``{parameter: ndarray}``: mean of ln(value in ``units[parameter]``) per feature set.
    log_std : dict
        ``{parameter: ndarray}``: standard deviation of that logarithm (dimensionless).
    units : dict
        ``{parameter: unit}``, e.g. ``{"k_yf": "N/m"}``.
    extrapolation : list of list of dict, optional
        Per feature set, the numeric features outside the range of the
        training table: ``{"feature", "value", "unit", "table_min",
        "table_max", "side" ("below" or "above"), "distance" (in ``unit``),
        "times_range"}`` (the distance over the table's range); an empty list
        inside it.  Empty when not known.
    """

    log_mean: dict
    log_std: dict
    units: dict
    extrapolation: list = attrs.field(factory=list)

    def outside(self, index: int = 0) -> list[dict]:
        """The features of feature set ``index`` outside the table's range (see ``extrapolation``).

        Parameters
        ----------
        index : int
            Which feature set.

        Returns
        -------
        list of dict
            One dict per feature outside the range; empty when every feature is inside it.
        """
        return [dict(e) for e in self.extrapolation[index]] if self.extrapolation else []

    def _check_parameter(self, parameter: str) -> None:
        if not isinstance(parameter, str) or parameter not in self.log_mean:
            raise InvalidValueError(f"parameter: got {parameter!r}, which was not predicted; the prediction has "
                                    f"{', '.join(self.log_mean)} (a surrogate predicts what it was fitted on)")

    def value(self, parameter: str) -> np.ndarray:
        """The median prediction ``exp(log_mean)``.

        Parameters
        ----------
        parameter : str
            A predicted parameter, e.g. ``"k_yf"``.

        Returns
        -------
        ndarray
            One value per feature set, in ``units[parameter]``.
        """
        self._check_parameter(parameter)
        return np.exp(self.log_mean[parameter])

    def std(self, parameter: str) -> np.ndarray:
        """The standard deviation of the log-normal predictive distribution.

        Parameters
        ----------
        parameter : str
            A predicted parameter.

        Returns
        -------
        ndarray
            One value per feature set, in ``units[parameter]``.
        """
        self._check_parameter(parameter)
        s = self.log_std[parameter]
        return self.value(parameter) * np.sqrt(np.expm1(s**2)) * np.exp(s**2 / 2)

    def interval(self, parameter: str, level: float = 0.95) -> tuple[np.ndarray, np.ndarray]:
        """Central interval of probability ``level`` (lower, upper).

        Parameters
        ----------
        parameter : str
            A predicted parameter.
        level : float
            Probability in (0, 1), e.g. 0.95.

        Returns
        -------
        lower, upper : ndarray
            One bound per feature set, in ``units[parameter]``.
        """
        self._check_parameter(parameter)
        if isinstance(level, bool) or not isinstance(level, (int, float, np.number)) or not 0 < level < 1:
            raise InvalidValueError(f"level: got {level!r}; expected a probability strictly between 0 and 1, "
                                    "e.g. 0.95")
        z = norm.ppf(0.5 + level / 2)
        m, s = self.log_mean[parameter], self.log_std[parameter]
        return np.exp(m - z * s), np.exp(m + z * s)

    def sample(self, n: int, rng: np.random.Generator | int | None = 0, index: int = 0) -> dict[str, np.ndarray]:
        """``n`` stratified samples of every parameter for feature set ``index``.

        Latin-hypercube style: each parameter's probabilities are evenly
        spaced (then shuffled independently), so that a small ``n`` still
        covers its distribution from tail to tail.

        Parameters
        ----------
        n : int
            Number of samples.
        rng : numpy.random.Generator or int or None
            Random generator or seed (default 0: reproducible).
        index : int
            Which feature set.

        Returns
        -------
        dict
            ``{parameter: ndarray of n values}``, in ``units[parameter]``.
        """
        whole_number(n, "n", 1, "a whole number of samples", MAX_REPEATS)
        rng = np.random.default_rng(rng)
        p = (np.arange(n) + 0.5) / n
        out = {}
        for name in self.log_mean:
            z = norm.ppf(rng.permutation(p))
            out[name] = np.exp(self.log_mean[name][index] + z * self.log_std[name][index])
        return out

    def to_json(self, index: int = 0) -> dict:
        """``{name: {"value", "unit", "std", "interval_95", "extrapolation"}}`` for feature set ``index``.

        ``extrapolation`` lists the features outside the table's range and how
        far (:meth:`outside`); an empty list when the prediction interpolates.

        Parameters
        ----------
        index : int
            Which feature set.

        Returns
        -------
        dict
            Values in SI units (``unit``, the joint parameters' of ``PARAMETER_UNITS`` whatever unit the table
            gave, ``table_unit``); plain floats, ready for JSON.
        """
        out = {}
        for p in self.log_mean:
            lo, hi = self.interval(p, 0.95)
            factor, unit = in_si(p, self.units[p])
            out[p] = {"value": factor * float(self.value(p)[index]), "unit": unit,
                      "std": factor * float(self.std(p)[index]),
                      "interval_95": [factor * float(lo[index]), factor * float(hi[index])],
                      "table_unit": self.units[p], "extrapolation": self.outside(index)}
        return out


class _Encoder:
    """Standardised numeric features and one-hot categorical ones."""

    def __init__(self, table: JointTable):
        self.names = list(table.features)
        self.units = dict(table.features)
        self.mean, self.scale, self.lo, self.hi, self.categories = {}, {}, {}, {}, {}
        self.constant: dict[str, Any] = {}  # features with one value in every row: they teach nothing
        for f, u in self.units.items():
            col = table.feature(f)
            if u is None:
                self.categories[f] = sorted(set(col))
                if len(self.categories[f]) == 1:
                    self.constant[f] = self.categories[f][0]
            else:
                col = np.asarray(col, dtype=float)
                self.mean[f], self.lo[f], self.hi[f] = col.mean(), col.min(), col.max()
                spread = col.std()
                if spread <= 1e-12 * max(abs(self.mean[f]), 1e-300):
                    self.constant[f] = float(self.mean[f])
                self.scale[f] = spread if f not in self.constant else 1.0

    def encode_columns(self, columns: Mapping[str, Sequence]) -> np.ndarray:
        parts = []
        for f in self.names:
            col = columns[f]
            if self.units[f] is None:
                cats = self.categories[f]
                unknown = sorted({c for c in col if c not in cats})
                if unknown:
                    raise InvalidValueError(
                        f"{f}: {', '.join(map(repr, unknown))} is not in the table; known: {', '.join(cats)}"
                    )
                parts.append(np.array([[c == k for k in cats] for c in col], dtype=float).reshape(len(col), len(cats)))
            else:
                parts.append(((np.asarray(col, dtype=float) - self.mean[f]) / self.scale[f])[:, None])
        return np.hstack(parts) if parts else np.zeros((0, 0))

    def check_constant(self, columns: Mapping[str, Sequence]) -> None:
        """Refuse a prediction at another value of a feature that is the same in every row of the table.

        Such a column says nothing about how the joint depends on the
        feature: a prediction elsewhere would be a guess with a falsely
        narrow interval.
        """
        for f, value in self.constant.items():
            unit = self.units[f]
            for v in columns[f]:
                same = v == value if unit is None else abs(float(v) - value) <= 1e-9 * max(abs(value), 1e-300)
                if not same:
                    shown = (f"{v!r}", f"{value!r}") if unit is None else (f"{float(v):g} {unit}", f"{value:g} {unit}")
                    raise InvalidValueError(
                        f"{f}: got {shown[0]}, but every row of the joint table has {f} = {shown[1]}, so the "
                        f"table says nothing about how the joint changes with {f}; predict at {shown[1]}, or "
                        "add identified joints with other values (or leave the column out)"
                    )

    def outside(self, columns: Mapping[str, Sequence]) -> list[list[dict]]:
        """Per feature set, the numeric features outside the table's range and how far."""
        n = len(next(iter(columns.values()))) if columns else 0
        out: list[list[dict]] = [[] for _ in range(n)]
        for f in self.names:
            if self.units[f] is None or f in self.constant:
                continue
            lo, hi = float(self.lo[f]), float(self.hi[f])
            span = max(hi - lo, 1e-12 * max(abs(hi), 1.0))
            for i, v in enumerate(np.asarray(columns[f], dtype=float)):
                dist = lo - v if v < lo else v - hi if v > hi else 0.0
                if dist > 0:
                    out[i].append({"feature": f, "value": float(v), "unit": self.units[f], "table_min": lo,
                                   "table_max": hi, "side": "below" if v < lo else "above",
                                   "distance": float(dist), "times_range": float(dist / span)})
        return out

    def check_range(self, outside: list[list[dict]], tolerance: float) -> None:
        for entries in outside:
            for e in entries:
                if e["times_range"] > tolerance:
                    side = "below the smallest" if e["side"] == "below" else "above the largest"
                    u = e["unit"]
                    warnings.warn(
                        f"{e['feature']} = {e['value']:g} {u} is {e['distance']:g} {u} ({e['times_range']:.1f} times "
                        f"the table's range {e['table_min']:g}-{e['table_max']:g} {u}) {side} in the table: an "
                        "extrapolation, the prediction and its uncertainty are not to be trusted",
                        ExtrapolationWarning, stacklevel=4,
                    )


class JointSurrogate(BaseEstimator):
    """Base class: fit on a :class:`JointTable`, predict parameters from features.

    Subclasses implement ``_fit_one(X, y) -> model`` and
    ``_predict_one(model, X) -> (mean, std)`` in log space.
    """

    extrapolation_tolerance: float = 0.25

    def fit(self, table: JointTable, targets: Sequence[str] | str | None = None) -> "JointSurrogate":
        """Fit one model per target parameter (default: every parameter of the table).

        Parameters
        ----------
        table : JointTable
            At least 3 rows of distinct features (repeated tests of one tool count once); the target values
            must be positive (logarithms are learnt).
        targets : str or sequence of str, optional
            Parameters to learn, e.g. ``"k_yf"``; default all of the table's.

        Returns
        -------
        JointSurrogate
            ``self``, fitted.
        """
        table.check_not_empty()
        if isinstance(targets, str):
            targets = [targets]
        targets = list(table.parameters) if targets is None else list(targets)
        for t in targets:
            table._check_parameter(t)
        table.check_distinct_features(3, "a surrogate")
        self.encoder_ = _Encoder(table)
        X = self.encoder_.encode_columns(table.columns)
        self.targets_ = tuple(targets)
        self.units_ = {t: table.parameters[t] for t in targets}
        self.feature_names_in_ = np.array(list(table.features), dtype=object)
        self.n_features_in_ = len(table.features)
        self.models_ = {}
        for t in targets:
            y = table.values(t)
            if np.any(y <= 0):
                raise InvalidValueError(f"{t}: the surrogates learn log values and need positive values")
            self.models_[t] = self._fit_one(X, np.log(y))
        return self

    def _columns(self, features) -> dict[str, list]:
        if isinstance(features, (str, bytes)):
            raise InvalidValueError(f"features: got the string {features!r}; expected a mapping such as "
                                    "{'tool_diameter': '14 mm', 'gauge_length': '90 mm'} (or a list of them)")
        expected = ("expected a mapping such as {'tool_diameter': '14 mm', 'gauge_length': '90 mm'} "
                    f"(or a list of them) with the table's features {', '.join(self.encoder_.names)}")
        if isinstance(features, Mapping):
            rows = [features]
        else:
            rows = list(features) if isinstance(features, Iterable) else [features]
            wrong = [r for r in rows if not isinstance(r, Mapping)]
            if wrong:
                raise InvalidValueError(f"features: got {wrong[0]!r}; {expected}")
        if not rows:
            raise InvalidValueError("features: got no feature sets")
        table = JointTable.empty({"k_yf": "N/m"}, self.encoder_.units)
        checked = [table.feature_values(r) for r in rows]
        return {f: [c[f] for c in checked] for f in self.encoder_.names}

    def predict(self, features: Mapping[str, Any] | Sequence[Mapping[str, Any]]) -> Prediction:
        """Predict the parameters for one feature set (a mapping) or several.

        Feature values are quantities or strings with units (``"14 mm"``),
        names for categorical features; every feature of the table is needed.

        Parameters
        ----------
        features : mapping or sequence of mapping
            ``{"tool_diameter": "12 mm", "gauge_length": "80 mm"}``, or a list of them.

        Returns
        -------
        Prediction
            Log-normal predictions, in the table's units; warns with
            :class:`ExtrapolationWarning` far outside the training features.
        """
        if not hasattr(self, "models_"):
            raise InvalidValueError(f"{type(self).__name__} is not fitted yet: call fit(table) first")
        return self._predict_columns(self._columns(features))

    def _predict_columns(self, columns, check_range: bool = True) -> Prediction:
        outside = self.encoder_.outside(columns)
        if check_range:
            self.encoder_.check_constant(columns)
            self.encoder_.check_range(outside, self.extrapolation_tolerance)
        X = self.encoder_.encode_columns(columns)
        means, stds = {}, {}
        for t, model in self.models_.items():
            means[t], stds[t] = self._predict_one(model, X)
        return Prediction(means, stds, dict(self.units_), outside)


class MLPSurrogate(JointSurrogate):
    """An ensemble of small multilayer perceptrons (scikit-learn ``MLPRegressor``).

    Parameters
    ----------
    hidden_layer_sizes : tuple of int
        Neurons per hidden layer (tanh activation).
    alpha : float
        L2 penalty.
    n_models : int
        Networks in the ensemble, each from another seed; their spread (plus
        the training residual) is the predictive standard deviation.
    max_iter : int
        Largest number of L-BFGS iterations per network.
    random_state : int
        Seed of the first network (the others take the next ones).
    """

    def __init__(self, hidden_layer_sizes=(6,), alpha=1.0, n_models=5, max_iter=2000, random_state=0):
        self.hidden_layer_sizes = hidden_layer_sizes
        self.alpha = alpha
        self.n_models = n_models
        self.max_iter = max_iter
        self.random_state = random_state

    def _fit_one(self, X, logy):
        mu, sd = logy.mean(), logy.std() or 1.0
        z = (logy - mu) / sd
        nets = []
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", ConvergenceWarning)
            for i in range(self.n_models):
                net = MLPRegressor(hidden_layer_sizes=self.hidden_layer_sizes, activation="tanh", solver="lbfgs",
                                   alpha=self.alpha, max_iter=self.max_iter, random_state=self.random_state + i)
                nets.append(net.fit(X, z))
        fitted = np.mean([n.predict(X) for n in nets], axis=0)
        dof = max(len(z) - 1, 1)
        resid = float(np.sqrt(np.sum((fitted - z) ** 2) / dof))
        return {"nets": nets, "mu": mu, "sd": sd, "resid": resid}

    def _predict_one(self, model, X):
        preds = np.array([n.predict(X) for n in model["nets"]])
        mean = preds.mean(axis=0) * model["sd"] + model["mu"]
        spread = preds.std(axis=0, ddof=1) if len(preds) > 1 else np.zeros(X.shape[0])
        std = np.sqrt(spread**2 + model["resid"] ** 2) * model["sd"]
        return mean, std


class GPSurrogate(JointSurrogate):
    """A Gaussian process (scikit-learn ``GaussianProcessRegressor``) on log parameters.

    Parameters
    ----------
    length_scale : float
        Initial length scale of the RBF kernel, in standardised feature units.
    min_length_scale : float
        Lower bound of the length scales.  With a dozen rows the likelihood
        otherwise prefers a wiggly fit through scattered points (on Table 4.2
        a bound of 2 takes the leave-one-out 95 % coverage from 9 to 11 of 13).
    noise_level : float
        Initial white-noise variance (standardised log units).
    n_restarts_optimizer : int
        Restarts of the kernel hyperparameter optimiser.
    random_state : int
        Seed of the restarts.
    """

    def __init__(self, length_scale=2.0, min_length_scale=2.0, noise_level=0.1, n_restarts_optimizer=1, random_state=0):
        self.length_scale = length_scale
        self.min_length_scale = min_length_scale
        self.noise_level = noise_level
        self.n_restarts_optimizer = n_restarts_optimizer
        self.random_state = random_state

    def _fit_one(self, X, logy):
        mu, sd = logy.mean(), logy.std() or 1.0
        z = (logy - mu) / sd
        kernel = (ConstantKernel(1.0, (1e-2, 1e2))
                  * RBF(np.full(X.shape[1], max(float(self.length_scale), self.min_length_scale)),
                        (self.min_length_scale, 1e2))
                  + WhiteKernel(self.noise_level, (1e-3, 1.0)))
        gp = GaussianProcessRegressor(kernel=kernel, normalize_y=False, n_restarts_optimizer=self.n_restarts_optimizer,
                                      random_state=self.random_state)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", ConvergenceWarning)
            gp.fit(X, z)
        return {"gp": gp, "mu": mu, "sd": sd}

    def _predict_one(self, model, X):
        m, s = model["gp"].predict(X, return_std=True)
        return m * model["sd"] + model["mu"], s * model["sd"]


def make_surrogate(model: str, **kwargs) -> JointSurrogate:
    """``"mlp"`` or ``"gp"`` as an unfitted surrogate.

    Parameters
    ----------
    model : {"mlp", "gp"}
        The kind of surrogate.
    **kwargs
        Hyperparameters of :class:`MLPSurrogate` or :class:`GPSurrogate`.

    Returns
    -------
    JointSurrogate
        The unfitted surrogate.
    """
    if model == "mlp":
        return MLPSurrogate(**kwargs)
    if model == "gp":
        return GPSurrogate(**kwargs)
    raise InvalidValueError(f"model: got {model!r}; expected 'mlp' or 'gp'")
