"""Identification from an assembly and a measurement set: what `substructure identify` runs.

:func:`identify_joint` fits the joint by the robust band fit on every
measured FRF taken with the joint in place (sensor masses and removed
components applied to the model as the set says), and, when the set holds
translational FRFs at two or more points along a component of each side,
also runs the closed form of thesis eq. 2.3 with rotations estimated by
finite differences, for the plot of the frequency-dependent result.
"""

from __future__ import annotations

from typing import Sequence

import attrs
import numpy as np

from .._json import finite as _finite
from .._text import plain_text
from ..assembly import Assembly
from ..coupling import remove_mass
from ..errors import InvalidValueError, SubstructureError
from ..frf import FRF
from ..measurements import MeasurementSet
from ..measurements.measurement_set import measurements_given
from ..points import parse_point
from ..rdof import estimate_rotational, positions_from
from ..updating import Evaluator, Structure
from ..updating.structure import assembly_checked
from .band_fit import _UNITS, JointIdentifier, model_of_measurement
from .closed_form import ClosedFormResult, closed_form, joint_sides

__all__ = ["IdentificationReport", "identify_joint"]

_ENTRIES = ("yf", "ym", "tf", "tm")


@attrs.frozen
class IdentificationReport:
    """The result of :func:`identify_joint`.

    ``k``, ``c``, ``k_std`` and ``c_std`` map ``yf``, ``ym``, ``tf``, ``tm`` to SI
    values (standard deviation 0 for entries that were not fitted);
    ``measured``, ``initial`` and ``predicted`` are the first measured FRF and
    the model's FRF there before and after the fit.

    Parameters
    ----------
    joint : str
        The joint's name.
    band : tuple of float
        The band fitted, ``(lo, hi)`` in Hz.
    k : dict
        Stiffness entries ``yf, ym, tf, tm`` in N/m, N, N/rad and N m/rad.
    c : dict
        Damping entries in N s/m, N s, N s/rad and N m s/rad.
    k_std : dict
        Standard deviations of ``k``, same units (0 where not fitted).
    c_std : dict
        Standard deviations of ``c``, same units.
    fitted : tuple of str
        The parameters fitted (``k_yf``, ...).
    warnings : tuple of str
        Problems found (a non-passive result, a poor fit).
    measured : FRF
        The first measured FRF (m/N for H).
    initial : FRF
        The model's FRF there before the fit.
    predicted : FRF
        The model's FRF there after the fit.
    residual_rms : float
        RMS of the complex log ratio of model to measurement over the band (dimensionless).
    closed_form : ClosedFormResult or None
        The closed form of thesis eq. 2.3, when the data allowed it.
    model : str
        The joint model chosen: ``diagonal``, ``full`` (with the cross terms) or ``given``.
    consistent : bool
        Whether the residual is consistent with the noise of the data.
    chi2_reduced : float
        ``chi^2`` per degree of freedom (about 1 when the model fits; dimensionless).
    correlation : tuple of tuple of float
        Correlations of the fitted parameters, in the order of ``fitted``.
    at_bound : dict
        The fitted parameters (``c_tm``, ...) that ended on a bound of their
        search, each with ``"lower"`` or ``"upper"``: their values are not
        measurements and their standard deviations are NaN (a note in
        ``warnings`` says what to do).  Empty when every value lies inside.
    search : dict
        The search range ``(lower, upper)`` of each fitted parameter (SI).
    calibration : float or None
        The relative uncertainty of the data's scale the joint was fitted
        with (None: the scale taken as exact).
    level : float or None
        With ``calibration``: the measured FRFs' common scale over the fitted
        model's, the level the joint was fitted at (e.g. 1.03: the data read
        3 % high).  None without.
    """

    joint: str
    band: tuple[float, float]
    k: dict
    c: dict
    k_std: dict
    c_std: dict
    fitted: tuple[str, ...]
    warnings: tuple[str, ...]
    measured: FRF
    initial: FRF
    predicted: FRF
    residual_rms: float
    closed_form: ClosedFormResult | None = None
    model: str = "given"
    consistent: bool = True
    chi2_reduced: float = float("nan")
    correlation: tuple = ()
    at_bound: dict = attrs.field(factory=dict)
    search: dict = attrs.field(factory=dict)
    calibration: float | None = None
    level: float | None = None

    def to_json(self) -> dict:
        """The JSON object of docs/file-formats.md (SI units, Hz; strict JSON), plus a few added keys.

        Returns
        -------
        dict
            ``joint``, ``band_hz``, ``k``, ``c``, ``k_std``, ``c_std``, ``warnings``, ``fitted``,
            ``residual_rms``, ``model``, ``consistent``, ``chi2_reduced``, ``parameters`` (each with
            ``at_bound``: null, ``"lower"`` or ``"upper"``, and ``search``: ``[lower, upper]``), ``correlation``,
            ``at_bound`` (the names of the parameters on a bound of their search), ``calibration`` and
            ``calibration_factor`` (the data's level with a calibration uncertainty; null without).
        """
        return {
            "joint": self.joint,
            "band_hz": [self.band[0], self.band[1]],
            "k": {e: _finite(v) for e, v in self.k.items()},
            "c": {e: _finite(v) for e, v in self.c.items()},
            "k_std": {e: _finite(v) for e, v in self.k_std.items()},
            "c_std": {e: _finite(v) for e, v in self.c_std.items()},
            "warnings": list(self.warnings),
            "fitted": list(self.fitted),
            "residual_rms": _finite(self.residual_rms),
            "model": self.model,
            "consistent": bool(self.consistent),
            "chi2_reduced": _finite(self.chi2_reduced),
            "parameters": {name: {"value": _finite(self._value(name)), "unit": _UNITS[name],
                                  "std": _finite(self._std(name)), "at_bound": self.at_bound.get(name),
                                  "search": [_finite(x) for x in self.search[name]] if name in self.search else None}
                           for name in self.fitted},
            "correlation": [[_finite(x) for x in row] for row in self.correlation],
            "at_bound": [name for name in self.fitted if name in self.at_bound],
            "calibration": self.calibration,
            "calibration_factor": None if self.level is None else _finite(self.level),
        }

    def _value(self, name: str) -> float:
        kind, entry = name.split("_", 1)
        return (self.k if kind == "k" else self.c)[entry]

    def _std(self, name: str) -> float:
        kind, entry = name.split("_", 1)
        return (self.k_std if kind == "k" else self.c_std)[entry]

    def plot(self):
        """Closed-form parameters with band and fit (when available), and the FRF before/after.

        Returns
        -------
        Figure
            The figure (never shown by the library).
        """
        import matplotlib.pyplot as plt

        names = ("k_yf", "c_yf") if self.closed_form is not None else ()
        fig, axes = plt.subplots(len(names) + 1, 1, figsize=(7.5, 3.0 + 2.2 * len(names)), layout="constrained")
        axes = np.atleast_1d(axes)
        if names:
            fitted = {name: self._value(name) for name in names}
            fitted.update({name + "_std": self._std(name) for name in names})
            self.closed_form.plot(names=names, band=self.band, fitted=fitted, ax=list(axes[:-1]))
        ax = axes[-1]
        f = self.measured.frequency.hz
        ax.semilogy(f, np.abs(self.measured.data[:, 0, 0]), color="0.3", lw=0.8, label="measured")
        ax.semilogy(f, np.abs(self.initial.data[:, 0, 0]), "--", color="tab:gray", lw=1, label="model before")
        ax.semilogy(f, np.abs(self.predicted.data[:, 0, 0]), color="tab:blue", lw=1.2, label="model, fitted joint")
        ax.axvspan(*self.band, color="tab:green", alpha=0.12)
        ax.set_xlabel("frequency [Hz]")
        ax.set_ylabel(plain_text(f"|{self.measured.outputs[0]} / {self.measured.inputs[0]}| [m/N]"))
        ax.legend(fontsize="small")
        ax.grid(True, alpha=0.3)
        fig.suptitle(plain_text(f"joint {self.joint!r}: band fit {self.band[0]:.0f}-{self.band[1]:.0f} Hz"))
        return fig


def _two_by_two(measurements, assembly: Assembly, points: Sequence[str], at: str, removed=()) -> FRF:
    """The 2x2 receptance at ``at`` from translational FRFs at ``points`` by finite differences.

    Uses the configuration (sensors on) with the most measurements among those
    with the given components removed; the sensors' masses are taken out first
    (thesis eq. 5.4), so the result is as if laser-measured.
    """
    configs = [(s, r) for s, r in measurements.configurations() if tuple(sorted(r)) == tuple(sorted(removed))]
    if not configs:
        raise SubstructureError(f"no measurements with {list(removed) or 'nothing'} removed")
    sensors, rem = max(configs, key=lambda sr: len(measurements.select(sensors=sr[0], removed=sr[1])))
    matrix = measurements.matrix(points, sensors=sensors, removed=rem)
    for name in sensors:
        sensor = assembly.sensor(name)
        matrix = remove_mass(matrix, f"{sensor.at}:y", sensor.mass)
    return estimate_rotational(matrix, points, positions_from(assembly, points), at)


def _points_on(measurements, assembly: Assembly, components: set, removed=()) -> list[str]:
    points = []
    for m in measurements:
        if tuple(sorted(m.removed)) != tuple(sorted(removed)):
            continue
        ref = parse_point(m.response)
        if ref.component in components and str(ref.point) not in points:
            points.append(str(ref.point))
    by_component: dict[str, list[str]] = {}
    for p in points:
        by_component.setdefault(parse_point(p).component, []).append(p)
    best = max(by_component.values(), key=len, default=[])
    return best if len(best) >= 2 else []


def identify_joint(assembly: Assembly, measurements, joint: str, band="auto",
                   parameters: str | Sequence[str] = "auto", bootstrap: int = 0,
                   random_state: int = 0, calibration: float | None = None) -> IdentificationReport:
    """Identify a joint from a measurement set (see the module docstring).

    Parameters
    ----------
    assembly : Assembly
        The model with the joint (its values start the fit).
    measurements : MeasurementSet or sequence of measurements
        The data.
    joint : str
        The joint's name.
    band : "auto" or (lo, hi)
        The band [Hz].
    parameters : "auto" or sequence of str
        ``"auto"``: the diagonal joint, with cross terms when significant.
    bootstrap : int
        Bootstrap refits for the standard deviations (0: from the Jacobian).
    random_state : int
        Seed of the bootstrap.
    calibration : float, optional
        The relative uncertainty of the data's scale (the hammer's and the
        sensors' sensitivities), e.g. 0.05: the joint is fitted at the common
        level that fits best within it (:class:`JointIdentifier`); default
        None, the scale taken as exact.

    Returns
    -------
    IdentificationReport
        The fitted values with standard deviations (SI), the closed form, the FRFs before and
        after.
    """
    assembly_checked(assembly)
    measurements = measurements_given(measurements)
    if hasattr(measurements, "validate"):
        measurements.validate(assembly)
    for i, m in enumerate(measurements):
        if not (hasattr(m, "frf") and hasattr(m, "removed")):
            raise InvalidValueError(
                f"measurements[{i}]: got {type(m).__name__}; expected a measurement (what was measured where, with "
                "which sensors on: Measurement.from_frf(frf, response, excitation), or a MeasurementSet); "
                "JointIdentifier fits plain FRFs")
    if not isinstance(measurements, MeasurementSet):  # a plain sequence: its configurations as a set's
        measurements = MeasurementSet("measurements", tuple(measurements))
    ident = JointIdentifier(joint, parameters=parameters, band=band, bootstrap=bootstrap,
                            random_state=random_state, calibration=calibration).fit(assembly, list(measurements))
    notes = list(ident.warnings_)
    first = next(m for m in measurements if not set(m.removed) & _sides_components(assembly, joint))
    model = model_of_measurement(assembly, first)
    tau = getattr(first, "window_tau", None)
    initial, predicted = (_seen(m, first.frf, tau) for m in (model, model.with_joint(ident.joint_)))
    if tau is not None:
        notes.append(f"measured through an exponential window (tau = {tau:.4g} s): the joint was fitted with the "
                     "model at omega - i/tau, the window's damping 1/(tau omega) in the model as in the data (its "
                     "damping is the joint's); the closed form is computed on the real lines and carries the "
                     "window's damping")
    result = None
    try:
        result = _closed_form(assembly, measurements, joint)
    except (SubstructureError, ValueError) as exc:
        notes.append(f"closed form skipped: {exc}")
    if result is not None:
        bad = result.ill_conditioned()
        if bad.any():
            notes.append(f"closed form: {int(bad.sum())} of {bad.size} lines are ill-conditioned")
    k = {e: ident.joint_.k.get(e) for e in _ENTRIES}
    c = {e: ident.joint_.c.get(e) for e in _ENTRIES}
    k_std = {e: 0.0 for e in _ENTRIES}
    c_std = {e: 0.0 for e in _ENTRIES}
    for name, sd in ident.std_.items():
        kind, entry = name.split("_", 1)
        target = k_std if kind == "k" else c_std
        for e in (("ym", "tf") if entry == "ym" else (entry,)):
            target[e] = float(sd)
    return IdentificationReport(
        joint=joint, band=ident.band_, k=k, c=c, k_std=k_std, c_std=c_std, fitted=tuple(ident.fitted_),
        warnings=tuple(notes), measured=first.frf, initial=initial, predicted=predicted,
        residual_rms=ident.residual_rms_, closed_form=result, model=ident.model_, consistent=ident.consistent_,
        chi2_reduced=ident.chi2_reduced_, correlation=tuple(tuple(float(x) for x in row) for row in ident.correlation_),
        at_bound=dict(ident.at_bound_), search=dict(ident.search_), calibration=ident.calibration,
        level=None if ident.calibration is None else ident.level_,
    )


def _seen(model: Assembly, frf: FRF, tau: float | None) -> FRF:
    """The model at a measured entry's lines, through the measurement's exponential window when it has one."""
    structure = None if tau is None else Structure.from_assembly(model)
    if structure is None or structure.not_at_complex_frequency():
        return model.frf(list(frf.outputs), list(frf.inputs), frf.frequency)
    y = Evaluator(list(frf.outputs), list(frf.inputs), frf.frequency.hz, decay=1.0 / tau)(structure)
    return FRF(frf.frequency, y, frf.outputs, frf.inputs)


def _sides_components(assembly: Assembly, joint: str) -> set:
    j = assembly.joint(joint)
    return {parse_point(p).component for p in j.between}


def _closed_form(assembly: Assembly, measurements, joint: str) -> ClosedFormResult | None:
    side_a, side_b, at_a, at_b = joint_sides(assembly, joint)
    names_b = set(side_b.component_names)
    points_b = _points_on(measurements, assembly, names_b)
    if not points_b:
        raise SubstructureError("no two measured points along one component beyond the joint")
    at = points_b[0] if parse_point(points_b[0]).where == "tip" else max(
        points_b, key=lambda p: positions_from(assembly, [p])[0].m_as("m"))
    coupled = _two_by_two(measurements, assembly, points_b, at)
    removed_b = tuple(sorted(c.name for c in assembly.components if set(c.component_names) <= names_b))
    points_a = _points_on(measurements, assembly, set(side_a.component_names), removed=removed_b)
    f = coupled.frequency
    side_a_frf = (_two_by_two(measurements, assembly, points_a, at_a, removed=removed_b) if points_a
                  else side_a.receptance(at_a, frequency=f))
    side_b_frf = side_b.frf([at, at_b] if at != at_b else [at], frequency=f)
    return closed_form(coupled, side_a_frf, side_b_frf, at=at, at_a=at_a, at_b=at_b, warn=False)
