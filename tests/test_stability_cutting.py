"""The cut (substructure.stability.cutting): units, checks, directional factors, speeds."""

from __future__ import annotations

import numpy as np
import pytest

from substructure import InvalidValueError, UnitError
from substructure.stability import MillingCut, TurningCut, as_speed_rpm, spindle_speeds, tooth_passing_hz
from substructure.units import Q_


def thesis_cut(**kw):
    spec = dict(radial_depth="3 mm", milling="up", kt="625 MPa", kn="100 MPa")
    spec.update(kw)
    return MillingCut.from_spec(4, "12 mm", **spec)


# -- bad input: clear errors ------------------------------------------------------------


def test_radial_depth_larger_than_diameter_is_an_error():
    with pytest.raises(InvalidValueError, match="radial_depth.*larger than the tool diameter"):
        MillingCut(4, "12 mm", "13 mm", kt="625 MPa", kn="100 MPa")
    with pytest.raises(InvalidValueError, match="immersion"):
        MillingCut.from_spec(4, "12 mm", immersion=1.2, kt="625 MPa", kr=0.16)


@pytest.mark.parametrize("teeth", [0, -2, 2.5, "4", True])
def test_teeth_must_be_a_positive_whole_number(teeth):
    with pytest.raises(InvalidValueError, match="teeth"):
        MillingCut(teeth, "12 mm", "3 mm", kt="625 MPa", kn="100 MPa")


@pytest.mark.parametrize("field, spec, match", [
    ("kt", dict(kt="-625 MPa", kn="100 MPa"), "kt.*cutting coefficient > 0"),
    ("kt", dict(kt="0 MPa", kn="100 MPa"), "kt"),
    ("kn", dict(kt="625 MPa", kn="-100 MPa"), "kn.*>= 0"),
    ("kr", dict(kt="625 MPa", kr=-0.1), "kr.*>= 0"),
])
def test_negative_coefficients_are_errors(field, spec, match):
    with pytest.raises(InvalidValueError, match=match):
        MillingCut.from_spec(4, "12 mm", radial_depth="3 mm", **spec)


def test_units_are_checked_and_named():
    with pytest.raises(UnitError, match="diameter"):
        MillingCut(4, 12, "3 mm", kt="625 MPa", kn="100 MPa")
    with pytest.raises(UnitError, match="kt.*pressure"):
        MillingCut(4, "12 mm", "3 mm", kt="625 N", kn="100 MPa")
    with pytest.raises(UnitError, match="ratio Kr = Kn/Kt.*kr=0.16"):
        MillingCut(4, "12 mm", "3 mm", kt="625 MPa", kn=0.16)
    with pytest.raises(UnitError, match="kr.*ratio.*kn='100 MPa'"):
        MillingCut.from_spec(4, "12 mm", radial_depth="3 mm", kt="625 MPa", kr="100 MPa")


def test_alternatives_must_be_given_once():
    with pytest.raises(InvalidValueError, match="exactly one"):
        MillingCut.from_spec(4, "12 mm", radial_depth="3 mm", immersion=0.25, kt="625 MPa", kn="100 MPa")
    with pytest.raises(InvalidValueError, match="exactly one"):
        MillingCut.from_spec(4, "12 mm", radial_depth="3 mm", kt="625 MPa", kn="100 MPa", kr=0.16)
    with pytest.raises(InvalidValueError, match="milling"):
        thesis_cut(milling="sideways")  # climb and conventional are the shop's up and down


def test_pressure_and_ratio_give_the_same_cut():
    a = thesis_cut()
    b = thesis_cut(kn=None, kr=0.16)
    c = MillingCut.from_spec(4, "12 mm", immersion=0.25, milling="up", kt="625 MPa", kr=0.16)
    assert a.kr == pytest.approx(0.16) and b.kn_pa == pytest.approx(1e8)
    np.testing.assert_allclose(a.mean_force_matrix(), b.mean_force_matrix(), rtol=1e-12)
    np.testing.assert_allclose(a.mean_force_matrix(), c.mean_force_matrix(), rtol=1e-12)


# -- geometry and directional factors -------------------------------------------------


def test_entry_and_exit_angles():
    assert thesis_cut().angles == pytest.approx((0.0, np.pi / 3))  # arccos(1 - 2 * 0.25)
    down = thesis_cut(milling="down")
    assert down.angles == pytest.approx((2 * np.pi / 3, np.pi))
    slot = thesis_cut(radial_depth="12 mm")
    assert slot.angles == pytest.approx((0.0, np.pi))


def altintas_alpha(st, ex, kr):
    """Altintas & Budak's directional coefficients, written out (Manufacturing Automation, ch. 3)."""
    def f(p):
        return 0.5 * np.array([[np.cos(2 * p) - 2 * kr * p + kr * np.sin(2 * p),
                                -np.sin(2 * p) - 2 * p + kr * np.cos(2 * p)],
                               [-np.sin(2 * p) + 2 * p + kr * np.cos(2 * p),
                                -np.cos(2 * p) - 2 * kr * p - kr * np.sin(2 * p)]])
    return f(ex) - f(st)


@pytest.mark.parametrize("milling", ["up", "down"])
@pytest.mark.parametrize("radial", ["0.6 mm", "3 mm", "9 mm", "12 mm"])
def test_mean_force_matrix_is_altintas_directional_factors(milling, radial):
    cut = thesis_cut(radial_depth=radial, milling=milling)
    st, ex = cut.angles
    expected = cut.teeth * cut.kt_pa / (4 * np.pi) * altintas_alpha(st, ex, cut.kr)
    np.testing.assert_allclose(cut.mean_force_matrix(), expected, rtol=1e-12, atol=1e-6 * cut.kt_pa)


@pytest.mark.parametrize("teeth, radial, milling", [(2, "10 mm", "down"), (3, "4 mm", "up"), (4, "0.3 mm", "down"),
                                                   (5, "12 mm", "up")])
def test_force_averages_match_numerical_integration(teeth, radial, milling):
    cut = MillingCut(teeth, "12 mm", radial, kt="6e8 Pa", kn="2e8 Pa", milling=milling)
    for a, b, cutting in cut.period_arcs():
        edges = np.linspace(a, b, 4)
        averages = cut.force_matrix_average(edges[:-1], edges[1:])
        for (lo, hi), avg in zip(zip(edges[:-1], edges[1:]), averages):
            theta = np.linspace(lo, hi, 20001)[1:-1]  # open interval: the cut indicator jumps at the ends
            numeric = cut.force_matrix(theta).mean(axis=0)
            np.testing.assert_allclose(avg, numeric, atol=2e-4 * cut.kt_pa)
        assert cutting == bool(np.abs(averages).max() > 0)
    theta = np.linspace(0, cut.period_angle, 200001)[:-1]
    np.testing.assert_allclose(cut.mean_force_matrix(), cut.force_matrix(theta).mean(axis=0), atol=1e-4 * cut.kt_pa)


def test_period_arcs_cover_the_tooth_period():
    for cut in (thesis_cut(), thesis_cut(milling="down"), thesis_cut(radial_depth="12 mm"),
                MillingCut(2, "10 mm", "0.5 mm", kt="6e8 Pa", kn="2e8 Pa", milling="down")):
        arcs = cut.period_arcs()
        assert arcs[0][0] == 0.0 and arcs[-1][1] == pytest.approx(cut.period_angle)
        assert all(b1 == a2 for (_, b1, _), (a2, _, _) in zip(arcs[:-1], arcs[1:]))
        cutting = sum(b - a for a, b, c in arcs if c)
        st, ex = cut.angles
        assert cutting == pytest.approx(min(ex - st, cut.period_angle))


def test_turning_cut_is_an_oriented_single_direction():
    cut = TurningCut("2000 MPa", orientation=0.8)
    np.testing.assert_allclose(cut.mean_force_matrix(), [[-1.6e9, 0], [0, 0]])
    assert cut.regenerations_per_revolution == 1
    assert TurningCut("2 GPa", direction="y").mean_force_matrix()[1, 1] == -2e9
    for bad in (0.0, 1.5, -2):
        with pytest.raises(InvalidValueError, match="orientation"):
            TurningCut("2000 MPa", orientation=bad)
    with pytest.raises(InvalidValueError, match="kf"):
        TurningCut("-2000 MPa")


# -- spindle speeds: rpm, never Hz ----------------------------------------------------


def test_speeds_in_rpm_and_angular_units():
    np.testing.assert_allclose(as_speed_rpm(Q_([1000.0, 2000.0], "rpm")), [1000.0, 2000.0])
    np.testing.assert_allclose(as_speed_rpm(Q_(2 * np.pi, "rad/s")), [60.0])
    np.testing.assert_allclose(as_speed_rpm("12000 rpm"), [12000.0])
    grid = spindle_speeds("1000 rpm", "2000 rpm", "250 rpm")
    np.testing.assert_allclose(grid.m_as("rpm"), [1000, 1250, 1500, 1750, 2000])


def test_speeds_in_hz_or_bare_are_refused():
    with pytest.raises(UnitError, match="Hz.*rpm.*hz_to_rpm"):
        as_speed_rpm(Q_([100.0, 200.0], "Hz"))
    with pytest.raises(UnitError, match="rpm"):
        spindle_speeds("50 Hz", "300 Hz", "1 Hz")
    with pytest.raises(UnitError, match="with their unit"):
        as_speed_rpm(np.array([1000.0, 2000.0]))
    with pytest.raises(InvalidValueError, match="increasing"):
        as_speed_rpm(Q_([2000.0, 1000.0], "rpm"))
    with pytest.raises(InvalidValueError, match="positive"):
        as_speed_rpm(Q_([0.0, 1000.0], "rpm"))


def test_tooth_passing_frequency_is_teeth_times_revolutions_per_second():
    assert tooth_passing_hz(12000, 4) == pytest.approx(800.0)  # not 800 * 2 * pi


@pytest.mark.parametrize("speed, teeth, message", [
    (12000, 0, "teeth: got 0; expected a whole number of teeth >= 1"),  # 0 Hz
    (12000, 2.5, "teeth: got 2.5"),
    ("12000", 4, "speed_rpm: got '12000'; expected spindle speeds in rpm, plain numbers >= 0"),
    ([-100.0, 2000.0], 4, "speed_rpm: got [-100.0, 2000.0]"),
])
def test_tooth_passing_refuses_no_teeth_and_speeds_that_are_not_speeds(speed, teeth, message):
    from substructure import InvalidValueError

    with pytest.raises(InvalidValueError) as caught:
        tooth_passing_hz(speed, teeth)
    assert message in str(caught.value)
