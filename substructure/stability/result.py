"""Stability lobes as a result object: speeds, depth limits, chatter frequencies.

:class:`Lobes` is what :func:`~substructure.stability.zoa` and
:func:`~substructure.stability.sdm` return: for each spindle speed [rpm] the
depth of cut limit [m] (the lowest lobe at that speed; ``inf`` where the
method finds no limit) and the chatter frequency [Hz] at that limit.  Depths
below the limit are stable.  :class:`LobesBand` holds the spread of several
results (e.g. from FRFs that span an uncertainty band).  Plots are drawn by
:mod:`substructure.stability.plotting`.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import attrs
import numpy as np

from ..errors import InvalidValueError, SubstructureWarning
from ..units import items_of
from .speeds import rpm_values

__all__ = ["Lobes", "LobesBand", "lobes_band", "StabilityWarning", "sampled_window_minimum"]


class StabilityWarning(SubstructureWarning):
    """A stability result may mislead: e.g. its limit sits at the edge of the FRF's band."""


def _array(value: Any) -> np.ndarray:
    out = np.array(value, dtype=float, copy=True)
    out.flags.writeable = False
    return out


_eq = attrs.cmp_using(eq=np.array_equal)


def _json_numbers(values: np.ndarray) -> list:
    return [float(v) if np.isfinite(v) else None for v in values]


@attrs.frozen
class Lobes:
    """A stability lobe diagram.

    Parameters
    ----------
    method : {"zoa", "sdm"}
        The method: zero-order approximation or semi-discretization.
    spindle_speed_rpm : ndarray
        Spindle speeds in rpm, increasing.
    depth_limit_m : ndarray
        Limiting axial depth of cut at each speed (``inf``: no limit found).
    chatter_frequency_hz : ndarray
        Chatter frequency at the limit (``nan`` where there is none).
    cut : MillingCut or TurningCut
        The cut the lobes are for.
    absolute_limit_m : float or None
        Zero-order: the speed-independent limit (the lowest depth of every
        lobe); ``None`` for semi-discretization.
    absolute_limit_frequency_hz : float or None
        The chatter frequency of the absolute limit.
    lobes : tuple of (ndarray, ndarray)
        Zero-order: the individual lobes as ``(speed_rpm, depth_m)``, for
        plots; empty for semi-discretization.
    bifurcation : tuple of str
        Semi-discretization: ``"hopf"`` (chatter at a frequency unrelated to
        the tooth passing) or ``"flip"`` (period doubling) at each speed.
    discretisation : dict
        Semi-discretization: the scheme and the numbers that define it.
    label : str or None
        Legend label.
    band : FlexibleBand or None
        The part of the FRF that was used (rigid-body and suspension lines
        left out, :mod:`~substructure.stability.band`); ``None`` for modes.
    source : object or None
        What computed the result, able to evaluate it at other speeds
        (:meth:`limit_on`, :meth:`window_minimum`); ``None`` for results
        built by hand, which are then read by interpolation.
    """

    method: str
    spindle_speed_rpm: np.ndarray = attrs.field(converter=_array, eq=_eq)
    depth_limit_m: np.ndarray = attrs.field(converter=_array, eq=_eq)
    chatter_frequency_hz: np.ndarray = attrs.field(converter=_array, eq=_eq)
    cut: Any = None
    absolute_limit_m: float | None = None
    absolute_limit_frequency_hz: float | None = None
    lobes: tuple = attrs.field(default=(), eq=False, repr=False)
    bifurcation: tuple = attrs.field(default=(), converter=tuple, repr=False)
    discretisation: dict = attrs.field(factory=dict, eq=False)
    label: str | None = None
    band: Any = attrs.field(default=None, eq=False)
    source: Any = attrs.field(default=None, eq=False, repr=False)

    def __attrs_post_init__(self) -> None:
        n = self.spindle_speed_rpm.size
        for name in ("depth_limit_m", "chatter_frequency_hz"):
            if getattr(self, name).shape != (n,):
                raise InvalidValueError(f"{name}: expected {n} values, one per spindle speed")

    def with_label(self, label: str) -> Lobes:
        """The same result with another legend label.

        Parameters
        ----------
        label : str
            The legend label.

        Returns
        -------
        Lobes
            A copy with the label.
        """
        return attrs.evolve(self, label=label)

    # -- reading the diagram ----------------------------------------------------
    def limit_at(self, speed_rpm: Any) -> np.ndarray:
        """Depth limit in m at speeds within the computed range, linearly interpolated.

        Parameters
        ----------
        speed_rpm : float, array_like, str or pint.Quantity
            Spindle speeds: plain numbers in rpm, or with an angular-speed
            unit (``"12000 rpm"``, ``Q_(1200, "rad/s")``); within the
            computed range.

        Raises
        ------
        InvalidValueError
            For speeds that are not finite or lie outside the computed range.
        UnitError
            For a speed in Hz or 1/s (ambiguous, see
            :func:`~substructure.stability.as_speed_rpm`) or in a unit that
            is not a speed.

        Returns
        -------
        ndarray
            The depth limits in m, the shape of ``speed_rpm``.
        """
        n = self._speeds(speed_rpm, "speed_rpm")
        return np.interp(n, self.spindle_speed_rpm, self.depth_limit_m)

    def is_stable(self, speed_rpm: Any, depth_m: Any) -> np.ndarray:
        """Whether cuts at these speeds and depths [m] are below the limit.

        Parameters
        ----------
        speed_rpm : float, array_like, str or pint.Quantity
            Spindle speeds, as :meth:`limit_at` takes them (plain numbers in
            rpm; within the computed range).
        depth_m : float or array_like
            Axial depths of cut in m.

        Raises
        ------
        InvalidValueError
            For speeds that are not finite or lie outside the computed range.
        UnitError
            For a speed in Hz or 1/s, or in a unit that is not a speed.

        Returns
        -------
        ndarray
            Boolean: True where the cut is stable.
        """
        return np.asarray(depth_m, float) < self.limit_at(speed_rpm)

    def best_speeds(self, count: int = 3) -> list[tuple[float, float]]:
        """The ``count`` best speeds: local maxima of the limit, ``(rpm, depth_m)``, deepest first.

        A maximum at either end of the speed range counts only when the limit
        falls away from it (it may lie outside the range).

        Parameters
        ----------
        count : int
            How many speeds at most: a whole number >= 1.

        Raises
        ------
        InvalidValueError
            For a ``count`` that is not a whole number >= 1.

        Returns
        -------
        list of tuple
            ``(speed in rpm, depth limit in m)``, deepest first.
        """
        if isinstance(count, bool) or not isinstance(count, (int, np.integer)) or count < 1:
            raise InvalidValueError(f"count: got {count!r}; expected a whole number >= 1 (how many speeds)")
        a = np.where(np.isfinite(self.depth_limit_m), self.depth_limit_m, np.nan)
        if a.size < 3 or np.all(np.isnan(a)):
            return []
        fill = np.nan_to_num(a, nan=-np.inf)
        inner = (fill[1:-1] >= fill[:-2]) & (fill[1:-1] > fill[2:])
        index = np.flatnonzero(inner) + 1
        index = index[np.argsort(-fill[index])][:count]
        return [(float(self.spindle_speed_rpm[i]), float(a[i])) for i in index]

    def limit_on(self, speed_rpm: Any) -> tuple[np.ndarray, np.ndarray]:
        """Depth limit [m] and chatter frequency [Hz] computed at other speeds [rpm].

        Parameters
        ----------
        speed_rpm : array_like, str or pint.Quantity
            Spindle speeds within the computed range, as :meth:`limit_at`
            takes them (plain numbers in rpm).

        Returns
        -------
        (ndarray, ndarray)
            Zero order: exactly what :func:`~substructure.stability.zoa` gives
            on these speeds (from the stored lobes, no new eigenvalues);
            semi-discretization: a new run on the speeds not computed before
            (the lobes' own speeds and those of earlier calls keep their
            values); results without a source: linear interpolation.
        """
        n = self._within(speed_rpm, "speed_rpm")
        if self.source is not None:
            return self.source.limit(n)
        return self.limit_at(n), np.interp(n, self.spindle_speed_rpm, self.chatter_frequency_hz)

    def _speeds(self, speed_rpm: Any, field: str) -> np.ndarray:
        """Speeds in rpm (plain numbers, or converted from their unit), the shape given, checked.

        Refused: values that are not finite and speeds outside the computed range.
        """
        n = rpm_values(speed_rpm, field)
        bad = n[~np.isfinite(n)]
        if bad.size:
            raise InvalidValueError(f"{field}: got {bad[0]:g}; expected finite speeds in rpm")
        lo, hi = self.spindle_speed_rpm[0], self.spindle_speed_rpm[-1]
        bad = n[(n < lo * (1 - 1e-12)) | (n > hi * (1 + 1e-12))]
        if bad.size:
            more = f" (and {bad.size - 1} more)" if bad.size > 1 else ""
            raise InvalidValueError(
                f"{field}: expected speeds within the computed range {lo:g}..{hi:g} rpm; got {bad[0]:g} rpm{more}")
        return n

    def _within(self, speed_rpm: Any, field: str) -> np.ndarray:
        """Speeds as a 1-D array (at least), refused when not finite or outside the computed range."""
        return np.atleast_1d(self._speeds(speed_rpm, field))

    def window_minimum(self, lo_rpm: Any, hi_rpm: Any) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The lowest depth limit over speed windows ``[lo, hi]`` [rpm].

        Parameters
        ----------
        lo_rpm, hi_rpm : float, array_like, str or pint.Quantity
            Window ends within the computed range, as :meth:`limit_at` takes
            speeds (plain numbers in rpm, or with an angular-speed unit): one
            number or a 1-D array each, of the same length, ``lo <= hi``.

        Raises
        ------
        InvalidValueError
            For ends that are empty, not one number or a 1-D array, of
            different lengths, not finite, reversed (``lo > hi``) or outside
            the computed range.
        UnitError
            For ends in Hz or 1/s, or in a unit that is not a speed.

        Returns
        -------
        (depth_m, speed_rpm, chatter_hz) : ndarrays
            Per window: the lowest limit, the speed where it is, and the
            chatter frequency there.  Zero order: exact for the lobes of the
            FRF lines (the envelope is piecewise linear between lines; its
            minimum over a window lies at an end or at a vertex of a lobe that
            is a local minimum of that lobe, and all of those are evaluated).
            Semi-discretization: the minimum over the computed speeds in
            the window, its ends and at least 32 speeds inside it on a
            geometric ladder that windows of the same relative width share
            (so that overlapping windows, and later calls, evaluate a speed
            once: see :meth:`limit_on`).  Without a source: the same
            samples, interpolated.
        """
        lo, hi = (_window_ends(rpm_values(v, f), f) for v, f in ((lo_rpm, "lo_rpm"), (hi_rpm, "hi_rpm")))
        _check_windows(lo, hi, "lo_rpm, hi_rpm")
        self._within(np.concatenate([lo, hi]), "lo_rpm, hi_rpm")
        if self.source is not None and hasattr(self.source, "window_minimum"):
            return self.source.window_minimum(lo, hi)
        return sampled_window_minimum(self.limit_on, lo, hi, self.spindle_speed_rpm)

    @property
    def min_limit_m(self) -> float:
        """The lowest depth limit over the speeds computed."""
        return float(np.min(self.depth_limit_m))

    # -- output -----------------------------------------------------------------
    def to_json(self) -> dict:
        """The JSON object of ``substructure lobes --json`` (SI units, ``null`` for no limit).

        Returns
        -------
        dict
            Speeds in rpm, depths in m, frequencies in Hz.
        """
        out = {
            "method": self.method,
            "spindle_speed_rpm": self.spindle_speed_rpm.tolist(),
            "depth_limit_m": _json_numbers(self.depth_limit_m),
            "chatter_frequency_hz": _json_numbers(self.chatter_frequency_hz),
        }
        if self.method == "zoa":
            out["absolute_limit_m"] = None if self.absolute_limit_m is None or not np.isfinite(
                self.absolute_limit_m) else float(self.absolute_limit_m)
            out["absolute_limit_frequency_hz"] = self.absolute_limit_frequency_hz
        if self.bifurcation:
            out["bifurcation"] = list(self.bifurcation)
        if self.discretisation:
            out["discretisation"] = dict(self.discretisation)
        if self.band is not None:
            out["structure_band"] = self.band.to_json()
        out["best_speeds"] = [{"spindle_speed_rpm": n, "depth_limit_m": a} for n, a in self.best_speeds()]
        return out

    def plot(self, ax: Any = None, **kw: Any):
        """Draw onto ``ax`` (new figure when None) with ``substructure.stability.plotting.plot_lobes``.

        Call it again with the same ``ax`` to put several results on one plot.

        Parameters
        ----------
        ax : Axes or Figure, optional
            Where to draw; a new figure when None.
        **kw
            ``lobes`` (draw the single lobes), ``recommendation`` (mark it and
            its safe window), ``title``, ``ylim_factor`` and line options.

        Returns
        -------
        matplotlib.figure.Figure
            The figure: depth limit in mm against spindle speed in rpm.
        """
        from .plotting import plot_lobes

        return plot_lobes([self], ax=ax, **kw)


@attrs.frozen
class LobesBand:
    """The spread of lobes computed from several FRFs (e.g. an FRF uncertainty band).

    Parameters
    ----------
    spindle_speed_rpm : ndarray
        Spindle speeds in rpm, common to the members.
    lower_m : ndarray
        The lowest and highest depth limit at each speed over the members.
    upper_m : ndarray
        The lowest and highest depth limit at each speed over the members.
    nominal : Lobes or None
        The result drawn as a line within the band.
    members : tuple of Lobes
        The results the band spans.
    label : str or None
        Legend label.
    """

    spindle_speed_rpm: np.ndarray = attrs.field(converter=_array, eq=_eq)
    lower_m: np.ndarray = attrs.field(converter=_array, eq=_eq)
    upper_m: np.ndarray = attrs.field(converter=_array, eq=_eq)
    nominal: Lobes | None = None
    members: tuple = attrs.field(default=(), converter=tuple, eq=False, repr=False)
    label: str | None = None

    def plot(self, ax: Any = None, **kw: Any):
        """Shade the band and draw the nominal lobes (``substructure.stability.plotting.plot_band``).

        Parameters
        ----------
        ax : Axes, optional
            Where to draw; a new figure when None.
        **kw
            Passed to the plotting function (line styles, ``lobes=True`` for the single lobes).

        Returns
        -------
        Figure
            The figure: depth limit in mm against spindle speed in rpm.
        """
        from .plotting import plot_band

        return plot_band(self, ax=ax, **kw)

    def to_json(self) -> dict:
        """The band for JSON output.

        Returns
        -------
        dict
            ``spindle_speed_rpm`` (rpm), ``lower_m`` and ``upper_m`` (m, ``null`` for no limit).
        """
        return {"spindle_speed_rpm": self.spindle_speed_rpm.tolist(), "lower_m": _json_numbers(self.lower_m),
                "upper_m": _json_numbers(self.upper_m)}


def _window_ends(ends: np.ndarray, field: str) -> np.ndarray:
    """Window ends as a non-empty 1-D array of finite numbers, else refused naming ``field``."""
    if ends.ndim > 1:
        raise InvalidValueError(f"{field}: got shape {ends.shape}; expected one number or a 1-D array of window ends")
    ends = np.atleast_1d(ends)
    if ends.size == 0:
        raise InvalidValueError(f"{field}: got no values; expected one or more window ends")
    bad = ends[~np.isfinite(ends)]
    if bad.size:
        raise InvalidValueError(f"{field}: got {bad[0]:g}; expected finite speeds in rpm")
    return ends


def _plain_numbers(value: Any, field: str) -> np.ndarray:
    """``value`` as a float array, refused naming ``field`` when it is not numbers."""
    try:
        return np.asarray(value, dtype=float)
    except (TypeError, ValueError, OverflowError):
        raise InvalidValueError(f"{field}: got {value!r}; expected speeds in rpm as plain numbers") from None


def _check_windows(lo: np.ndarray, hi: np.ndarray, fields: str) -> None:
    """Refuse window ends of different lengths and reversed windows (lo > hi), naming ``fields``."""
    if lo.shape != hi.shape:
        raise InvalidValueError(f"{fields}: got {lo.size} and {hi.size} ends; expected as many of one as of the other")
    reversed_ = np.flatnonzero(lo > hi)
    if reversed_.size:
        i = int(reversed_[0])
        raise InvalidValueError(f"{fields}: got the window {lo[i]:g}..{hi[i]:g} rpm (index {i}); expected lo <= hi")


def sampled_window_minimum(evaluate, lo: np.ndarray, hi: np.ndarray, speeds: np.ndarray | None = None,
                           count: int = 33) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Window minima by evaluating a limit on samples of each window.

    The samples are each window's ends, the computed speeds inside it and
    the points of a geometric ladder of speeds inside it, the ladder's step
    the window's relative width over ``count - 1`` rounded down to a fixed
    scale (``2**(k/8)``): windows of one relative width (a speed tolerance)
    share their samples, within one call and between calls.

    Parameters
    ----------
    evaluate : callable
        ``evaluate(speeds_rpm) -> (depth_m, chatter_hz)``.
    lo, hi : array_like
        Window ends in rpm (plain numbers): finite, positive, one number or
        a 1-D array each, of the same length, ``lo <= hi``.
    speeds : array_like, optional
        Computed speeds [rpm]; those inside a window are evaluated too.
    count : int, default 33
        Fewest samples per window, its ends included: a whole number >= 2.

    Raises
    ------
    InvalidValueError
        For windows that are empty, not finite, not positive, reversed or
        of different lengths, and for a ``count`` that is not a whole
        number >= 2.

    Returns
    -------
    (depth_m, speed_rpm, chatter_hz) : ndarrays
        Per window: the lowest sampled limit, where, and its chatter frequency.
    """
    if isinstance(count, bool) or not isinstance(count, (int, np.integer)) or count < 2:
        raise InvalidValueError(
            f"count: got {count!r}; expected a whole number >= 2 (samples per window, its ends included)")
    lo, hi = (_window_ends(_plain_numbers(v, f), f) for v, f in ((lo, "lo"), (hi, "hi")))
    for ends, field in ((lo, "lo"), (hi, "hi")):
        if np.any(ends <= 0):
            raise InvalidValueError(f"{field}: got {ends[ends <= 0][0]:g}; expected positive speeds in rpm")
    _check_windows(lo, hi, "lo, hi")
    if speeds is not None:
        speeds = _plain_numbers(speeds, "speeds").ravel()
    extra = []
    for a, b in zip(lo, hi):
        ladder = np.empty(0)
        if b > a:
            step = 2.0 ** (np.floor(8.0 * np.log2(np.log(b / a) / (count - 1))) / 8.0)
            ladder = np.exp(np.arange(np.ceil(np.log(a) / step), np.floor(np.log(b) / step) + 1) * step)
        inside = speeds[(speeds > a) & (speeds < b)] if speeds is not None else np.empty(0)
        extra.append(np.unique(np.concatenate([[a, b], ladder[(ladder > a) & (ladder < b)], inside])))
    flat = np.concatenate(extra)
    depth, chatter = evaluate(flat)
    bounds = np.cumsum([0] + [e.size for e in extra])
    out = np.empty(lo.size), np.empty(lo.size), np.empty(lo.size)
    for w in range(lo.size):
        d = depth[bounds[w]:bounds[w + 1]]
        k = int(np.argmin(d))
        out[0][w], out[1][w], out[2][w] = d[k], flat[bounds[w] + k], chatter[bounds[w] + k]
    return out


def lobes_band(results: Sequence[Lobes], nominal: Lobes | None = None, label: str | None = None) -> LobesBand:
    """The band spanned by several lobe diagrams on the same speeds.

    Parameters
    ----------
    results : sequence of Lobes
        E.g. lobes from FRFs at the ends of (or sampled from) an FRF
        uncertainty band.
    nominal : Lobes, optional
        The result drawn as a line; default: none.
    label : str, optional
        Legend label.

    Returns
    -------
    LobesBand
        The lowest and highest depth limit (m) at each speed (rpm).
    """
    results = [] if isinstance(results, Lobes) else items_of(results, "results", "Lobes")
    if not results or not all(isinstance(r, Lobes) for r in results):
        raise InvalidValueError("results: expected one or more Lobes")
    speeds = results[0].spindle_speed_rpm
    for r in results[1:] + ([nominal] if nominal is not None else []):
        if not np.array_equal(r.spindle_speed_rpm, speeds):
            raise InvalidValueError("results: every Lobes must be on the same spindle speeds")
    depths = np.array([r.depth_limit_m for r in results])
    return LobesBand(speeds, depths.min(axis=0), depths.max(axis=0), nominal=nominal, members=results, label=label)
