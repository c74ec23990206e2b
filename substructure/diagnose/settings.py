"""The settings of a diagnosis: every threshold, grid, budget and factor of the search and the report, named.

:class:`DiagnoseSettings` is a frozen record with one field per number the
diagnosis tunes (a literal that is mathematics, such as the half of a
midpoint, or a tolerance of floating-point rounding, is not a setting);
:data:`DEFAULT_SETTINGS` holds the values the tests and the documentation
are written for.  :func:`substructure.diagnose.diagnose` takes one as
``settings`` and hands it to every function that uses one of its values:
there is no module-level state to change, and two diagnoses with different
settings may run side by side.  Override a value with ``attrs.evolve`` or by
naming it::

    settings = DiagnoseSettings(most_changes=3, budget=10000)
"""

from __future__ import annotations

import enum
import math
from typing import Any, Callable

import attrs

from ..errors import InvalidValueError
from ..units import finite_real
from ..updating.likelihood import CALIBRATION_HINT

__all__ = ["DiagnoseSettings", "DEFAULT_SETTINGS", "FROM_SETTINGS"]


class _FromSettings(enum.Enum):
    """The default of an argument of :func:`~substructure.diagnose.diagnose` that the settings also hold."""

    FROM_SETTINGS = "from the settings"

    def __repr__(self) -> str:
        return "FROM_SETTINGS"


#: The default of ``diagnose``'s ``max_steps``, ``budget`` and ``time_limit``: the value of the settings.
FROM_SETTINGS = _FromSettings.FROM_SETTINGS


def _real(value) -> bool:
    return finite_real(value)


def _fail(attribute, value, expected: str):
    raise InvalidValueError(f"DiagnoseSettings.{attribute.name}: got {value!r}; expected {expected}")


def _count(minimum: int = 1) -> Callable[[Any, Any, Any], None]:
    def check(_, attribute, value) -> None:
        if not (isinstance(value, int) and not isinstance(value, bool) and value >= minimum):
            _fail(attribute, value, f"a whole number >= {minimum}")
    return check


def _number(lo: float = 0.0, hi: float = math.inf, lo_open: bool = True, hi_open: bool = False,
            optional: bool = False) -> Callable[[Any, Any, Any], None]:
    left, right = "(" if lo_open else "[", ")" if hi_open or hi == math.inf else "]"
    what = f"a number in {left}{lo:g}, {hi:g}{right}" + (" or None (no limit)" if optional else "")

    def inside(x) -> bool:
        return _real(x) and (x > lo if lo_open else x >= lo) and (x < hi if hi_open else x <= hi)

    def check(_, attribute, value) -> None:
        if not (optional and value is None or inside(value)):
            _fail(attribute, value, what)
    check.inside = inside  # type: ignore[attr-defined]
    check.what = what  # type: ignore[attr-defined]
    return check


def _numbers(lo: float = 0.0, hi: float = math.inf, lo_open: bool = True,
             hi_open: bool = False) -> Callable[[Any, Any, Any], None]:
    one = _number(lo, hi, lo_open, hi_open)

    def check(_, attribute, value) -> None:
        if not (isinstance(value, tuple) and value and all(one.inside(x) for x in value)):  # type: ignore[attr-defined]
            _fail(attribute, value, f"a non-empty tuple of numbers, each {one.what[2:]}")  # type: ignore[attr-defined]
    return check


def _flag(instance, attribute, value) -> None:
    if not isinstance(value, bool):
        _fail(attribute, value, "True or False")


def _tuple(value):
    return tuple(value) if isinstance(value, list) else value


@attrs.frozen(kw_only=True)
class DiagnoseSettings:
    """Every threshold, grid, budget and factor of a diagnosis (frozen; keyword arguments only).

    The defaults are :data:`DEFAULT_SETTINGS`; each field is checked on
    construction, and a wrong type or value raises
    :class:`~substructure.errors.InvalidValueError` naming the field.  Shares
    and factors are dimensionless; "lines" are frequency lines of the data;
    "evaluations" are model evaluations of all lines of all measured FRFs.
    The fields are grouped as the diagnosis uses them: the search's budget,
    the screening, the scan's grids, the polish of the scan's best values,
    the starts from mode shifts, the refinement, and the verdict and the
    report.

    Parameters
    ----------
    budget : float or None
        The search's budget in evaluations (default 3000, about 30 s for 3
        FRFs of 2,500 lines on one core of a 2-core machine; None: no limit).
        Once spent no step is added and a step fits only its best candidate
        on all lines (the checks after the forward search always run).
        Counted in evaluations, not seconds, so that the same data give the
        same answer on any machine.
    budget_lines : int
        The fewest lines an evaluation of all lines counts as (default 2500):
        data of fewer lines (a short record's coarse grid) count each
        evaluation as its share of this, so that their search may do as
        much work as one FRF of 2,500 lines (counted in full evaluations,
        the 142 lines of 30 ms taps spent the budget in the first step).
    time_limit : float or None
        A limit in wall-clock seconds as well (default None; with one, the
        answer may depend on the machine's speed).
    max_steps : int
        Most changes the forward selection adds (default 4): two effects at
        once, and room for a step the elimination drops again.
    most_changes : int
        Most changes an explanation may hold (default 2): two effects at once
        (a reground tool and a forgotten sensor) are found together; three or
        more that together only just reach the noise are the mark of one
        effect the search lacks, and the verdict says so.
    screen_lines : int
        Lines per FRF of the screening subsample, about (default 250): every
        k-th line, enough to see every resonance of a 5 kHz band at 4 Hz
        lines while costing a tenth of an evaluation.
    peak_lines : int
        Lines kept either side of every measured resonance the model lacks in
        the screening subsample (default 2): a subsample of every k-th line can
        step over such a narrow peak.
    mode_peak_share : float
        Measured and model peaks below this share of the highest are left out
        of the pairing of modes (default 0.02: a fiftieth, below what a tap
        test's first modes show).
    mode_prominence : float
        Least prominence of a peak in ``ln|H|`` (default 0.1: 10 %), so that
        ripples are not modes ...
    mode_prominence_floors : float
        ... and, for a measured peak, at least this many noise floors (default 5.0).
    mode_pairing : float
        A measured mode without a model mode within this factor in frequency
        stays unpaired (default 1.5).
    error_bands_share : float
        The bands where the error is are named until they hold this share of it
        (default 0.5).
    error_bands_width : float
        The squared log ratio is smoothed over this share of the band before the
        error bands are cut (default 0.02) ...
    error_bands_floors : float
        ... and a band lies above this many noise floors (default 2.0: noise is
        not a failure of the model).
    main_mode_share : float
        A paired mode is strong when its measured peak is at least this share
        of the highest (default 0.1); the largest relative shift of the strong
        modes starts the catalogue's effects.
    shortlist_share : float
        A screened candidate gets a full fit when its improvement of ``chi^2``
        is at least this share of the best one's (default 0.25): decided by
        each candidate's own improvement, never by a count.
    shortlist_max : int
        Most candidates of one kind (the model's parameters and elements, the
        catalogue's effects, or effects registered by users) fitted further in
        one step (default 6), so that registered effects never push a built-in
        candidate out.
    tie_chi2 : float
        Candidates whose screened ``chi^2`` differ by at most this are taken in
        order of preference (default 1.0, a unit of ``chi^2``: below what the
        data can decide).
    short_fit_evaluations : int
        A short local fit (on the screening lines, or a check on all lines)
        may spend this many evaluations per parameter plus one (default 5).
    inertia_floor : float
        The least upper bound of a body's rotary inertia [kg m^2] (default
        1e-3); otherwise the bound is that of its largest mass at the radius of
        the widest section, twice over.
    scan_values : int
        Values of a candidate's main parameter scanned over its range at one
        place (default 9: two values per decade over four decades).
    scan_values_placed : int
        Values scanned at each place of a candidate with several places (an
        element along its component; default 5).
    signed_decades : float
        A linear parameter whose range holds zero (a cross term) is scanned at
        both signs over this many decades below its largest magnitude (default
        3.0): its typical values are small next to its passivity bound.
    signed_values_min : int
        Least number of magnitudes of such a signed scan (default 7).
    body_positions : int
        Positions along its component at which a body or a spring is scanned
        (default 9: an eighth of the length apart).
    section_lengths : tuple of float
        Lengths of a section change scanned, as shares of its component's
        length (default (0.12, 0.3, 0.6)).
    section_starts : int
        Starts of each of those lengths, spread over the component (default 5).
    section_ratios : tuple of float
        Diameter ratios of a section change scanned (default (0.7, 0.85, 1.2)).
    named_grid : int
        Sizes of an effect of the catalogue that comes with positions (springs)
        crossed with them, in the first step on data with a resonance the model
        lacks (default 33): such effects have narrow minima near the band's edge.
    named_second : int
        Positions (all alike) crossed with each size of that grid (default 10).
    named_third : int
        Values of each of two positions crossed with ``scan_values`` sizes
        (default 4).
    scale_span : float
        An effect of several log-scale parameters is also scanned with all of
        them scaled together by factors from ``1 / scale_span`` to
        ``scale_span`` (default 100.0: two decades either way).
    scale_values : int
        Factors of that scan (default 9).
    place_search : int
        Steps of the golden-section search of an element's main parameter at
        each of its places, between the grid's neighbours of the best value
        there (all places evaluated together; default 10, about a hundredth
        of the grid's step).
    polish_points : int
        The best scanned candidates are refined at points ``1 / polish_points``
        of a grid step apart either side of the scan's best (default 3) before
        Brent's.
    brent_candidates : int
        Candidates (best scanned first) refined by those points and Brent's; the
        others by their slope (default 24).
    brent_evaluations : int
        Most evaluations of one refinement by Brent's method (default 8).
    brent_tolerance : float
        Brent's tolerance on the parameter's fitted scale (default 1e-3, a
        thousandth of a natural log unit: far below a fit's precision).
    slope_divisions : int
        The slope at the scan's best is taken over a grid step divided by this
        (default 20).
    jacobian_step : float
        Relative step of the finite differences that refit the changes already
        added to first order during the scan (default 1e-4).
    mode_window : float
        Relative half-width of the window in which a mode is followed from one
        trial to the next in the starts from mode shifts (default 0.12).
    mode_follow : float
        Relative half-width in which a mode is first followed from the model's
        (default 0.05).
    mode_locate : float
        Relative half-width in which a paired mode's peak is located on the
        model's lines (default 0.02).
    in_place_lines : int
        A mode within this many lines of the model's is in place (default 2): a
        peak picked on noisy lines moves by a line or two.
    secant_iterations : int
        Secant steps of the starts from mode shifts (default 3).
    secant_first_step : float
        The first step of the secant on the fitted scale (default 0.02).
    secant_max_step : float
        Largest secant step on a log scale (default 1.5, a factor e^1.5).
    secant_tolerance : float
        The secant stops at a step below this (default 1e-4).
    element_probe_linear : float
        An element on a linear scale is probed from zero with this share of its
        range (default 0.01).
    element_probe_log : float
        An element on a log scale is probed from zero with this share of its
        upper bound (default 1e-3).
    element_factors : tuple of float
        An element's predicted value is tried times each of these (default
        (0.6, 1.0, 1.5)): mode frequencies are smooth but not linear in it.
    mode_start_places : int
        An element with more screening places than this is started from mode
        shifts at every other one (default 5).
    rigid_below : float
        A free body's mass, inertia and centre are read off the model at this
        share of the lowest resonance the model lacks, and again at twice it
        (default 0.1): below the first flexible mode, where the receptances
        are the rigid body's mass line.
    rigid_free : float
        The body is free where those two readings agree within this share
        (default 0.05); held to the ground, they do not.
    rigid_resonances : int
        The lowest resonances the model lacks (in any FRF measured, one seen
        in several within a line counted once) of which every two are matched
        by the two modes of the body on its springs (default 3).
    rigid_shifts : tuple of float
        The upper of the two also matched this many lines away (default
        (-1.0, -0.5, 0.0, 0.5, 1.0)): a peak on noisy lines sits up to a line
        off, and the two modes' ratio places the springs.
    rigid_places : int
        Values of each of the two places of springs under a free body on which
        its two rigid-body modes are matched to two resonances the model
        lacks (default 91, half a per cent of the body's length apart): their
        minimum is narrower than any scan's grid.
    rigid_places_alone : int
        Values of each place on which either mode is put at the lowest
        resonance alone (default 19): two modes close together show as one.
    rigid_sharpened : int
        Those starts (the best by ``chi^2`` of each group: the lowest resonance
        alone, each two of them) whose main parameter is searched close to
        each (default 8).
    rigid_span : float
        How far: the half-width of that search on the parameter's fitted
        scale (default 0.1, 10 % of a stiffness): a start places the modes
        within a line of the measured ones, and a lightly damped mode's
        minimum is narrower than a line.
    review_pool : int
        Alternatives the review refits in place of each kept change (default 3).
    review_near_share : float
        A screened candidate not fitted enters the review's pool when its
        improvement is at least this share of the chosen one's (default 0.9).
    pair_pool : int
        Singles of the first step (best first) whose pairs the parsimony check
        fits from fair starts (default 4).
    same_direction : float
        Two singles whose changes of the residual have a cosine above this are
        one explanation under two names (default 0.995).
    pair_screen_evaluations : int
        Most evaluations of a pair's fit on the screening lines (default 40).
    pairs_fitted : int
        Pairs (best on the screening lines) fitted on all lines (default 2).
    other_firsts : int
        Where the forward path did not reach the noise with at most
        ``most_changes`` changes, the other singles of the first step (best
        first) from which a second step is screened: its first choice may be
        the wrong one (default 3; 0: not tried).
    pair_seconds : int
        Shortlisted second changes of that step fitted on all lines with each
        single (default 3).
    confirm_firsts : int
        Where the forward path reached the noise with two changes, the other
        singles of the first step (best first) from which a second step is
        screened too, its best second change fitted on all lines: a first
        choice that stood in for another effect, completed by an invented
        second change, meets the pair that describes the data better
        (default 1; 0: not checked).
    confirm_screen_step : int
        That second step screens every this-many-th line of the screening
        subsample, from the scan's own starts (default 2).
    confirm_named : int
        Where that path's first change is an element at a fitted place (a
        section change: the generic stand-in), the catalogue's effects on the
        same component (those that improved the model in the first step
        best first, then the others from their starts; at most this many)
        are fitted on all lines and start that second step too: a tapered
        tool with a sensor otherwise came back as a section change and a
        bore (default 2; 0: not tried).
    other_starts : int
        Starts per placed change from which other values of the same change are
        fitted (default 2).
    other_apart : float
        Values count as other values when a parameter differs by more than this
        share of its range on its fitted scale (default 0.05) ...
    other_apart_std : float
        ... and by more than this many standard deviations (default 3.0).
    rivals_checked : int
        Most rival explanations whose separation is computed for the verdict
        (default 3).
    explained_error_factor : float
        ``explained`` also needs the final RMS error within this many noise
        floors (default 1.5), a plain check beside the statistical test:
        each line as the noise model scores it (capped as in the band test),
        and within what the noise allows when that is more (the floor living
        on a few lines).
    point_reach : float
        A measured point given at a distance along a beam (``tool.tip-20
        mm``, ``holder@30 mm``: placed with a ruler) is a candidate,
        ``point-position``: its position fitted within this many metres of
        the one its name says (default 0.005; 0: not a candidate).  A sensor
        2 mm from where the record puts it otherwise came back as three
        invented changes of the structure.  A measured free tip
        (``tool.tip``) is tried alone, within this many metres towards its
        base, after a search that explained nothing; where it is hit and
        takes part in a cross FRF, the hammer's place apart from the
        sensor's (``hit-position``) within as many.
    tip_share : float
        A measured free tip tried alone that does not reach the noise but
        removes at least this share of the misfit above it (``chi^2 - n``;
        default 0.9) is named in the report as nearly the answer (further
        from the edge than ``point_reach``, or the sensor and the hammer at
        different heights where no cross FRF tells them apart).  Tested 1
        to 4 mm below the tip it removes 97 % or more; for effects of the
        structure at most 41 %.
    calibration : float or None
        The relative uncertainty of the measured FRFs' common scale, the
        hammer's and the sensors' sensitivities (e.g. 0.05; default None: the
        scale taken as exact).  With it every model is compared with the data
        after the common level that fits best, within ``1 + calibration``
        either way (:class:`~substructure.updating.Likelihood`), and the
        report gives that level: a test 3 % off in scale, normal for a real
        one, is not a change of the structure.
    calibration_hint : tuple of float
        Without ``calibration``, an unexplained verdict whose final model the
        data match in level only within this range of shares (default
        (0.01, 0.25): 1 % to 25 % above or below throughout) suggests giving
        it: a real test's scale is rarely better than a few per cent.
    seen_window : bool
        When a measurement that declares no window shows its noise correlated
        as through an exponential window (``NoiseModel.seen_tau``) and the data
        are not explained, diagnose again with each such measurement read as
        through the window its noise shows (default True).  An analyser that
        windows the response adds the damping ``1/(tau omega)`` to every mode,
        which no change of the structure makes; if that explains the data,
        the diagnosis through the window is returned and its report says so
        first (``Verdict.assumed_windows``); otherwise the first one.
    partial_gain : float
        An unexplained verdict's partial explanation keeps a change only when
        the error, refitted without it, is higher by at least this share of
        the noise floor (default 0.05): against a misfit that no candidate
        explains, every flexible change wins a little, significantly against
        the noise alone; such corrections are named as left out, not
        stacked.
    signature_step : float
        The factor of the finite differences of the signature (default 1.05: 5 %).
    signature_window : float
        Relative half-width in which the signature locates a mode (default 0.15).
    signature_share : float
        A knob names the signature when it explains more than this share of the
        mode shifts (default 0.5).
    level_bands : int
        Bands of equal numbers of lines over which the level signature compares
        the data with the model (default 8).
    level_floors : float
        The level signature needs the median log ratio above this many noise
        floors (default 2.0).
    level_spread : float
        ... and every band's median between ``1 / level_spread`` and
        ``level_spread`` times it (default 2.0) ...
    level_in_place : float
        ... and every mode within this share of its frequency (or
        ``in_place_lines``) of the model's (default 0.01).
    report_bands : int
        Most bands the report names where the remaining error lives (default 5).
    band_merge : float
        Bands of one FRF closer than this share of their frequency are named as
        one (default 0.05).
    separation_every : int
        The separating measurement is computed on every this-many-th line
        (default 4).
    """

    budget: float | None = attrs.field(default=3000, validator=_number(optional=True))
    budget_lines: int = attrs.field(default=2500, validator=_count())
    time_limit: float | None = attrs.field(default=None, validator=_number(optional=True))
    max_steps: int = attrs.field(default=4, validator=_count())
    most_changes: int = attrs.field(default=2, validator=_count())
    screen_lines: int = attrs.field(default=250, validator=_count())
    peak_lines: int = attrs.field(default=2, validator=_count(0))
    mode_peak_share: float = attrs.field(default=0.02, validator=_number(0.0, 1.0, lo_open=False, hi_open=True))
    mode_prominence: float = attrs.field(default=0.1, validator=_number())
    mode_prominence_floors: float = attrs.field(default=5.0, validator=_number(0.0, lo_open=False))
    mode_pairing: float = attrs.field(default=1.5, validator=_number(1.0))
    error_bands_share: float = attrs.field(default=0.5, validator=_number(0.0, 1.0))
    error_bands_width: float = attrs.field(default=0.02, validator=_number(0.0, 1.0))
    error_bands_floors: float = attrs.field(default=2.0, validator=_number(0.0, lo_open=False))
    main_mode_share: float = attrs.field(default=0.1, validator=_number(0.0, 1.0))
    shortlist_share: float = attrs.field(default=0.25, validator=_number(0.0, 1.0))
    shortlist_max: int = attrs.field(default=6, validator=_count())
    tie_chi2: float = attrs.field(default=1.0, validator=_number(0.0, lo_open=False))
    short_fit_evaluations: int = attrs.field(default=5, validator=_count())
    inertia_floor: float = attrs.field(default=1e-3, validator=_number())
    scan_values: int = attrs.field(default=9, validator=_count(2))
    scan_values_placed: int = attrs.field(default=5, validator=_count(2))
    signed_decades: float = attrs.field(default=3.0, validator=_number())
    signed_values_min: int = attrs.field(default=7, validator=_count(2))
    body_positions: int = attrs.field(default=9, validator=_count(2))
    section_lengths: tuple[float, ...] = attrs.field(default=(0.12, 0.3, 0.6), converter=_tuple,
                                                     validator=_numbers(0.0, 1.0))
    section_starts: int = attrs.field(default=5, validator=_count(2))
    section_ratios: tuple[float, ...] = attrs.field(default=(0.7, 0.85, 1.2), converter=_tuple,
                                                    validator=_numbers())
    named_grid: int = attrs.field(default=33, validator=_count(2))
    named_second: int = attrs.field(default=10, validator=_count(2))
    named_third: int = attrs.field(default=4, validator=_count(2))
    scale_span: float = attrs.field(default=100.0, validator=_number(1.0, lo_open=True))
    scale_values: int = attrs.field(default=9, validator=_count(2))
    place_search: int = attrs.field(default=10, validator=_count(0))
    polish_points: int = attrs.field(default=3, validator=_count())
    brent_candidates: int = attrs.field(default=24, validator=_count(0))
    brent_evaluations: int = attrs.field(default=8, validator=_count())
    brent_tolerance: float = attrs.field(default=1e-3, validator=_number())
    slope_divisions: int = attrs.field(default=20, validator=_count(2))
    jacobian_step: float = attrs.field(default=1e-4, validator=_number(0.0, 1.0, hi_open=True))
    mode_window: float = attrs.field(default=0.12, validator=_number(0.0, 1.0, hi_open=True))
    mode_follow: float = attrs.field(default=0.05, validator=_number(0.0, 1.0, hi_open=True))
    mode_locate: float = attrs.field(default=0.02, validator=_number(0.0, 1.0, hi_open=True))
    in_place_lines: int = attrs.field(default=2, validator=_count(0))
    secant_iterations: int = attrs.field(default=3, validator=_count(0))
    secant_first_step: float = attrs.field(default=0.02, validator=_number())
    secant_max_step: float = attrs.field(default=1.5, validator=_number())
    secant_tolerance: float = attrs.field(default=1e-4, validator=_number())
    element_probe_linear: float = attrs.field(default=0.01, validator=_number(0.0, 1.0))
    element_probe_log: float = attrs.field(default=1e-3, validator=_number(0.0, 1.0))
    element_factors: tuple[float, ...] = attrs.field(default=(0.6, 1.0, 1.5), converter=_tuple,
                                                     validator=_numbers())
    mode_start_places: int = attrs.field(default=5, validator=_count())
    rigid_below: float = attrs.field(default=0.1, validator=_number(0.0, 0.5))
    rigid_free: float = attrs.field(default=0.05, validator=_number(0.0, 1.0, hi_open=True))
    rigid_resonances: int = attrs.field(default=3, validator=_count(2))
    rigid_shifts: tuple[float, ...] = attrs.field(default=(-1.0, -0.5, 0.0, 0.5, 1.0), converter=_tuple,
                                                  validator=_numbers(-math.inf, math.inf))
    rigid_places: int = attrs.field(default=91, validator=_count(2))
    rigid_places_alone: int = attrs.field(default=19, validator=_count(2))
    rigid_sharpened: int = attrs.field(default=8, validator=_count(0))
    rigid_span: float = attrs.field(default=0.1, validator=_number())
    review_pool: int = attrs.field(default=3, validator=_count(0))
    review_near_share: float = attrs.field(default=0.9, validator=_number(0.0, 1.0))
    pair_pool: int = attrs.field(default=4, validator=_count(0))
    same_direction: float = attrs.field(default=0.995, validator=_number(0.0, 1.0))
    pair_screen_evaluations: int = attrs.field(default=40, validator=_count())
    pairs_fitted: int = attrs.field(default=2, validator=_count(0))
    other_firsts: int = attrs.field(default=3, validator=_count(0))
    pair_seconds: int = attrs.field(default=3, validator=_count())
    confirm_firsts: int = attrs.field(default=1, validator=_count(0))
    confirm_screen_step: int = attrs.field(default=2, validator=_count())
    confirm_named: int = attrs.field(default=2, validator=_count(0))
    other_starts: int = attrs.field(default=2, validator=_count(0))
    other_apart: float = attrs.field(default=0.05, validator=_number(0.0, 1.0))
    other_apart_std: float = attrs.field(default=3.0, validator=_number(0.0, lo_open=False))
    rivals_checked: int = attrs.field(default=3, validator=_count(0))
    explained_error_factor: float = attrs.field(default=1.5, validator=_number(1.0, lo_open=False))
    point_reach: float = attrs.field(default=0.005, validator=_number(0.0, 0.1, lo_open=False))
    tip_share: float = attrs.field(default=0.9, validator=_number(0.0, 1.0, hi_open=True))
    calibration: float | None = attrs.field(default=None, validator=_number(0.0, 1.0, hi_open=True, optional=True))
    calibration_hint: tuple[float, ...] = attrs.field(default=CALIBRATION_HINT, converter=_tuple,
                                                      validator=_numbers(0.0, 1.0, hi_open=True))
    seen_window: bool = attrs.field(default=True, validator=_flag)
    partial_gain: float = attrs.field(default=0.05, validator=_number(0.0, lo_open=False))
    signature_step: float = attrs.field(default=1.05, validator=_number(1.0, 2.0))
    signature_window: float = attrs.field(default=0.15, validator=_number(0.0, 1.0, hi_open=True))
    signature_share: float = attrs.field(default=0.5, validator=_number(0.0, 1.0, lo_open=False, hi_open=True))
    level_bands: int = attrs.field(default=8, validator=_count())
    level_floors: float = attrs.field(default=2.0, validator=_number(0.0, lo_open=False))
    level_spread: float = attrs.field(default=2.0, validator=_number(1.0))
    level_in_place: float = attrs.field(default=0.01, validator=_number(0.0, 1.0, lo_open=False, hi_open=True))
    report_bands: int = attrs.field(default=5, validator=_count())
    band_merge: float = attrs.field(default=0.05, validator=_number(0.0, 1.0, lo_open=False, hi_open=True))
    separation_every: int = attrs.field(default=4, validator=_count())

    def to_json(self) -> dict:
        """The settings as one JSON object (tuples as lists).

        Returns
        -------
        dict
            ``{field: value}`` for every field.
        """
        return {k: list(v) if isinstance(v, tuple) else v for k, v in attrs.asdict(self).items()}


#: The settings the tests and the documentation are written for.
DEFAULT_SETTINGS = DiagnoseSettings()
