"""Rotational DOF estimation by finite differences (thesis section 2.2.3, eq. 2.12-2.18).

Rotations and moments are hard to measure; translations and forces are not.
Duarte and Ewins's finite-difference method estimates the rotational
receptances ``L = y/m``, ``N = theta/f`` and ``P = theta/m`` at a point from the
translational point and cross receptances between the ``y`` DOFs of two or
three (or more) points of known spacing along one component:
``H_est = T H_meas T^T`` (eq. 2.17), where the transformation ``T`` has a row
that interpolates ``y`` at the point and a row of finite-difference weights
for ``theta = dy/dx``.  Two points give first-order differences, three
second-order ones; forward, central or backward follows from where the point
lies among the measurement points.

Positions are coordinates ``x`` along the component's axis, from its base
toward its tip (conventions.md: ``theta = dy/dx``), e.g. from
:func:`positions_from`.  Only their differences matter, so any origin works,
but the direction must be base to tip: the thesis numbers points from the
tool tip inward, so its "forward" matrix at the tip (eq. 2.14) is, with the
tip at ``x = L`` and the other points at ``L - s`` and ``L - 2s``, the
backward stencil ``theta = (y(L-2s) - 4 y(L-s) + 3 y(L)) / (2s)`` here, and
the estimated ``L`` and ``N`` have this library's sign.  :func:`transformation`
reproduces the thesis's matrices exactly when given the positions in the
thesis's column order and direction (``T_2f = transformation([2s, s, 0], 0)``).

The weights are those of the derivatives of the Lagrange interpolation
polynomial through the points, exact for polynomials of degree ``n - 1``; the
work over frequency is one batched matrix product.
"""

from __future__ import annotations

import math
import numbers
from typing import Any, Sequence

import numpy as np
import pint

from .errors import InvalidValueError, UnitError, UnknownPointError
from .frf import FRF, frf_checked
from .points import PointRef, parse_point
from .units import Q_, items_of, to_si, whole_number

__all__ = [
    "fd_weights",
    "transformation",
    "estimate_rotational",
    "estimate_rotational_cross",
    "positions_from",
]


def _is_length(value: Any) -> bool:
    return isinstance(value, (str, pint.Quantity))


def _coordinates(positions: Any, at: Any) -> tuple[np.ndarray, float]:
    """Plain floats, or lengths converted to metres; the two kinds are not mixed."""
    if isinstance(positions, (str, pint.Quantity)) and np.ndim(getattr(positions, "magnitude", 0)) == 0:
        raise InvalidValueError(f"positions: got {positions!r}; expected a sequence of at least 2 positions")
    values = items_of(positions, "positions", "at least 2 positions")
    lengths = [_is_length(v) for v in values] + [_is_length(at)]
    if any(lengths) and not all(lengths):
        raise UnitError(
            f"positions, at: got {values!r} and {at!r}; give all of them as lengths ('5 mm') "
            "or all as plain numbers in one unit"
        )
    if all(lengths):
        x = np.array([to_si(v, f"positions[{i}]", "m") for i, v in enumerate(values)], dtype=float)
        return x, to_si(at, "at", "m")
    for i, v in enumerate(values + [at]):
        if isinstance(v, bool) or not isinstance(v, numbers.Real) or not math.isfinite(v):
            field = "at" if i == len(values) else f"positions[{i}]"
            raise InvalidValueError(f"{field}: got {v!r}; expected a finite number or a length")
    return np.array(values, dtype=float), float(at)


def _check_distinct(x: np.ndarray, names: Sequence[str] | None = None) -> None:
    if x.size < 2:
        raise InvalidValueError(
            f"positions: got {x.size} position(s); finite differences need at least 2 points "
            "(2 for first order, 3 for second order)"
        )
    order = np.argsort(x, kind="stable")
    gaps = np.diff(x[order])
    tol = 1e-12 * max(float(np.ptp(x)), float(np.abs(x).max()), np.finfo(float).tiny)
    if (gaps <= tol).any():
        k = int(np.argmax(gaps <= tol))
        i, j = sorted((int(order[k]), int(order[k + 1])))
        what = f" ({names[i]} and {names[j]})" if names is not None else ""
        raise InvalidValueError(
            f"positions: positions[{i}] and positions[{j}]{what} coincide at {x[i]!r}; "
            "finite differences need distinct positions"
        )


def fd_weights(positions: Sequence[Any], at: Any, derivative: int = 1) -> np.ndarray:
    """Finite-difference weights of a derivative at ``at`` from values at ``positions``.

    ``sum(w * u(positions))`` is the ``derivative``-th derivative at ``at`` of
    the polynomial of degree ``n - 1`` through the ``n`` values: exact for
    polynomials of that degree, of order ``n - derivative`` in the spacing
    for smooth functions (higher for symmetric stencils).

    Parameters
    ----------
    positions : sequence of float, or of lengths
        At least ``derivative + 1`` (and 2) distinct positions, in any order.
        Plain numbers give weights in the inverse unit of the numbers;
        lengths (pint quantities or strings like ``"5 mm"``) are converted to
        metres and give weights per metre (``1/m**derivative``).
    at : float or length
        Where the derivative is wanted (of the same kind as ``positions``).
    derivative : int, default 1
        0 gives the Lagrange interpolation weights.

    Returns
    -------
    ndarray
        Weights, shape ``(n,)``, in the order of ``positions``.

    Examples
    --------
    >>> fd_weights([0.0, 1.0, 2.0], 0.0)     # second-order forward: (-3, 4, -1) / 2
    array([-1.5,  2. , -0.5])
    >>> fd_weights([-1.0, 0.0, 1.0], 0.0)    # central
    array([-0.5,  0. ,  0.5])
    """
    whole_number(derivative, "derivative", 0, "an integer")
    x, x0 = _coordinates(positions, at)
    _check_distinct(x)
    n = x.size
    if derivative > n - 1:
        raise InvalidValueError(
            f"derivative: got {derivative} with {n} points; a derivative of order d needs at least "
            "d + 1 points"
        )
    t = x - x0
    if derivative == 0 and (t == 0.0).any():
        return (t == 0.0).astype(float)  # the point itself: a unit row
    weights = np.empty(n)
    for j in range(n):  # n is the stencil size (2 to 5), not a frequency count
        others = np.delete(t, j)
        # l_j(t) = prod_k (t - t_k) / prod_k (t_j - t_k); its d-th derivative at 0 is d! times
        # the coefficient of t^d of the numerator (np.poly: highest power first).
        numerator = np.poly(others)
        weights[j] = math.factorial(derivative) * numerator[n - 1 - derivative] / np.prod(t[j] - others)
    return weights + 0.0  # no negative zeros


def transformation(positions: Sequence[Any], at: Any) -> np.ndarray:
    """The transformation ``T`` of eq. 2.17: rows ``y`` and ``theta`` at ``at``.

    Parameters
    ----------
    positions : sequence of float, or of lengths
        Positions of the measured ``y`` DOFs along the axis (see
        :func:`fd_weights` for the units).
    at : float or length
        Where ``y`` and ``theta`` are estimated.

    Returns
    -------
    ndarray, shape (2, n)
        Row 0: Lagrange weights of ``y(at)`` (a unit row when ``at`` is one
        of the positions); row 1: weights of ``dy/dx`` at ``at``.

    Examples
    --------
    The thesis's matrices for a spacing ``s``, positions in its column order:

    >>> s = 0.5
    >>> transformation([s, 0.0], 0.0)              # T_1f, eq. 2.12
    array([[ 0.,  1.],
           [ 2., -2.]])
    >>> transformation([2 * s, s, 0.0], 0.0) * 2 * s   # 2s T_2f, eq. 2.14
    array([[ 0.,  0.,  1.],
           [-1.,  4., -3.]])
    """
    return np.vstack([fd_weights(positions, at, 0), fd_weights(positions, at, 1)])


def _point(value: Any, field: str) -> PointRef:
    if not isinstance(value, (str, PointRef)):
        raise InvalidValueError(f"{field}: got {value!r}; expected a point name such as 'tool.tip'")
    try:
        return parse_point(value)
    except UnknownPointError as exc:
        raise UnknownPointError(f"{field}: {exc}") from None


def _check_names_agree(refs: list, x: np.ndarray, names: dict) -> None:
    """Refuse positions that contradict what the point names say of them.

    A name measured from the base (``base``, ``@40 mm``) fixes the position; names measured back from the tip
    (``tip``, ``tip-5 mm``) fix their distances from each other (the component's length is not known here).
    """
    tip_lengths = []
    for i, ref in enumerate(refs):
        d = 0.0 if ref.distance is None else float(ref.distance.m_as("m"))
        if ref.where in ("base", "at"):
            implied, given = d, float(x[i])
        elif ref.where in ("tip", "from_tip"):
            tip_lengths.append((i, float(x[i]) + d))  # the component's length, as this point's position says
            continue
        else:  # a measured component's own label: nothing to compare
            continue
        if abs(implied - given) > 1e-9 + 1e-6 * max(abs(implied), abs(given)):
            raise InvalidValueError(
                f"{names['positions']}[{i}]: got {given * 1e3:.6g} mm for {ref.point}, which its name places at "
                f"{implied * 1e3:.6g} mm from the base; give the positions in the points' order (positions_from "
                "reads them from the model)")
    for (i, length), (j, other) in zip(tip_lengths, tip_lengths[1:]):
        if abs(length - other) > 1e-9 + 1e-6 * max(abs(length), abs(other)):
            gap = (float(x[j]) - float(x[i])) * 1e3
            said = ((0.0 if refs[i].distance is None else refs[i].distance.m_as("mm"))
                    - (0.0 if refs[j].distance is None else refs[j].distance.m_as("mm")))
            raise InvalidValueError(
                f"{names['positions']}[{i}], {names['positions']}[{j}]: {refs[j].point} is {gap:+.6g} mm from "
                f"{refs[i].point} by the positions given, {said:+.6g} mm by their names; give the positions in the "
                "points' order (positions_from reads them from the model)")


def _stencil(points: Any, positions: Any, at: Any, at_position: Any, suffix: str = ""):
    """Labels of the measured y DOFs, the transformation, and the point's name."""
    names = {"points": f"points{suffix}", "positions": f"positions{suffix}", "at": f"at{suffix}"}
    if isinstance(points, str) or isinstance(positions, str):
        raise InvalidValueError(f"{names['points']}, {names['positions']}: expected sequences, one entry per point")
    points = items_of(points, names["points"], "point names, one per position")
    positions = items_of(positions, names["positions"], "positions, one per point")
    if len(points) < 2:
        raise InvalidValueError(
            f"{names['points']}: got {len(points)} point(s); finite differences need at least 2 "
            "(2 for first order, 3 for second order)"
        )
    if len(positions) != len(points):
        raise InvalidValueError(
            f"{names['positions']}: got {len(positions)} position(s) for {len(points)} points; expected one per point"
        )
    refs = [_point(p, f"{names['points']}[{i}]") for i, p in enumerate(points)]
    for i, ref in enumerate(refs):
        if ref.dof not in (None, "y"):
            raise InvalidValueError(
                f"{names['points']}[{i}]: got {points[i]!r}; the stencil is made of translational (y) DOFs"
            )
    components = list(dict.fromkeys(r.component for r in refs))
    if len(components) > 1:
        raise InvalidValueError(
            f"{names['points']}: the points lie on components {', '.join(map(repr, components))}; a "
            "finite-difference stencil runs along the axis of one component"
        )
    point_names = [str(r.point) for r in refs]
    twice = sorted({p for p in point_names if point_names.count(p) > 1})
    if twice:
        raise InvalidValueError(f"{names['points']}: {', '.join(twice)} given more than once")
    at_ref = _point(at, names["at"])
    if at_ref.dof is not None:
        raise InvalidValueError(f"{names['at']}: got {at!r}; expected a point name without a DOF suffix")
    if at_ref.component != components[0]:
        raise InvalidValueError(
            f"{names['at']}: {at_ref.point} is not on component {components[0]!r}, where the points are"
        )
    at_name = str(at_ref.point)
    x = np.array([to_si(p, f"{names['positions']}[{i}]", "m") for i, p in enumerate(positions)])
    if at_position is None:
        if at_name not in point_names:
            raise InvalidValueError(
                f"{names['at']}: {at_name} is not one of the points ({', '.join(point_names)}); "
                f"give its position with at_position{suffix}"
            )
        x0 = float(x[point_names.index(at_name)])
    else:
        x0 = to_si(at_position, f"at_position{suffix}", "m")
    _check_distinct(x, point_names)
    _check_names_agree(refs, x, names)
    return [f"{p}:y" for p in point_names], transformation(x, x0), at_name


def estimate_rotational(
    frf: FRF, points: Sequence[str], positions: Sequence[Any], at: str, *, at_position: Any = None
) -> FRF:
    """The 2x2 receptance ``[[H, L], [N, P]]`` at a point from translational FRFs (eq. 2.17).

    Parameters
    ----------
    frf : FRF
        Translational receptances whose outputs and inputs include the ``y``
        DOFs of ``points`` (labels ``"POINT:y"``), e.g. from
        :meth:`MeasurementSet.matrix`; other entries are ignored.
    points : sequence of str
        At least 2 points on one component.
    positions : sequence of pint.Quantity or str
        Their coordinates along the component's axis, base toward tip (e.g.
        from :func:`positions_from`); distinct.
    at : str
        The point where the rotational terms are wanted, usually one of
        ``points`` (the tip: a backward stencil; an interior point: central).
    at_position : pint.Quantity or str, optional
        Its coordinate, needed only when ``at`` is not one of ``points``
        (the ``y`` row then interpolates, or extrapolates, between them).

    Returns
    -------
    FRF
        Outputs and inputs ``("AT:y", "AT:theta")``, same axis and quantity as
        ``frf``.

    Raises
    ------
    InvalidValueError
        For fewer than 2 points, repeated points or positions, points on
        different components.
    UnitError
        For positions without units.
    UnknownPointError
        When a point's ``y`` DOF is not among the FRF's outputs or inputs.

    Notes
    -----
    Accuracy: the error of ``N`` and ``L`` falls as ``s**(n-1)`` with the
    spacing ``s`` (first order with 2 points, second with 3), but noise is
    amplified as ``1/s`` (``1/s**2`` for ``P``): Duarte and Ewins recommend
    smaller spacings for ``L``, ``N`` and larger ones for ``P``.

    What is estimated is the slope ``dy/dx`` of the displacement, not the
    section rotation ``theta`` of a Timoshenko beam (conventions.md): at a
    loaded point they differ by the shear angle, so ``N`` and ``L`` at a tool
    tip tend to ``N + 1/(kappa G A)``.  The displacement under a point force
    also has a slope jump ``1/(kappa G A)`` at the force, which the
    driving-point terms of ``H_meas`` carry into ``P`` as a bias
    ``-sum_ij T_1i T_1j |x_i - x_j| / (2 kappa G A)``: ``1/(kappa G A s)``
    for 2 points, ``2.5/(kappa G A s)`` for the 3-point stencil at an end,
    constant over frequency and growing as the spacing shrinks: another
    reason for a larger spacing for ``P``.
    """
    frf_checked(frf)
    labels, t, name = _stencil(points, positions, at, at_position)
    h = frf.select(labels, labels).data
    data = t @ h @ t.T
    out = (f"{name}:y", f"{name}:theta")
    return FRF(frf.frequency, data, out, out, frf.quantity)


def estimate_rotational_cross(
    frf: FRF,
    points_a: Sequence[str], positions_a: Sequence[Any], at_a: str,
    points_b: Sequence[str], positions_b: Sequence[Any], at_b: str,
    *, at_position_a: Any = None, at_position_b: Any = None,
) -> FRF:
    """The 2x2 cross receptance between two points, each from its own stencil: ``T_a H_ab T_b^T``.

    Parameters
    ----------
    frf : FRF
        Translational receptances whose outputs include the ``y`` DOFs of
        ``points_a`` and whose inputs include those of ``points_b``.
    points_a, positions_a, at_a
        The response side, as in :func:`estimate_rotational` (positions with units).
    points_b, positions_b, at_b
        The excitation side; may be on another component.
    at_position_a, at_position_b : quantity or str, optional
        Positions of ``at_a`` and ``at_b`` when they are not among the points (lengths).

    Returns
    -------
    FRF
        Outputs ``("A:y", "A:theta")``, inputs ``("B:y", "B:theta")``:
        ``[[H_ab, L_ab], [N_ab, P_ab]]``.
    """
    frf_checked(frf)
    labels_a, t_a, name_a = _stencil(points_a, positions_a, at_a, at_position_a, "_a")
    labels_b, t_b, name_b = _stencil(points_b, positions_b, at_b, at_position_b, "_b")
    h = frf.select(labels_a, labels_b).data
    data = t_a @ h @ t_b.T
    return FRF(frf.frequency, data, (f"{name_a}:y", f"{name_a}:theta"), (f"{name_b}:y", f"{name_b}:theta"),
               frf.quantity)


def positions_from(assembly_or_component: Any, points: Sequence[str]) -> tuple[pint.Quantity, ...]:
    """Each point's distance from its component's base, for :func:`estimate_rotational`.

    Parameters
    ----------
    assembly_or_component : Assembly or Beam
        Where the points are; an assembly looks the component up by name.
    points : sequence of str
        Point names on one component (``"tool.tip"``, ``"tool.tip-5 mm"``,
        ``"tool@40 mm"``); DOF suffixes are ignored.

    Returns
    -------
    tuple of pint.Quantity
        Distances in metres, in the order of ``points``.

    Raises
    ------
    InvalidValueError
        For points on different components, or a component without geometry
        (a measured component: give the positions yourself).
    UnknownPointError
        For a point that is not on the component.
    """
    points = [points] if isinstance(points, str) else items_of(points, "points", "point names")
    refs = [_point(p, f"points[{i}]") for i, p in enumerate(points)]
    if not refs:
        raise InvalidValueError("points: got none; expected point names on one component")
    names = list(dict.fromkeys(r.component for r in refs))
    if len(names) > 1:
        raise InvalidValueError(
            f"points: the points lie on components {', '.join(map(repr, names))}; positions along an "
            "axis are defined on one component"
        )
    holder = assembly_or_component
    is_assembly = not hasattr(holder, "position") and hasattr(holder, "component")
    component = holder.component(names[0]) if is_assembly else holder
    if not hasattr(component, "position"):
        raise InvalidValueError(
            f"points: component {names[0]!r} ({type(component).__name__}) has no geometry; give the "
            "positions along its axis yourself"
        )
    return tuple(Q_(component.position(r.point), "m") for r in refs)
