"""What a diagnosis reports: the changes found, the candidates, the steps, and the :class:`Diagnosis`.

:class:`Found` is a fitted change with its values, standard deviations and
nominal values (the interface of an effect instance, so that
``assembly.with_effect(found)`` works); :class:`Candidate` and :class:`Step`
are the first step's candidates and the refinement's steps; :class:`Diagnosis`
holds the verdict and writes the JSON of the project's file-format page
(:func:`strict` keeps it strict JSON).  :func:`substructure.diagnose.diagnose`
makes them.

A :class:`Diagnosis` is a few records a reader can find their way in:
``verdict`` (:class:`Verdict`: explained or not, the report's lines, the
missing effect), ``measures`` (:class:`Measures`: the error measure, the noise
floor, the errors before and after, the consistency test, the comparisons),
``changes`` (:class:`Changes`: the changes kept, the refined model, the
candidates, the steps) and ``alternatives`` (:class:`Alternatives`: the
explanations as good, and the measurement that separates them), with the
search's record and the settings it ran with.  Every field of a record is
also read from the diagnosis under its own name (``d.explained``,
``d.noise_floor``, ``d.final_effects``, ...).
"""

from __future__ import annotations

import attrs

from .._json import finite as _finite, strict
from ..assembly import Assembly
from ..updating.selection import ErrorCheck
from .compare import Comparison
from .settings import DEFAULT_SETTINGS, DiagnoseSettings

__all__ = ["Found", "Candidate", "Step", "Verdict", "Measures", "Changes", "Alternatives", "Diagnosis", "strict"]


class Found:
    """A change with fitted values: what a candidate or a refinement step reports.

    It has the interface of an :class:`~substructure.diagnose.effects.Effect`
    instance (``name``, ``where``, ``values``, ``explanation``,
    ``parameters_json()``, ``apply(assembly)``), so that
    ``assembly.with_effect(found)`` works, plus ``std`` and ``nominal``.

    Parameters
    ----------
    change : Change
        The change.
    values : dict
        Fitted values (SI).
    std : dict, optional
        Standard deviations (SI).
    """

    def __init__(self, change, values: dict, std: dict | None = None):
        self.change = change
        self.values = {k: float(v) for k, v in values.items()}
        self.std = {k: float(v) for k, v in (std or {}).items()}

    @property
    def name(self) -> str:
        """The effect's name (``model-parameter``, ``added-mass``, ``sensor-mass``, ...)."""
        return self.change.effect

    @property
    def where(self) -> str:
        """Where it acts (a path, a point, a joint, a component)."""
        return self.change.place(self.values)

    @property
    def explanation(self) -> str:
        """Its signature in the FRF, in words."""
        return self.change.explanation

    @property
    def nominal(self) -> dict:
        """The model's values before a correction (parameters that have one)."""
        return {s.name: s.nominal for s in self.change.specs if s.nominal is not None}

    def parameters_json(self) -> dict:
        """``{name: {"value", "unit", "std"[, "nominal"]}}`` (SI, strict JSON).

        Returns
        -------
        dict
            One entry per parameter.
        """
        out = {}
        for s in self.change.specs:
            entry = {"value": _finite(self.values.get(s.name)), "unit": s.unit, "std": _finite(self.std.get(s.name))}
            if s.nominal is not None:
                entry["nominal"] = _finite(s.nominal)
            out[s.name] = entry
        return out

    def apply(self, assembly: Assembly) -> Assembly:
        """The assembly with this change (a normal assembly that saves as usual).

        Parameters
        ----------
        assembly : Assembly
            The model.

        Returns
        -------
        Assembly
            The changed model.
        """
        return self.change.apply(assembly, self.values)

    def __repr__(self) -> str:
        vals = ", ".join(f"{k}={v:.4g}" for k, v in self.values.items())
        return f"{self.name}(where={self.where!r}, {vals})"


def _effect_json(found: Found) -> dict:
    return {"effect": found.name, "where": found.where, "parameters": found.parameters_json()}


@attrs.frozen
class Candidate:
    """One candidate of the first round, fitted: its error and ``chi^2`` after the fit.

    Parameters
    ----------
    effect : Found
        The change with its values.
    error : float
        The error measure after the fit (dimensionless).
    chi2 : float
        ``chi^2`` after the fit.
    fitted : bool
        Fitted on all lines (else its values are the screening's).
    nfev : int
        Model evaluations of its fit.
    """

    effect: Found = attrs.field(eq=False)
    error: float
    chi2: float = 0.0
    fitted: bool = True
    nfev: int = 0

    @property
    def name(self) -> str:
        """The effect's name."""
        return self.effect.name

    @property
    def where(self) -> str:
        """Where it acts."""
        return self.effect.where

    def to_json(self) -> dict:
        """The candidate's JSON object.

        Returns
        -------
        dict
            ``effect``, ``where``, ``parameters``, ``error``, ``chi2``, ``fitted``, ``explanation``.
        """
        return {**_effect_json(self.effect), "error": _finite(self.error), "chi2": _finite(self.chi2),
                "fitted": self.fitted, "explanation": self.effect.explanation}


@attrs.frozen
class Step:
    """One refinement step: the change added (None at step 0), its values when added, the error after.

    Parameters
    ----------
    step : int
        Its number (0: the model as given).
    added : Found or None
        The change added, with its values at this step.
    error : float
        The error measure after the step.
    chi2_reduced : float
        ``chi^2 / nu`` after the step.
    statistic : float or None
        The significance test's likelihood ratio that admitted it.
    threshold : float or None
        The test's threshold.
    """

    step: int
    added: Found | None = attrs.field(eq=False)
    error: float
    chi2_reduced: float = float("nan")
    statistic: float | None = None
    threshold: float | None = None

    def to_json(self) -> dict:
        """The step's JSON object.

        Returns
        -------
        dict
            ``step``, ``added``, ``error``, ``chi2_reduced`` and, for a change, ``where``, ``parameters``,
            ``significance``.
        """
        out = {"step": self.step, "added": None if self.added is None else self.added.name, "error": self.error}
        if self.added is not None:
            out["where"] = self.added.where
            out["parameters"] = self.added.parameters_json()
            out["significance"] = {"statistic": _finite(self.statistic), "threshold": _finite(self.threshold)}
        out["chi2_reduced"] = _finite(self.chi2_reduced)
        return out


@attrs.frozen
class Verdict:
    """What a diagnosis concludes.

    Parameters
    ----------
    explained : bool
        The final residual is consistent with the noise (and within
        ``explained_error_factor`` noise floors), with one explanation of at
        most ``most_changes`` changes, none on the bound of its search.
    report : tuple of str
        The verdict's lines when the data are not explained (the first says so).
    missing_effect : str or None
        The first change of the refinement.
    missing_where : str or None
        Where it acts.
    assumed_windows : tuple of (str, float)
        The measurements the explanation reads as through an exponential
        window they do not declare, each with the time constant [s] its
        noise shows (``DiagnoseSettings.seen_window``); empty when none.
    """

    explained: bool
    report: tuple[str, ...] = ()
    missing_effect: str | None = None
    missing_where: str | None = None
    assumed_windows: tuple[tuple[str, float], ...] = ()


@attrs.frozen
class Measures:
    """How far model and measurement are apart, before and after, against the noise.

    Parameters
    ----------
    metric : str
        ``"rms_log_ratio"``.
    band : tuple of float
        The band used ``(lo, hi)`` [Hz].
    noise_floor : float
        The error a perfect model would show, from the data's own noise (dimensionless).
    baseline_error : float
        The error of the model as given (dimensionless).
    final_error : float
        The error of the final model (dimensionless).
    consistency : Consistency
        The test of the final model.
    correlation : dict
        ``parameters`` and ``matrix`` of the final fit's correlations.
    baseline : tuple of Comparison
        Every measurement against the model as given.
    final : tuple of Comparison
        Every measurement against the final model.
    error_check : ErrorCheck or None
        The plain check of the verdict: the final error in noise floors with
        each line as the noise model scores it, and what the noise allows
        (:func:`~substructure.updating.error_check`).
    level : float or None
        With ``settings.calibration``: the measured FRFs' common scale over
        the final model's, profiled out of every comparison
        (:meth:`~substructure.updating.Likelihood.level`); None without.
    """

    metric: str
    band: tuple[float, float]
    noise_floor: float
    baseline_error: float
    final_error: float = float("nan")
    consistency: object = attrs.field(default=None, eq=False)
    correlation: dict = attrs.field(factory=dict, eq=False)
    baseline: tuple[Comparison, ...] = attrs.field(default=(), eq=False)
    final: tuple[Comparison, ...] = attrs.field(default=(), eq=False)
    error_check: ErrorCheck | None = attrs.field(default=None, eq=False)
    level: float | None = None


@attrs.frozen
class Changes:
    """What the search found and tried.

    Parameters
    ----------
    final_effects : tuple of Found
        The changes kept, with their final values and standard deviations.
    refined_assembly : Assembly
        The model with the changes kept.
    candidates : tuple of Candidate
        The first step's candidates, best first.
    refinement : tuple of Step
        Step 0 (the model as given), then one per change kept.
    """

    final_effects: tuple = attrs.field(eq=False)
    refined_assembly: Assembly = attrs.field(eq=False)
    candidates: tuple[Candidate, ...] = ()
    refinement: tuple[Step, ...] = ()


@attrs.frozen
class Alternatives:
    """Explanations the data do not tell from the one found, and the measurement that would.

    Parameters
    ----------
    ambiguous : tuple of (Found, float)
        Alternatives of the first change inside the indifference region, with their errors.
    ambiguous_with : tuple of str
        Their names (and those of the rivals).
    suggestion : str or None
        The measurement that would tell the first change from its first alternative.
    separation : dict or None
        ``response``, ``excitation``, ``non_contact``, ``chi2``, ``text``.
    rivals : tuple of (Explanation, dict)
        Whole explanations as good as the one reported that are different
        structures, each with the measurement that separates it; when there
        are any, the verdict is not explained.
    equivalents : tuple of (int, Found, float)
        What the data allow as well instead of a kept change, beyond
        ``ambiguous``: the alternatives of its step inside the indifference
        region and the replacements by rivals on the same parts; each with
        the index of the change in ``final_effects`` it could stand for,
        the alternative, and the error of the explanation with it.  They
        change the same parts another way (a holder's density or a body on
        that holder), so they are not rivals: the preferred one is reported,
        and these beside it.
    """

    ambiguous: tuple = attrs.field(default=(), eq=False)
    ambiguous_with: tuple[str, ...] = ()
    suggestion: str | None = None
    separation: dict | None = attrs.field(default=None, eq=False)
    rivals: tuple = attrs.field(default=(), eq=False)
    equivalents: tuple = attrs.field(default=(), eq=False)


def _read(record: str, name: str):
    """A read-only property of the diagnosis that reads ``name`` of one of its records."""
    kind = {"verdict": Verdict, "measures": Measures, "changes": Changes, "alternatives": Alternatives}[record]

    def get(self):
        return getattr(getattr(self, record), name)

    get.__doc__ = f"``{record}.{name}``: see :class:`{kind.__name__}`."
    return property(get)


@attrs.frozen
class Diagnosis:
    """What :func:`diagnose` found, in records.  ``to_json`` gives the JSON of docs/file-formats.md.

    Every field of the records is also an attribute of the diagnosis
    (read-only): ``explained``, ``report``, ``missing_effect``,
    ``missing_where`` (of ``verdict``); ``metric``, ``band``,
    ``noise_floor``, ``baseline_error``, ``final_error``, ``consistency``,
    ``correlation``, ``baseline``, ``final``, ``error_check`` (of ``measures``);
    ``final_effects``, ``refined_assembly``, ``candidates``, ``refinement``
    (of ``changes``); ``ambiguous``, ``ambiguous_with``, ``suggestion``,
    ``separation``, ``rivals``, ``equivalents`` (of ``alternatives``).

    Parameters
    ----------
    verdict : Verdict
        Explained or not, and the report's lines.
    measures : Measures
        The errors against the noise, before and after.
    changes : Changes
        The changes kept, the refined model, the candidates and the steps.
    alternatives : Alternatives
        Explanations as good as the one found, and what separates them.
    search : dict
        What the search did: ``candidates``, ``steps_screened``,
        ``full_fits``, ``evaluations`` (model evaluations of all lines),
        ``budget``, ``time_limit_s``, ``seconds``, ``cut`` (the budget
        stopped part of it) and ``cut_at`` (where).
    settings : DiagnoseSettings
        The settings the diagnosis ran with.
    """

    verdict: Verdict
    measures: Measures
    changes: Changes
    alternatives: Alternatives = attrs.field(factory=Alternatives)
    search: dict = attrs.field(factory=dict, eq=False)
    settings: DiagnoseSettings = attrs.field(default=DEFAULT_SETTINGS, eq=False)

    explained = _read("verdict", "explained")
    report = _read("verdict", "report")
    missing_effect = _read("verdict", "missing_effect")
    missing_where = _read("verdict", "missing_where")
    assumed_windows = _read("verdict", "assumed_windows")
    metric = _read("measures", "metric")
    band = _read("measures", "band")
    noise_floor = _read("measures", "noise_floor")
    baseline_error = _read("measures", "baseline_error")
    final_error = _read("measures", "final_error")
    consistency = _read("measures", "consistency")
    correlation = _read("measures", "correlation")
    baseline = _read("measures", "baseline")
    final = _read("measures", "final")
    error_check = _read("measures", "error_check")
    level = _read("measures", "level")
    final_effects = _read("changes", "final_effects")
    refined_assembly = _read("changes", "refined_assembly")
    candidates = _read("changes", "candidates")
    refinement = _read("changes", "refinement")
    ambiguous = _read("alternatives", "ambiguous")
    ambiguous_with = _read("alternatives", "ambiguous_with")
    suggestion = _read("alternatives", "suggestion")
    separation = _read("alternatives", "separation")
    rivals = _read("alternatives", "rivals")
    equivalents = _read("alternatives", "equivalents")

    @property
    def effects(self) -> list[Found]:
        """The changes the refinement kept, with their final values (refitted together)."""
        return list(self.final_effects)

    def to_json(self) -> dict:
        """One JSON object (strict JSON: no NaN or infinities); see docs/file-formats.md.

        Returns
        -------
        dict
            The keys of the contract and the added ones.
        """
        return strict(self._json())

    def _json(self) -> dict:
        cons = self.consistency
        return {
            "metric": self.metric,
            "baseline_error": _finite(self.baseline_error),
            "noise_floor": _finite(self.noise_floor),
            "explained": bool(self.explained),
            "missing_effect": self.missing_effect,
            "ambiguous_with": list(self.ambiguous_with),
            "candidates": [c.to_json() for c in self.candidates],
            "refinement": [s.to_json() for s in self.refinement],
            "missing_where": self.missing_where,
            "assumed_windows": [{"measurement": which, "window_tau_s": _finite(tau)}
                                for which, tau in self.assumed_windows],
            "suggestion": self.suggestion,
            "band_hz": list(self.band),
            "final_error": _finite(self.final_error),
            "error_check": None if self.error_check is None else {
                "ratio": _finite(self.error_check.ratio), "allowed": _finite(self.error_check.allowed)},
            "final_effects": [_effect_json(e) for e in self.final_effects],
            "calibration_factor": None if self.level is None else _finite(self.level),
            "correlation": self.correlation,
            "consistency": None if cons is None else {
                "chi2_reduced": _finite(cons.chi2_reduced), "threshold": _finite(cons.threshold),
                "bands_hz": [{"frf": (self.final[b.item].measured.outputs[0] + " / "
                                      + self.final[b.item].measured.inputs[0]),
                              "lo": b.lo_hz, "hi": b.hi_hz, "ratio": _finite(b.ratio), "share": _finite(b.share)}
                             for b in cons.bands]},
            "ambiguous": [{**_effect_json(a), "error": _finite(err)} for a, err in self.ambiguous],
            "separation": self.separation,
            "rivals": [{"effects": [_effect_json(f) for f in r.founds], "separation": sep} for r, sep in self.rivals],
            "equivalents": [{"of": int(i), **_effect_json(a), "error": _finite(err)} for i, a, err in self.equivalents],
            "search": dict(self.search),
            "report": list(self.report),
            "settings": self.settings.to_json(),
            "modes": [
                {"measured_hz": m.measured_hz, "model_hz": m.model_hz, "shift_hz": m.shift_hz,
                 "amplitude_ratio": m.amplitude_ratio}
                for m in self.baseline[0].modes
            ],
            "error_bands_hz": [[lo, hi, share] for lo, hi, share in self.baseline[0].bands],
        }

    def plot_where(self, ax=None):
        """The baseline comparison: FRFs overlaid, residual, error bands, mode shifts.

        Parameters
        ----------
        ax : sequence of three Axes, optional
            Where to draw.

        Returns
        -------
        matplotlib.figure.Figure
            The figure.
        """
        return self.baseline[0].plot(ax=ax)

    def plot_history(self, ax=None):
        """The error falling step by step, against the noise floor.

        Parameters
        ----------
        ax : Axes, optional
            Where to draw.

        Returns
        -------
        matplotlib.figure.Figure
            The figure.
        """
        from .plots import plot_history

        return plot_history(self, ax=ax)
