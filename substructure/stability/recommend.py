"""The machinist's answer: a spindle speed and an axial depth, with a stated margin.

:func:`recommend` reads a lobe diagram (and, where one exists, the lobes of
an FRF uncertainty band) and chooses the speed and depth that remove the
most material while staying stable with a margin:

* **Speed window.**  A speed ``n`` is considered with its window
  ``[n (1 - x), n (1 + x)]``, ``x = speed_tolerance``: the lobes move when
  the natural frequency does (a sensor's mass, temperature, a joint), and a
  speed at the sharp tip of a lobe is stable only there.  The limit used is
  the lowest over the whole window (exact for zero-order lobes, see
  :meth:`~substructure.stability.Lobes.window_minimum`), and over every
  member of the uncertainty band.
* **Depth margin.**  The recommended depth is ``(1 - margin)`` times that
  lowest limit, so that at every speed of the window (and for every FRF of
  the band) the depth is below the limit by at least the fraction
  ``margin`` of it.
* **Machine.**  The depth is also kept below the machine's (or the tool's)
  largest depth and below the depth whose cutting power or torque would
  exceed the spindle's at that speed (:mod:`~substructure.stability.machine`).
* **Choice.**  Among the speeds whose window lies inside the computed
  range and the machine's speed range, the one with the largest removal
  rate ``a * n`` wins; the runners-up are the best of the other pockets of
  the diagram (pockets are split at the minima of the limit).

A speed whose limiting chatter frequency lies on a rigid-body or suspension
line (``Lobes.band``) is never recommended.
"""

from __future__ import annotations

from typing import Any

import attrs
import numpy as np

from ..errors import InvalidValueError
from ..units import whole_number
from .machine import MachineLimits, cut_power, cut_torque, removal_rate

__all__ = ["Recommendation", "recommend", "RECOMMENDATION_KEYS", "NoRecommendationError"]


class NoRecommendationError(InvalidValueError):
    """The lobes are fine, but no operating point can be recommended from them.

    Raised by :func:`recommend` when no computed speed has its whole window
    inside the computed range and the machine's speed range, when no limit
    at all bounds the depth, or when every candidate chatters on a
    rigid-body line.  The message says which; a command prints the lobes
    and gives the message as the reason (``"recommended": null``).
    """

#: The keys of ``Recommendation.to_json()`` that the ``recommended`` object of
#: ``substructure lobes --json`` always has.
RECOMMENDATION_KEYS = ("spindle_speed_rpm", "depth_m", "limit_depth_m", "margin", "mrr_m3_per_s",
                       "chatter_frequency_hz")


@attrs.frozen
class Recommendation:
    """A recommended operating point.

    Parameters
    ----------
    spindle_speed_rpm : float
        The speed [rpm].
    depth_m : float
        The axial depth of cut [m].
    limit_depth_m : float
        The lowest stability limit [m] over the speed window (and the FRF
        band); ``depth_m <= (1 - margin) * limit_depth_m``.
    margin : float
        The stated margin: the fraction of the limit kept in reserve.
    mrr_m3_per_s : float or None
        Material removal rate [m^3/s] (``None`` without a feed per tooth).
    chatter_frequency_hz : float
        The chatter frequency [Hz] where the window's limit is reached.
    speed_tolerance : float
        ``x`` of the window ``n (1 +- x)``.
    window_rpm : (float, float)
        The speed window checked [rpm].
    limit_at_speed_m : float
        The nominal limit at the recommended speed itself [m].
    limiting_speed_rpm : float
        Where in the window the lowest limit is [rpm].
    limited_by : str
        What set the depth: ``"stability"``, ``"max depth"``, ``"power"`` or
        ``"torque"``.
    power_w, torque_n_m : float or None
        The cut's average power [W] and torque [N m] (with a feed per tooth).
    available_power_w : float
        What the spindle offers at that speed [W] (``inf``: no limit given).
    band_members : int
        How many lobe diagrams the window was checked on (1 + the band's).
    cutting_speed_m_per_min : float or None
        The cutting (surface) speed ``pi D n`` [m/min].
    feed_per_tooth_m : float or None
        The cut's feed per tooth [m] (None without one).
    feed_rate_m_per_min : float or None
        The table feed ``f_z z n`` [m/min] (None without a feed per tooth).
    runners_up : tuple of Recommendation
        The best choices of other pockets, best first.
    """

    spindle_speed_rpm: float
    depth_m: float
    limit_depth_m: float
    margin: float
    mrr_m3_per_s: float | None
    chatter_frequency_hz: float
    speed_tolerance: float
    window_rpm: tuple
    limit_at_speed_m: float
    limiting_speed_rpm: float
    limited_by: str
    power_w: float | None = None
    torque_n_m: float | None = None
    available_power_w: float = float("inf")
    band_members: int = 1
    cutting_speed_m_per_min: float | None = None
    feed_per_tooth_m: float | None = None
    feed_rate_m_per_min: float | None = None
    runners_up: tuple = attrs.field(default=(), converter=tuple)

    @property
    def reserve(self) -> float:
        """``1 - depth / limit_depth``: the margin actually kept (>= ``margin``)."""
        return 1.0 - self.depth_m / self.limit_depth_m if np.isfinite(self.limit_depth_m) else 1.0

    def to_json(self, runners_up: bool = True) -> dict:
        """The ``recommended`` object of ``substructure lobes --json`` (SI units, rpm).

        Parameters
        ----------
        runners_up : bool, default True
            Include the runners-up (each without its own).

        Returns
        -------
        dict
            The keys of :data:`RECOMMENDATION_KEYS` first, then the details.
        """
        def num(v):
            return None if v is None or not np.isfinite(v) else float(v)

        out = {
            "spindle_speed_rpm": float(self.spindle_speed_rpm),
            "depth_m": float(self.depth_m),
            "limit_depth_m": num(self.limit_depth_m),
            "margin": float(self.margin),
            "mrr_m3_per_s": num(self.mrr_m3_per_s),
            "chatter_frequency_hz": num(self.chatter_frequency_hz),
            "speed_tolerance": float(self.speed_tolerance),
            "window_rpm": [float(v) for v in self.window_rpm],
            "limit_at_speed_m": num(self.limit_at_speed_m),
            "limiting_speed_rpm": float(self.limiting_speed_rpm),
            "limited_by": self.limited_by,
            "reserve": float(self.reserve),
            "power_w": num(self.power_w),
            "torque_n_m": num(self.torque_n_m),
            "available_power_w": num(self.available_power_w),
            "band_members": self.band_members,
            "cutting_speed_m_per_min": num(self.cutting_speed_m_per_min),
            "cutting_speed_sfm": None if self.cutting_speed_m_per_min is None
            else float(self.cutting_speed_m_per_min / 0.3048),
            "feed_per_tooth_m": num(self.feed_per_tooth_m),
            "feed_rate_m_per_min": num(self.feed_rate_m_per_min),
        }
        if runners_up:
            out["runners_up"] = [r.to_json(runners_up=False) for r in self.runners_up]
        return out

    def describe(self) -> list[str]:
        """Lines for the human output, in rpm and mm.

        Returns
        -------
        list of str
            The recommendation, its limit and margin, the chatter frequency, the power.
        """
        lo, hi = self.window_rpm
        lines = [f"{self.spindle_speed_rpm:.0f} rpm, axial depth {self.depth_m * 1e3:.3g} mm"
                 + (f", removal rate {self.mrr_m3_per_s * 6e7:.4g} cm^3/min" if self.mrr_m3_per_s is not None else "")]
        limit = (f"{self.limit_depth_m * 1e3:.3g} mm" if np.isfinite(self.limit_depth_m) else "none found")
        lines.append(f"stability limit {limit} at worst within {lo:.0f}..{hi:.0f} rpm "
                     f"(+-{self.speed_tolerance:.0%})"
                     + (f" and over {self.band_members} FRFs of the uncertainty band" if self.band_members > 1 else "")
                     + f"; margin {self.margin:.0%} (depth = {1 - self.reserve:.0%} of that limit; "
                     f"set by {self.limited_by})")
        if np.isfinite(self.chatter_frequency_hz):
            lines.append(f"chatter there would be at {self.chatter_frequency_hz:.5g} Hz; the limit at "
                         f"{self.spindle_speed_rpm:.0f} rpm itself is {self.limit_at_speed_m * 1e3:.3g} mm")
        if self.cutting_speed_m_per_min is not None:
            vc = self.cutting_speed_m_per_min
            feed = ("" if self.feed_per_tooth_m is None else
                    f", feed {self.feed_per_tooth_m * 1e3:.3g} mm/tooth = {self.feed_rate_m_per_min * 1e3:.4g} mm/min")
            lines.append(f"cutting speed {vc:.0f} m/min ({vc / 0.3048:.0f} SFM){feed}")
        if self.power_w is not None:
            avail = (f" of {self.available_power_w / 1e3:.3g} kW available" if np.isfinite(self.available_power_w)
                     else "")
            lines.append(f"cutting power {self.power_w / 1e3:.3g} kW{avail}, torque {self.torque_n_m:.3g} N m")
        return lines


def _check(value: Any, field: str, lo: float, hi: float) -> float:
    try:
        v = float(value)
    except (TypeError, ValueError, OverflowError):
        v = np.nan
    if not lo <= v < hi:
        raise InvalidValueError(f"{field}: got {value!r}; expected a number in [{lo:g}, {hi:g})")
    return v


def _same_cut(a: Any, b: Any) -> bool:
    keys = ("teeth", "immersion", "milling", "kt_pa", "kn_pa")
    return all(np.isclose(getattr(a, k), getattr(b, k), rtol=1e-9) if isinstance(getattr(a, k), float)
               else getattr(a, k) == getattr(b, k) for k in keys)


def _pockets(depth: np.ndarray) -> np.ndarray:
    """Pocket label of each speed: the count of local minima of the limit to its left."""
    d = np.where(np.isfinite(depth), depth, np.nanmax(np.where(np.isfinite(depth), depth, np.nan)) * 10
                 if np.isfinite(depth).any() else 1.0)
    minima = np.zeros(d.size, dtype=int)
    if d.size > 2:
        minima[1:-1] = (d[1:-1] < d[:-2]) & (d[1:-1] <= d[2:])
    return np.cumsum(minima)


def recommend(lobes: Any, cut: Any, limits: MachineLimits | None = None, *, margin: float = 0.2,
              speed_tolerance: float = 0.03, band: Any = None, count: int = 3) -> Recommendation:
    """The recommended spindle speed and depth of cut, with a margin.

    Parameters
    ----------
    lobes : Lobes
        The stability lobes of the cut (zero order or semi-discretization).
    cut : MillingCut
        The cut of the lobes; with ``feed_per_tooth`` for the removal rate,
        power and torque (required when ``limits`` has a power or torque).
    limits : MachineLimits, optional
        Speed range, power, torque and largest depth; none by default.
    margin : float, default 0.2
        Fraction of the stability limit kept in reserve: the depth is at most
        ``(1 - margin)`` times the lowest limit of the window.
    speed_tolerance : float, default 0.03
        ``x``: the speed must stay stable (with the margin) over
        ``n (1 +- x)``.
    band : LobesBand, optional
        Lobes of an FRF uncertainty band on the same speeds: the window must
        hold for every member (:func:`~substructure.stability.lobes_band`).
    count : int, default 3
        The recommendation and up to ``count - 1`` runners-up.

    Returns
    -------
    Recommendation
        The best speed and depth, with its runners-up.

    Raises
    ------
    InvalidValueError
        For a margin outside ``[0, 1)``, a tolerance outside ``[0, 0.5)``, a
        cut other than the lobes', and power or torque limits without a feed
        per tooth.
    NoRecommendationError
        (an ``InvalidValueError``) When no speed's whole window
        ``n (1 +- x)`` fits the computed range and the machine's speed range,
        or nothing bounds the depth, or the lobes' FRF data end on the flank
        of a mode above their band (``FlexibleBand.above``): the lobes stand,
        the recommendation is absent, and the message says why.
    """
    from .result import Lobes, LobesBand

    if not isinstance(lobes, Lobes):
        raise InvalidValueError(f"lobes: got {type(lobes).__name__}; expected Lobes (zoa or sdm)")
    margin = _check(margin, "margin", 0.0, 1.0)
    x = _check(speed_tolerance, "speed_tolerance", 0.0, 0.5)
    whole_number(count, "count", 1, "a whole number of speeds (the recommendation and its runners-up)")
    if not hasattr(cut, "radial_depth"):
        raise InvalidValueError(f"cut: got {type(cut).__name__}; a recommendation is for a milling cut (MillingCut)")
    if lobes.cut is not None and hasattr(lobes.cut, "radial_depth") and not _same_cut(lobes.cut, cut):
        raise InvalidValueError("cut: it is not the cut the lobes were computed for (teeth, immersion, milling, "
                                "Kt or Kn differ)")
    above = getattr(lobes.band, "above", None)
    if above:  # the lobes stand, drawn from what was measured; a depth to cut at would ignore the mode above
        raise NoRecommendationError(f"a mode lies above the FRF's band ({above}): its limit is unknown; measure "
                                    "the FRF beyond it")
    limits = MachineLimits() if limits is None else limits
    if not isinstance(limits, MachineLimits):
        raise InvalidValueError(f"limits: got {type(limits).__name__}; expected MachineLimits")
    has_feed = getattr(cut, "feed_per_tooth", None) is not None
    if (limits.power is not None or limits.torque is not None) and not has_feed:
        raise InvalidValueError("feed_per_tooth: checking the spindle's power or torque needs the cut's feed per "
                                "tooth (MillingCut(..., feed_per_tooth='0.1 mm'), --feed-per-tooth)")
    members = [lobes]
    if band is not None:
        if not isinstance(band, LobesBand):
            raise InvalidValueError(f"band: got {type(band).__name__}; expected a LobesBand")
        if not np.array_equal(band.spindle_speed_rpm, lobes.spindle_speed_rpm):
            raise InvalidValueError("band: its lobes are on other spindle speeds than lobes")
        members += [m for m in band.members if m is not lobes]
    speeds = lobes.spindle_speed_rpm
    lo, hi = speeds * (1 - x), speeds * (1 + x)
    # the whole window, not only its centre, must lie inside the computed speeds and the machine's range
    eligible = ((lo >= speeds[0] * (1 - 1e-12)) & (hi <= speeds[-1] * (1 + 1e-12)) & limits.speed_ok(lo)
                & limits.speed_ok(hi))
    if not eligible.any():
        machine = "".join(f", {name} {v:g} rpm" for name, v in (("min speed", limits.min_speed),
                                                                 ("max speed", limits.max_speed)) if v is not None)
        raise NoRecommendationError(
            f"speeds: no computed speed has its whole window n(1 +- {x:g}) inside the computed range "
            f"{speeds[0]:g}..{speeds[-1]:g} rpm and the machine's speed range{machine}; widen the speeds "
            "(or lower --speed-tolerance)")
    # per speed: a bound on the window's limit from the computed speeds (exact minima come later)
    sampled = np.min([m.depth_limit_m for m in members], axis=0)
    first = np.searchsorted(speeds, lo, side="left")
    last = np.searchsorted(speeds, hi, side="right")
    coarse = np.array([sampled[a:b].min() if b > a else np.inf for a, b in zip(first, last)])
    per_depth_power = cut_power(cut, 1.0, speeds) if has_feed else np.zeros(speeds.size)
    per_depth_torque = cut_torque(cut, 1.0, speeds) if has_feed else np.zeros(speeds.size)
    with np.errstate(divide="ignore", invalid="ignore"):
        power_depth = np.where(per_depth_power > 0, limits.power_w(speeds) / per_depth_power, np.inf)
        torque_depth = np.where(per_depth_torque > 0, limits.torque_nm(speeds) / per_depth_torque, np.inf)
    machine_depth = np.minimum(np.minimum(power_depth, torque_depth), limits.max_depth_m)

    def depth_of(window_limit: np.ndarray, idx: np.ndarray) -> np.ndarray:
        return np.minimum((1.0 - margin) * window_limit, machine_depth[idx])

    order = np.flatnonzero(eligible)
    bound = depth_of(coarse[order], order) * speeds[order]
    finite = np.isfinite(bound)
    if not finite.any():
        raise NoRecommendationError("lobes: no stability limit found in any speed window and no largest depth, power "
                                "or torque limit given; give limits=MachineLimits(max_depth=...) "
                                "(--max-depth on the command line)")
    order, bound = order[finite], bound[finite]  # no limit at all there: nothing to recommend
    order = order[np.argsort(-bound, kind="stable")]
    bound = np.sort(bound)[::-1]
    pockets = _pockets(lobes.depth_limit_m)
    exact: dict[int, tuple[float, float, float]] = {}
    zero_order = all(getattr(m.source, "critical", None) is not None for m in members)
    batch = order.size if zero_order else 4
    chosen: list[int] = []
    position = 0

    def settle() -> None:  # exact window minima for the next batch of candidates
        nonlocal position
        idx = order[position:position + batch]
        position += idx.size
        results = [m.window_minimum(lo[idx], hi[idx]) for m in members]
        for k, i in enumerate(idx):
            best = min(range(len(results)), key=lambda r: results[r][0][k])
            exact[int(i)] = (float(results[best][0][k]), float(results[best][1][k]), float(results[best][2][k]))

    def excluded(i: int) -> bool:
        f = exact[i][2]
        return any(m.band is not None and m.band.excluded_hz is not None and np.isfinite(f)
                   and f < m.band.lo_hz * (1 - 1e-12) for m in members)

    while len(chosen) < count:
        taken = {int(pockets[c]) for c in chosen}
        scored = [(depth_of(np.array([exact[i][0]]), np.array([i]))[0] * speeds[i], i) for i in exact
                  if int(pockets[i]) not in taken and not excluded(i)]
        best = max(scored, default=None)
        rest = bound[position] if position < order.size else -np.inf
        if best is not None and best[0] >= rest:
            chosen.append(best[1])
            continue
        if position >= order.size:
            break
        settle()
    if not chosen:
        raise NoRecommendationError("lobes: every candidate speed is limited by chatter on a rigid-body or suspension "
                                "line; check the structure band")
    results = []
    for i in chosen:
        limit, where, chatter = exact[i]
        depth = float(depth_of(np.array([limit]), np.array([i]))[0])
        reasons = {"stability": (1 - margin) * limit, "max depth": limits.max_depth_m,
                   "power": power_depth[i], "torque": torque_depth[i]}
        results.append(Recommendation(
            spindle_speed_rpm=float(speeds[i]), depth_m=depth, limit_depth_m=limit, margin=margin,
            mrr_m3_per_s=float(removal_rate(cut, depth, speeds[i])) if has_feed else None,
            chatter_frequency_hz=chatter, speed_tolerance=x, window_rpm=(float(lo[i]), float(hi[i])),
            limit_at_speed_m=float(lobes.depth_limit_m[i]), limiting_speed_rpm=where,
            limited_by=min(reasons, key=reasons.get),
            power_w=float(per_depth_power[i] * depth) if has_feed else None,
            torque_n_m=float(per_depth_torque[i] * depth) if has_feed else None,
            available_power_w=float(limits.available_power_w(speeds[i])), band_members=len(members),
            cutting_speed_m_per_min=float(np.pi * cut.diameter.m_as("m") * speeds[i]),
            feed_per_tooth_m=float(cut.feed_per_tooth.m_as("m")) if has_feed else None,
            feed_rate_m_per_min=float(cut.feed_per_tooth.m_as("m") * cut.teeth * speeds[i]) if has_feed else None))
    return attrs.evolve(results[0], runners_up=tuple(results[1:]))
