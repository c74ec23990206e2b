"""Band identification: constant joint stiffness and damping fitted to measured FRFs, by likelihood.

The thesis's future work asks for an identification that no noisy matrix
inversion drives.  :class:`JointIdentifier` fits constant ``k`` and ``c`` to
the measured translational FRFs directly, over the band where the joint is
observable (the mode it dominates, found from the model's sensitivity to
the joint, :func:`auto_band`), with the likelihood of the model-updating
core (:mod:`substructure.updating`): complex log ratios of model to
measurement weighted by the noise of each line, estimated from the data.

The joint model is chosen by the same significance test as the diagnosis:
the diagonal joint of thesis eq. 2.4 (``k_yf, k_tm, c_yf, c_tm``) and, when
the cross terms ``k_ym = k_tf``, ``c_ym = c_tf`` of eq. 2.5 lower ``chi^2``
significantly, the full one.  Standard deviations and correlations come
from the Jacobian, inflated by the misfit when the residual is not
consistent with the noise; then a warning says that the model misses
something (run ``substructure diagnose``) instead of reporting tight values.
"""

from __future__ import annotations

import warnings
from typing import Mapping, Sequence

import attrs
import numpy as np

from ..assembly import Assembly
from ..errors import InvalidValueError, NonPassiveJointWarning
from ..frf import FRF
from ..joints import DAMPING_UNITS, STIFFNESS_UNITS, Joint, JointProvenance
from ..measurements import model_of_measurement
from ..points import parse_point
from ..units import MAX_REPEATS, whole_number
from ..updating.fit import fit
from ..updating.likelihood import CALIBRATION_HINT, Likelihood, calibration_checked, measured_frfs
from ..updating.parameters import ParameterSet, ParamSpec
from ..updating.selection import consistency, significance
from .closed_form import PARAMETERS

__all__ = ["JointIdentifier", "auto_band", "model_of_measurement", "DIAGONAL", "CROSS"]

DIAGONAL = ("k_yf", "k_tm", "c_yf", "c_tm")
"""The diagonal joint of thesis eq. 2.4."""
CROSS = ("k_ym", "c_ym")
"""The cross terms of eq. 2.5 (``k_ym = k_tf``, ``c_ym = c_tf``)."""

LEVEL_REFIT = 0.99
"""Without a calibration uncertainty, the refit that suggests one (a level off by ``CALIBRATION_HINT`` of the
updating core, lowering ``chi^2`` significantly) takes the level within a factor ``1 + LEVEL_REFIT`` either way; a
level found beyond ``1 + CALIBRATION_HINT[1]`` (and one of the fit itself beyond it) is named a unit error."""

_UNITS = {name: (STIFFNESS_UNITS if name[0] == "k" else DAMPING_UNITS)[name[2:]] for name in PARAMETERS}


def _set_parameter(k: dict, c: dict, name: str, value: float) -> None:
    kind, entry = name.split("_", 1)
    target, units = (k, STIFFNESS_UNITS) if kind == "k" else (c, DAMPING_UNITS)
    entries = ("ym", "tf") if entry == "ym" else (entry,)
    for e in entries:
        target[e] = f"{float(value)!r} {units[e]}"


def _joint_values(joint: Joint) -> dict[str, float]:
    return {
        name: (joint.k if name[0] == "k" else joint.c).get(name.split("_", 1)[1])
        for name in PARAMETERS
    }


def _frf_of(measurement) -> FRF:
    frf = measurement if isinstance(measurement, FRF) else measurement.frf
    if not isinstance(frf, FRF):
        raise InvalidValueError(f"measurements: got {measurement!r}; expected FRFs or measurements with .frf")
    return frf.to_receptance()


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
    parameters : "auto" or sequence of str
        ``"auto"`` (default): the diagonal joint (``k_yf, k_tm, c_yf, c_tm``,
        thesis eq. 2.4), with the cross terms ``k_ym`` (= ``k_tf``) and
        ``c_ym`` of eq. 2.5 added when they lower ``chi^2`` significantly
        (:func:`substructure.updating.selection.significance`).  Or which of
        :data:`~substructure.identify.closed_form.PARAMETERS` to fit; the
        others keep the assembly's values.
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
    calibration : float, optional
        The relative uncertainty of the measured FRFs' common scale (the
        hammer's and the sensors' sensitivities), e.g. 0.05: the joint is
        fitted at the common level that fits best within it (profiled out
        of every comparison, as in
        :class:`~substructure.updating.likelihood.Likelihood`), so that a test
        read a few per cent high or low does not bend the joint's values.
        None (default): the scale is taken as exact, and a note says when the
        data differ from the fitted model by a common factor.

    Attributes
    ----------
    joint_ : Joint
        The fitted joint.
    values_, std_ : dict of str to float
        Fitted parameters and their standard deviations (SI units; inflated
        by the misfit when the residual is not consistent with the noise).
    correlation_ : ndarray
        Correlations of the fitted parameters (order of ``fitted_``).
    fitted_ : tuple of str
        The parameters fitted.
    model_ : str
        ``"diagonal"``, ``"full"`` (with cross terms) or ``"given"``.
    band_ : (float, float)
    cost_ : float
        ``chi^2`` at the optimum.
    chi2_reduced_ : float
        ``chi^2 / (n - p)``: about 1 when the residual is noise.
    consistent_ : bool
        The residual is consistent with the noise
        (:func:`substructure.updating.selection.consistency`).
    residual_rms_ : float
        RMS of the complex log ratio of model to measurement over the band.
    at_bound_ : dict of str to str
        The fitted parameters that ended on a bound of their search, each
        with ``"lower"`` or ``"upper"``: their values are not measurements (the
        data in the band do not determine them, or the true value lies beyond
        the search) and their standard deviations are NaN.  Empty when every
        fitted value lies inside its search.
    search_ : dict of str to (float, float)
        The search range of each fitted parameter (SI): a factor of 1000
        either side of its start for the diagonal terms, ``+-3 sqrt(k_yf k_tm)``
        (``+-3 sqrt(c_yf c_tm)``) for the cross terms.
    warnings_ : list of str
        Misfit, passivity and reciprocity findings, and the values on a bound.
    n_lines_ : int
        Number of frequency lines (over all FRFs) in the fit.
    level_ : float
        The measured FRFs' common scale over the fitted model's (the
        noise-weighted mean of ``ln |measured / model|``, exponentiated): with
        ``calibration``, the level the joint was fitted at; without, what it
        would be (about 1 when the scale is right).
    """

    def __init__(self, joint: str, parameters: str | Sequence[str] = "auto", band="auto", bootstrap: int = 0,
                 random_state: int = 0, initial: Mapping | None = None, calibration: float | None = None):
        self.joint = joint
        self.calibration = calibration
        try:
            self.parameters = parameters if isinstance(parameters, str) else tuple(parameters)
        except TypeError:  # not a sequence: refused by _check, by name
            self.parameters = parameters
        self.band = band
        self.bootstrap = bootstrap
        self.random_state = random_state
        if initial is not None and not isinstance(initial, Mapping):
            raise InvalidValueError(f"initial: got {initial!r}; expected a mapping of parameter names to start "
                                    "values (SI units), or None")
        self.initial = dict(initial or {})

    def _check(self) -> None:
        # checked whatever the parameters (with 'auto' they were not: -1 failed in numpy, 2.5 in range, True was 1)
        if not isinstance(self.joint, str):
            raise InvalidValueError(f"joint: got {self.joint!r}; expected a joint's name, e.g. 'holder-tool'")
        if not isinstance(self.parameters, (str, tuple)):
            raise InvalidValueError(f"parameters: got {self.parameters!r}; expected 'auto' or some of "
                                    f"{', '.join(PARAMETERS)}")
        whole_number(self.bootstrap, "bootstrap", 0, "an integer", MAX_REPEATS)
        whole_number(self.random_state, "random_state", 0, "a seed, an integer")
        calibration_checked(self.calibration)
        if isinstance(self.parameters, str):
            if self.parameters != "auto":
                raise InvalidValueError(f"parameters: got {self.parameters!r}; expected 'auto' or some of "
                                        f"{', '.join(PARAMETERS)}")
            return
        unknown = [p for p in self.parameters if p not in PARAMETERS]
        if unknown or not self.parameters:
            raise InvalidValueError(
                f"parameters: got {list(self.parameters)}; expected 'auto' or some of {', '.join(PARAMETERS)}"
            )
        twice = sorted({p for p in self.parameters if self.parameters.count(p) > 1})
        if twice:
            raise InvalidValueError(f"parameters: {', '.join(twice)} named twice in {list(self.parameters)}; "
                                    "name each parameter once")

    def _joint(self, template: Joint, values: Mapping[str, float]) -> Joint:
        k, c = (template.k.as_dict(), template.c.as_dict()) if not template.rigid else ({}, {})
        for name, value in values.items():
            _set_parameter(k, c, name, value)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", (NonPassiveJointWarning,))
            return Joint(template.name, template.between, k=k, c=c,
                         provenance=JointProvenance("identified", "fitted to the measured FRFs (band fit)"))

    def _specs(self, names, start: Mapping[str, float]) -> list[ParamSpec]:
        specs = []
        for name in names:
            v = float(start[name])
            if name in CROSS:
                diag = ("k_yf", "k_tm") if name == "k_ym" else ("c_yf", "c_tm")
                scale = max(np.sqrt(abs(start[diag[0]] * start[diag[1]])), 1e-12)
                specs.append(ParamSpec(name, _UNITS[name], -3 * scale, 3 * scale, v, False))
            else:
                specs.append(ParamSpec(name, _UNITS[name], v / 1e3, v * 1e3, v, True))
        return specs

    def _fit(self, lik, template, names, start):
        paths = {n: f"joints.{template.name}.{n[0]}.{n.split('_', 1)[1]}" for n in names}
        change = ParameterSet("joint", template.name, paths, self._specs(names, start))
        values = {n: start[n] for n in names}
        if "k_yf" in names:  # a scan of the main stiffness first, against local minima
            trials = [(lik.chi2([(change, {**values, "k_yf": start["k_yf"] * f})]), f)
                      for f in np.geomspace(0.1, 10.0, 41)]
            values["k_yf"] = start["k_yf"] * min(trials)[1]
        return fit(lik, [(change, values)])

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
        names = DIAGONAL if self.parameters == "auto" else self.parameters
        missing = [p for p in names if p not in CROSS and not nominal[p] > 0]
        if missing:
            given = ("is rigid" if template.rigid and not self.initial else
                     "has " + ", ".join(f"{p} = {nominal[p]:.4g} {_UNITS[p]}" for p in missing))
            raise InvalidValueError(
                f"joint {self.joint!r} {given} in the assembly; the fit of {', '.join(missing)} starts from the "
                f"joint's value and searches a factor of 1000 either side of it, so it needs a value > 0: give the "
                f"joint a positive {', '.join(missing)} in the assembly file, the start of the search "
                f"(initial={{...}} in SI units in Python)"
            )
        start_joint = self._joint(template, {p: nominal[p] for p in PARAMETERS if nominal[p] != 0 or p in CROSS})
        model = assembly.with_joint(start_joint)
        points = [parse_point(p).component for p in template.between]
        cases = [m for m in measurements
                 if not any(any(pt in assembly.component(r).component_names for pt in points)
                            for r in set(getattr(m, "removed", ()) or ()))]
        if not cases:
            have = sorted({f"{getattr(m, 'response', '?')} with {list(getattr(m, 'removed', ()))} removed"
                           for m in measurements})
            raise InvalidValueError(
                f"measurements: the fit of joint {self.joint!r} needs at least one FRF measured with the joint "
                f"in place (neither {' nor '.join(points)} removed); the set has only: {'; '.join(have) or 'nothing'}"
            )
        first = _frf_of(cases[0])
        prepared = model_of_measurement(model, cases[0]).prepare(list(first.outputs), list(first.inputs),
                                                                 first.frequency)
        auto = isinstance(self.band, str) and self.band == "auto"
        if auto:
            band = auto_band(prepared, start_joint)
        else:
            try:
                lo, hi = (float(x) for x in self.band)
            except (TypeError, ValueError, OverflowError):
                raise InvalidValueError(f"band: got {self.band!r}; expected 'auto' or (lo, hi) in Hz") from None
            if not lo < hi:
                raise InvalidValueError(f"band: got {self.band!r}; expected lo < hi")
            band = (lo, hi)
        self._enough(cases, band, len(names))
        Likelihood(model, measured_frfs(cases)[0])  # the data as a whole against the model: quantity and sign
        for attempt in range(2 if auto else 1):
            lik = self._likelihood(model, cases, band, len(names))
            result = self._fit(lik, start_joint, names, nominal)
            if not auto:
                break
            new_band = auto_band(prepared, self._joint(template, {**nominal, **result.changes[0][1]}))
            if abs(new_band[0] - band[0]) + abs(new_band[1] - band[1]) < 0.02 * (band[1] - band[0]):
                break
            band = new_band
        self.model_ = "given" if self.parameters != "auto" else "diagonal"
        notes = []
        if self.parameters == "auto":
            best = {**nominal, **result.changes[0][1]}
            full = self._fit(lik, start_joint, DIAGONAL + CROSS, best)
            test = significance(result.chi2, full.chi2, len(CROSS), lik.n, full.p)
            if test.significant:
                result, self.model_ = full, "full"
                notes.append(f"the cross terms k_ym = k_tf and c_ym = c_tf are significant (likelihood ratio "
                             f"{test.statistic:.3g} > {test.threshold:.3g}): the joint is fitted with them (eq. 2.5)")
        values = {**nominal, **result.changes[0][1]}
        self.fitted_ = tuple(result.changes[0][1])
        self.joint_ = self._joint(template, {p: values[p] for p in self.fitted_} if not template.rigid else values)
        self.values_ = {p: float(result.changes[0][1][p]) for p in self.fitted_}
        self.std_ = dict(result.std[0])
        self.correlation_ = result.correlation
        ratios = lik.log_ratios(result.changes)
        test = consistency(lik, ratios, result.p)
        self.consistent_ = test.consistent
        self.chi2_reduced_ = result.chi2_reduced
        if not test.consistent:
            notes.append(f"the model does not fit the data within their noise (chi^2/nu = {result.chi2_reduced:.3g}, "
                         f"the noise allows {test.threshold:.3g}): it misses something (a sensor, flutes, another "
                         "joint term...), so the values are uncertain and their standard deviations are inflated "
                         "by the misfit; run `substructure diagnose` to find what is missing")
        if self.bootstrap:
            self.std_ = self._bootstrap(lik, result)
        specs = {spec.name: spec for spec in result.changes[0][0].specs}
        self.search_ = {p: (float(specs[p].lower), float(specs[p].upper)) for p in self.fitted_}
        self.at_bound_ = {}
        for (_, p), hit in zip(result.names, result.at_bound):
            if hit:
                lo, hi = self.search_[p]
                middle = np.sqrt(lo * hi) if specs[p].log else 0.5 * (lo + hi)
                self.at_bound_[p] = "lower" if self.values_[p] <= middle else "upper"
                self.std_[p] = float("nan")
        notes += [_bound_note(p, self.values_[p], side, self.search_[p], specs[p].log)
                  for p, side in self.at_bound_.items()]
        notes += [m.noise.seen_note(m.label) + ": its damping 1/(tau omega) is otherwise taken for the joint's"
                  for m in lik.measured if m.noise.seen_tau is not None]
        self.band_ = band
        self.cost_ = float(result.chi2)
        self.residual_rms_ = float(np.sqrt(np.mean(np.concatenate([np.abs(r) ** 2 for r in ratios]))))
        self.warnings_ = notes + _passivity(self.joint_)
        self.n_lines_ = int(sum(m.frf.frequency.n for m in lik.measured))
        self.level_ = lik.level(result.changes)
        note = _level_note(lik, result, self.level_)
        if note:
            self.warnings_.append(note)
        return self

    def _likelihood(self, model, cases, band, n_par):
        self._enough(cases, band, n_par)
        measured, _ = measured_frfs(cases, band)
        return Likelihood(model, measured, calibration=self.calibration)

    @staticmethod
    def _enough(cases, band, n_par) -> None:
        for m in cases:
            frf = _frf_of(m)
            mask = frf.frequency.band_mask(*band)
            if mask.sum() < max(n_par + 2, 10):
                raise InvalidValueError(
                    f"band: {band[0]:.0f}-{band[1]:.0f} Hz holds {int(mask.sum())} lines of the data "
                    f"({frf.frequency.start:.0f}-{frf.frequency.stop:.0f} Hz); too few to fit"
                )

    def _bootstrap(self, lik, result):
        """Standard deviations from refits on the model plus resampled log-ratio residuals."""
        rng = np.random.default_rng(self.random_state)
        change, best = result.changes[0]
        model = lik.predict(result.changes)
        ratios = lik.log_ratios(result.changes)
        samples = []
        for _ in range(self.bootstrap):
            boot = []
            for m, y, r in zip(lik.measured, model, ratios):
                pick = r[rng.integers(0, r.size, r.size)]
                data = m.frf.data.copy()
                data[lik.lines, 0, 0] = y / np.exp(pick)
                boot.append(attrs.evolve(m, frf=FRF(m.frf.frequency, data, m.frf.outputs, m.frf.inputs)))
            refit = fit(Likelihood(lik.assembly, boot, lik.lines, lik.calibration), [(change, best)],
                        max_nfev=50 * len(best))
            samples.append([refit.changes[0][1][p] for p in best])
        spread = np.std(np.array(samples), axis=0, ddof=1)
        return {p: float(max(result.std[0][p], s)) for p, s in zip(best, spread)}

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


def _level_note(lik, result, level: float) -> str | None:
    """What the data's common level says of the values: at the calibration's bound, beyond any calibration (a unit
    error), or (without a calibration uncertainty) a level that a refit with one finds significant and that leaves
    a residual consistent with the noise (a level that does not account for the misfit is no hint: the model misses
    something else)."""
    if lik.calibration is not None:
        if abs(np.log(level)) < np.log1p(lik.calibration) * (1 - 1e-9):
            return None
        return (f"the measured FRFs read {level:.4g} times the fitted model's throughout, on the bound of the "
                f"calibration uncertainty given ({lik.calibration:.3g}): the data differ from the model by more than "
                "it, and the values absorb the rest; check the hammer's and the sensors' sensitivities and units, "
                "and what the model may miss")
    lo, hi = CALIBRATION_HINT
    unit = ("the measured FRFs read {:.4g} times the {} model's throughout, more than a joint or a sensor's "
            "calibration gives: a unit error (mm/N read as m/N, g as m/s^2, a sensitivity in another unit)? The "
            "values above are fitted to it; check the units of the data")
    if abs(np.log(level)) > np.log1p(hi):
        return unit.format(level, "fitted")
    wide = Likelihood(lik.assembly, lik.measured, lik.lines, LEVEL_REFIT)
    change, values = result.changes[0]
    refit = fit(wide, [(change, values)])
    level = wide.level(refit.changes)
    if not lo <= abs(level - 1.0) or not significance(result.chi2, refit.chi2, 1, lik.n, refit.p + 1).significant:
        return None
    if not consistency(wide, wide.log_ratios(refit.changes), refit.p + 1).consistent:
        return None  # the level does not account for the misfit: the model misses something else
    if abs(np.log(level)) > np.log1p(hi):
        return unit.format(level, "refitted")
    return (f"the measured FRFs read {level:.4g} times the model's throughout, a common factor the joint cannot "
            "give: the values above (and the joint model chosen) absorb it, fitted at the scale as given; a real "
            "test's scale (the hammer's and the sensors' sensitivities) is rarely better than a few per cent: if "
            "yours is uncertain by that much, give it (calibration=0.05, identify --calibration 0.05) and the joint "
            "is fitted at the level that fits")


def _bound_note(name: str, value: float, side: str, search: tuple[float, float], log: bool) -> str:
    """The note of a fitted value on a bound of its search: not a measurement, and what to do."""
    unit = _UNITS[name]
    width = ("a factor of 1000 either side of its start" if log
             else f"{search[0]:.4g} to {search[1]:.4g} {unit}, three times the geometric mean of the diagonal terms")
    return (f"{name} = {value:.4g} {unit} is on the {side} bound of its search ({width}), not a measurement: the "
            f"data in the band do not determine it, or its true value lies beyond the search; widen the band "
            f"(--band, band=), fit without {name} (--parameters, parameters=; it keeps the assembly's value) or "
            "start it from a better value (the joint's value in the assembly file, or initial= in Python)")


def _passivity(joint: Joint) -> list[str]:
    notes = []
    for name, m in (("k", joint.k.values), ("c", joint.c.values)):
        if m[0, 1] != m[1, 0]:
            notes.append(f"{name} is not symmetric ({name}_ym != {name}_tf)")
        det = m[0, 0] * m[1, 1] - m[0, 1] * m[1, 0]
        if m[0, 0] < 0 or m[1, 1] < 0 or det < 0:
            notes.append(f"{name} is not positive semi-definite: the joint is not passive")
    return notes
