"""The words of a diagnosis: every sentence it writes for a user, from numbers and names.

The verdict's lines (``Diagnosis.report``), the text of a value on the bound
of its search, the separating measurement, the signature of the modes and
of a calibration error, and the command's summary are written here and only
here; the modules that decide (:mod:`~substructure.diagnose.diagnosis`,
:mod:`~substructure.diagnose.report`) hand over numbers and names.  Each
function returns plain text (one line, or a list of lines); none computes
anything a decision depends on.  Progress lines (``progress=True``) are not
part of the result and stay beside the work they report.
"""

from __future__ import annotations

import math
from typing import Iterable, Sequence

__all__ = [
    "UNEXPLAINED", "values_text", "left_out", "calibrated", "level_hint",
    "bound_text", "partial", "too_many_changes", "bounded", "on_bound",
    "not_unique", "tell_apart", "budget_cut", "windowed", "correlated", "window_assumed", "interpolated",
    "window_not_enough", "outlying", "unexplained", "error_lives",
    "error_spread",
    "best_partial", "nothing_improves", "mode_line", "signature_line", "level_line", "separation_text",
    "parameter_values", "summary",
]

UNEXPLAINED = "unexplained: no candidate explains the data"
"""How the first line of every unexplained verdict begins."""
OUTLYING_MARK = "the model and the data differ far beyond the noise"
"""How the note on a run of lines far beyond the noise (:func:`outlying`) begins, after the measurement."""


def values_text(change, values) -> str:
    """``name = value unit, ...`` of a change's values, for reports.

    Parameters
    ----------
    change : Change
        The change (its ``specs`` give names and units).
    values : dict
        Its values (SI).

    Returns
    -------
    str
        The values, four significant digits each.
    """
    return ", ".join(f"{s.name} = {values[s.name]:.4g} {s.unit}".replace(" dimensionless", "") for s in change.specs)


def bound_text(effect: str, where: str, name: str, value: float, unit: str, side: str, bound: float) -> str:
    """One fitted value on the bound of its search, in words.

    Parameters
    ----------
    effect, where : str
        The change's effect and place.
    name : str
        The parameter.
    value : float
        Its value (SI, in ``unit``).
    unit : str
        Its unit.
    side : str
        ``"lower"`` or ``"upper"``.
    bound : float
        The bound (SI, in ``unit``).

    Returns
    -------
    str
        E.g. ``"joint-damping at holder-tool: c_yf = 240 N*s/m, the upper bound of its search (240 N*s/m)"``.
    """
    return f"{effect} at {where}: {name} = {value:.4g} {unit}, the {side} bound of its search ({bound:.4g} {unit})"


def partial(kind: str, effects: Iterable) -> str:
    """The note that an explanation the verdict does not claim is reported as partial.

    Parameters
    ----------
    kind : str
        Why it is not claimed: ``"composite"``, ``"bounded"``, ``"ambiguous"``.
    effects : iterable of Found
        Its changes (written by their ``repr``).

    Returns
    -------
    str
        One line.
    """
    return f"the best ({kind}) explanation is reported as partial: " + ", ".join(repr(e) for e in effects)


def too_many_changes(most: int, places: Sequence[str], strengths: Sequence[float] = ()) -> str:
    """The verdict when the noise is reached only with more changes than an explanation may hold.

    Parameters
    ----------
    most : int
        Most changes an explanation may hold (``DiagnoseSettings.most_changes``).
    places : sequence of str
        ``"effect at place"`` of each change.
    strengths : sequence of float, optional
        Each forward step's test statistic over its threshold, to tell changes that each only just pass their
        test (the mark of one missing effect) from changes each far beyond it.

    Returns
    -------
    str
        The verdict's first line.
    """
    said = (f"; the forward steps passed their tests {', '.join(f'{s:.3g}' for s in strengths)} times over"
            if strengths else "")
    return (f"{UNEXPLAINED} with at most {most} changes; {len(places)} together reach the noise "
            f"({', '.join(places)}){said}: changes that each only just pass their test are the mark of one effect "
            f"the search lacks; changes each far beyond it may be as many effects at once, beyond what an "
            f"explanation may hold (DiagnoseSettings(most_changes={len(places)}) takes them as one)")


def bounded(hits: Sequence[str]) -> str:
    """The verdict when the explanation holds a value on the bound of its search.

    Parameters
    ----------
    hits : sequence of str
        Each value on its bound (:func:`bound_text`).

    Returns
    -------
    str
        The verdict's first line.
    """
    return (f"{UNEXPLAINED} within the bounds of its search: {'; '.join(hits)}; a value on its bound is not a "
            "measurement (the data ask for more than the change allows: the mark of another effect, missing)")


def on_bound(hits: Sequence[str]) -> str:
    """The note, in an unexplained verdict, of values on the bounds of their search.

    Parameters
    ----------
    hits : sequence of str
        Each value on its bound (:func:`bound_text`).

    Returns
    -------
    str
        One line.
    """
    return f"on the bound of its search (not a measurement): {'; '.join(hits)}"


def not_unique(kept_name: str, kept_where: str, rival_name: str, rival_where: str, indifference: float,
               same_change_values: Sequence[str] | None) -> str:
    """The verdict when two explanations that are different structures fit alike.

    Parameters
    ----------
    kept_name, kept_where : str
        The explanation the search kept.
    rival_name, rival_where : str
        Its rival.
    indifference : float
        The BIC difference within which the data do not decide.
    same_change_values : sequence of str or None
        When the rival is the same change at other values, those values
        (:func:`values_text` per change); None when it changes other parts.

    Returns
    -------
    str
        The verdict's first line.
    """
    how = ("are the same change at other values (" + "; ".join(same_change_values) + ")"
           if same_change_values is not None else "change different parts")
    return (f"{UNEXPLAINED} uniquely: {kept_name} at {kept_where} and {rival_name} at {rival_where} both leave a "
            f"residual consistent with the noise (their BIC differ by at most {indifference:g}) but {how}")


def tell_apart(text: str) -> str:
    """The line naming the measurement that separates two explanations.

    Parameters
    ----------
    text : str
        The measurement (:func:`separation_text`).

    Returns
    -------
    str
        One line.
    """
    return f"to tell them apart: {text}"


def taken_below(point: str, place: str) -> str:
    """How to tell a test taken below a free tip from a change of the structure there that fits as well, with a ruler.

    Parameters
    ----------
    point : str
        The tip as the measurements name it (``tool.tip``).
    place : str
        Where the rival explanation says the test was taken (``tool.tip-1.2 mm``).

    Returns
    -------
    str
        The measurement, for :func:`tell_apart`.
    """
    return (f"measure how far below the edge the sensor and the hammer sat (the rival says {point} was taken at "
            f"{place}) and the tool's overhang")


def calibrated(level: float, calibration: float) -> str:
    """The common level of the data over the model, fitted within the calibration uncertainty given.

    Parameters
    ----------
    level : float
        The measured FRFs' scale over the final model's.
    calibration : float
        The relative uncertainty given (``DiagnoseSettings.calibration``).

    Returns
    -------
    str
        One line of the report.
    """
    text = (f"level: the measured FRFs read {level:.4g} times the final model's throughout, fitted within the "
            f"calibration uncertainty given ({calibration:.3g}, a factor {1 / (1 + calibration):.4g} to "
            f"{1 + calibration:.4g}); every comparison is made at that level")
    if abs(math.log(level)) >= math.log1p(calibration) * (1 - 1e-9):
        text += ("; it is at the bound: the data's scale differs by more than the uncertainty given (check the "
                 "hammer's and the sensors' sensitivities and units)")
    return text


def level_hint(level: float) -> str:
    """The suggestion to give the calibration uncertainty, for data that differ from the final model in level.

    Parameters
    ----------
    level : float
        The measured FRFs' scale over the final model's (:meth:`Likelihood.level`).

    Returns
    -------
    str
        One line of the report.
    """
    return (f"level: the measured FRFs read {level:.4g} times the final model's throughout, a common factor that "
            "no change of the structure gives; a real test's scale (the hammer's and the sensors' sensitivities) is "
            "rarely better than a few per cent: if yours is uncertain by that much, give it "
            "(DiagnoseSettings(calibration=0.05), diagnose --calibration 0.05) and the comparison is made at the "
            "level that fits")


def left_out(parts: Sequence[tuple[str, str, float]], gain: float, floor: float) -> str:
    """The changes an unexplained verdict's partial explanation leaves out (``partial_gain``).

    Parameters
    ----------
    parts : sequence of (str, str, float)
        Each change's effect, place and the error it was worth.
    gain : float
        The share of the noise floor a change must be worth.
    floor : float
        The noise floor.

    Returns
    -------
    str
        One line of the report.
    """
    listed = "; ".join(f"{e} at {p} ({w:.2g})" for e, p, w in parts)
    return (f"left out of the partial explanation, each worth less than {gain:g} times the noise floor "
            f"({gain * floor:.2g}) in error: {listed}; a misfit no candidate explains lets any change win a "
            "little of it")


def held_back(effect: str, where: str, chi2_with: float, chi2_without: float) -> str:
    """A change the cross-validation dropped (:mod:`substructure.diagnose.crossval`).

    Parameters
    ----------
    effect, where : str
        The change's effect and place.
    chi2_with, chi2_without : float
        ``chi^2`` of the held-back lines predicted with the change and without it.

    Returns
    -------
    str
        One line of the report.
    """
    return (f"dropped {effect} at {where}: did not predict held-back lines (their chi^2 {chi2_with:.1f} with it, "
            f"{chi2_without:.1f} without)")


def tip_nearly(point: str, place: str, share: float, error: float, floor: float, at_reach: bool) -> str:
    """A measured free tip that, taken alone towards its base, nearly explains the data.

    Parameters
    ----------
    point : str
        The tip as the measurements name it (``tool.tip``).
    place : str
        Where it was taken (``tool.tip-2 mm``).
    share : float
        The share of the misfit above the noise it removes.
    error, floor : float
        The error with the tip there, and the noise floor.
    at_reach : bool
        The place is as far as the search reaches (``DiagnoseSettings.point_reach``).

    Returns
    -------
    str
        One line of the report.
    """
    where = (f"{place}, as far as the search reaches (DiagnoseSettings.point_reach)" if at_reach else place)
    return (f"{point} taken at {where} removes {share:.0%} of the misfit alone (error {error:.4g}, "
            f"{error / floor:.2f} x the noise floor), not all of it: were the sensor and the hammer at different "
            f"heights{', or further from the edge' if at_reach else ''}? Give each point as measured "
            f"({point}-N mm) in the measurement set")


def budget_cut(where: str) -> str:
    """The note that the search's budget cut it short.

    Parameters
    ----------
    where : str
        Where it was cut.

    Returns
    -------
    str
        One line.
    """
    return f"the search was cut by its budget ({where}); a larger budget (--budget, --time-limit) may find more"


def windowed(which: str, tau: float, lo_hz: float, hi_hz: float, lines: float, lacking: Sequence[str] = ()) -> str:
    """The note that a measurement was taken through an exponential window, and how the model was compared with it.

    Parameters
    ----------
    which : str
        The measurement (``response / excitation``).
    tau : float
        The window's time constant [s].
    lo_hz, hi_hz : float
        The band's ends, at which the added damping ratio is quoted [Hz] (it is largest at the lowest line).
    lines : float
        The noise's correlation between neighbouring lines: a sum of lines varies this many times as much as
        one of independent lines (``NoiseModel.correlation``).
    lacking : sequence of str
        The components and joint models that kept the model from being evaluated through the window (their
        methods take no ``decay``); empty when it was.

    Returns
    -------
    str
        One line.
    """
    def zeta(f_hz: float) -> str:
        return f"{1.0 / (tau * 2.0 * math.pi * f_hz):.2g} at {f_hz:.4g} Hz"

    head = (f"{which} was measured through an exponential window (tau = {tau:.4g} s): it adds the damping ratio "
            f"1/(tau omega) to every mode ({zeta(lo_hz)} to {zeta(hi_hz)})")
    if not lacking:
        return (head + ", and the model was compared through the same window (evaluated at the complex frequency "
                f"omega - i/tau); its noise is correlated over neighbouring lines, counted as {lines:.3g} times "
                "fewer lines")
    return (head + f", which the model lacks: {', '.join(lacking)} cannot be evaluated through it (a "
            "receptance_matrix or dynamic_stiffness that takes decay can); damping found here may be the window's "
            "(the time records processed without it, substructure tap --no-exponential-window, leave the error of "
            "the taps' end counted as noise instead; taps long enough for the response to die out need no window)")


def correlated(which: str, noise, lo_hz: float, hi_hz: float) -> str:
    """The note that a measurement's noise is correlated over neighbouring lines though it says of no window.

    Parameters
    ----------
    which : str
        The measurement (``response / excitation``).
    noise : NoiseModel
        Its noise, with ``seen_tau`` set (:meth:`~substructure.updating.NoiseModel.seen_note`).
    lo_hz, hi_hz : float
        The band's ends, at which the window's damping ratio is quoted [Hz].

    Returns
    -------
    str
        One line.
    """
    zeta = [f"{1.0 / (noise.seen_tau * 2.0 * math.pi * f):.2g} at {f:.4g} Hz" for f in (lo_hz, hi_hz)]
    return (noise.seen_note(which) + f": it adds the damping ratio 1/(tau omega) to every mode ({zeta[0]} to "
            f"{zeta[1]} for this one), which the model lacks")


def _windows_text(windows: Sequence[tuple[str, float]]) -> str:
    return "; ".join(f"{which} as through exp(-t/tau), tau = {tau:.3g} s" for which, tau in windows)


def window_assumed(windows: Sequence[tuple[str, float]], error: float, floor: float) -> str:
    """The first line of a verdict explained once the measurements were read through the window their noise shows.

    Parameters
    ----------
    windows : sequence of (str, float)
        Each measurement so read and the time constant [s] its noise's correlation gives (``NoiseModel.seen_tau``).
    error, floor : float
        The error the best model left without the window, and the noise floor then.

    Returns
    -------
    str
        One line.
    """
    return (f"explained through an exponential window the data do not declare ({_windows_text(windows)}, read "
            "from the noise's correlation over neighbouring lines): an analyser that windows the response adds the "
            "damping ratio 1/(tau omega) to every mode, which no change of the structure makes; read without it, the "
            f"data were not explained (error {error:.4g}, {error / floor:.2g} times the noise floor). Check "
            "that the analyser applied such a window and give its time constant (window_tau_s in the measurement "
            "set)")


def window_not_enough(windows: Sequence[tuple[str, float]]) -> str:
    """The note that reading the measurements through the window their noise shows explained them no better.

    Parameters
    ----------
    windows : sequence of (str, float)
        Each measurement so read and the time constant [s] its noise gives.

    Returns
    -------
    str
        One line.
    """
    return f"read through the window its noise shows ({_windows_text(windows)}), the data are not explained either"


def truncated(which: str, error: float, at_hz: float) -> str:
    """The note that a measurement's taps ended while the response still rang (an error counted as noise).

    Parameters
    ----------
    which : str
        The measurement (``response / excitation``).
    error : float
        The largest relative error the end of the taps leaves within the band (``Measurement.truncation``).
    at_hz : float
        Where [Hz].

    Returns
    -------
    str
        One line.
    """
    return (f"{which}: the taps ended while the response still rang; the error that leaves (up to {error:.2g} "
            f"relative, near {at_hz:.4g} Hz) is counted as noise, so that less can be told there (a longer record "
            "would not need it)")


def outlying(which: str, lo_hz: float, hi_hz: float, count: int) -> str:
    """The note that neighbouring lines of a measurement lie far beyond its noise (judged as outliers only).

    Parameters
    ----------
    which : str
        The measurement (``response / excitation``).
    lo_hz, hi_hz : float
        The run's first and last line [Hz].
    count : int
        Its number of lines.

    Returns
    -------
    str
        One line.
    """
    return (f"{which}: {OUTLYING_MARK} on {count} neighbouring lines at "
            f"{lo_hz:.4g}-{hi_hz:.4g} Hz; the tests count each such line as an outlier of the data (as a double hit "
            "or the first lines of a short record make), so a difference confined there is not judged: if these "
            "lines are to be trusted (coherence near 1), the model misses something there; if not, leave them out "
            "with --band")


def empty_lines(which: str, hz) -> str:
    """The note that a measurement holds nothing on some lines of the band (zero or not finite), left out.

    Parameters
    ----------
    which : str
        The measurement (``response / excitation``).
    hz : array of float
        The frequencies of those lines [Hz].

    Returns
    -------
    str
        One line.
    """
    shown = ", ".join(f"{f:.6g}" for f in hz[:3]) + (", ..." if len(hz) > 3 else "")
    return (f"{which} holds no value on {len(hz)} line{'s' if len(hz) != 1 else ''} of the band ({shown} Hz: zero "
            "or not finite, a dropout or lines an analyser left empty): left out of every comparison")


def interpolated(which: str, step: int, degree: int, measured: int, lines: int) -> str:
    """The note that a measurement's lines are interpolated from every ``step``-th of them, compared on those alone.

    Parameters
    ----------
    which : str
        The measurement (``response / excitation``).
    step : int
        Lines from one measured line to the next.
    degree : int
        The interpolant's degree between them (0: a value held, 1: straight lines, 3: a cubic spline).
    measured, lines : int
        The measured lines in the band, and all its lines.

    Returns
    -------
    str
        One line.
    """
    how = {0: "each value held to the next", 1: "straight lines between them", 3: "a cubic spline through them"}
    return (f"{which}: its lines are interpolated from every {step}th of them ({how.get(degree, f'degree {degree}')}, "
            f"read from the data): the model is compared on the {measured} measured lines of the {lines} in the "
            "band, and the noise estimated on them (the lines between hold no measurement of their own)")


def estimated_as_h2(which: str, compared_as_h1: bool) -> str:
    """The note that a measurement is an H2 estimate, and how the diagnosis took it.

    Parameters
    ----------
    which : str
        The measurement (``response / excitation``).
    compared_as_h1 : bool
        Whether its coherence let it be compared as the H1 of the same taps, ``gamma^2 H2``.

    Returns
    -------
    str
        One line.
    """
    if compared_as_h1:
        return (f"{which} is an H2 estimate: compared as the H1 of the same taps, gamma^2 H2 (H2 exceeds the FRF "
                "by 1/gamma^2 where the response's noise is large)")
    return (f"{which} is an H2 estimate without its coherence: it exceeds the FRF by 1/gamma^2 where the response's "
            "noise is large, which the comparison cannot take out (give the coherence column, or an H1)")


def unexplained(final_error: float, floor: float, chi2_reduced: float, threshold: float,
                scored: tuple[float, float] | None = None, local: bool = False) -> str:
    """The first line of the verdict when no candidate reaches the noise.

    Parameters
    ----------
    final_error : float
        The best model's error (``rms_log_ratio``).
    floor : float
        The noise floor.
    chi2_reduced : float
        Its ``chi^2 / nu``.
    threshold : float
        What the noise allows.
    scored : (float, float), optional
        The plain check when it failed: the error in noise floors with each
        line as the noise model scores it, and what the noise allows.
    local : bool
        The residual fails band by band only (the whole band's tests pass):
        said, so that numbers within the noise do not read as a pass.

    Returns
    -------
    str
        One line.
    """
    return (f"{UNEXPLAINED}; the best model found leaves an error of {final_error:.4g}, {final_error / floor:.2g} "
            f"times the noise floor ({floor:.4g}); chi^2/nu = {chi2_reduced:.4g} where the noise allows "
            f"{threshold:.4g}"
            + ("" if scored is None else f"; with each line as the noise model scores it, {scored[0]:.3g} noise "
               f"floors where the noise allows {scored[1]:.3g}")
            + ("; within the noise over the whole band, not band by band: the error is local (where, below)"
               if local else ""))


def error_lives(bands: Sequence[tuple[str, float, float, float]]) -> str:
    """Where the remaining error lives.

    Parameters
    ----------
    bands : sequence of (label, lo, hi, share)
        FRF label, band edges [Hz] and share of the error, largest first.

    Returns
    -------
    str
        One line.
    """
    return "the remaining error lives in: " + "; ".join(f"{lab} {lo:.0f}-{hi:.0f} Hz ({share:.0%})"
                                                        for lab, lo, hi, share in bands)


def error_spread() -> str:
    """The line when no band of lines stands out.

    Returns
    -------
    str
        One line.
    """
    return "the remaining error is spread over the band (no single band stands out)"


def best_partial(parts: Sequence[tuple[str, str, str]]) -> str:
    """The best partial explanation of an unexplained verdict.

    Parameters
    ----------
    parts : sequence of (effect, place, values)
        Each change with its values (:func:`values_text`).

    Returns
    -------
    str
        One line.
    """
    return "best partial explanation (partial): " + "; ".join(f"{e} at {p} ({v})" for e, p, v in parts)


def nothing_improves() -> str:
    """The line when no candidate improves the model significantly.

    Returns
    -------
    str
        One line.
    """
    return "no candidate improves the model significantly"


def mode_line(model_hz: float, strain: str, motion: str, relative: float | None, in_place_lines: int = 2) -> str:
    """One mode of the model against the measurement.

    Parameters
    ----------
    model_hz : float
        The model's mode [Hz].
    strain, motion : str
        Where its strain and its motion mostly are.
    relative : float or None
        ``ln(f_measured / f_model)``; None when the mode is in place.
    in_place_lines : int
        Within how many lines a mode is in place.

    Returns
    -------
    str
        One line.
    """
    lines = "two" if in_place_lines == 2 else str(in_place_lines)
    state = f"within {lines} lines" if relative is None else \
        f"{abs(relative):.1%} {'lower' if relative < 0 else 'higher'} in the measurement"
    return f"mode at {model_hz:.0f} Hz in the model (strain mostly in the {strain}, motion mostly in the {motion}): " \
           f"{state}"


def signature_line(lower: Sequence[float], higher: Sequence[float], text: str, kind: str, factor: float,
                   share: float) -> str:
    """The signature: which change would move the modes as measured.

    Parameters
    ----------
    lower, higher : sequence of float
        The model's modes [Hz] lower, higher in the measurement.
    text : str
        The knob (``"the stiffness of the tool"``).
    kind : str
        ``"stiffness"`` or ``"mass"``.
    factor : float
        The least-squares amplitude ``a`` of the knob's pattern (its sign says which way).
    share : float
        Share of the mode shifts it accounts for.

    Returns
    -------
    str
        One line.
    """
    if kind == "stiffness":
        what = f"{text} {'lower' if factor < 0 else 'higher'} than the model"
        alt = " (or mass added where that part moves)" if factor < 0 else ""
    else:
        what = f"{text} {'higher' if factor > 0 else 'lower'} than the model"
        alt = f" (or softness near the {text.replace('the mass of the ', '')})" if factor > 0 else ""
    low = [f"{f:.0f} Hz" for f in lower]
    high = [f"{f:.0f} Hz" for f in higher]
    pattern = "; ".join(x for x in (f"lower in the measurement: {', '.join(low)}" if low else "",
                                    f"higher: {', '.join(high)}" if high else "") if x)
    return f"signature: {pattern}; this pattern matches {what}{alt}, which accounts for {share:.0%} of the mode shifts"


def level_line(factors: Sequence[tuple[str, str, float]]) -> str:
    """The signature of a calibration or unit error.

    Parameters
    ----------
    factors : sequence of (response, excitation, factor)
        Per FRF, the factor of the measurement over the model.

    Returns
    -------
    str
        One line.
    """
    text = "; ".join(f"{o} / {i}: {x:.3g} times" for o, i, x in factors)
    return (f"signature: the measurement is a constant factor times the model over the whole band with every mode "
            f"in place ({text}): a calibration or unit error (the hammer's or the sensor's sensitivity, g taken "
            f"for m/s^2) scales an FRF like this, while a change of the structure would have to scale every mass "
            f"and stiffness alike; check the calibration before the model (no change of the structure is fitted "
            f"to such data)")


def separation_text(a_name: str, a_where: str, b_name: str, b_where: str, value: float, indifference: float,
                    response: str, excitation: str, non_contact: bool) -> str:
    """The measurement that tells two explanations apart, or that none does.

    Parameters
    ----------
    a_name, a_where, b_name, b_where : str
        The two explanations.
    value : float
        ``chi^2`` of their difference at the best measurement.
    indifference : float
        Above this the measurement tells them apart.
    response, excitation : str
        The best measurement's points.
    non_contact : bool
        With a non-contact sensor.

    Returns
    -------
    str
        One sentence.
    """
    if value <= indifference:
        return (f"no measurement at the ends, quarter points and middles of the components tells {a_name} at "
                f"{a_where} from {b_name} at {b_where}: they are equivalent descriptions of these data")
    kind = "point FRF" if response == excitation else "cross FRF"
    how = " with a non-contact sensor (laser vibrometer)" if non_contact else ""
    return (f"measure the {kind} {response} / {excitation}{how}: {a_name} at {a_where} and {b_name} at {b_where} "
            f"differ there by chi^2 = {value:.3g} over the band (above {indifference:g} tells them apart)")


def parameter_values(found) -> str:
    """A found change's values with their standard deviations and the model's values, for the summary.

    Parameters
    ----------
    found : Found
        The change with its values.

    Returns
    -------
    str
        ``name = value +- std unit (model: nominal), ...``.
    """
    parts = []
    for name, spec in found.parameters_json().items():
        unit = "" if spec["unit"] == "dimensionless" else f" {spec['unit']}"
        std = f" +- {spec['std']:.2g}" if spec.get("std") is not None else ""
        nominal = f" (model: {spec['nominal']:.4g})" if spec.get("nominal") is not None else ""
        parts.append(f"{name} = {spec['value']:.4g}{std}{unit}{nominal}")
    return ", ".join(parts)


def summary(result, model_name: str, measured: int) -> list[str]:
    """The summary ``substructure diagnose`` prints: the verdict first when unexplained (or explained only through a
    window the data do not declare), then the numbers.

    Parameters
    ----------
    result : Diagnosis
        The diagnosis.
    model_name : str
        The assembly's name.
    measured : int
        Number of measured FRFs.

    Returns
    -------
    list of str
        The lines.
    """
    floor = result.noise_floor
    # an explanation through a window the data do not declare says so first
    said = 1 if result.explained and result.assumed_windows else 0
    lines = list(result.report[:said]) if result.explained else list(result.report)
    lines.append(f"model {model_name!r} against {measured} measured FRF(s), "
                 f"{result.band[0]:.0f}-{result.band[1]:.0f} Hz")
    lines.append(f"error ({result.metric}): {result.baseline_error:.4f}; noise floor of the data: {floor:.4f}")
    if result.explained and result.level is not None:  # else the report above said it
        lines.append(f"level: the measured FRFs read {result.level:.4g} times the final model's (calibration "
                     "uncertainty given)")
    base = result.baseline[0]
    for m in [m for m in base.modes if m.model_hz is not None][:12]:
        lines.append(f"  mode at {m.measured_hz:7.0f} Hz measured, {m.model_hz:7.0f} Hz in the model "
                     f"({m.shift_hz:+.0f} Hz), peak x{m.amplitude_ratio:.2f}")
    if base.bands:
        lines.append("  most of the error is in " + ", ".join(f"{lo:.0f}-{hi:.0f} Hz ({share:.0%})"
                                                           for lo, hi, share in base.bands))
    if result.missing_effect is None:
        judged = (" on the lines the tests judge (see the note on lines far beyond the noise)"
                  if any(OUTLYING_MARK in r for r in result.report) else "")
        lines.append(f"the model is as good as the data allow: nothing is missing{judged}" if result.explained
                     else "no candidate explains the difference significantly")
    else:
        label = "missing effect" if result.explained else "best partial explanation (partial)"
        for i, e in enumerate(result.effects):
            lines.append(f"{label if i == 0 else 'and'}: {e.name} at {e.where}")
            lines.append(f"  {parameter_values(e)}")
            lines.append(f"  why: {e.explanation}")
            same = [a for j, a, _ in result.equivalents if j == i]
            if same:
                lines.append("  as well (the data cannot tell them apart): "
                             + "; ".join(f"{a.name} at {a.where} ({parameter_values(a)})" for a in same[:3]))
        if result.ambiguous:
            alts = "; ".join(f"{a.name} at {a.where} ({parameter_values(a)})" for a, _ in result.ambiguous[:3])
            lines.append(f"  equally possible: {alts}")
            if result.suggestion:
                lines.append(f"  to tell them apart: {result.suggestion}")
    if len(result.refinement) > 1:
        lines.append("refinement (watch the error fall; chi^2/nu of each step's fit, every line in full):")
        for step in result.refinement:
            what = "model as given" if step.added is None else f"+ {step.added.name} at {step.added.where}"
            lines.append(f"  step {step.step}: {what:50s} error {step.error:.4f}  chi^2/nu {step.chi2_reduced:.4g}")
    if result.explained:  # an explained verdict's report holds the facts of the data only (a window, an H2, ...)
        lines.extend(f"note: {line}" for line in result.report[said:])
    cons = result.consistency
    verdict = "explained" if result.explained else "not explained"
    check = result.error_check
    scored = "" if check is None else (f"; {check.ratio:.2f} with each line as the noise model scores it, up to "
                                       f"{check.allowed:.2f}")
    lines.append(f"verdict: {verdict}: final error {result.final_error:.4f} ({result.final_error / floor:.2f} x the "
                 f"noise floor{scored}), chi^2/nu = {cons.chi2_reduced:.4g} with each line capped at the noise's "
                 f"0.1 % tail (consistent with the noise up to "
                 f"{cons.threshold:.4g})")
    return lines
