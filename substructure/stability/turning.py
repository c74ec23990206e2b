"""Turning and boring: :class:`TurningCut`, the oriented single-direction cut of Tlusty.

The chip thickness is regenerated once per revolution and the structure is
seen along one direction through the directional factor ``u``; the force
matrix is constant, so its averages are exact.
"""

from __future__ import annotations

from typing import Any

import attrs
import numpy as np
import pint

from ..errors import InvalidValueError
from ..units import dimensionless
from ._cut_fields import _pressure

__all__ = ["TurningCut"]


def _orientation(value: Any) -> float:
    u = dimensionless(value, "orientation")
    if u == 0.0 or abs(u) > 1.0:
        raise InvalidValueError(
            f"orientation: got {value!r}; expected the directional factor u, 0 < |u| <= 1 "
            "(the product of the cosines between force, mode and chip thickness directions)"
        )
    return u


def _direction(value: Any) -> str:
    if not isinstance(value, str) or value not in ("x", "y"):
        raise InvalidValueError(f"direction: got {value!r}; expected 'x' or 'y'")
    return value


@attrs.frozen
class TurningCut:
    """Turning or boring: a single-direction oriented cut (Tlusty).

    The chip thickness is regenerated once per revolution, and the structure
    is seen along one direction through the directional factor ``u``:
    ``F = -a Kf u (r - r_prev)`` along ``direction``, which gives the classic
    limit ``a_lim = -1 / (2 Kf u Re G)``.

    Parameters
    ----------
    kf : quantity or str
        Cutting pressure along the resultant force, e.g. ``"2000 MPa"``.
    orientation : float, default 1.0
        Directional factor ``u`` (``0 < |u| <= 1``).
    direction : {"x", "y"}, default "x"
        The FRF direction the oriented structure is measured in.
    """

    kf: pint.Quantity = attrs.field(converter=_pressure("kf", allow_zero=False))
    orientation: float = attrs.field(default=1.0, converter=_orientation)
    direction: str = attrs.field(default="x", validator=lambda i, a, v: _direction(v))

    teeth = 1  # one regeneration per revolution

    @property
    def regenerations_per_revolution(self) -> int:
        """One delay per revolution."""
        return 1

    @property
    def period_angle(self) -> float:
        """The delay is one revolution: ``2*pi``."""
        return 2.0 * np.pi

    def describe(self) -> str:
        """One line for summaries.

        Returns
        -------
        str
            The cut with its units.
        """
        return f"turning, Kf = {self.kf:~P}, orientation u = {self.orientation:g} along {self.direction}"

    def _matrix(self) -> np.ndarray:
        out = np.zeros((2, 2))
        i = 0 if self.direction == "x" else 1
        out[i, i] = -float(self.kf.m_as("Pa")) * self.orientation
        return out

    def force_matrix(self, theta: Any) -> np.ndarray:
        """The constant force matrix in N/m^2 at any angle, shape ``(..., 2, 2)``.

        Parameters
        ----------
        theta : array_like
            Angles in rad (the matrix does not depend on them).

        Returns
        -------
        ndarray
            Shape ``theta.shape + (2, 2)``, in N/m^2.
        """
        theta = np.asarray(theta, dtype=float)
        return np.broadcast_to(self._matrix(), theta.shape + (2, 2)).copy()

    def period_arcs(self) -> list[tuple[float, float, bool]]:
        """One arc, always cutting.

        Returns
        -------
        list of tuple
            ``[(0, 2 pi, True)]``, angles in rad.
        """
        return [(0.0, 2.0 * np.pi, True)]

    def force_matrix_average(self, theta_a: Any, theta_b: Any) -> np.ndarray:
        """The constant force matrix for each interval, shape ``(n, 2, 2)``.

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
        n = np.atleast_1d(np.asarray(theta_a, float)).size
        return np.broadcast_to(self._matrix(), (n, 2, 2)).copy()

    def mean_force_matrix(self) -> np.ndarray:
        """``-Kf u`` in the oriented direction, N/m^2, shape (2, 2).

        Returns
        -------
        ndarray
            Shape ``(2, 2)``, in N/m^2.
        """
        return self._matrix()
