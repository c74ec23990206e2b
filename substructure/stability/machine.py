"""The machine's limits and what a cut asks of them: spindle speed, power, torque, depth.

:class:`MachineLimits` holds what the spindle can do (all optional, units on
every value): the speed range, the power and the torque (each a constant or
a curve over speed) and the largest axial depth.  :func:`cut_power` gives
the average cutting power of a milling cut from its tangential force law,
:func:`removal_rate` the material removal rate; both need the feed per
tooth.

The average power (straight teeth, chip thickness ``h = c sin(phi)``):

``P = a n N / 60 * R * integral_{phi_st}^{phi_ex} f_t(c sin phi) dphi``

with ``f_t`` the tangential force per unit depth (``Kt h + Kte`` for the
linear model), ``R`` the tool radius, ``N`` the teeth, ``n`` the speed in
rpm.  For the linear model this is ``P = Kt * MRR + Kte a R N n/60
(phi_ex - phi_st)``: the specific cutting energy times the removal rate
plus the edge (ploughing) power.  The radial force does no work.
"""

from __future__ import annotations

from typing import Any

import attrs
import numpy as np
import pint

from ..errors import InvalidValueError
from ..units import Q_, quantity, show_value
from .speeds import as_speed_rpm

__all__ = ["MachineLimits", "SpeedCurve", "cut_power", "removal_rate", "cut_torque"]


def _speed_value(field: str):
    def convert(value: Any) -> float | None:
        if value is None:
            return None
        return float(as_speed_rpm(value, field)[0])

    return convert


@attrs.frozen
class SpeedCurve:
    """A quantity given as a curve over spindle speed, linear between its points.

    Parameters
    ----------
    speed_rpm : ndarray
        Spindle speeds in rpm, increasing (0 allowed).
    value : pint.Quantity
        The values at these speeds (e.g. power in kW, torque in N m), an array.

    Notes
    -----
    Outside its speed range a curve gives 0: the spindle is not rated
    there, so no cut is allowed.
    """

    speed_rpm: np.ndarray
    value: pint.Quantity

    def at(self, speed_rpm: Any, unit: str) -> np.ndarray:
        """Values at speeds, linear between the curve's points, 0 outside its range.

        Parameters
        ----------
        speed_rpm : array_like
            Spindle speeds in rpm.
        unit : str
            Unit of the values returned (e.g. ``"W"``).

        Returns
        -------
        ndarray
            The values in ``unit``.
        """
        n = np.asarray(speed_rpm, dtype=float)
        v = self.value.m_as(unit)
        inside = (n >= self.speed_rpm[0] * (1 - 1e-12)) & (n <= self.speed_rpm[-1] * (1 + 1e-12))
        return np.where(inside, np.interp(n, self.speed_rpm, v), 0.0)


def _limit(field: str, dimension: str, unit: str):
    def convert(value: Any) -> pint.Quantity | SpeedCurve | None:
        if value is None or isinstance(value, SpeedCurve):
            return value
        if isinstance(value, (str, pint.Quantity)) and np.ndim(getattr(value, "magnitude", 0)) == 0:
            q = quantity(value, field, dimension)
            if not q.magnitude > 0:
                raise InvalidValueError(f"{field}: got {show_value(value)}; expected a positive value")
            return q
        try:
            speeds, values = value if len(value) == 2 and not isinstance(value[0], (tuple, list)) else zip(*value)
        except (TypeError, ValueError):
            raise InvalidValueError(
                f"{field}: got {show_value(value)}; expected a constant ('15 kW') or a curve: (speeds, values) as two "
                "quantity arrays, or a list of (speed, value) pairs") from None
        speed_rpm = _curve_speeds(_stack([speeds] if isinstance(speeds, str) else speeds, f"{field} speeds"),
                                  f"{field} speeds")
        vals = _stack(values, f"{field} values")
        if not vals.check(dimension):
            raise InvalidValueError(f"{field}: the curve's values are in {vals.units}; expected {unit}")
        if vals.magnitude.shape != speed_rpm.shape or speed_rpm.size < 2:
            raise InvalidValueError(f"{field}: expected two or more (speed, value) points, as many values as speeds")
        if np.any(~np.isfinite(vals.magnitude)) or np.any(vals.magnitude < 0):
            raise InvalidValueError(f"{field}: expected finite values >= 0 on the curve")
        return SpeedCurve(speed_rpm, vals)

    return convert


def _curve_speeds(q: pint.Quantity, field: str) -> np.ndarray:
    """Curve speeds in rpm: an angular-speed unit, >= 0, strictly increasing (0 rpm allowed)."""
    as_speed_rpm(Q_(1.0, str(q.units)), field)  # the unit check (Hz refused)
    n = q.m_as("rpm")
    if np.any(~np.isfinite(n)) or np.any(n < 0) or np.any(np.diff(n) <= 0):
        raise InvalidValueError(f"{field}: expected speeds >= 0, strictly increasing")
    return n


def _stack(values: Any, field: str) -> pint.Quantity:
    if isinstance(values, pint.Quantity):
        return Q_(np.atleast_1d(values.magnitude).astype(float), str(values.units))
    try:
        items = [Q_(v) if isinstance(v, str) else v for v in values]
        unit = str(items[0].units) if items and all(isinstance(v, pint.Quantity) for v in items) else None
        if unit is not None:
            return Q_(np.array([v.m_as(unit) for v in items], dtype=float), unit)
    except (TypeError, ValueError, pint.errors.PintError):  # not a sequence; text no unit; units of two kinds
        pass
    raise InvalidValueError(f"{field}: got {show_value(values)}; expected quantities with units of one kind, e.g. "
                            "'15 kW' or '6000 rpm'")


@attrs.frozen
class MachineLimits:
    """What the machine allows; every value optional (``None``: no limit).

    Parameters
    ----------
    max_speed, min_speed : quantity or str, optional
        Spindle speed range, e.g. ``"24000 rpm"``.
    power : quantity, str or curve, optional
        Spindle power available at the tool: a constant (``"15 kW"``) or a
        curve over speed, given as ``(speeds, powers)`` (two quantity arrays)
        or a list of ``(speed, power)`` pairs; linear between points, zero
        outside the curve's speeds.
    torque : quantity, str or curve, optional
        Spindle torque, likewise (``"60 N*m"``).  With both, the available
        power at speed ``n`` is ``min(P(n), T(n) * 2 pi n / 60)``.
    max_depth : quantity or str, optional
        Largest axial depth of cut (the machine's, or the tool's flute length).

    Examples
    --------
    >>> limits = MachineLimits(max_speed="24000 rpm", power="15 kW", torque="40 N*m")
    >>> round(float(limits.available_power_w(1000.0)), 1)    # torque-limited at low speed
    4188.8
    """

    max_speed: float | None = attrs.field(default=None, converter=_speed_value("max_speed"))
    min_speed: float | None = attrs.field(default=None, converter=_speed_value("min_speed"))
    power: Any = attrs.field(default=None, converter=_limit("power", "[power]", "W"))
    torque: Any = attrs.field(default=None, converter=_limit("torque", "[force] * [length]", "N*m"))
    max_depth: pint.Quantity | None = attrs.field(default=None, converter=attrs.converters.optional(
        lambda v: _positive_length(v, "max_depth")))

    def __attrs_post_init__(self) -> None:
        if self.max_speed is not None and self.min_speed is not None and self.min_speed >= self.max_speed:
            raise InvalidValueError(f"min_speed: {self.min_speed:g} rpm is not below max_speed {self.max_speed:g} rpm")

    @property
    def max_depth_m(self) -> float:
        """The depth limit in m (``inf`` without one)."""
        return np.inf if self.max_depth is None else float(self.max_depth.m_as("m"))

    def power_w(self, speed_rpm: Any) -> np.ndarray:
        """Rated power [W] at speeds [rpm] (``inf`` without a power limit).

        Parameters
        ----------
        speed_rpm : array_like
            Spindle speeds in rpm.

        Returns
        -------
        ndarray
            Rated power in W (``inf`` without a limit).
        """
        return _value_at(self.power, speed_rpm, "W")

    def torque_nm(self, speed_rpm: Any) -> np.ndarray:
        """Rated torque [N m] at speeds [rpm] (``inf`` without a torque limit).

        Parameters
        ----------
        speed_rpm : array_like
            Spindle speeds in rpm.

        Returns
        -------
        ndarray
            Rated torque in N m (``inf`` without a limit).
        """
        return _value_at(self.torque, speed_rpm, "N*m")

    def available_power_w(self, speed_rpm: Any) -> np.ndarray:
        """``min(P(n), T(n) omega)`` [W] at speeds [rpm].

        Parameters
        ----------
        speed_rpm : array_like
            Spindle speeds in rpm.

        Returns
        -------
        ndarray
            Available power in W.
        """
        n = np.asarray(speed_rpm, dtype=float)
        return np.minimum(self.power_w(n), self.torque_nm(n) * 2.0 * np.pi * n / 60.0)

    def speed_ok(self, speed_rpm: Any) -> np.ndarray:
        """Whether speeds [rpm] lie in ``[min_speed, max_speed]``.

        Parameters
        ----------
        speed_rpm : array_like
            Spindle speeds in rpm.

        Returns
        -------
        ndarray
            True where the speed is allowed.
        """
        n = np.asarray(speed_rpm, dtype=float)
        ok = np.ones(n.shape, dtype=bool)
        if self.max_speed is not None:
            ok &= n <= self.max_speed * (1 + 1e-12)
        if self.min_speed is not None:
            ok &= n >= self.min_speed * (1 - 1e-12)
        return ok

    def to_json(self) -> dict:
        """The limits in SI numbers (curves as lists of points).

        Returns
        -------
        dict
            ``max_speed_rpm``, ``min_speed_rpm``, ``power_w``, ``torque_n_m``, ``max_depth_m``.
        """
        def value(v, unit):
            if v is None:
                return None
            if isinstance(v, SpeedCurve):
                return {"spindle_speed_rpm": v.speed_rpm.tolist(), "values": v.value.m_as(unit).tolist()}
            return float(v.m_as(unit))

        return {"max_speed_rpm": self.max_speed, "min_speed_rpm": self.min_speed, "power_w": value(self.power, "W"),
                "torque_n_m": value(self.torque, "N*m"), "max_depth_m": value(self.max_depth, "m")}


def _positive_length(value: Any, field: str) -> pint.Quantity:
    q = quantity(value, field, "[length]")
    if not q.magnitude > 0:
        raise InvalidValueError(f"{field}: got {show_value(value)}; expected a positive length")
    return q


def _value_at(limit: Any, speed_rpm: Any, unit: str) -> np.ndarray:
    n = np.asarray(speed_rpm, dtype=float)
    if limit is None:
        return np.full(n.shape, np.inf)
    if isinstance(limit, SpeedCurve):
        return limit.at(n, unit)
    return np.full(n.shape, float(limit.m_as(unit)))


# -- what a cut asks ------------------------------------------------------------------------

_GAUSS = np.polynomial.legendre.leggauss(64)


def _feed(cut: Any) -> float:
    c = getattr(cut, "feed_per_tooth", None)
    if c is None:
        raise InvalidValueError(
            "feed_per_tooth: the cut has none; power, torque and removal rate need the feed per tooth "
            "(MillingCut(..., feed_per_tooth='0.1 mm'), --feed-per-tooth)")
    return float(c.m_as("m"))


def _tangential_law(cut: Any):
    work = getattr(cut, "workpiece", None)
    if work is not None and work.model == "kienzle":
        return work.tangential_force_per_depth
    kt, kte = cut.kt_pa, float(cut.kte.m_as("N/m"))
    return lambda h: kt * h + np.where(h > 0, kte, 0.0)


def cut_power(cut: Any, depth_m: Any, speed_rpm: Any) -> np.ndarray:
    """Average cutting power [W] of a milling cut at depths [m] and speeds [rpm] (broadcast).

    Parameters
    ----------
    cut : MillingCut
        With ``feed_per_tooth``; the tangential force law is the workpiece's
        (Kienzle) or ``Kt h + Kte``.
    depth_m : array_like
        Axial depths of cut in m.
    speed_rpm : array_like
        Spindle speeds in rpm.

    Returns
    -------
    ndarray
        ``a n N / 60 * R * integral f_t(c sin phi) dphi`` over the engagement
        (64-point Gauss-Legendre, exact to rounding for the linear law).
    """
    if not hasattr(cut, "angles") or not hasattr(cut, "diameter"):
        raise InvalidValueError(f"cut: got {type(cut).__name__}; power and removal rate are for milling cuts")
    c = _feed(cut)
    st, ex = cut.angles
    x, w = _GAUSS
    phi = 0.5 * (ex - st) * x + 0.5 * (ex + st)
    integral = 0.5 * (ex - st) * float(np.sum(w * _tangential_law(cut)(c * np.sin(phi))))
    radius = 0.5 * float(cut.diameter.m_as("m"))
    return np.asarray(depth_m, dtype=float) * np.asarray(speed_rpm, dtype=float) * cut.teeth / 60.0 * radius * integral


def cut_torque(cut: Any, depth_m: Any, speed_rpm: Any) -> np.ndarray:
    """Average spindle torque of the cut: power / (2 pi n / 60).

    Parameters
    ----------
    cut : MillingCut
        With ``feed_per_tooth``.
    depth_m, speed_rpm : array_like
        Axial depths [m] and spindle speeds [rpm] (broadcast).

    Returns
    -------
    ndarray
        Torque in N m.
    """
    n = np.asarray(speed_rpm, dtype=float)
    return cut_power(cut, depth_m, n) / (2.0 * np.pi * n / 60.0)


def removal_rate(cut: Any, depth_m: Any, speed_rpm: Any) -> np.ndarray:
    """Material removal rate [m^3/s]: ``a * a_e * N * c * n / 60``.

    Parameters
    ----------
    cut : MillingCut
        With ``feed_per_tooth``.
    depth_m, speed_rpm : array_like
        Axial depths [m] and spindle speeds [rpm] (broadcast).

    Returns
    -------
    ndarray
        Removal rate in m^3/s.
    """
    c = _feed(cut)
    return (np.asarray(depth_m, dtype=float) * float(cut.radial_depth.m_as("m")) * cut.teeth * c
            * np.asarray(speed_rpm, dtype=float) / 60.0)
