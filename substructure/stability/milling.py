"""Peripheral milling: :class:`MillingCut`, the time-varying force matrix of straight teeth.

Built from the teeth, the immersion (or radial depth) and the cutting
coefficients (Altintas & Budak 1995; Insperger & Stepan 2004), or from a
workpiece of the coefficient table; gives the instantaneous force matrix,
its exact averages over angle intervals for semi-discretization and its
zero-order mean.
"""

from __future__ import annotations

from typing import Any

import attrs
import numpy as np
import pint

from ..errors import InvalidValueError, UnitError
from ..units import Q_, dimensionless
from ._cut_fields import _edge, _length, _milling, _pressure, _teeth

__all__ = ["MillingCut"]


# -- the instantaneous force matrix and its antiderivative --------------------
#
# For a tooth at angle phi (measured clockwise from the y axis, x the feed),
# chip thickness h = (x - x_prev) sin(phi) + (y - y_prev) cos(phi) and
# Ft = Kt a h, Fr = Kn a h give F = a Kt k(phi) (r - r_prev) with
#   k = [[-(c + kr s) s, -(c + kr s) c], [(s - kr c) s, (s - kr c) c]],
# s = sin(phi), c = cos(phi), kr = Kn/Kt (Altintas & Budak 1995: k = A/2).


def _force_antiderivative(phi: np.ndarray, kr: float) -> np.ndarray:
    """Integral of ``k(phi)`` (per unit Kt), shape ``phi.shape + (2, 2)``."""
    s2 = np.sin(phi) ** 2
    half = phi / 2.0
    q = np.sin(2.0 * phi) / 4.0
    out = np.empty(np.shape(phi) + (2, 2))
    out[..., 0, 0] = -s2 / 2.0 - kr * (half - q)
    out[..., 0, 1] = -(half + q) - kr * s2 / 2.0
    out[..., 1, 0] = (half - q) - kr * s2 / 2.0
    out[..., 1, 1] = s2 / 2.0 - kr * (half + q)
    return out


def _force_matrix_at(phi: np.ndarray, kr: float) -> np.ndarray:
    """``k(phi)`` per unit Kt, shape ``phi.shape + (2, 2)``."""
    s, c = np.sin(phi), np.cos(phi)
    out = np.empty(np.shape(phi) + (2, 2))
    out[..., 0, 0] = -(c + kr * s) * s
    out[..., 0, 1] = -(c + kr * s) * c
    out[..., 1, 0] = (s - kr * c) * s
    out[..., 1, 1] = (s - kr * c) * c
    return out


@attrs.frozen
class MillingCut:
    """A peripheral milling cut with straight teeth (no helix), equally spaced.

    Parameters
    ----------
    teeth : int
        Number of teeth (flutes), >= 1.
    diameter : quantity or str
        Tool diameter, e.g. ``"12 mm"``.
    radial_depth : quantity or str
        Radial depth of cut (width of the cut seen from above), ``0 < a_e <= D``.
    kt : quantity or str
        Tangential cutting coefficient, a pressure (``"625 MPa"``).
    kn : quantity or str
        Normal (radial) cutting coefficient, a pressure (``"100 MPa"``), >= 0.
        Without helix and lead angle the radial force is the normal force, so
        a "Kr" given as a pressure is this ``kn``; a "Kr" given as a ratio is
        ``kn / kt`` (use :meth:`from_spec` with ``kr=``).
    milling : {"up", "down", "conventional", "climb"}
        Up (conventional) milling: the tooth enters at zero chip thickness;
        down (climb) milling: it leaves at zero chip thickness.  The shop's
        words are accepted and stored as ``"up"`` or ``"down"``; the default
        is up milling (kept for the results of earlier versions).
    feed_per_tooth : quantity or str, optional
        Feed per tooth (chip load), e.g. ``"0.1 mm"``.  Stability does not use
        it (the linear model has no static chip); the material removal rate
        and the cutting power do (:func:`~substructure.stability.recommend`).
    kte, kne : quantity or str, default "0 N/m"
        Edge (ploughing) force per unit length of cutting edge, tangential and
        normal (``"27.7 N/mm"``).  They add power, not regeneration.
    workpiece : Workpiece, optional
        Where the coefficients came from (:func:`~substructure.stability.workpiece`);
        a Kienzle entry also sets the force law used for the power.

    Notes
    -----
    Angles are measured clockwise from the ``y`` axis, ``x`` is the feed
    direction.  Up milling cuts from ``phi_st = 0`` to
    ``phi_ex = arccos(1 - 2 a_e/D)``, down milling from
    ``phi_st = arccos(2 a_e/D - 1)`` to ``phi_ex = pi`` (Altintas,
    *Manufacturing Automation*, ch. 3).

    Examples
    --------
    >>> cut = MillingCut(4, "12 mm", "3 mm", kt="625 MPa", kn="100 MPa", milling="up")
    >>> round(cut.immersion, 3), round(cut.kr, 3)
    (0.25, 0.16)
    """

    teeth: int = attrs.field(converter=_teeth)
    diameter: pint.Quantity = attrs.field(converter=_length("diameter"))
    radial_depth: pint.Quantity = attrs.field(converter=_length("radial_depth"))
    kt: pint.Quantity = attrs.field(kw_only=True, converter=_pressure("kt", allow_zero=False))
    kn: pint.Quantity = attrs.field(kw_only=True, converter=_pressure("kn", allow_zero=True))
    milling: str = attrs.field(default="up", kw_only=True, converter=_milling)
    feed_per_tooth: pint.Quantity | None = attrs.field(default=None, kw_only=True, converter=attrs.converters.optional(
        _length("feed_per_tooth")))
    kte: pint.Quantity = attrs.field(default="0 N/m", kw_only=True, converter=_edge("kte"))
    kne: pint.Quantity = attrs.field(default="0 N/m", kw_only=True, converter=_edge("kne"))
    workpiece: Any = attrs.field(default=None, kw_only=True, eq=False, repr=False)

    def __attrs_post_init__(self) -> None:
        d, ae = self.diameter.m_as("m"), self.radial_depth.m_as("m")
        if ae > d * (1.0 + 1e-12):
            raise InvalidValueError(
                f"radial_depth: got {self.radial_depth:~P}, larger than the tool diameter "
                f"{self.diameter:~P}; expected 0 < radial depth <= diameter (a slot is radial depth = diameter)"
            )

    @classmethod
    def from_spec(cls, teeth: Any, diameter: Any, *, radial_depth: Any = None, immersion: Any = None,
                  milling: str = "up", kt: Any, kn: Any = None, kr: Any = None, **extra: Any) -> MillingCut:
        """A cut from the alternatives users meet: radial depth or immersion, Kn or Kr.

        Parameters
        ----------
        teeth : int
            Number of teeth.
        diameter : quantity or str
            Tool diameter, a length (``"12 mm"``).
        radial_depth : quantity or str, optional
            Radial depth of cut, a length; or
        immersion : float, optional
            Radial immersion ratio ``a_e / D`` in ``(0, 1]``.
        milling : {"up", "down"}
            Up or down milling.
        kt : quantity or str
            Tangential cutting pressure (``"625 MPa"``).
        kn : quantity or str, optional
            Normal cutting pressure; or
        kr : float, optional
            The ratio ``Kn / Kt`` (dimensionless, >= 0).  A pressure given as
            ``kr`` is refused with a hint: give it as ``kn``.
        **extra
            ``feed_per_tooth``, ``kte``, ``kne``, ``workpiece`` as in the class.

        Returns
        -------
        MillingCut
            The cut.
        """
        if (radial_depth is None) == (immersion is None):
            raise InvalidValueError("radial_depth, immersion: give exactly one of them")
        if (kn is None) == (kr is None):
            raise InvalidValueError("kn, kr: give exactly one of kn (a pressure) and kr (the ratio Kn/Kt)")
        diameter = _length("diameter")(diameter)
        if immersion is not None:
            ratio = dimensionless(immersion, "immersion")
            if not 0.0 < ratio <= 1.0:
                raise InvalidValueError(
                    f"immersion: got {immersion!r}; expected the ratio a_e/D in (0, 1] "
                    "(a radial depth larger than the diameter is not a cut)"
                )
            radial_depth = diameter * ratio
        kt = _pressure("kt", allow_zero=False)(kt)
        if kr is not None:
            if isinstance(kr, (str, pint.Quantity)) and not Q_(kr).dimensionless:
                raise UnitError(
                    f"kr: got {kr!r}; kr is the ratio Kn/Kt (a plain number). "
                    f"For a radial cutting pressure use kn={kr!r}"
                )
            ratio = dimensionless(kr, "kr")
            if ratio < 0:
                raise InvalidValueError(f"kr: got {kr!r}; expected a ratio Kn/Kt >= 0")
            kn = kt * ratio
        return cls(teeth, diameter, radial_depth, kt=kt, kn=kn, milling=milling, **extra)

    @classmethod
    def for_workpiece(cls, teeth: Any, diameter: Any, workpiece: Any, *, radial_depth: Any = None,
                      immersion: Any = None, milling: str = "up", feed_per_tooth: Any = None, kn: Any = None,
                      kr: Any = None) -> MillingCut:
        """A cut whose coefficients come from the workpiece table.

        Parameters
        ----------
        teeth : int
            Number of teeth.
        diameter : str or pint.Quantity
            Tool diameter, a length.
        workpiece : Workpiece or str
            An entry of the table or its name (:func:`~substructure.stability.workpiece`).
        radial_depth : str or pint.Quantity, optional
            Radial depth of cut, a length; or
        immersion : float, optional
            ``a_e / D`` in (0, 1].
        milling : {"up", "down"}
            Up (default) or down milling.
        feed_per_tooth : quantity or str, optional
            Needed for a Kienzle entry (its coefficient depends on the chip
            thickness) and for power and removal rate.
        kn, kr : optional
            The normal coefficient (pressure) or ratio ``Kn/Kt``, where the
            entry has none (or to replace its value).

        Returns
        -------
        MillingCut
        """
        from .workpieces import workpiece as lookup

        entry = lookup(workpiece) if isinstance(workpiece, str) else workpiece
        probe = cls.from_spec(teeth, diameter, radial_depth=radial_depth, immersion=immersion, milling=milling,
                              kt="1 Pa", kr=0.0)
        coeff = entry.coefficients(probe.mean_chip_thickness(feed_per_tooth))
        if kn is None and kr is None:
            if coeff["kn"] is None:
                raise InvalidValueError(
                    f"workpiece {entry.name!r}: the table has no radial (normal) coefficient for it "
                    f"({entry.model} entry from {entry.short_source}); give kn (a pressure) or kr (the ratio Kn/Kt)")
            kn = coeff["kn"]
        return cls.from_spec(teeth, diameter, radial_depth=probe.radial_depth, milling=milling, kt=coeff["kt"],
                             kn=kn, kr=kr, feed_per_tooth=feed_per_tooth, kte=coeff["kte"], kne=coeff["kne"],
                             workpiece=entry)

    def mean_chip_thickness(self, feed_per_tooth: Any = None) -> pint.Quantity | None:
        """Average chip thickness over the engagement, ``c (cos phi_st - cos phi_ex) / (phi_ex - phi_st)``.

        Parameters
        ----------
        feed_per_tooth : quantity or str, optional
            Default: the cut's own.

        Returns
        -------
        pint.Quantity or None
            ``None`` without a feed per tooth.
        """
        c = self.feed_per_tooth if feed_per_tooth is None else _length("feed_per_tooth")(feed_per_tooth)
        if c is None:
            return None
        st, ex = self.angles
        return (c * (np.cos(st) - np.cos(ex)) / (ex - st)).to(c.units)

    # -- derived values ---------------------------------------------------------
    @property
    def immersion(self) -> float:
        """Radial immersion ratio ``a_e / D``."""
        return float(self.radial_depth.m_as("m") / self.diameter.m_as("m"))

    @property
    def kt_pa(self) -> float:
        """Tangential coefficient in Pa (N/m^2)."""
        return float(self.kt.m_as("Pa"))

    @property
    def kn_pa(self) -> float:
        """Normal coefficient in Pa (N/m^2)."""
        return float(self.kn.m_as("Pa"))

    @property
    def kr(self) -> float:
        """The ratio ``Kn / Kt``."""
        return self.kn_pa / self.kt_pa

    @property
    def regenerations_per_revolution(self) -> int:
        """Delays per revolution: the number of teeth (the delay is the tooth period)."""
        return self.teeth

    @property
    def angles(self) -> tuple[float, float]:
        """Entry and exit angles ``(phi_st, phi_ex)`` in rad."""
        ratio = min(self.immersion, 1.0)
        if self.milling == "up":
            return 0.0, float(np.arccos(1.0 - 2.0 * ratio))
        return float(np.arccos(2.0 * ratio - 1.0)), float(np.pi)

    @property
    def period_angle(self) -> float:
        """Angle turned in one regeneration delay: ``2*pi / teeth``."""
        return 2.0 * np.pi / self.teeth

    def describe(self) -> str:
        """One line for summaries.

        Returns
        -------
        str
            The cut with its units.
        """
        shop = "conventional" if self.milling == "up" else "climb"
        text = (f"{self.milling} ({shop}) milling, {self.teeth} teeth, D = {self.diameter:~P}, "
                f"a_e = {self.radial_depth:~P} (a_e/D = {self.immersion:.3g}), "
                f"Kt = {self.kt.to('MPa'):.4g~P}, Kn = {self.kn.to('MPa'):.4g~P} (Kn/Kt = {self.kr:.3g})")
        if self.feed_per_tooth is not None:
            text += f", feed {self.feed_per_tooth.to('mm'):.4g~P}/tooth"
        if self.workpiece is not None:
            text += f", workpiece {self.workpiece.name}"
        return text

    def to_json(self) -> dict:
        """The ``cut`` object of ``substructure lobes --json`` (SI units).

        Returns
        -------
        dict
            ``teeth``, ``diameter_m``, ``radial_depth_m``, ``milling``, ``kt_pa``,
            ``kn_pa`` and ``feed_per_tooth_m`` (None when not given).
        """
        feed = self.feed_per_tooth
        return {"teeth": self.teeth, "diameter_m": float(self.diameter.m_as("m")),
                "radial_depth_m": float(self.radial_depth.m_as("m")), "milling": self.milling,
                "milling_shop_name": "conventional" if self.milling == "up" else "climb",
                "kt_pa": self.kt_pa, "kn_pa": self.kn_pa,
                "feed_per_tooth_m": None if feed is None else float(feed.m_as("m"))}

    # -- what the methods use -----------------------------------------------------
    def force_matrix(self, theta: Any) -> np.ndarray:
        """Instantaneous ``K(theta)`` in N/m^2 at angles ``theta`` of tooth 0, shape ``(..., 2, 2)``.

        The sum over the teeth in the cut; zero when none is.

        Parameters
        ----------
        theta : array_like
            Angles of tooth 0, in rad.

        Returns
        -------
        ndarray
            Shape ``theta.shape + (2, 2)``, in N/m^2 (force per unit depth and unit chip thickness).
        """
        theta = np.asarray(theta, dtype=float)
        st, ex = self.angles
        out = np.zeros(theta.shape + (2, 2))
        for j in range(self.teeth):
            phi = np.mod(theta + j * self.period_angle, 2.0 * np.pi)
            inside = (phi >= st) & (phi <= ex)
            out += np.where(inside[..., None, None], _force_matrix_at(phi, self.kr), 0.0)
        return self.kt_pa * out

    def period_arcs(self) -> list[tuple[float, float, bool]]:
        """The delay period ``[0, 2*pi/teeth)`` split where teeth enter or leave the cut.

        Returns
        -------
        list of tuple
            ``(theta_a, theta_b, cutting)`` with angles of tooth 0 in rad: between them
            ``K`` is smooth, and zero when ``cutting`` is False.
        """
        p = self.period_angle
        cuts = {0.0, p}
        for angle in self.angles:
            r = float(np.mod(angle, p))
            if 1e-12 < r < p - 1e-12:
                cuts.add(r)
        edges = sorted(cuts)
        return [(a, b, self._teeth_in_cut(0.5 * (a + b)).size > 0) for a, b in zip(edges[:-1], edges[1:])]

    def _teeth_in_cut(self, theta: float) -> np.ndarray:
        st, ex = self.angles
        phi = np.mod(theta + np.arange(self.teeth) * self.period_angle, 2.0 * np.pi)
        return np.flatnonzero((phi > st) & (phi < ex))

    def force_matrix_average(self, theta_a: Any, theta_b: Any) -> np.ndarray:
        """Average of ``K`` over angle intervals ``[theta_a, theta_b]``, in N/m^2, shape ``(n, 2, 2)``.

        Each interval must lie inside one arc of :meth:`period_arcs`; the
        integral is exact (closed-form antiderivative of the trigonometric
        entries), which keeps low immersions accurate.

        Parameters
        ----------
        theta_a : array_like
            Start angles of tooth 0, in rad.
        theta_b : array_like
            End angles, in rad (same shape).

        Returns
        -------
        ndarray
            Shape ``(n, 2, 2)``, in N/m^2.
        """
        theta_a, theta_b = np.atleast_1d(np.asarray(theta_a, float)), np.atleast_1d(np.asarray(theta_b, float))
        out = np.zeros(theta_a.shape + (2, 2))
        for i, (a, b) in enumerate(zip(theta_a, theta_b)):
            for j in self._teeth_in_cut(0.5 * (a + b)):
                # the unwrapped angle of tooth j is theta + shift
                shift = np.mod(0.5 * (a + b) + j * self.period_angle, 2.0 * np.pi) - 0.5 * (a + b)
                upper = _force_antiderivative(np.array(b + shift), self.kr)
                lower = _force_antiderivative(np.array(a + shift), self.kr)
                out[i] += (upper - lower) / (b - a)
        return self.kt_pa * out

    def mean_force_matrix(self) -> np.ndarray:
        """The zero-order matrix ``K0``: ``K`` averaged over a tooth period, N/m^2, shape (2, 2).

        Equal to ``teeth * Kt / (4 pi) * alpha`` with Altintas & Budak's
        directional coefficients ``alpha``.

        Returns
        -------
        ndarray
            Shape ``(2, 2)``, in N/m^2.
        """
        st, ex = self.angles
        integral = _force_antiderivative(np.array(ex), self.kr) - _force_antiderivative(np.array(st), self.kr)
        return self.kt_pa * self.teeth * integral / (2.0 * np.pi)

