"""Robust band identification: constant joint stiffness and damping fitted to measured FRFs.

The thesis's future work asks for an identification that no noisy matrix
inversion drives.  :class:`JointIdentifier` fits constant ``k`` and ``c`` by
least squares to the measured translational FRFs directly, over the band
where the joint is observable (the mode it dominates, found from the model's
sensitivity to the joint, :func:`auto_band`), with standard deviations from
the fit's Jacobian and optionally a bootstrap over the residuals.
"""

from __future__ import annotations

import warnings
from typing import Mapping, Sequence

import attrs
import numpy as np
from scipy.optimize import least_squares

from ..assembly import Assembly
from ..errors import InvalidValueError, NonPassiveJointWarning
from ..frf import FRF
from ..joints import DAMPING_UNITS, STIFFNESS_UNITS, Joint
from ..points import parse_point
from .closed_form import PARAMETERS

__all__ = ["JointIdentifier", "auto_band", "model_of_measurement"]

def model_of_measurement(assembly: Assembly, measurement) -> Assembly:
    """The model of the structure as it was measured: removed components, sensors on.

    Parameters
    ----------
    assembly : Assembly
        The model, with every sensor the measurements name declared in it.
    measurement : Measurement or FRF
        A measurement with ``.sensors`` and ``.removed`` (a bare FRF has neither).

    Returns
    -------
    Assembly
        The model without the removed components, with exactly the listed sensors on.
    """
    removed = tuple(getattr(measurement, "removed", ()) or ())
    sensors = tuple(getattr(measurement, "sensors", ()) or ())
    model = assembly.without(*removed) if removed else assembly
    on = [assembly.sensor(name) for name in sensors]
    return model.without_sensors().attach(*on)


def _frf_of(measurement) -> FRF:
    frf = measurement if isinstance(measurement, FRF) else measurement.frf
    if not isinstance(frf, FRF):
        raise InvalidValueError(f"measurements: got {measurement!r}; expected FRFs or measurements with .frf")
    return frf.to_receptance()


def _set_parameter(k: dict, c: dict, name: str, value: float) -> None:
    kind, entry = name.split("_", 1)
    target, units = (k, STIFFNESS_UNITS) if kind == "k" else (c, DAMPING_UNITS)
    entries = ("ym", "tf") if entry == "ym" else (entry,)
    for e in entries:
        target[e] = f"{float(value)!r} {units[e]}"


@attrs.frozen
class _MatrixJoint:
    """A joint given by SI matrices, for fast model evaluations inside fits."""

    name: str
    between: tuple[str, str]
    k: np.ndarray
    c: np.ndarray
    rigid: bool = False

    @classmethod
    def from_values(cls, template, values: Mapping[str, float]) -> "_MatrixJoint":
        k = np.array([[values["k_yf"], values["k_ym"]], [values["k_ym"], values["k_tm"]]], dtype=float)
        c = np.array([[values["c_yf"], values["c_ym"]], [values["c_ym"], values["c_tm"]]], dtype=float)
        return cls(template.name, tuple(template.between), k, c)

    def dynamic_stiffness(self, frequency_hz: np.ndarray) -> np.ndarray:
        omega = 2.0 * np.pi * np.asarray(frequency_hz, dtype=float)
        return self.k[:, :, None] + 1j * omega * self.c[:, :, None]


def _joint_values(joint: Joint) -> dict[str, float]:
    return {
        name: (joint.k if name[0] == "k" else joint.c).get(name.split("_", 1)[1])
        for name in PARAMETERS
    }


def auto_band(prepared, joint: Joint, parameter: str = "k_yf", factor: float = 1.2) -> tuple[float, float]:
    """The band of the mode the joint dominates, from the model's sensitivity to it.

    The model FRF is computed with the joint's ``parameter`` as given and
    multiplied by ``factor``; among the resonances at least 2 % as high as
    the highest (weaker ones sit near a tap test's noise floor), the one
    whose frequency moves most (relatively) is the joint's mode, and the band
    runs between the minima of ``|H|`` on either side of it, within 0.7 to
    1.3 times its frequency.

    Parameters
    ----------
    prepared : PreparedFRF
        The model's FRF at the measured point (:meth:`Assembly.prepare`).
    joint : Joint
        The joint to identify.
    parameter : str
        The joint parameter to vary (``"k_yf"``).
    factor : float
        The factor it is multiplied by (dimensionless).

    Returns
    -------
    tuple of float
        The band ``(lo, hi)`` in Hz.
    """
    base = prepared.evaluate()
    values = _joint_values(joint)
    k, c = joint.k.as_dict(), joint.c.as_dict()
    _set_parameter(k, c, parameter, values[parameter] * factor)
    with warnings.catch_warnings():  # the start joint has warned already if it is not passive
        warnings.simplefilter("ignore", NonPassiveJointWarning)
        stiffer = prepared.evaluate(joints={joint.name: attrs.evolve(joint, k=k, c=c)})
    f = base.frequency.hz
    h0 = np.abs(base.data[:, 0, 0])
    h1 = np.abs(stiffer.data[:, 0, 0])
    peaks = base.peaks(base.outputs[0], base.inputs[0])
    if peaks.size == 0:
        raise InvalidValueError("band: the model FRF has no resonance on the grid; give the band explicitly")
    scores = []
    top = max(h0[np.searchsorted(f, p)] for p in peaks)
    for p in peaks:
        window = (f > 0.8 * p) & (f < 1.25 * p)
        f1 = f[window][np.argmax(h1[window])]
        # relative shift; a mode weaker than 2 % of the strongest sits near the
        # noise floor of a tap test and is not considered
        strong = h0[np.searchsorted(f, p)] >= 0.02 * top
        scores.append(abs(f1 - p) / p if strong else -1.0)
    peak = peaks[int(np.argmax(scores))]
    i = int(np.searchsorted(f, peak))
    lo = i
    while lo > 0 and h0[lo - 1] <= h0[lo] and f[lo - 1] > 0.7 * peak:
        lo -= 1
    hi = i
    while hi < f.size - 1 and h0[hi + 1] <= h0[hi] and f[hi + 1] < 1.3 * peak:
        hi += 1
    return float(f[lo]), float(f[hi])


class JointIdentifier:
    """Constant joint stiffness and damping fitted to measured FRFs over a band.

    Parameters
    ----------
    joint : str
        Name of the joint in the assembly.
    parameters : sequence of str
        Which of :data:`PARAMETERS` to fit; the others keep the assembly's
        values.  Default: ``k_yf``, ``k_tm``, ``c_yf``, ``c_tm`` (the diagonal
        joint of thesis eq. 2.4); add ``k_ym`` (= ``k_tf``) and ``c_ym`` for the
        fully populated joint of eq. 2.5.
    band : "auto" or (lo, hi)
        Frequency band in Hz; ``"auto"``: the mode the joint dominates
        (:func:`auto_band`).
    bootstrap : int
        Number of bootstrap refits over the residuals (0: standard
        deviations from the Jacobian only).
    random_state : int
        Seed of the bootstrap.
    initial : mapping, optional
        Starting values (SI), overriding the assembly's joint (needed where it
        gives 0 or a rigid joint).

    Attributes
    ----------
    joint_ : Joint
        The fitted joint.
    values_, std_ : dict of str to float
        Fitted parameters and their standard deviations (SI units).
    band_ : (float, float)
    cost_ : float
        Final sum of squared relative residuals.
    residual_rms_ : float
        RMS of the relative complex residual over the band.
    warnings_ : list of str
        Passivity and reciprocity findings on the fitted joint.
    n_lines_ : int
        Number of frequency lines (over all FRFs) in the fit.

    Notes
    -----
    Residuals are ``(H_model - H_measured) / |H_measured|`` (real and
    imaginary parts) at every line of the band for every measured FRF of a
    configuration in which the joint exists, so that multiplicative noise is
    weighted evenly.  Positive parameters are fitted as logarithms; the
    standard deviations come from ``s^2 (J^T J)^-1`` with ``s^2`` the residual
    variance, mapped back by the delta method.
    """

    def __init__(self, joint: str, parameters: Sequence[str] = ("k_yf", "k_tm", "c_yf", "c_tm"),
                 band="auto", bootstrap: int = 0, random_state: int = 0, initial: Mapping | None = None):
        self.joint = joint
        self.parameters = tuple(parameters)
        self.band = band
        self.bootstrap = bootstrap
        self.random_state = random_state
        self.initial = dict(initial or {})

    # -- helpers -----------------------------------------------------------------

    def _check(self) -> None:
        unknown = [p for p in self.parameters if p not in PARAMETERS]
        if unknown or not self.parameters:
            raise InvalidValueError(
                f"parameters: got {list(self.parameters)}; expected some of {', '.join(PARAMETERS)}"
            )
        if not (isinstance(self.bootstrap, int) and self.bootstrap >= 0):
            raise InvalidValueError(f"bootstrap: got {self.bootstrap!r}; expected an integer >= 0")

    def _joint(self, template: Joint, values: Mapping[str, float]) -> Joint:
        k, c = template.k.as_dict() if not template.rigid else {}, template.c.as_dict() if not template.rigid else {}
        for name, value in values.items():
            _set_parameter(k, c, name, value)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", (NonPassiveJointWarning,))
            return Joint(template.name, template.between, k=k, c=c)

    def fit(self, assembly: Assembly, measurements: Sequence) -> "JointIdentifier":
        """Fit the joint to the measurements; returns ``self``.

        Parameters
        ----------
        assembly : Assembly
            The model, with the joint to identify (its values are the start).
        measurements : sequence of FRF or measurement objects
            Each an FRF of measured receptances (translational ``:y`` labels,
            as tapped) or an object with ``.frf``, ``.sensors`` (names of the
            assembly's sensors that were on) and ``.removed`` (components taken
            off); those in which the joint is removed are skipped.

        Returns
        -------
        JointIdentifier
            ``self``, with ``values_`` and ``std_`` (SI units: N/m, N, N/rad, N m/rad and
            the same times s), ``joint_`` and the fit's residual.
        """
        self._check()
        template = assembly.joint(self.joint)
        nominal = _joint_values(template) if not template.rigid else {p: 0.0 for p in PARAMETERS}
        nominal.update(self.initial)
        missing = [p for p in self.parameters if p in ("k_yf", "k_tm", "c_yf", "c_tm") and nominal[p] <= 0]
        if missing:
            raise InvalidValueError(
                f"initial: the assembly gives no starting value for {', '.join(missing)} of joint "
                f"{self.joint!r}; pass initial={{...}} in SI units"
            )
        cases = []
        points = [parse_point(p).component for p in template.between]
        for m in measurements:
            removed = set(getattr(m, "removed", ()) or ())
            if any(any(pt in assembly.component(r).component_names for pt in points) for r in removed):
                continue
            frf = _frf_of(m)
            prepared = model_of_measurement(assembly, m).prepare(list(frf.outputs), list(frf.inputs), frf.frequency)
            cases.append((prepared, frf))
        if not cases:
            have = sorted({f"{getattr(m, 'response', '?')} with {list(getattr(m, 'removed', ()))} removed"
                           for m in measurements})
            raise InvalidValueError(
                f"measurements: the fit of joint {self.joint!r} needs at least one FRF measured with the joint "
                f"in place (neither {' nor '.join(points)} removed); the set has only: {'; '.join(have) or 'nothing'}"
            )
        auto = self.band == "auto"
        if auto:
            band = auto_band(cases[0][0], self._joint(template, nominal))
        else:
            try:
                lo, hi = (float(x) for x in self.band)
            except (TypeError, ValueError):
                raise InvalidValueError(f"band: got {self.band!r}; expected 'auto' or (lo, hi) in Hz") from None
            if not lo < hi:
                raise InvalidValueError(f"band: got {self.band!r}; expected lo < hi")
            band = (lo, hi)
        for attempt in range(2 if auto else 1):
            fit, data, values, positive, start, linear_scale, bounds, x0, residual = self._fit_band(
                template, nominal, cases, band
            )
            if not auto:
                break
            # The band came from the starting model; once fitted, look again.
            new_band = auto_band(cases[0][0], self._joint(template, values(fit.x)))
            if abs(new_band[0] - band[0]) + abs(new_band[1] - band[1]) < 0.02 * (band[1] - band[0]):
                break
            band = new_band
        m, n = fit.fun.size, fit.x.size
        s2 = float(np.sum(fit.fun**2)) / max(m - n, 1)
        jtj = fit.jac.T @ fit.jac
        cov = s2 * np.linalg.pinv(jtj)
        best = values(fit.x)
        std = {}
        for name, pos, var in zip(self.parameters, positive, np.diag(cov)):
            sd = float(np.sqrt(max(var, 0.0)))
            std[name] = best[name] * sd if pos else sd * linear_scale[name]
        if self.bootstrap:
            std = self._bootstrap(template, data, fit, residual, values, bounds, x0, std)
        self.joint_ = self._joint(template, best)
        self.values_ = {p: float(best[p]) for p in self.parameters}
        self.std_ = std
        self.band_ = band
        self.cost_ = float(np.sum(fit.fun**2))
        self.residual_rms_ = float(np.sqrt(np.mean(fit.fun**2) * 2))
        self.warnings_ = _passivity(self.joint_)
        self.n_lines_ = int(sum(d[1].shape[0] for d in data))
        return self

    def _fit_band(self, template, nominal, cases, band):
        data = []
        for prepared, frf in cases:
            mask = frf.frequency.band_mask(*band)
            if mask.sum() < len(self.parameters) + 2:
                raise InvalidValueError(
                    f"band: {band[0]:.0f}-{band[1]:.0f} Hz holds {int(mask.sum())} lines of the data "
                    f"({frf.frequency.start:.0f}-{frf.frequency.stop:.0f} Hz); too few to fit"
                )
            sub = prepared.frequency.crop(*band)
            small = type(prepared)(prepared.assembly, _points(frf.outputs), _points(frf.inputs), sub)
            data.append((small, frf.data[mask]))

        positive = [p not in ("k_ym", "c_ym") for p in self.parameters]
        start = np.array([nominal[p] for p in self.parameters], dtype=float)
        linear_scale = {
            "k_ym": max(abs(nominal["k_yf"] * nominal["k_tm"]) ** 0.5, 1.0),
            "c_ym": max(abs(nominal["c_yf"] * nominal["c_tm"]) ** 0.5, 1e-6),
        }

        def values(x):
            out = dict(nominal)
            for name, xi, pos, s0 in zip(self.parameters, x, positive, start):
                out[name] = s0 * np.exp(xi) if pos else s0 + xi * linear_scale[name]
            return out

        def residual(x, data=data):
            joint = _MatrixJoint.from_values(template, values(x))
            parts = []
            for prepared, measured in data:
                model = prepared.evaluate(joints={self.joint: joint}).data
                r = (model - measured) / np.abs(measured)
                parts.append(r.real.ravel())
                parts.append(r.imag.ravel())
            return np.concatenate(parts)

        # A scan over the main stiffness first (one decade either way), against
        # local minima; then bounded least squares: positive parameters within a
        # factor 100 of their start, linear ones within +-10 scales.
        x0 = np.zeros(len(self.parameters))
        if "k_yf" in self.parameters:
            i = self.parameters.index("k_yf")
            trial = []
            for factor in np.geomspace(0.1, 10.0, 41):
                x = x0.copy()
                x[i] = np.log(factor)
                trial.append((float(np.sum(residual(x) ** 2)), factor))
            x0[i] = np.log(min(trial)[1])
        limit = np.where(positive, np.log(100.0), 10.0)
        bounds = (x0 - limit, x0 + limit)
        fit = least_squares(residual, x0, bounds=bounds, method="trf", x_scale=1.0, max_nfev=200 * len(x0))
        return fit, data, values, positive, start, linear_scale, bounds, x0, residual

    def _bootstrap(self, template, data, fit, residual, values, bounds, x0, std):
        """Standard deviations from refits on the model plus resampled relative residuals."""
        rng = np.random.default_rng(self.random_state)
        best = values(fit.x)
        joint = _MatrixJoint.from_values(template, best)
        model_data = [prepared.evaluate(joints={self.joint: joint}).data for prepared, _ in data]
        rel = [(meas - mod) / np.abs(meas) for (_, meas), mod in zip(data, model_data)]
        samples = []
        for _ in range(self.bootstrap):
            boot = []
            for (prepared, _), mod, r in zip(data, model_data, rel):
                flat = r.ravel()
                pick = flat[rng.integers(0, flat.size, flat.size)].reshape(r.shape)
                boot.append((prepared, mod * (1 + pick)))
            refit = least_squares(lambda x: residual(x, boot), fit.x, bounds=bounds, method="trf",
                                  x_scale=1.0, max_nfev=50 * len(x0))
            samples.append([values(refit.x)[p] for p in self.parameters])
        spread = np.std(np.array(samples), axis=0, ddof=1)
        return {p: float(max(std[p], s)) for p, s in zip(self.parameters, spread)}

    def predict(self, assembly: Assembly, outputs, inputs=None, frequency=None) -> FRF:
        """The assembly's FRF with the fitted joint.

        Parameters
        ----------
        assembly : Assembly
            The model.
        outputs : str or sequence of str
            Response points (``"tool.tip:y"``).
        inputs : str or sequence of str, optional
            Excitation points; default ``outputs``.
        frequency : Frequency or array_like, optional
            Frequency lines (plain numbers in Hz); default the assembly's grid.

        Returns
        -------
        FRF
            The receptances with the fitted joint (m/N, ...).
        """
        return assembly.with_joint(self.joint_).frf(outputs, inputs, frequency)


def _points(labels) -> list[str]:
    return list(labels)


def _passivity(joint: Joint) -> list[str]:
    notes = []
    for name, m in (("k", joint.k.values), ("c", joint.c.values)):
        if m[0, 1] != m[1, 0]:
            notes.append(f"{name} is not symmetric ({name}_ym != {name}_tf)")
        det = m[0, 0] * m[1, 1] - m[0, 1] * m[1, 0]
        if m[0, 0] < 0 or m[1, 1] < 0 or det < 0:
            notes.append(f"{name} is not positive semi-definite: the joint is not passive")
    return notes
