"""Tests of substructure.rdof: rotational FRFs by finite differences (thesis eq. 2.12-2.18)."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from substructure import FRF, Frequency, MeasuredComponent, Segment, Tool, default_assembly
from substructure.errors import InvalidValueError, UnitError, UnknownPointError
from substructure.rdof import (
    estimate_rotational,
    estimate_rotational_cross,
    fd_weights,
    positions_from,
    transformation,
)

from conftest import make_assembly

TOOL = Tool("tool", [Segment("80 mm", "12 mm", material="carbide")])
LOW = Frequency.from_hz([200.0, 500.0, 1000.0])


def exact(points, frequency=LOW) -> FRF:
    return TOOL.receptance(frequency, points)


def stencil(spacing_mm: float, n: int) -> list[str]:
    """n points ending at the tip, spacing_mm apart, ordered base to tip."""
    return [f"tool.tip-{k * spacing_mm:g} mm" if k else "tool.tip" for k in range(n - 1, -1, -1)]


# -- weights ---------------------------------------------------------------------------------


@pytest.mark.parametrize("s", [0.5, 0.004, 0.035])
def test_transformation_reproduces_the_thesis_matrices(s):
    # Positions in the column order of eq. 2.18 (points 3, 2, 1) and the thesis's direction.
    expected = {
        "T1f": ([s, 0.0], [[0, 1], [1 / s, -1 / s]]),                                # eq. 2.12
        "T1b": ([-s, 0.0], [[0, 1], [-1 / s, 1 / s]]),                               # eq. 2.13
        "T2f": ([2 * s, s, 0.0], np.array([[0, 0, 2 * s], [-1, 4, -3]]) / (2 * s)),  # eq. 2.14
        "T2c": ([-s, 0.0, s], np.array([[0, 2 * s, 0], [-1, 0, 1]]) / (2 * s)),      # eq. 2.15
        "T2b": ([-2 * s, -s, 0.0], np.array([[0, 0, 2 * s], [1, -4, 3]]) / (2 * s)),  # eq. 2.16
    }
    for name, (positions, matrix) in expected.items():
        t = transformation(positions, 0.0)
        if s == 0.5:  # binary fractions: exact to the last bit
            np.testing.assert_array_equal(t, matrix, err_msg=name)
        else:
            np.testing.assert_allclose(t, matrix, rtol=1e-13, atol=0, err_msg=name)


def test_weights_of_the_named_schemes():
    s = 0.25
    np.testing.assert_array_equal(fd_weights([0, s, 2 * s], 0.0), np.array([-3, 4, -1]) / (2 * s))  # forward
    np.testing.assert_array_equal(fd_weights([-s, 0, s], 0.0), np.array([-1, 0, 1]) / (2 * s))      # central
    np.testing.assert_array_equal(fd_weights([-2 * s, -s, 0], 0.0), np.array([1, -4, 3]) / (2 * s))  # backward
    np.testing.assert_array_equal(fd_weights([0, s], 0.0), [-1 / s, 1 / s])
    np.testing.assert_array_equal(fd_weights([-s, 0, s], 0.0, derivative=2), np.array([1, -2, 1]) / s**2)


@given(
    raw=st.lists(st.integers(-40, 40), min_size=2, max_size=5, unique=True),
    at=st.integers(-50, 50),
    coefficients=st.lists(st.floats(-3, 3), min_size=5, max_size=5),
)
def test_weights_are_exact_for_polynomials_of_degree_n_minus_1(raw, at, coefficients):
    x = np.array(raw, dtype=float) / 10.0
    x0 = at / 10.0
    n = x.size
    poly = np.polynomial.Polynomial(coefficients[:n])  # degree n - 1
    for d in range(n):
        value = fd_weights(x, x0, derivative=d) @ poly(x)
        expected = poly.deriv(d)(x0) if d else poly(x0)
        scale = max(1.0, np.abs(poly.coef).sum() * max(1.0, abs(x0), np.abs(x).max()) ** n)
        assert abs(value - expected) <= 1e-9 * scale


def test_weights_take_lengths_in_metres():
    w = fd_weights(["70 mm", "75 mm", "80 mm"], "80 mm")
    np.testing.assert_allclose(w, np.array([1, -4, 3]) / 0.01, rtol=1e-12)
    t = transformation(["70 mm", "75 mm", "80 mm"], "75 mm")
    np.testing.assert_array_equal(t[0], [0, 1, 0])  # a measured point: a unit row


@pytest.mark.parametrize(
    "positions, at, derivative, error, match",
    [
        ([0.0], 0.0, 1, InvalidValueError, "at least 2"),
        ([0.0, 1.0, 1.0], 0.0, 1, InvalidValueError, r"positions\[1\] and positions\[2\] coincide"),
        ([0.0, 1.0], 0.0, 2, InvalidValueError, "at least d \\+ 1"),
        ([0.0, 1.0], 0.0, -1, InvalidValueError, "derivative"),
        (["0 mm", 1.0], "0 mm", 1, UnitError, "all of them as lengths"),
        (["0 mm", "1 s"], "0 mm", 1, UnitError, r"positions\[1\]"),
        ([0.0, float("nan")], 0.0, 1, InvalidValueError, r"positions\[1\]"),
    ],
)
def test_weight_errors(positions, at, derivative, error, match):
    with pytest.raises(error, match=match):
        fd_weights(positions, at, derivative)


# -- estimates on the library's own beam model -----------------------------------------------


def slope_reference() -> np.ndarray:
    """theta/f at the tip as the slope dy/dx sees it: N + 1/(kappa G A) (conventions.md, 'What theta is').

    A Timoshenko beam's section rotation psi differs from the slope dw/dx by the
    shear angle V/(kappa G A); at the tip, loaded by f, V = f.  Finite
    differences of displacements estimate the slope.
    """
    return exact(["tip"]).entry("tool.tip:theta", "tool.tip:y") + 1.0 / TOOL.segments[0].section().kGA


def error_of_n(spacing_mm: float, n: int) -> np.ndarray:
    points = stencil(spacing_mm, n)
    est = estimate_rotational(exact(points), points, positions_from(TOOL, points), "tool.tip")
    reference = slope_reference()
    return np.abs(est.entry("tool.tip:theta", "tool.tip:y") - reference) / np.abs(reference)


@pytest.mark.parametrize("n, ratio", [(2, 2.0), (3, 4.0)])
def test_convergence_order_at_low_frequency(n, ratio):
    coarse, fine = error_of_n(2.0, n), error_of_n(1.0, n)
    observed = coarse / fine
    assert np.all(np.abs(observed / ratio - 1.0) < 0.3), observed
    assert np.all(error_of_n(0.5, n) < fine)


def test_estimated_2x2_is_close_to_the_exact_one():
    grid = Frequency.from_hz([100.0, 200.0, 500.0])
    points = ["tool.tip-10 mm", "tool.tip-5 mm", "tool.tip"]
    est = estimate_rotational(exact(points, grid), points, positions_from(TOOL, points), "tool.tip")
    truth = exact(["tip"], grid)
    assert est.outputs == est.inputs == ("tool.tip:y", "tool.tip:theta")
    # the y row is a unit row: H is the measured one (up to the model's rounding between calls)
    np.testing.assert_allclose(est.entry("tool.tip:y", "tool.tip:y"), truth.entry("tool.tip:y", "tool.tip:y"),
                               rtol=1e-12)
    relative = np.abs(est.data - truth.data) / np.abs(truth.data)
    assert relative[:, [0, 0, 1], [0, 1, 0]].max() < 0.005  # H exact, L and N: the shear angle (0.1 %)
    assert relative[:, 1, 1].max() < 0.03                    # P: a few percent at low frequency
    np.testing.assert_allclose(est.data[:, 0, 1], est.data[:, 1, 0], rtol=1e-12)  # L = N, reciprocity


@pytest.mark.parametrize("n, factor", [(2, 1.0), (3, 2.5)])
def test_p_is_biased_by_the_shear_kink_as_documented(n, factor):
    # The displacement under a point force has a slope jump 1/(kappa G A) at the force (Timoshenko):
    # P_est - P -> factor / (kappa G A s), constant over frequency, growing as the spacing shrinks.
    kga = TOOL.segments[0].section().kGA
    points = stencil(1.0, n)
    est = estimate_rotational(exact(points), points, positions_from(TOOL, points), "tool.tip")
    bias = est.entry("tool.tip:theta", "tool.tip:theta") - exact(["tip"]).entry("tool.tip:theta", "tool.tip:theta")
    np.testing.assert_allclose(bias, factor / (kga * 0.001), rtol=0.03)


def test_first_order_is_the_two_point_difference():
    points = ["tool.tip-5 mm", "tool.tip"]
    h = exact(points)
    est = estimate_rotational(h, points, ["75 mm", "80 mm"], "tool.tip")
    y_tip, y_in = h.entry("tool.tip:y", "tool.tip:y"), h.entry("tool.tip-5 mm:y", "tool.tip:y")
    np.testing.assert_allclose(est.entry("tool.tip:theta", "tool.tip:y"), (y_tip - y_in) / 0.005, rtol=1e-12)


def test_central_differences_at_an_interior_point():
    points = ["tool.tip-10 mm", "tool.tip-5 mm", "tool.tip"]
    est = estimate_rotational(exact(points), points, positions_from(TOOL, points), "tool.tip-5 mm")
    assert est.outputs == ("tool.tip-5 mm:y", "tool.tip-5 mm:theta")
    truth = exact(["tip-5 mm"])
    relative = np.abs(est.data - truth.data) / np.abs(truth.data)
    assert relative[:, 0, 0].max() < 1e-12
    assert relative[:, [0, 1], [1, 0]].max() < 0.005
    assert relative[:, 1, 1].max() < 0.05
    # the interpolated y row at a point between the measured ones
    mid = estimate_rotational(exact(points), points, positions_from(TOOL, points), "tool.tip-7.5 mm",
                              at_position="72.5 mm")
    truth_mid = exact(["tip-7.5 mm"])
    assert rel(mid.data[:, 0, 0], truth_mid.data[:, 0, 0]) < 1e-4


def rel(a, b) -> float:
    return float(np.abs(a - b).max() / np.abs(b).max())


def test_cross_estimate_between_two_stencils():
    tip = ["tool.tip-10 mm", "tool.tip-5 mm", "tool.tip"]
    base = ["tool.base", "tool@5 mm", "tool@10 mm"]
    h = exact(tip + base)
    est = estimate_rotational_cross(h, tip, positions_from(TOOL, tip), "tool.tip",
                                    base, positions_from(TOOL, base), "tool.base")
    assert est.outputs == ("tool.tip:y", "tool.tip:theta") and est.inputs == ("tool.base:y", "tool.base:theta")
    truth = h.select(["tool.tip:y", "tool.tip:theta"], ["tool.base:y", "tool.base:theta"])
    # at free ends without load the shear force vanishes: the slope is the section rotation
    assert np.abs(est.data - truth.data).max(axis=0).max() / np.abs(truth.data).max() < 1e-3
    for i in range(2):
        for j in range(2):
            assert rel(est.data[:, i, j], truth.data[:, i, j]) < 5e-3


def test_works_on_any_frequency_count_in_one_product():
    grid = Frequency.from_range("100 Hz", "5000 Hz", "1 Hz")
    points = stencil(5.0, 3)
    est = estimate_rotational(exact(points, grid), points, positions_from(TOOL, points), "tool.tip")
    assert est.shape == (grid.n, 2, 2) and est.frequency == grid


def test_positions_from_an_assembly():
    assembly = make_assembly()
    assert [q.m_as("mm") for q in positions_from(assembly, ["tool.base", "tool.tip-15 mm", "tool.tip"])] == \
        pytest.approx([0.0, 45.0, 60.0])
    with pytest.raises(InvalidValueError, match="components 'holder', 'tool'"):
        positions_from(assembly, ["holder.tip", "tool.tip"])
    with pytest.raises(UnknownPointError, match="outside"):
        positions_from(assembly, ["tool@70 mm"])
    measured = MeasuredComponent("sh", exact(["tip"]))
    with pytest.raises(InvalidValueError, match="no geometry"):
        positions_from(measured, ["tool.tip"])


@pytest.mark.parametrize(
    "points, positions, at, error, match",
    [
        (["tool.tip"], ["80 mm"], "tool.tip", InvalidValueError, "at least 2"),
        (["tool.tip-5 mm", "tool.tip"], ["80 mm", "80 mm"], "tool.tip", InvalidValueError,
         r"positions\[0\] and positions\[1\] \(tool\.tip-5 mm and tool\.tip\) coincide"),
        (["tool.tip", "tool.tip"], ["75 mm", "80 mm"], "tool.tip", InvalidValueError, "more than once"),
        (["tool.tip-5 mm", "tool.tip"], [0.075, 0.08], "tool.tip", UnitError, "bare number"),
        (["tool.tip-5 mm", "tool.tip"], ["75 mm"], "tool.tip", InvalidValueError, "one per point"),
        (["holder.tip", "tool.tip"], ["66 mm", "80 mm"], "tool.tip", InvalidValueError, "one component"),
        (["tool.tip-5 mm", "tool.tip"], ["75 mm", "80 mm"], "holder.tip", InvalidValueError, "not on component"),
        (["tool.tip-5 mm", "tool.tip"], ["75 mm", "80 mm"], "tool.base", InvalidValueError, "at_position"),
        (["tool.tip-5 mm:theta", "tool.tip"], ["75 mm", "80 mm"], "tool.tip", InvalidValueError, "translational"),
        (["tool.tip-3 mm", "tool.tip"], ["77 mm", "80 mm"], "tool.tip", UnknownPointError, "tool.tip-3 mm:y"),
    ],
)
def test_estimate_errors(points, positions, at, error, match):
    h = exact(["tip-5 mm", "tip"])
    with pytest.raises(error, match=match):
        estimate_rotational(h, points, positions, at)


@pytest.mark.parametrize("positions, match", [
    (["60 mm", "10 mm", "20 mm"], r"positions\[0\], positions\[1\]: tool\.tip-5 mm is -50 mm from tool\.tip by the "
                                  r"positions given, -5 mm by their names"),
    (["66 mm", "71 mm", "76 mm"], r"tool\.tip-5 mm is \+5 mm from tool\.tip .* -5 mm by their names"),
])
def test_positions_that_contradict_the_point_names_are_refused(positions, match):
    """Names measured back from the tip fix the points' distances from each other: positions in another order or
    scale gave numbers for a stencil that is not the one measured."""
    asm = default_assembly()
    pts = ["tool.tip", "tool.tip-5 mm", "tool.tip-10 mm"]
    ty = asm.frf([p + ":y" for p in pts], [p + ":y" for p in pts], frequency=Frequency.from_range("100 Hz", "2000 Hz",
                                                                                                  "100 Hz"))
    with pytest.raises(InvalidValueError, match=match):
        estimate_rotational(ty, pts, positions, "tool.tip")
    right = estimate_rotational(ty, pts, positions_from(asm, pts), "tool.tip")
    shifted = estimate_rotational(ty, pts, ["86 mm", "81 mm", "76 mm"], "tool.tip")  # the tip-relative names agree
    np.testing.assert_allclose(shifted.data, right.data, rtol=1e-12)
    with pytest.raises(InvalidValueError, match=r"positions\[0\]: got 5 mm for tool@6 mm, which its name places at "
                                                r"6 mm from the base"):
        estimate_rotational(asm.frf(["tool@6 mm:y", "tool@16 mm:y"], frequency=[100.0]), ["tool@6 mm", "tool@16 mm"],
                            ["5 mm", "16 mm"], "tool@6 mm")
