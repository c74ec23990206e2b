"""Hostile inputs to the Python API of components, joints, points and sweeps.

Each case gave a silently wrong value, a raw Python error from deep inside, or
gigabytes of memory before it was checked where it enters.
"""

from __future__ import annotations

import math
import re
import sys
from pathlib import Path

import attrs
import numpy as np
import pytest

from substructure import (Assembly, Flutes, Frequency, Holder, Joint, Material, MeasuredComponent, Segment, Sensor,
                          Tool, UnitError, add_mass, decouple, default_assembly, remove_mass)
from substructure.components import own_parameters, with_parameter
from substructure.coupling import modify
from substructure.errors import InvalidValueError, NonPassiveJointWarning, NonReciprocalWarning, UnknownPointError
from substructure.frf import FRF
from substructure.materials import get_material
from substructure.points import parse_point
from substructure.sweep import sweep

GRID = [500.0, 1000.0]


@pytest.mark.parametrize("text", ["1,5 mm", "1, 5 mm", "1,000 mm"])
def test_a_comma_in_a_value_is_refused_not_dropped(text):
    """pint drops the comma: '1,5 mm' was a segment of 15 mm and '1, 5 mm' one of 5 mm."""
    with pytest.raises(UnitError, match=r"length: cannot read '1, ?[05]+ mm': a comma is neither a decimal point"):
        Segment(text, "12 mm")


def test_a_comma_in_a_plain_number_is_refused_too():
    with pytest.raises(InvalidValueError, match=r"loss_factor: cannot read '0,002': a comma"):
        Material("x", "210 GPa", 0.3, "7850 kg/m^3", loss_factor="0,002")
    with pytest.raises(InvalidValueError, match=r"flutes.diameter_ratio: cannot read '0,8': a comma"):
        Flutes("0,8")


@pytest.mark.parametrize("between", [None, 5, (p for p in ("a.tip", "b.base")), "a.tip"])
def test_a_joint_between_that_is_not_two_points_is_named(between):
    """None, a number or a generator gave a raw TypeError (object has no len())."""
    with pytest.raises(InvalidValueError, match=r"between: got .*; expected two point names"):
        Joint("j", between, k={"yf": "1e7 N/m"})


def test_a_material_name_that_is_not_a_text():
    """A list gave a raw TypeError (unhashable type)."""
    with pytest.raises(InvalidValueError, match=r"material: got \[\]; expected the name of a material"):
        get_material([])


def test_a_helix_in_percent_is_not_taken_as_radians():
    """'30 %' is the number 0.3, which was read as 0.3 rad: a helix of 17.2 deg."""
    with pytest.raises(UnitError, match=r"helix: got '30 %'; expected an angle"):
        Tool.end_mill("12 mm", "50 mm", "30 mm", helix="30 %")
    assert Tool.end_mill("12 mm", "50 mm", "30 mm", helix="0.5 rad").helix.m_as("rad") == pytest.approx(0.5)


@pytest.mark.parametrize("args, message", [
    (("-12 mm", "50 mm", "30 mm"), r"diameter: got '-12 mm'; expected a positive length"),
    (("12 mm", "-50 mm"), r"overhang: got '-50 mm'; expected a positive length"),
    (("12 mm", "50 mm", "-30 mm"), r"flute_length: got '-30 mm'; expected a length >= 0"),
])
def test_end_mill_names_its_own_arguments(args, message):
    """A negative flute length was refused as 'length: got <Quantity(-30, 'millimeter')>'."""
    with pytest.raises(InvalidValueError, match=message):
        Tool.end_mill(*args)


@pytest.mark.parametrize("frequency", [True, ["500", "1000"], [np.True_]])
def test_booleans_and_texts_are_not_frequencies(frequency):
    """True was 1 Hz, and ['500', '1000'] 500 and 1000 Hz, while '500 Hz' was refused."""
    with pytest.raises(InvalidValueError, match=r"frequency: got .*; expected a Frequency"):
        default_assembly().receptance("tool.tip:y", frequency=frequency)


def test_a_frequency_far_beyond_the_beam_model_is_refused_before_the_memory_goes():
    """A line at 3e7 Hz cut the spindle into some 3000 pieces (0.5 GB, 1 s); at 1e8 Hz 4 GB and a
    MemoryError, at 1e12 Hz 15 GB: a frequency in the wrong unit took the machine down."""
    d = default_assembly()
    with pytest.raises(InvalidValueError, match=r"frequency: got a line at 3e\+07 Hz, where component 'spindle' "
                                                r"would be cut into about .* pieces"):
        d.receptance("tool.tip:y", frequency=[500.0, 3e7])
    with pytest.raises(InvalidValueError, match=r"component 'tool' would be cut"):
        d.component("tool").receptance([1e12])
    rods = [Assembly("rod", components=(Tool("rod", [Segment(f"{L} m", "12 mm", material="carbide")]),))
            for L in (5, 5.1)]  # some 3000 pieces at 3 MHz
    with pytest.raises(InvalidValueError, match=r"component 'rod' would be cut"):  # the batched beams too
        sweep(rods, "rod.tip:y", frequency=[3e6])
    assert np.isfinite(d.receptance("tool.tip:y", frequency=[1e5]).data).all()   # a fast tap test still works


def test_sweep_arguments_that_are_not_what_it_takes():
    d = default_assembly()
    with pytest.raises(InvalidValueError, match=r"sweep: variant 1 is 2; expected an Assembly"):
        sweep([d, 2], "tool.tip:y", frequency=GRID)
    with pytest.raises(InvalidValueError, match=r"sweep: got an object of type Assembly; expected a sequence of "
                                                r"assemblies \(a list: \[assembly\] for one\)"):
        sweep(d, "tool.tip:y", frequency=GRID)
    for chunk in ("10", 1.5, 0, True):
        with pytest.raises(InvalidValueError, match=r"chunk_lines: got .*; expected a whole number of lines >= 1"):
            sweep([d], "tool.tip:y", frequency=GRID, chunk_lines=chunk)


def test_a_sweep_too_large_for_memory_is_refused_before_any_work(monkeypatch):
    """The result was allocated whole after every variant was planned: a million variants of 2491 lines
    asked for 40 GB."""
    monkeypatch.setattr(sys.modules["substructure.sweep"], "MAX_SWEEP_VALUES", 10)
    d = default_assembly()
    with pytest.raises(InvalidValueError, match=r"sweep: 3 variants x 2 lines x 2 x 2 DOFs would be 24 complex "
                                                r"values .* more than 1e\+01"):
        sweep([d, d, d], "tool.tip", frequency=GRID)
    assert sweep([d, d], "tool.tip:y", frequency=GRID).data.shape == (2, 2, 1, 1)   # 4 values: below


def test_point_names_take_spaces_around_the_minus_as_around_the_rest():
    """'tool .tip-5 mm' and 'tool.tip-5 mm ' were read, 'tool.tip -5 mm' and 'tool.tip - 5 mm' refused."""
    for text in ("tool.tip - 5 mm", "tool.tip -5 mm", " tool . tip - 5mm:y"):
        assert str(parse_point(text).point) == "tool.tip-5 mm"
    d = default_assembly()
    np.testing.assert_array_equal(d.receptance("tool.tip - 5 mm:y", frequency=GRID).data,
                                  d.receptance("tool.tip-5 mm:y", frequency=GRID).data)


@pytest.mark.parametrize("text, message", [
    ("tool.tip-5 mm-3 mm", r"the distance '5 mm-3 mm' holds a sum or a difference"),   # was tool.tip-2 mm
    ("tool@5 mm + 3 mm", r"the distance '5 mm \+ 3 mm' holds a sum or a difference"),   # was tool@8 mm
    ("tool.tip:y:theta", r"more than one ':'; expected one DOF suffix"),
])
def test_point_names_that_were_computed_or_misread(text, message):
    with pytest.raises(UnknownPointError, match=message):
        parse_point(text)
    assert str(parse_point("tool@1e-3 m")) == "tool@0.001 m"   # an exponent is not a difference


def test_a_measured_component_with_labels_that_are_not_points_is_refused_where_it_is_made():
    """Labels 'a', 'b' were accepted, and the assembly built from it failed on point 'a' without naming the
    measured component."""
    y = Tool.end_mill("12 mm", "50 mm").receptance(GRID, ["tip"])
    with pytest.raises(InvalidValueError, match=r"frf: the label 'a:y' is not a point name with its DOF"):
        MeasuredComponent("m", FRF(y.frequency, y.data, ("a:y", "a:theta"), ("a:y", "a:theta")))
    with pytest.raises(InvalidValueError, match=r"frf: the label 'a' is not a point name"):
        MeasuredComponent("m", FRF(y.frequency, y.data, ("a", "b"), ("a", "b")))
    assert Assembly("x", components=(MeasuredComponent("m", y),)).receptance("tool.tip:y", frequency=GRID).shape \
        == (2, 1, 1)


def _as(frf, quantity):
    omega = frf.frequency.omega
    factor = {"mobility": 1j * omega, "accelerance": -(omega**2)}[quantity]
    return attrs.evolve(frf, data=frf.data * factor[:, None, None], quantity=quantity)


@pytest.mark.parametrize("quantity", ["mobility", "accelerance"])
def test_a_mass_added_to_a_mobility_or_an_accelerance_is_added_to_what_it_measures(quantity):
    """The receptance formula ran on the accelerance's values: a 2 g sensor added to a tool tip accelerance gave
    values 1e5 times too small, still labelled an accelerance."""
    d = default_assembly()
    h = d.receptance("tool.tip:y", frequency=GRID)
    added = add_mass(_as(h, quantity), "tool.tip", "2 g")
    assert added.quantity == quantity
    np.testing.assert_allclose(added.to_receptance().data, add_mass(h, "tool.tip", "2 g").data, rtol=1e-12)
    back = remove_mass(added, "tool.tip", "2 g")
    np.testing.assert_allclose(back.to_receptance().data, h.data, rtol=1e-9)


def test_decoupling_an_accelerance_and_on_the_rotation_alone():
    """decouple took an accelerance as a receptance; and at an interface of theta alone it took the joint's
    k_yf for its k_tm (here 0: the tool was not removed at all, 1.4 % off)."""
    grid = Frequency.from_hz([500.0, 1000.0, 1500.0])
    joint = Joint("holder-tool", ("holder.tip", "tool.base"), k={"tm": "8e4 N*m/rad"}, c={"tm": "4 N*m*s/rad"})
    d = default_assembly().with_joint(joint)
    expected = d.without("tool").frf(["holder.tip:theta"], frequency=grid)
    removed = d.component("tool").receptance(grid, ["base"]).select(["tool.base:theta"], ["tool.base:theta"])
    alone = decouple(d.frf(["holder.tip:theta"], frequency=grid), removed, [("holder.tip", "tool.base", joint)])
    np.testing.assert_allclose(alone.data, expected.data, rtol=1e-9)
    both = d.frf(["holder.tip"], frequency=grid)
    alone = decouple(_as(both, "accelerance"), d.component("tool").receptance(grid, ["base"]),
                     [("holder.tip", "tool.base", joint)])
    assert alone.quantity == "accelerance"
    np.testing.assert_allclose(alone.to_receptance().data, d.without("tool").frf(["holder.tip"], frequency=grid).data,
                               rtol=1e-9)


def test_modifications_that_gave_raw_errors_or_refused_a_spaced_point():
    d = default_assembly()
    h = d.receptance("tool.tip:y", frequency=GRID)
    for dz in (5.0, np.ones((1, 1, 7)), lambda f: 3):
        with pytest.raises(InvalidValueError, match=r"delta_stiffness: got an array of shape .*; expected \(r, r\) or "
                                                    r"\(r, r, 2\)"):
            modify(h, "tool.tip:y", dz)
    with pytest.raises(InvalidValueError, match=r"interface\[0\]: got \('holder.tip', 'tool.base'\); expected"):
        decouple(h, h, [("holder.tip", "tool.base")])
    with pytest.raises(InvalidValueError, match=r"frf: got str; expected an FRF"):
        add_mass("tool.tip", "tool.tip", "2 g")
    np.testing.assert_array_equal(add_mass(h, "tool.tip :y", "2 g").data, add_mass(h, "tool.tip:y", "2 g").data)


def test_a_beams_own_receptance_takes_its_points_as_the_assembly_does():
    """points='tip' was read letter by letter ('point tool.t'), None gave an AttributeError, a point of another
    component was read as 'tool.holder.tip', the same place twice said 'positions: expected distinct positions',
    and position(5) gave an AttributeError."""
    tool = Tool.end_mill("12 mm", "50 mm", "30 mm")
    assert tool.receptance(GRID, "tip").outputs == ("tool.tip:y", "tool.tip:theta")
    assert tool.receptance(GRID, [" tip - 5 mm"]).outputs[0] == "tool.tip-5 mm:y"
    with pytest.raises(UnknownPointError, match=r"point: got None; expected a point of 'tool'"):
        tool.receptance(GRID, [None])
    with pytest.raises(UnknownPointError, match=r"point holder.tip: not on component 'tool'"):
        tool.receptance(GRID, ["holder.tip"])
    with pytest.raises(InvalidValueError, match=r"points: 'tip' and '@50 mm' are the same place of 'tool'"):
        tool.receptance(GRID, ["tip", "@50 mm"])
    with pytest.raises(UnknownPointError, match=r"point 'tool.tip:y': a DOF suffix is not allowed here"):
        tool.receptance(GRID, ["tip:y"])
    with pytest.raises(UnknownPointError, match=r"point: got 5; expected a point of 'tool'"):
        tool.position(5)


def test_a_joint_of_1e300_n_per_m_is_checked_without_overflow():
    """The passivity check multiplied the entries: a RuntimeWarning (an error under -W error) for k = 1e300."""
    Joint("j", ("a.tip", "b.base"), k={"yf": "1e300 N/m", "tm": "1e300 N*m/rad"})
    with pytest.warns(NonPassiveJointWarning, match=r"k_ym\*k_tf = 4e\+12 > k_yf\*k_tm = 1e\+12"):
        Joint("j", ("a.tip", "b.base"), k={"yf": "1e7 N/m", "ym": "2e6 N", "tf": "2e6 N/rad", "tm": "1e5 N*m/rad"})


def test_the_progress_of_a_long_sweep_is_a_line_per_percent_at_most(capsys):
    """A line per chunk: with one variant per chunk, 300 variants printed 300 lines (a million, a million)."""
    d = default_assembly().without("spindle", "holder")
    variants = [d.with_component(Tool.end_mill("12 mm", f"{40 + 0.1 * i:.1f} mm")) for i in range(300)]
    sweep(variants, "tool.tip:y", frequency=GRID, chunk_lines=1, progress=True)
    lines = capsys.readouterr().err.splitlines()
    assert len(lines) == 101 and lines[0] == "sweep: 1/300 variants" and lines[-1] == "sweep: 300/300 variants"


@pytest.mark.parametrize("key, value, message", [
    ("gap_length", "-2 mm", r"gap_length: got '-2 mm'; expected a length >= 0"),   # was a 72 mm holder for 70 mm
    ("flange_diameter", "-63 mm", r"flange_diameter: got '-63 mm'; expected a positive length"),   # was 'od: ...'
    ("nut_length", "0 mm", r"nut_length: got '0 mm'; expected a positive length"),   # was 'length: ...'
])
def test_catalogue_lengths_are_checked_under_their_own_names(key, value, message):
    with pytest.raises(InvalidValueError, match=message):
        Holder.from_catalog("BT40 ER32", bore="12 mm", gauge_length="70 mm", **{key: value})
    assert Holder.from_catalog("BT40 ER32", bore="12 mm", gauge_length="70 mm", gap_length="0 mm").length_m \
        == pytest.approx(0.070)


@attrs.frozen
class _SteppedHolder(Holder):
    """A holder with a count among its fields, as the shrink-fit holder of docs/extending.md."""

    steps: int = attrs.field(default=4, kw_only=True)
    nut_kg: float = attrs.field(default=1, kw_only=True)

    def __attrs_post_init__(self):
        if not isinstance(self.steps, int) or self.steps < 1:
            raise InvalidValueError(f"steps: got {self.steps!r}; expected a whole number >= 1")

    def receptance_matrix(self, refs, frequency_hz, decay=0.0):
        return Holder.receptance_matrix(self, refs, frequency_hz, decay)


def test_a_count_among_a_components_fields_is_not_a_parameter_to_fit():
    """steps = 4 was offered to the fits as a number from 0.4 to 40: setting it to 4.37 failed in the middle of a
    diagnosis (or, without the class's own check, made a holder of 4.37 steps); a text value gave a raw ValueError."""
    holder = _SteppedHolder("holder", [Segment("50 mm", "40 mm")])
    assert [p.name for p in own_parameters(holder)] == ["nut_kg"]   # 1, written as an int, is still a value
    with pytest.raises(UnknownPointError, match=r"no parameter 'steps'; its own parameters: nut_kg"):
        with_parameter(holder, "steps", 4.37)
    with pytest.raises(InvalidValueError, match=r"nut_kg: got 'abc'; expected a number"):
        with_parameter(holder, "nut_kg", "abc")
    assert with_parameter(holder, "nut_kg", 0.4).nut_kg == 0.4


def test_a_sweep_that_moves_a_sensor_between_points_it_computes_anyway_is_refused():
    """With the sensor at two points that are both outputs, the variants had the same nodes and names and every
    variant was computed with the sensor where variant 0 has it: variant 1 was 118 % off, silently."""
    d = default_assembly()
    variants = [d.attach(Sensor("acc", p, "20 g")) for p in ("tool.tip", "holder.tip")]
    with pytest.raises(InvalidValueError, match=r"sweep: variant 1 .* has sensor 'acc' at holder.tip, variant 0 at "
                                                r"tool.tip; a sweep needs each joint, sensor, mass and support at the "
                                                r"same points"):
        sweep(variants, ["tool.tip:y", "holder.tip:y"], frequency=GRID)
    j = d.joint("holder-tool")   # a joint written the other way round couples alike: accepted, and right
    flipped = d.with_joint(Joint(j.name, j.between[::-1], k=j.k, c=j.c))
    result = sweep([d, flipped], "tool.tip:y", frequency=GRID)
    np.testing.assert_allclose(result[1].data, flipped.receptance("tool.tip:y", frequency=GRID).data, rtol=1e-12)


@attrs.frozen
class _Lump:
    """A lumped body of one's own whose L and N differ: not a linear elastic structure."""

    name: str
    cross: float = 1e-9

    @property
    def component_names(self):
        return frozenset({self.name})

    def node_key(self, ref):
        return (self.name, ref.where)

    def receptance_matrix(self, refs, frequency_hz):
        w2 = (2 * np.pi * np.asarray(frequency_hz)) ** 2
        y = np.zeros((2, 2, w2.size), dtype=complex)
        y[0, 0], y[1, 1], y[0, 1] = -1 / (0.5 * w2), -1 / (1e-4 * w2), self.cross
        return y


def test_a_component_of_ones_own_that_is_not_reciprocal_is_warned_of():
    """Its receptances entered the coupling as they were: the tool point FRF was not reciprocal, without a word."""
    d = default_assembly().without("tool")
    lumped = d.add(_Lump("nut")).connect("holder.tip", "nut.tip", k={"yf": "1e8 N/m", "tm": "1e6 N*m/rad"})
    with pytest.warns(NonReciprocalWarning, match=r"component 'nut' \(_Lump\): receptance_matrix gave a matrix that "
                                                  r"is not symmetric \(nut.tip:y / nut.tip:theta and nut.tip:theta / "
                                                  r"nut.tip:y differ by"):
        lumped.receptance("holder.tip:y", frequency=GRID)
    symmetric = d.add(_Lump("nut", 0.0)).connect("holder.tip", "nut.tip", k={"yf": "1e8 N/m", "tm": "1e6 N*m/rad"})
    assert np.isfinite(symmetric.receptance("holder.tip:y", frequency=GRID).data).all()   # no warning: an error here


def test_an_angle_with_a_comma_is_refused_in_python_too():
    """A tool's helix and a shrink-fit holder's nose angle as texts with a comma were read by pint as ten times the
    angle ("3,5 deg" as 35 deg) in the Python API (the file reader refused them); they are refused by name."""
    from substructure import Holder, InvalidValueError, Tool, UnitError

    with pytest.raises(UnitError, match="helix.*comma"):
        Tool.end_mill("12 mm", "50 mm", "30 mm", helix="3,5 deg")
    assert Tool.end_mill("12 mm", "50 mm", "30 mm", helix="3.5 deg") is not None
    with pytest.raises(InvalidValueError, match="nose_angle.*comma"):
        Holder.from_catalog("BT40 shrink-fit", bore="12 mm", nose_angle="4,5 deg")
    assert Holder.from_catalog("BT40 shrink-fit", bore="12 mm", nose_angle="4.5 deg") is not None


def test_a_name_given_for_the_object_and_component_names_as_a_text_are_named():
    """with_component("tool") and with_joint("x") raised AttributeErrors; a component of one's own whose
    component_names is a text (not a set of names) failed later with a KeyError of one letter's name."""
    from substructure import default_assembly
    from substructure.errors import InvalidValueError as Invalid

    sys.path.insert(0, str(Path(__file__).parent))
    from custom_components import NutChuck

    model = default_assembly()
    with pytest.raises(Invalid, match=r"with_component: got 'tool'.*assembly.component\('tool'\)"):
        model.with_component("tool")
    with pytest.raises(Invalid, match=r"with_joint: got 'x', which is not a joint"):
        model.with_joint("x")
    with pytest.raises(Invalid, match="with_component: got None"):
        model.with_component(None)

    class TextNames(NutChuck):
        @property
        def component_names(self):
            return "holder"

    holder = model.component("holder")
    with pytest.raises(Invalid, match="component_names is 'holder'; expected a set"):
        model.with_component(TextNames("holder", holder.segments, nut_mass="150 g"))
    assert model.with_component(NutChuck("holder", holder.segments, nut_mass="150 g")) is not None


def test_a_joint_too_stiff_for_floating_point_says_to_make_it_rigid():
    """A joint of 1e200 N/m made the coupling singular and was reported as 'a rigid joint that closes a loop of rigid
    joints', which it is not: the error now names its stiffness and says to give it as rigid."""
    from substructure import AssemblyError

    model = default_assembly()
    joint = model.joints[1]
    stiff = model.with_joint(Joint(joint.name, joint.between, k={"yf": "1e200 N/m", "tm": "1e200 N*m/rad"}))
    with pytest.raises(AssemblyError, match=r"singular in floating point: its dynamic stiffness reaches 1e\+200.*"
                                            r"rigid=True"):
        stiff.frf("tool.tip", frequency=Frequency.from_hz([100.0, 1000.0]))
    rigid = model.with_joint(Joint(joint.name, joint.between, rigid=True))
    assert np.isfinite(rigid.frf("tool.tip", frequency=Frequency.from_hz([100.0, 1000.0])).data).all()


@pytest.mark.parametrize("field, value", [("E", "1e-100 Pa"), ("E", "1e300 GPa"), ("rho", "1e300 kg/m^3"),
                                          ("rho", "1e-3 kg/m^3"), ("loss_factor", 1e300)])
def test_a_material_the_beam_model_cannot_compute_is_refused_where_it_is_made(field, value):
    """In Python these were accepted and failed later in the beam model with a raw OverflowError or 'cannot convert
    float NaN to integer' (the assembly file's reader already refused them at their key)."""
    args = {"name": "odd", "E": "200 GPa", "nu": 0.3, "rho": "7800 kg/m^3", field: value}
    with pytest.raises(InvalidValueError, match=f"^{field}: got "):
        Material(**args)
    Material("light", "1 GPa", 0.3, "1 kg/m^3", 9.0)  # within the ranges


def test_the_plot_note_says_what_the_entries_drawn_are():
    """The note under an FRF plot said 'H = displacement / force' also for a rotation's or a moment's entries."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from substructure.plot import plot_frf

    model = default_assembly()
    grid = Frequency.from_hz(np.linspace(100.0, 2000.0, 50))
    frf = model.frf(["tool.tip:y", "tool.tip:theta"], ["tool.tip:y", "tool.tip:theta"], frequency=grid)

    def note(entries) -> str:
        fig = plot_frf(frf, entries=entries)
        text = next(t.get_text() for t in fig.axes[-1].texts if t.get_gid() == "substructure-note")
        plt.close(fig)
        return text

    assert note([("tool.tip:y", "tool.tip:y")]).startswith("H = displacement / force")
    assert note([("tool.tip:theta", "tool.tip:theta")]).startswith("H = rotation / moment")
    assert note([("tool.tip:theta", "tool.tip:y"), ("tool.tip:y", "tool.tip:y")]).startswith(
        "H = displacement or rotation / force")


# -- the SI form's evaluator, a public class of the model-updating core -----------------------------------------


@pytest.mark.parametrize("kwargs, message", [
    ({"frequency_hz": [np.nan, 100.0]}, "lines above 0 Hz, each finite"),
    ({"frequency_hz": [np.inf, 100.0]}, "lines above 0 Hz, each finite"),
    ({"frequency_hz": np.linspace(20.0, 500.0, 30).reshape(5, 6)}, "shape (5, 6); expected one line after another"),
    ({"frequency_hz": ["100", "200"]}, "expected numbers in Hz, not texts"),
    ({"frequency_hz": [True, 200.0]}, "expected numbers in Hz, not texts or booleans"),
    ({"outputs": "tool.tip"}, "outputs: got 'tool.tip'; expected a sequence of DOF labels"),
    ({"inputs": []}, "inputs: got []; expected a sequence of DOF labels"),
    ({"cache": -1}, "cache: got -1; expected a whole number >= 0"),
    ({"memo_bytes": 2.5}, "memo_bytes: got 2.5"),
])
def test_the_evaluator_refuses_what_it_cannot_evaluate_where_it_is_made(kwargs, message):
    """A NaN line reached the beam kernel, a 2-D array of lines was flattened, texts were read as numbers, a text
    of outputs was taken letter by letter ("point 't'"), and a negative cache emptied itself at every call."""
    from substructure.updating import Evaluator

    args = {"outputs": ["tool.tip"], "inputs": ["tool.tip"], "frequency_hz": [100.0, 200.0], **kwargs}
    with pytest.raises(InvalidValueError) as caught:
        Evaluator(**args)
    assert message in str(caught.value)


def test_the_evaluator_given_an_assembly_says_to_make_its_structure():
    from substructure.updating import Evaluator, Structure

    evaluator = Evaluator(["tool.tip"], ["tool.tip"], [100.0, 200.0])
    for call in (lambda: evaluator(default_assembly()), lambda: evaluator.many([default_assembly()])):
        with pytest.raises(InvalidValueError, match=r"got Assembly; expected a Structure \(Structure.from_assembly"):
            call()
    assert evaluator(Structure.from_assembly(default_assembly())).shape == (2, 1, 1)


# -- the model-updating core's public functions ---------------------------------------------------------------


@pytest.fixture(scope="module")
def core():
    from substructure.synthetic import simulate
    from substructure.updating import Likelihood, measured_frfs

    model = default_assembly()
    data = [m.frf for m in simulate(model, ["tool.tip", "holder.tip"], frequency=np.linspace(20.0, 5000.0, 120),
                                    noise=0.01, seed=0)]
    measured, _ = measured_frfs(data)
    return model, data, measured, Likelihood(model, measured)


@pytest.mark.parametrize("lines, message", [
    ([-1, 3], "expected increasing, distinct indices from 0 to 119"),  # counted from the end
    ([3, 3, 4], "expected increasing, distinct indices"),               # a line weighed twice
    ([0, 500], "expected increasing, distinct indices from 0 to 119"),   # a raw IndexError
    ([0.5, 3.2], "expected a 1-D array of line indices (whole numbers)"),
    (np.ones(120, bool), "expected a 1-D array of line indices (whole numbers)"),  # lines 0 and 1
    ([], "expected a 1-D array of line indices"),
])
def test_a_likelihood_refuses_lines_the_data_do_not_have_once_each(core, lines, message):
    from substructure.updating import Likelihood

    model, _, measured, _ = core
    with pytest.raises(InvalidValueError, match="lines: got") as caught:
        Likelihood(model, measured, np.asarray(lines))
    assert message in str(caught.value)


def test_a_likelihood_refuses_no_data_and_a_subsample_step_below_one(core):
    from substructure.updating import Likelihood, measured_frfs

    model, data, _, lik = core
    with pytest.raises(InvalidValueError, match="measured: got \\[\\]; expected at least one Measured"):
        Likelihood(model, [])
    for step in (0, -3, 2.5, True):
        with pytest.raises(InvalidValueError, match=f"step: got {step!r}; expected a whole number >= 1"):
            lik.subsample(step)
    assert lik.subsample(2).lines.tolist() == list(range(0, 120, 2))
    with pytest.raises(InvalidValueError, match="band: got '100-2000'; expected \\(lo, hi\\) in Hz"):
        measured_frfs(data, band="100-2000")


def test_the_tests_of_the_core_refuse_numbers_they_cannot_judge(core):
    """A NaN chi^2 gave a verdict of 'not significant' without a word, n = 0 a raw math domain error, a negative
    misfit scale or number of parameters an answer."""
    from substructure.updating import consistency, indifferent, significance

    *_, lik = core
    with pytest.raises(InvalidValueError, match="significance: chi\\^2 of nan"):
        significance(float("nan"), 90.0, 1, 1000, 1)
    with pytest.raises(InvalidValueError, match="significance: chi\\^2 of -1.0"):
        significance(-1.0, -2.0, 1, 1000, 1)
    with pytest.raises(InvalidValueError, match="significance: k: got 1.5"):
        significance(100.0, 90.0, 1.5, 1000, 1)
    assert not significance(100.0, math.inf, 1, 1000, 1).significant  # a model that cannot be held
    with pytest.raises(InvalidValueError, match="indifferent: n: got 0"):
        indifferent(10.0, 1, 12.0, 1, 0)
    with pytest.raises(InvalidValueError, match="indifferent: s2: got -1.0"):
        indifferent(10.0, 1, 12.0, 1, 100, -1.0)
    with pytest.raises(InvalidValueError, match="consistency: p: got -1"):
        consistency(lik, lik.log_ratios([]), -1)


@pytest.mark.parametrize("path, value, message", [
    ("components.tool.segments.0.od", float("nan"), "the value makes a size that is not a finite number"),
    ("materials.carbide.E", float("nan"), "makes E nan Pa"),
    ("components.tool.segments.0.od", "12 mm", "got '12 mm'; expected a finite number"),
    ("joints.holder-tool.k.yf", float("inf"), "got inf; expected a finite number"),
    ("materials.carbide.E", 0.0, "makes E 0 Pa; expected E in [1000, 1e+13] Pa"),
    ("materials.carbide.rho", -5.0, "makes rho -5 kg/m^3"),
    ("materials.carbide.nu", 0.6, "makes nu 0.6; expected nu in (-1, 0.5)"),
    ("materials.carbide.loss_factor", -0.1, "makes loss_factor -0.1; expected loss_factor in [0, 10]"),
    ("components.tool.E", 1e-20, "makes E 5.8e-09 Pa"),
])
def test_the_si_form_refuses_the_values_set_parameters_refuses(path, value, message):
    """apply_path_si (the fits' setter) took these and gave a structure of a material the beam model cannot
    compute; set_parameters, which shares its parser, refused each through the objects."""
    from substructure.updating import Structure, apply_path_si, set_parameters

    model = default_assembly()
    with pytest.raises(InvalidValueError) as caught:
        apply_path_si(Structure.from_assembly(model), path, value)
    assert f"parameter {path!r}" in str(caught.value) and message in str(caught.value)
    with pytest.raises(InvalidValueError, match=f"parameter {path!r}"):
        set_parameters(model, {path: value})


def test_a_noise_window_of_zero_lines_is_refused_not_taken_for_the_default(core):
    from substructure.updating import estimate_noise

    _, data, _, _ = core
    with pytest.raises(InvalidValueError, match="window: got 0; expected an odd number of lines"):
        estimate_noise(data[0], 0)


@pytest.mark.parametrize("args, message", [
    (("tool", -0.076, 0.1), "length: got -0.076; expected a finite number > 0"),
    (("tool", "76 mm", 0.1), "length: got '76 mm'"),
    (("tool", 0.076, 0.0), "mass_max: got 0.0"),
    (("tool", 0.076, 0.1, (0.05, 0.2)), "position: got (0.05, 0.2); expected (lo, hi) with 0 <= lo <= hi <= length"),
    ((None, 0.076, 0.1), "component: got None; expected a component's name"),
])
def test_a_body_at_a_fitted_place_refuses_bounds_it_cannot_have(args, message):
    """A negative length or a range past the component's end gave bounds a fit then searched outside the beam."""
    from substructure.updating import AddedMass

    with pytest.raises(InvalidValueError) as caught:
        AddedMass(*args)
    assert message in str(caught.value)


def test_diagnose_takes_one_frf_as_one_measurement_and_refuses_a_name_for_the_model(core):
    """One FRF was iterated (FRF[0]: 'index: got 0; expected a pair'); a name for the model gave an AttributeError."""
    from substructure.diagnose import diagnose

    model, data, _, _ = core
    one = diagnose(model, data[0], budget=50)
    assert one.explained and not one.effects
    with pytest.raises(InvalidValueError, match="assembly: got str; expected an Assembly"):
        diagnose("default", data)


def test_a_fit_refuses_changes_values_and_options_it_cannot_use(core):
    """A free list of another length was cut to the changes, max_nfev = 0 became the default, a value of NaN, a
    text or a name the change does not have reached scipy or numpy as raw errors."""
    from substructure.updating import ParameterChange, fit, model_parameters

    model, _, _, lik = core
    change = ParameterChange(model_parameters(model)[0])
    for kwargs, message in (({"free": [True, False]}, "free: got [True, False]; expected one True or False per "
                                                        "change (1)"),
                            ({"max_nfev": 0}, "max_nfev: got 0; expected a whole number >= 1")):
        with pytest.raises(InvalidValueError, match=re.escape(message)):
            fit(lik, [(change, {})], **kwargs)
    for values, message in (({"banana": 1.0}, "has no parameter 'banana'; expected some of value"),
                            ({"value": float("nan")}, "value = nan; expected a finite number"),
                            ({"value": "3"}, "value = '3'; expected a finite number")):
        with pytest.raises(InvalidValueError, match=re.escape(message)):
            fit(lik, [(change, values)])
    with pytest.raises(InvalidValueError, match=re.escape("changes[0]: got ('x', {}); expected a pair")):
        fit(lik, [("x", {})])


@pytest.mark.parametrize("kwargs, message", [
    ({"bootstrap": -1}, "bootstrap: got -1; expected an integer >= 0"),     # numpy warnings, then a raw TypeError
    ({"bootstrap": 2.5}, "bootstrap: got 2.5; expected an integer >= 0"),   # a raw TypeError of range
    ({"bootstrap": True}, "bootstrap: got True; expected an integer >= 0"),  # one refit
    ({"bootstrap": 2, "random_state": "x"}, "random_state: got 'x'; expected a seed"),
])
def test_identify_joint_checks_its_bootstrap_with_the_automatic_parameters(kwargs, message):
    """The check of bootstrap ran only when parameters were named; with the default 'auto' it was skipped."""
    from substructure.identify import identify_joint
    from substructure.synthetic import simulate

    model = default_assembly()
    taps = simulate(model, ["tool.tip", "tool.tip-20 mm"], frequency=np.linspace(20.0, 5000.0, 50), seed=0)
    with pytest.raises(InvalidValueError, match=re.escape(message)):
        identify_joint(model, taps, "holder-tool", **kwargs)
    with pytest.raises(InvalidValueError, match="assembly: got str; expected an Assembly"):
        identify_joint("default", taps, "holder-tool")


def test_the_parameter_functions_say_what_a_model_and_values_are():
    """A name given for the model, or a list of pairs for the values, gave AttributeErrors deep inside."""
    from substructure.updating import (ParameterChange, Structure, get_parameter, model_parameters,
                                       set_parameters)

    for call in (lambda: get_parameter("default", "joints.holder-tool.k.yf"), lambda: model_parameters("default"),
                 lambda: Structure.from_assembly("default"), lambda: set_parameters("default", {})):
        with pytest.raises(InvalidValueError, match="assembly: got str; expected an Assembly"):
            call()
    with pytest.raises(InvalidValueError, match="values: got list; expected a mapping of parameter paths"):
        set_parameters(default_assembly(), [("joints.holder-tool.k.yf", 2e7)])
    with pytest.raises(InvalidValueError, match="parameter: got 'joints.holder-tool.k.yf'; expected a ModelParameter"):
        ParameterChange("joints.holder-tool.k.yf")


def test_one_record_given_as_two_measurements_is_refused():
    """A file copied under another name gives two measurements with the same numbers on every line: weighed
    twice and fitted at two places, it was taken without a word.  A reciprocal pair may be equal (an exact
    simulation) and stays."""
    import numpy as np

    from substructure import FRF, Frequency, default_assembly
    from substructure.diagnose import diagnose
    from substructure.measurements import Measurement
    from substructure.synthetic import simulate
    from substructure.updating.likelihood import measured_frfs

    model = default_assembly()
    grid = Frequency.from_hz(np.linspace(20.0, 5000.0, 300))
    tip, holder = (m.frf for m in simulate(model, ["tool.tip", "holder.tip"], frequency=grid, noise=0.01, seed=4))
    copy = Measurement.from_frf(tip, "tool.tip-20 mm", "tool.tip", file="b.uff")
    first = Measurement.from_frf(tip, "tool.tip", "tool.tip", file="a.uff")
    for data in ([first, copy], [tip, holder, FRF(tip.frequency, tip.data, ("tool.tip-20 mm:y",), tip.inputs)]):
        with pytest.raises(InvalidValueError, match=r"hold the same numbers on every line: one record given twice"):
            measured_frfs(data)
    with pytest.raises(InvalidValueError, match=r"tool\.tip:y / tool\.tip:y \(a\.uff\) and .*\(b\.uff\)"):
        diagnose(model, [first, copy], progress=False)
    exact = model.frf(["tool.tip:y", "holder.tip:y"], frequency=grid)
    hab = exact.select(["tool.tip:y"], ["holder.tip:y"])
    pair = [hab, FRF(hab.frequency, hab.data, hab.inputs, hab.outputs)]  # H_ba given as H_ab (reciprocity)
    assert len(measured_frfs(pair)[0]) == 2  # a reciprocal pair with the same numbers: both kept
    assert len(measured_frfs([tip, holder])[0]) == 2


@pytest.mark.parametrize("point", [1.0, None, math.nan, 1j, True])
def test_a_point_that_is_no_name_is_refused_by_name_not_by_iterating_it(point):
    # 'float' object is not iterable, from the list of points
    with pytest.raises(UnknownPointError, match=r"point: got .*; expected a name like 'tool\.tip'"):
        default_assembly().frf(point, frequency=GRID)
    if point is not None:  # no inputs: the outputs'
        with pytest.raises(UnknownPointError, match=r"point: got .*; expected a name like 'tool\.tip'"):
            default_assembly().frf("tool.tip", point, frequency=GRID)


def test_a_frequency_beyond_float_range_is_refused_as_too_high():
    # 1e100 Hz made the wavenumbers NaN and the pieces "cannot convert float NaN to integer"
    for hz in (1e100, 1e300):
        with pytest.raises(InvalidValueError, match=r"got a line at 1e\+[0-9]+ Hz, where component '\w+' would be cut "
                                                    r"into about inf pieces"):
            default_assembly().frf("tool.tip", frequency=[hz])


def test_frequencies_as_a_quantity_are_converted_and_other_units_refused():
    # numpy's iscomplexobj raised TypeError on any pint quantity
    from substructure import Q_
    assert np.array_equal(Frequency(Q_(np.array([1.0, 2.0]), "kHz")).hz, [1000.0, 2000.0])
    assert np.allclose(Frequency(Q_(np.array([600.0, 1200.0]), "rpm")).hz, [10.0, 20.0], rtol=1e-15)
    for value in (Q_(np.array([1.0, 2.0]), "s"), Q_(math.nan, "m")):
        with pytest.raises(UnitError, match=r"hz: got a quantity in (s|m); expected frequencies"):
            Frequency(value)


def _a_tap():
    from substructure.tap import TapRecord
    n, fs = 2048, 10240.0
    force = np.zeros(n)
    force[100:104] = [10.0, 30.0, 30.0, 10.0]
    response = np.convolve(force, np.exp(-np.arange(n) / 200.0) * np.sin(np.arange(n) * 0.5))[:n]
    return TapRecord(np.arange(n) / fs, force + 1e-3 * np.random.default_rng(0).normal(size=n), response)


@pytest.mark.parametrize("settings, message", [
    (dict(band=1000.0), r"band: got 1000\.0; expected \(lo, hi\) in Hz"),  # cannot unpack non-iterable float
    (dict(band="abc"), r"band: got 'abc'; expected \(lo, hi\)"),
    (dict(band=(2000.0, 100.0)), r"band: got \(2000\.0, 100\.0\); expected \(lo, hi\) in Hz, two finite numbers with "
                                 r"0 <= lo < hi"),
    (dict(band=(0.0, math.nan)), r"band: got \(0\.0, nan\)"),
    (dict(pre_trigger=None), r"pre_trigger: got None s; expected a finite number >= 0"),  # float(None)
    (dict(tau=10 ** 400), r"tau: got 1000\d+ s; expected a finite number > 0"),  # OverflowError
    (dict(estimator=np.array([])), r"estimator: got array\(\[\], dtype=float64\); expected one of H1"),
])
def test_tap_settings_of_the_wrong_kind_are_refused_by_name(settings, message):
    from substructure.tap import process_taps
    with pytest.raises(InvalidValueError, match=message):
        process_taps([_a_tap()], **settings)


def test_reading_a_result_with_speeds_beyond_every_float_is_an_error():
    from substructure.stability import MillingCut, spindle_speeds, zoa
    frf = default_assembly().frf("tool.tip:y", frequency=np.arange(100.0, 5000.0, 10.0))
    cut = MillingCut(teeth=4, diameter="12 mm", radial_depth="3 mm", kt="700 MPa", kn="200 MPa")
    lobes = zoa(frf, cut, spindle_speeds("2000 rpm", "20000 rpm", "100 rpm"))
    with pytest.raises(InvalidValueError, match=r"expected spindle speeds in rpm"):
        lobes.limit_at(10 ** 400)  # int too large to convert to float


@pytest.mark.parametrize("power, message", [
    ([1, 2], r"power speeds: got 1; expected quantities with units of one kind"),  # 'int' object is not iterable
    ([("6000 rpm", "abc"), ("8000 rpm", "1 kW")], r"power values: got \('abc', '1 kW'\)"),  # pint's own error
    ([("6000 rpm", "1 kW"), ("8000 rpm", "1 m")], r"power values: got \('1 kW', '1 m'\)"),  # DimensionalityError
])
def test_a_power_curve_that_is_no_curve_of_quantities_is_refused(power, message):
    from substructure.stability import MachineLimits
    with pytest.raises(InvalidValueError, match=message):
        MachineLimits(power=power)


def test_a_label_that_is_no_text_and_a_scalar_quantity_for_a_sweep_are_refused():
    frf = default_assembly().frf("tool.tip:y", frequency=GRID)
    with pytest.raises(UnknownPointError, match=r"output array\(\[\], dtype=float64\) is not in this FRF"):
        frf.select([np.array([])], ["tool.tip:y"])  # the truth value of an empty array is ambiguous
    from substructure import Q_
    with pytest.raises(InvalidValueError, match=r"sweep: got .*; expected a sequence of assemblies"):
        sweep(Q_(1, "s"), "tool.tip:y", frequency=GRID)  # 'int' object is not iterable


def test_the_writers_of_modes_and_joint_tables_keep_an_existing_file_unless_told():
    # both replaced any file of that name without a word, where every other writer of the package refuses
    import tempfile

    from substructure import Q_
    from substructure.errors import OutputExistsError
    from substructure.stability import ModalModel, Mode
    from substructure.surrogate import thesis_table_4_2
    with tempfile.TemporaryDirectory() as folder:
        for name, write in [("modes.csv", ModalModel([Mode("x", "922 Hz", 0.011, Q_(1e7, "N/m"))]).to_csv),
                            ("table.csv", thesis_table_4_2().to_csv), ("table.toml", thesis_table_4_2().to_toml)]:
            path = Path(folder) / name
            path.write_text("the user's own file\n", encoding="utf-8")
            with pytest.raises(OutputExistsError, match=re.escape(f"{path}: the file exists; pass overwrite=True")):
                write(path)
            assert path.read_text(encoding="utf-8") == "the user's own file\n"
            write(path, overwrite=True)
            assert path.read_text(encoding="utf-8") != "the user's own file\n"


@pytest.mark.parametrize("path", [1.0, None])
def test_a_file_name_that_is_no_name_is_refused_by_every_reader_and_writer(path):
    # TypeError: expected str, bytes or os.PathLike object, from os.fspath or open deep inside
    from substructure.errors import FileFormatError
    from substructure.io.frf_files import read_csv, read_mat
    from substructure.io.measurements import load_measurements
    from substructure.io.tap_files import read_tap_csv, read_tap_mat
    from substructure.stability import ModalModel, Mode
    frf = default_assembly().frf("tool.tip:y", frequency=GRID)
    modes = ModalModel([Mode("x", "922 Hz", 0.011, "1e7 N/m")])
    for call in (frf.to_csv, frf.to_uff, modes.to_csv, read_csv, read_mat, read_tap_csv, read_tap_mat,
                 load_measurements):
        with pytest.raises(FileFormatError, match=r"got (1\.0 of type float|None of type NoneType); expected the "
                                                  r"name of an? [\w ()]+"):
            call(path)


def test_what_is_no_frf_measurement_or_name_is_refused_where_it_enters():
    # each raised AttributeError, TypeError, ValueError or OverflowError from inside
    from substructure.diagnose import DiagnoseSettings, compare, diagnose, noise_floor
    from substructure.stability import cutting_data
    frf = default_assembly().frf("tool.tip:y", frequency=np.arange(100.0, 3000.0, 20.0))
    with pytest.raises(InvalidValueError, match=r"measurements: got float; expected a MeasurementSet"):
        diagnose(default_assembly(), 1.0, progress=False)
    with pytest.raises(InvalidValueError, match=r"model: got float; expected an FRF"):
        compare(1.0, frf)
    with pytest.raises(InvalidValueError, match=r"measured: got NoneType; expected an FRF"):
        noise_floor(None)
    with pytest.raises(InvalidValueError, match=r"workpiece: got 1\.0; expected a workpiece's name or a Workpiece"):
        cutting_data(1.0, "carbide")
    with pytest.raises(UnknownPointError, match=r"component: got \[1, 2\]; expected a component's name"):
        default_assembly().component([1, 2])
    with pytest.raises(InvalidValueError, match=r"DiagnoseSettings\.budget: got 1000\d+; expected a number"):
        DiagnoseSettings(budget=10 ** 400)
    with pytest.raises(InvalidValueError, match=r"data: cannot read int as complex numbers"):
        FRF(frf.frequency, 10 ** 400, ["a"], ["b"])
    with pytest.raises(InvalidValueError, match=r"quantity: got array\(\[\], dtype=float64\); expected one of"):
        FRF.single(frf.frequency, frf.data[:, 0, 0], quantity=np.array([]))


def test_a_file_name_with_a_nul_character_is_refused_by_writers_and_the_command_line(tmp_path, capsys):
    # ValueError: embedded null byte, from open and from resolving the command's file names
    from substructure import save_assembly
    from substructure.cli import main
    from substructure.errors import FileFormatError
    for write in (default_assembly().frf("tool.tip:y", frequency=GRID).to_csv,
                  lambda p: save_assembly(default_assembly(), p)):
        with pytest.raises(FileFormatError, match=r"got 'a\\x00b'; expected the name of a .* \(a file name holds no "
                                                  r"NUL character\)"):
            write("a\x00b")
    path = tmp_path / "tip.csv"
    default_assembly().frf("tool.tip:y", frequency=np.arange(200.0, 5000.0, 10.0)).to_csv(path)
    code = main(["lobes", "--frf", str(path), "--frf-y", "a\x00b", "--radial-depth", "3 mm", "--teeth", "4",
                 "--diameter", "12 mm", "--workpiece", "steel-1045"])
    assert code == 1 and "holds no NUL character" in capsys.readouterr().err


def test_a_count_of_repetitions_beyond_any_end_is_refused_in_python_as_on_the_command_line():
    # bootstrap=10**40 refitted for ever; the command line stopped it at --bootstrap 10000, Python did not
    from substructure.cli._common import MAX_REPEATS as COMMAND_LINE
    from substructure.identify import JointIdentifier
    from substructure.units import MAX_REPEATS
    assert COMMAND_LINE == MAX_REPEATS == 10_000
    with pytest.raises(InvalidValueError, match=r"bootstrap: got 10{40}; expected an integer from 0 to 10,000"):
        JointIdentifier("holder-tool", bootstrap=10 ** 40)._check()
    JointIdentifier("holder-tool", bootstrap=MAX_REPEATS)._check()
    from substructure.surrogate import make_surrogate, thesis_table_4_2
    prediction = make_surrogate("gp").fit(thesis_table_4_2()).predict({"tool_diameter": "12 mm",
                                                                       "gauge_length": "60 mm"})
    with pytest.raises(InvalidValueError, match=r"n: got 10{12}; expected a whole number of samples from 1 to 10,000"):
        prediction.sample(10 ** 12)  # 8 GB of quantiles before the first sample


def test_identification_measurements_and_decoupling_refuse_what_is_no_name_sequence_or_number():
    # each raised TypeError, ValueError (an array's truth value) or OverflowError from inside
    from substructure.identify import JointIdentifier, identify_joint
    from substructure.measurements import Measurement
    frf = default_assembly().frf("tool.tip:y", frequency=np.arange(200.0, 3000.0, 20.0))
    with pytest.raises(InvalidValueError, match=r"joint: got array\(\[\], dtype=float64\); expected a joint's name"):
        JointIdentifier(np.array([]))._check()
    with pytest.raises(InvalidValueError, match=r"parameters: got 1\.0; expected 'auto' or some of k_yf"):
        JointIdentifier("holder-tool", parameters=1.0)._check()
    with pytest.raises(InvalidValueError, match=r"initial: got 'abc'; expected a mapping of parameter names"):
        JointIdentifier("holder-tool", initial="abc")
    with pytest.raises(InvalidValueError, match=r"measurements: got float; expected a MeasurementSet or a list"):
        identify_joint(default_assembly(), 1.0, "holder-tool")
    for field in ("coherence", "force_noise", "truncation"):
        with pytest.raises(InvalidValueError, match=rf"{field}: got int; expected an array of"):
            Measurement("tool.tip:y", "tool.tip:y", frf, **{field: 10 ** 400})
    with pytest.raises(InvalidValueError, match=r"window_tau: got 10{400}; expected the exponential window's time"):
        Measurement("tool.tip:y", "tool.tip:y", frf, window_tau=10 ** 400)
    with pytest.raises(InvalidValueError, match=r"estimator: got array\(\[\], dtype=float64\); expected one of H1"):
        Measurement("tool.tip:y", "tool.tip:y", frf, estimator=np.array([]))
    both = default_assembly().frf("tool.tip", frequency=GRID)
    with pytest.raises(InvalidValueError, match=r"interface: got 1\.0; expected a sequence of \(point_in_coupled"):
        decouple(both, both, 1.0)


def test_finite_real_is_the_one_test_of_a_finite_number():
    from fractions import Fraction

    from substructure.units import finite_real
    assert all(finite_real(v) for v in (0, -3, 2.5, np.float32(1.0), np.int64(7), Fraction(1, 3), 10 ** 300))
    assert not any(finite_real(v) for v in (True, np.bool_(False), math.nan, math.inf, 10 ** 400, "1", None, 1j))


@pytest.fixture(scope="module")
def lobes_of_the_built_in_tool():
    from substructure.stability import MillingCut, fit_modes, spindle_speeds, zoa
    frf = default_assembly().frf("tool.tip:y", frequency=np.arange(100.0, 5000.0, 10.0))
    cut = MillingCut(teeth=4, diameter="12 mm", radial_depth="3 mm", kt="700 MPa", kn="200 MPa")
    speeds = spindle_speeds("2000 rpm", "20000 rpm", "200 rpm")
    return frf, cut, speeds, zoa(frf, cut, speeds), fit_modes(frf)


def test_the_stability_settings_of_the_wrong_kind_are_refused_by_name(lobes_of_the_built_in_tool):
    # each raised TypeError ('<' between int and str, not iterable), ValueError or OverflowError from inside
    from substructure.stability import MillingCut, ModalFitter, TurningCut, flexible_band, lobes_band, recommend, sdm
    frf, cut, speeds, lobes, modes = lobes_of_the_built_in_tool
    refused = [
        (lambda: recommend(lobes, cut, margin=10 ** 400), r"margin: got 10+; expected a number in \[0, 1\)"),
        (lambda: recommend(lobes, cut, count="abc"), r"count: got 'abc'; expected a whole number of speeds"),
        (lambda: lobes_band(math.nan, nominal=lobes), r"results: got nan; expected a sequence of Lobes"),
        (lambda: flexible_band(math.nan), r"frf: got float; expected an FRF"),
        (lambda: sdm(modes, cut, speeds, rtol="abc"), r"rtol: got 'abc'; expected a relative tolerance in \(0, 0\.5\)"),
        (lambda: sdm(modes, cut, speeds, coarse_ratio=math.inf), r"coarse_ratio: got inf; expected a ratio > 1"),
        (lambda: sdm(modes, cut, speeds, max_phase_step="abc"), r"max_phase_step: got 'abc'; expected a positive"),
        (lambda: sdm(modes, cut, speeds, min_intervals=None), r"min_intervals: got None; expected a whole number"),
        (lambda: sdm(modes, cut, speeds, min_intervals=10 ** 40), r"min_intervals: got 10+; expected a whole number "
                                                                   r"from 1 to"),
        (lambda: sdm(modes, cut, speeds, depth_range=math.nan), r"depth_range: got nan; expected a sequence of two "
                                                                r"depths"),
        (lambda: MillingCut(teeth=4, diameter="12 mm", radial_depth="3 mm", kt="700 MPa", kn="200 MPa",
                            milling=[1, 2]), r"milling: got \[1, 2\]; expected 'down' \(climb\) or 'up'"),
        (lambda: TurningCut(kf="1000 MPa", direction=np.array([])), r"direction: got array\(\[\], dtype=float64\); "
                                                                    r"expected 'x' or 'y'"),
        (lambda: ModalFitter(band=math.nan).fit(frf), r"band: got nan; expected a sequence of two frequencies"),
        # a text band had been ignored
        (lambda: ModalFitter(band="abc").fit(frf), r"band: got 'abc'; expected a sequence of two frequencies"),
    ]
    for call, message in refused:
        with pytest.raises(InvalidValueError, match=message):
            call()


@pytest.mark.parametrize("settings, message", [
    (dict(method=np.array([])), r"method: got array\(\[\], dtype=float64\); expected 'zoa' or 'sdm'"),
    (dict(title=np.array([])), r"title: got array\(\[\], dtype=float64\); expected a text or None"),
    (dict(notes=math.nan), r"notes: got nan; expected a list of texts"),
    (dict(notes="one note"), r"notes: got 'one note'; expected a list of texts"),  # one letter a note, before
    (dict(margin=10 ** 400), r"margin: got 10+; expected a number in \[0, 1\)"),
])
def test_report_settings_of_the_wrong_kind_are_refused_before_any_work(settings, message):
    from substructure.report import report
    with pytest.raises(InvalidValueError, match=message):
        report(default_assembly(), **settings)


def test_names_kinds_and_band_ends_of_the_wrong_kind_are_refused_by_the_assembly_and_the_frf():
    # the truth value of an array, an unhashable list, an integer beyond every float: raw errors before
    frf = default_assembly().frf("tool.tip:y", frequency=np.arange(100.0, 3000.0, 20.0))
    with pytest.raises(UnknownPointError, match=r"no component array\(\[\], dtype=float64\) in assembly"):
        default_assembly().without(np.array([]))
    with pytest.raises(UnknownPointError, match=r"sensor: got array\(\[\], dtype=float64\); expected a sensor's name"):
        default_assembly().sensor(np.array([]))
    with pytest.raises(InvalidValueError, match=r"hi: got 10+; expected a finite frequency in Hz"):
        frf.crop(100.0, 10 ** 400)
    with pytest.raises(InvalidValueError, match=r"kind: got \[1, 2\]; expected one of bode"):
        frf.plot(kind=[1, 2])
    with pytest.raises(InvalidValueError, match=r"unit: got \[1, 2\]; expected one of"):
        frf.plot(unit=[1, 2])


def test_finite_differences_simulations_and_priors_refuse_what_is_no_sequence_or_count(tmp_path):
    # 'float' object is not iterable, '<' between str and int, SeedSequence's own error, NaN to integer
    from substructure.joint_priors import joint_variants, prior_joint, with_joint_priors
    from substructure.rdof import fd_weights, positions_from
    from substructure.synthetic import simulate, write_measurement_set
    model = default_assembly()
    refused = [
        (lambda: fd_weights(math.nan, "0 mm"), r"positions: got nan; expected a sequence of at least 2 positions"),
        (lambda: positions_from(model, math.nan), r"points: got nan; expected a sequence of point names"),
        (lambda: simulate(model, math.nan, frequency=GRID), r"points: got nan; expected a sequence of point names"),
        (lambda: simulate(model, [], frequency=GRID), r"points: got none; expected at least one response point"),
        (lambda: simulate(model, ["tool.tip"], frequency=GRID, noise="abc"), r"noise: got 'abc'; expected a level"),
        (lambda: simulate(model, ["tool.tip"], frequency=GRID, seed=math.nan), r"seed: got nan; expected a seed"),
        (lambda: simulate(model, ["tool.tip"], frequency=GRID, sensors=1.0), r"sensors: got 1\.0; expected a "
                                                                               r"sequence of names"),
        (lambda: joint_variants(model, 2.7), r"levels: got 2\.7; expected a whole number of levels >= 2"),
        (lambda: joint_variants(model, 6), r"levels: got 6; expected a whole number of levels from 2 to 5"),
        (lambda: prior_joint([1, 2], "collet", "j", ("holder.tip", "tool.base")), r"role: got \[1, 2\]"),
        (lambda: with_joint_priors(model, math.nan), r"names: got nan; expected a sequence of joint names"),
    ]
    for call, message in refused:
        with pytest.raises(InvalidValueError, match=message):
            call()
    from substructure.errors import FileFormatError
    with pytest.raises(FileFormatError, match=r"got nan of type float; expected the name of a directory"):
        write_measurement_set(simulate(model, ["tool.tip"], frequency=GRID), math.nan)


def test_result_methods_refuse_axes_points_assemblies_and_tolerances_of_the_wrong_kind():
    # AttributeError ('float' object has no attribute 'figure'), not iterable, '>' between float and str
    from substructure.diagnose import diagnose
    from substructure.synthetic import simulate
    grid = np.arange(100.0, 3000.0, 20.0)
    data = simulate(default_assembly().attach(Sensor("acc", "tool.tip", "2 g")), ["tool.tip"], frequency=grid,
                    noise=0.01)
    d = diagnose(default_assembly(), data, progress=False)
    with pytest.raises(InvalidValueError, match=r"ax: got 1 axes for the 1 panel\(s\) \('history',\)"):
        d.plot_history(ax=math.nan)
    with pytest.raises(InvalidValueError, match=r"ax: got 1 axes for the 3 panel\(s\) \('magnitude', 'phase', "
                                                r"'residual'\)"):
        d.plot_where(ax=math.nan)
    with pytest.raises(InvalidValueError, match=r"points: got nan; expected a sequence of point names"):
        data.matrix(math.nan)
    with pytest.raises(InvalidValueError, match=r"assembly: got float; expected an Assembly"):
        data.validate(math.nan)
    with pytest.raises(InvalidValueError, match=r"rtol: got 'abc'; expected a relative tolerance >= 0"):
        default_assembly().frf("tool.tip", frequency=GRID).check_reciprocity(rtol="abc")


def test_a_study_s_methods_and_joint_table_of_the_wrong_kind_are_refused_by_name():
    # 'float' object is not iterable; TypeError from os.fspath
    from substructure.errors import FileFormatError
    from substructure.study import Compute, SurrogateSpec
    with pytest.raises(InvalidValueError, match=r"lobes: got nan; expected a sequence of methods, zoa and/or sdm"):
        Compute(lobes=math.nan)
    with pytest.raises(InvalidValueError, match=r"lobes: got \[1, 2\]; expected zoa and/or sdm"):
        Compute(lobes=[[1, 2]])
    with pytest.raises(FileFormatError, match=r"got nan of type float; expected the name of a joint table"):
        SurrogateSpec(table=math.nan)
