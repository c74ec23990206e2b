"""Unit checks at the boundary: one registry, bare numbers and wrong dimensions rejected."""

import math
import re

import numpy as np
import pint
import pytest

from substructure import InvalidValueError, Material, Segment, UnitError
from substructure.units import (Q_, bare_unit, dimensionless, format_quantity, hz_to_rpm, instrument_unit, quantity,
                                rpm_to_hz, to_si, ureg)


def test_strings_and_quantities_are_accepted():
    assert quantity("60 mm", "od", "[length]") == Q_(0.06, "m")
    assert to_si(Q_(60, "mm"), "od", "m") == pytest.approx(0.06)
    assert to_si("4.19e7 N/m", "k", "N/m") == 4.19e7


def test_quantity_of_another_registry_is_converted():
    other = pint.UnitRegistry()
    q = quantity(other.Quantity(12, "mm"), "od", "[length]")
    assert q._REGISTRY is ureg
    assert q.m_as("m") == pytest.approx(0.012)


@pytest.mark.parametrize("value", [60, 60.0, np.float64(60.0)])
def test_bare_number_is_rejected_with_field_and_expectation(value):
    with pytest.raises(UnitError, match=r"od: got the bare number .*expected a length"):
        quantity(value, "od", "[length]")


def test_wrong_dimension_names_field_value_and_expectation():
    with pytest.raises(UnitError, match=r"od: got '60 kg' with dimension \[mass\]; expected a length"):
        quantity("60 kg", "od", "[length]")


def test_unitless_string_and_garbage_are_rejected():
    with pytest.raises(UnitError, match="without a unit"):
        quantity("60", "od", "[length]")
    with pytest.raises(UnitError, match="cannot read"):
        quantity("sixty mm", "od", "[length]")


@pytest.mark.parametrize("text", ["nan mm", "inf mm"])
def test_non_finite_values_are_rejected(text):
    with pytest.raises(InvalidValueError, match="finite"):
        quantity(text, "od", "[length]")


def test_dimensionless_rejects_units_and_non_numbers():
    assert dimensionless(0.3, "nu") == 0.3
    with pytest.raises(UnitError):
        dimensionless(Q_(3, "mm"), "nu")
    with pytest.raises(InvalidValueError):
        dimensionless(float("nan"), "nu")
    with pytest.raises(InvalidValueError):
        dimensionless(True, "nu")


def test_format_quantity_round_trips_exactly():
    for q in (Q_(60, "mm"), Q_(0.1 + 0.2, "m"), Q_(4.19e7, "N/m"), Q_(1e-8, "kg*m**2")):
        back = ureg.Quantity(format_quantity(q))
        assert back == q and back.magnitude == q.magnitude


def test_rpm_helpers_are_explicit_and_exact():
    assert rpm_to_hz(6000) == 100.0
    assert hz_to_rpm(100.0) == 6000.0
    # The trap the helper avoids: pint treats rpm as an angular velocity.
    assert ureg.Quantity(6000, "rpm").m_as("Hz") == pytest.approx(100 * 2 * math.pi)


def test_negative_length_and_id_ge_od_are_errors():
    with pytest.raises(InvalidValueError, match="length: got '-5 mm'; expected a positive length"):
        Segment("-5 mm", "12 mm")
    with pytest.raises(InvalidValueError, match="id: got 12 mm with od 12 mm; expected id < od"):
        Segment("5 mm", "12 mm", "12 mm")


def test_material_checks():
    with pytest.raises(InvalidValueError, match=r"nu: got 0.5; expected a Poisson ratio in \(-1, 0.5\)"):
        Material("x", E="200 GPa", nu=0.5, rho="7800 kg/m^3")
    with pytest.raises(InvalidValueError, match="loss_factor: got -0.1"):
        Material("x", E="200 GPa", nu=0.3, rho="7800 kg/m^3", loss_factor=-0.1)
    with pytest.raises(UnitError, match="E: got the bare number 200000000000.0"):
        Material("x", E=200e9, nu=0.3, rho="7800 kg/m^3")
    with pytest.raises(UnitError, match="rho"):
        Material("x", E="200 GPa", nu=0.3, rho="7800 kg")
    m = Material("x", E="260 GPa", nu=0.3, rho="7800 kg/m^3", loss_factor=0.01)
    assert m.G.m_as("GPa") == pytest.approx(100.0)
    assert m.E_si == pytest.approx(260e9 * (1 + 0.01j))


def test_catalogue():
    from substructure import CATALOG, get_material

    assert set(CATALOG) == {"steel", "carbide", "aluminium"}
    assert Material.from_catalog("steel") is CATALOG["steel"]
    with pytest.raises(InvalidValueError, match="unknown material 'unobtainium'; known: aluminium, carbide, steel"):
        get_material("unobtainium")


@pytest.mark.parametrize("text, si, factor", [
    ("m/s2", "m/s^2", 1.0), ("m s-2", "m/s^2", 1.0), ("m.s-2", "m/s^2", 1.0), ("m\u00b7s\u207b\u00b2", "m/s^2", 1.0),
    ("mm/s\u00b2", "m/s^2", 1e-3), ("m/s**2", "m/s^2", 1.0), ("g", "m/s^2", 9.80665), ("G", "m/s^2", 9.80665),
    ("\u00b5m", "m", 1e-6), ("\u03bcm", "m", 1e-6), ("um", "m", 1e-6), ("lb", "N", 0.45359237 * 9.80665),
    ("mV/lb", "V/N", 1e-3 / (0.45359237 * 9.80665)), ("mV/g", "V/(m/s^2)", 1e-3 / 9.80665), ("(m/s2)/N", "1/kg", 1.0),
    ("g/N", "1/kg", 9.80665), ("m^2", "m^2", 1.0), ("gn", "m/s^2", 9.80665), ("mV/g_n", "V/(m/s^2)", 1e-3 / 9.80665),
    # US vibration units: a mil is 0.001 in = 25.4 um (pint's mil is an angle), ips an inch per second
    ("mil", "m", 25.4e-6), ("mils", "m", 25.4e-6), ("mV/mil", "V/m", 1e-3 / 25.4e-6), ("ips", "m/s", 0.0254),
    ("mV/ips", "V/(m/s)", 1e-3 / 0.0254), ("in/lbf", "m/N", 0.0254 / (0.45359237 * 9.80665)),
])
def test_instrument_units_read_as_acquisition_programs_write_them(text, si, factor):
    # factors by the definitions: g_n = 9.80665 m/s^2, 1 lb = 0.45359237 kg, so 1 lbf = 0.45359237 g_n newtons
    assert ureg.Quantity(1.0, instrument_unit(text)).m_as(si) == pytest.approx(factor, rel=1e-12)


@pytest.mark.parametrize("text", ["m/s^", "Volts per g", "m/(s"])
def test_an_instrument_unit_pint_cannot_read_is_a_value_error(text):
    with pytest.raises(ValueError):
        instrument_unit(text)


@pytest.mark.parametrize("cell, unit", [("[Hz]", "Hz"), ("(m/N)", "m/N"), (" [ mm/N ] ", "mm/N"),
                                        ("(m/s2)/N", "(m/s2)/N"), ("(m/s^2)/(N)", "(m/s^2)/(N)"), ("g/N", "g/N"),
                                        ("", None), ("[]", None)])
def test_a_unit_cell_loses_only_the_brackets_around_the_whole(cell, unit):
    assert bare_unit(cell) == unit


@pytest.mark.parametrize("text, read_by_pint", [
    ("20,5 mm", "205 mm"),      # a decimal comma: pint drops it
    ("1,000 mm", "1000 mm"),
    ("20 , 5 mm", "100 mm"),
    ("1 2 mm", "2 mm"),         # "12 mm" with a stray space: pint multiplies the numbers
    ("1 1/2 in", "0.5 in"),     # a mixed fraction
    ("20 mm 2", "40 mm"),
])
def test_a_number_pint_would_read_as_another_is_refused(text, read_by_pint):
    assert ureg.Quantity(text) == ureg.Quantity(read_by_pint)  # what was read silently before
    said = r"od: (cannot read|got) '.*'(: a comma|: a number written after).*expected a length"
    with pytest.raises(UnitError, match=said):
        quantity(text, "od", "[length]")


@pytest.mark.parametrize("text", ["0,002", "1 2"])
def test_a_dimensionless_number_pint_would_read_as_another_is_refused(text):
    said = r"loss_factor: (cannot read|got) '.*'(: a comma|: a number written after)"
    with pytest.raises(InvalidValueError, match=said):
        dimensionless(text, "loss_factor")


@pytest.mark.parametrize("text", ["20 mm", "20mm", "2.5e-3 m", ".5 in", "1/2 in", "20 mm - 5 mm", "5e-8 kg*m**2"])
def test_numbers_with_operators_and_exponents_still_read(text):
    quantity(text, "x", str(ureg.Quantity(text).dimensionality))


def test_a_dimensionless_unit_where_a_dimension_is_expected_is_named():
    with pytest.raises(UnitError, match=r"od: got '20 mil', whose unit mil has no dimension .*'thou'"):
        quantity("20 mil", "od", "[length]")
    with pytest.raises(UnitError, match=r"od: got '20 %', whose unit percent has no dimension"):
        quantity("20 %", "od", "[length]")


@pytest.mark.parametrize("text, read_by_pint, char", [
    ("12 \u2212 3 mm", "36 mm", "\u2212"),  # a Unicode minus sign, as word processors write it
    ("12 \u2013 3 mm", "36 mm", "\u2013"),  # an en dash
    ("12 # 3 mm", "12", "#"),               # the rest read as a comment
    ("2' 3 mm", "6 mm", "'"),
    ("12\u200bmm", "12 mm", "\u200b"),      # a zero-width space pasted from a web page
])
def test_a_character_pint_would_skip_is_refused(text, read_by_pint, char):
    assert ureg.Quantity(text) == ureg.Quantity(read_by_pint)  # what was read silently before
    said = rf"od: got .*: the character {re.escape(repr(char))} \(U\+{ord(char):04X}\) is neither"
    with pytest.raises(UnitError, match=said):
        quantity(text, "od", "[length]")


def test_a_unicode_minus_at_the_start_says_so_and_unit_symbols_still_read():
    with pytest.raises(UnitError, match="write '-' for a minus sign"):
        quantity("\u22125 mm", "od", "[length]")
    assert quantity("5e-8 kg\u00b7m\u00b2", "J", "[mass] * [length] ** 2") == Q_(5e-8, "kg*m^2")
    assert quantity("3 \u00c5", "x", "[length]") == Q_(3, "angstrom")
    assert quantity("9.81 m\u00b7s\u207b\u00b2", "a", "[length] / [time] ** 2") == Q_(9.81, "m/s^2")


def test_a_fraction_or_a_decimal_magnitude_is_taken_as_a_float():
    """Q_(Fraction(1, 3), "mm") or a Decimal magnitude passed the checks and failed later in numpy with a raw
    TypeError ('ufunc isfinite not supported'); such a magnitude is taken as the float it is."""
    from decimal import Decimal
    from fractions import Fraction

    from substructure import Segment
    from substructure.units import Q_, quantity

    assert Segment(Q_(Fraction(1, 3), "mm"), "12 mm").length_m == pytest.approx(1e-3 / 3, rel=1e-15)
    q = quantity(Q_(Decimal("12.5"), "mm"), "od", "[length]")
    assert isinstance(q.magnitude, float) and q.magnitude == 12.5


def test_whole_number_takes_integers_only_and_names_the_field():
    import numpy as np
    import pytest

    from substructure.errors import InvalidValueError
    from substructure.units import whole_number

    assert whole_number(np.int64(3), "steps", 1) == 3 and type(whole_number(np.int64(3), "steps", 1)) is int
    for value in (True, 2.0, "3", 0, None):
        with pytest.raises(InvalidValueError, match=f"steps: got {value!r}; expected a whole number of steps >= 1"):
            whole_number(value, "steps", 1, "a whole number of steps")


@pytest.mark.parametrize("text, dimension, value", [
    ("12 mm*rad/deg", "[length]", "687.5"),  # read as 687.5 mm without a word
    ("12 mm*rad", "[length]", "12 mm"),
    ("3 mm*%", "[length]", "3 mm"),
    ("8e4 N*m*rad/deg", "[mass] * [length] ** 2 / [time] ** 2", "4583662"),
])
def test_units_without_a_dimension_that_only_scale_the_number_are_refused(text, dimension, value):
    with pytest.raises(UnitError, match=rf"od: got '{re.escape(text)}'; its units? .* no dimension .*{value}"):
        quantity(text, "od", dimension)


def test_an_angle_unit_that_carries_meaning_stays():
    from substructure import Joint

    joint = Joint("j", ["a.tip", "b.base"], k={"yf": "1e7 N/m", "tm": "8e4 N*m/deg"})
    assert joint.k.values[1, 1] == pytest.approx(8e4 * 180.0 / math.pi, rel=1e-12)  # per degree: 57.3 per rad
    with pytest.raises(UnitError, match="only scales the number"):
        Segment("12 mm*rad/deg", "10 mm")
