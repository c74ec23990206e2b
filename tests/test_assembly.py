"""Assembly graph: building, lookups, joints' checks and bad input."""


import numpy as np
import pytest

from conftest import make_assembly, make_holder, make_tool
from substructure import (
    Assembly,
    AssemblyError,
    Frequency,
    InvalidValueError,
    Joint,
    NonPassiveJointWarning,
    NonReciprocalWarning,
    Segment,
    Sensor,
    Support,
    Tool,
    UnitError,
    UnknownPointError,
)
from substructure.datasets import thesis_joint
from substructure.points import parse_point


def test_thesis_tables_are_accepted_with_a_non_passive_warning():
    for table in ("2.1", "2.2"):
        k, c = thesis_joint(table)
        with pytest.warns(NonPassiveJointWarning, match=r"non-passive.*k_ym\*k_tf = .* > k_yf\*k_tm"):
            joint = Joint("j", ("a.tip", "b.base"), k=k, c=c)
        assert joint.k.get("ym") == joint.k.get("tf")


def test_asymmetric_joint_warns():
    with pytest.warns(NonReciprocalWarning, match="not symmetric"):
        Joint("j", ("a.tip", "b.base"), k={"yf": "1e7 N/m", "ym": "1e3 N", "tf": "2e3 N/rad", "tm": "1e4 N*m/rad"})


def test_joint_errors():
    with pytest.raises(UnitError, match="k.yf: got the bare number"):
        Joint("j", ("a.tip", "b.base"), k={"yf": 1e7})
    with pytest.raises(UnitError, match=r"k.tm: got '1e4 N/m' with dimension"):
        Joint("j", ("a.tip", "b.base"), k={"yf": "1e7 N/m", "tm": "1e4 N/m"})
    with pytest.raises(InvalidValueError, match=r"unknown entries \['xy'\]"):
        Joint("j", ("a.tip", "b.base"), k={"xy": "1 N/m"})
    with pytest.raises(InvalidValueError, match="a rigid joint takes no k or c"):
        Joint("j", ("a.tip", "b.base"), k={"yf": "1 N/m"}, rigid=True)
    with pytest.raises(InvalidValueError, match="needs stiffness entries"):
        Joint("j", ("a.tip", "b.base"))
    with pytest.raises(InvalidValueError, match="between"):
        Joint("j", ("a.tip", "a.tip"), rigid=True)
    with pytest.raises(InvalidValueError, match="name"):
        Joint("bad.name", ("a.tip", "b.base"), rigid=True)


def test_sensor_and_support_errors():
    with pytest.raises(InvalidValueError, match="mass: got '-2 g'"):
        Sensor("acc", "tool.tip", "-2 g")
    with pytest.raises(UnitError, match="inertia"):
        Sensor("acc", "tool.tip", "2 g", "5 kg")
    with pytest.raises(InvalidValueError, match="needs stiffness k or damping c"):
        Support("spindle@10 mm")
    assert Sensor.laser("ldv", "tool.tip").mass_kg == 0.0


def test_point_names():
    assert str(parse_point("tool.tip")) == "tool.tip"
    ref = parse_point("spindle@310 mm:theta")
    assert (ref.component, ref.where, ref.distance.m_as("mm"), ref.dof) == ("spindle", "at", 310, "theta")
    assert parse_point("tool.tip-15 mm").where == "from_tip"
    for bad in ["tool", "tool.tip:z", "tool@ten", "tool@-3 mm", ""]:
        with pytest.raises(UnknownPointError):
            parse_point(bad)


def test_unknown_points_and_names_are_errors():
    with pytest.raises(UnknownPointError, match="no component 'tol'.*components: holder, spindle, tool"):
        make_assembly().connect("tol.tip", "holder.tip", rigid=True)
    with pytest.raises(UnknownPointError, match="lies outside 'tool'"):
        make_assembly().attach(Sensor("acc", "tool@80 mm", "2 g"))
    with pytest.raises(UnknownPointError, match="'tool' has points base, tip"):
        make_assembly().attach(Sensor("acc", "tool.middle", "2 g"))
    with pytest.raises(AssemblyError, match="component name 'tool' is used twice"):
        Assembly("dup", components=(make_tool(), make_tool()))
    with pytest.raises(AssemblyError, match="sensor names used twice"):
        make_assembly().attach(Sensor("a", "tool.tip", "1 g"), Sensor("a", "tool.base", "1 g"))
    with pytest.raises(InvalidValueError, match="is not a component"):
        Assembly("x", components=("tool",))
    with pytest.raises(InvalidValueError, match="no default grid"):
        make_assembly().receptance("tool.tip")


def test_receptance_labels_and_dofs(assembly, grid):
    full = assembly.receptance("tool.tip", frequency=grid)
    h = assembly.receptance("tool.tip:y", frequency=grid)
    assert h.outputs == ("tool.tip:y",) and h.data.shape == (len(grid), 1, 1)
    np.testing.assert_array_equal(h.data[:, 0, 0], full.data[:, 0, 0])
    cross = assembly.receptance("tool.tip:theta", "holder.tip:y", frequency=grid)
    assert cross.outputs == ("tool.tip:theta",) and cross.inputs == ("holder.tip:y",)
    # the same physical point under two names
    same = assembly.receptance("tool@60 mm:y", frequency=grid)
    np.testing.assert_allclose(same.data, h.data, rtol=1e-12)


def test_building_returns_new_assemblies(assembly, grid):
    s = Sensor("acc", "tool.tip", "2 g")
    with_s = assembly.attach(s)
    assert assembly.sensors == () and with_s.sensors == (s,)
    assert with_s.without_sensors().sensors == ()
    assert with_s.sensor("acc") is s
    with pytest.warns(NonPassiveJointWarning):  # the thesis's Table 2.2 joint stays non-passive
        stiffer = assembly.with_joint(assembly.joint("holder-tool").with_parameters(k={"yf": "1e8 N/m"}))
    assert stiffer.joint("holder-tool").k.get("yf") == 1e8
    assert stiffer.joint("holder-tool").k.get("tm") == assembly.joint("holder-tool").k.get("tm")
    # With a passive (diagonal) joint, a stiffer joint raises the tool mode.
    diagonal = {"ym": "0 N", "tf": "0 N/rad"}
    soft = assembly.with_joint(assembly.joint("holder-tool").with_parameters(
        k={"yf": "1e7 N/m", **diagonal}, c={"ym": "0 N*s", "tf": "0 N*s/rad"}))
    hard = soft.with_joint(soft.joint("holder-tool").with_parameters(k={"yf": "1e8 N/m"}))
    f_soft = soft.receptance("tool.tip:y", frequency=grid).peaks()
    f_hard = hard.receptance("tool.tip:y", frequency=grid).peaks()
    assert f_hard[1] > f_soft[1]
    shorter = assembly.with_component(make_tool(40.0))
    assert shorter.component("tool").length.m_as("mm") == pytest.approx(40)
    assert "joint holder-tool: holder.tip -- tool.base" in assembly.describe()


def test_support_to_ground_shifts_rigid_modes(grid):
    """A free-free tool on a soft spring gets a bounce mode at sqrt(k/m)/(2 pi)."""
    tool = Tool("tool", [Segment("100 mm", "20 mm")])
    m = tool.mass()
    k = 1e4
    asm = Assembly("bounce", components=(tool,)).support("tool@50 mm", k={"yf": f"{k} N/m"})
    grid = Frequency.from_range("1 Hz", "200 Hz", "0.05 Hz")
    peaks = asm.receptance("tool@50 mm:y", frequency=grid).peaks()
    assert peaks[0] == pytest.approx(np.sqrt(k / m) / (2 * np.pi), abs=0.05)


def test_frequencies_must_be_positive_for_free_free_components(assembly):
    with pytest.raises(InvalidValueError, match="no static receptance"):
        assembly.receptance("tool.tip", frequency=Frequency.from_hz([0.0, 10.0]))


def test_angular_frequency_quantities_are_not_taken_as_hz(assembly):
    """rad/s and rpm are converted explicitly (/ 2 pi, / 60), never taken as Hz (pint's 2 pi error)."""
    from substructure import Q_

    at_hz = assembly.receptance("tool.tip:y", frequency=[100.0, 1500.0])
    in_rad = assembly.receptance("tool.tip:y", frequency=Q_(2 * np.pi * np.array([100.0, 1500.0]), "rad/s"))
    in_rpm = assembly.receptance("tool.tip:y", frequency=Q_(np.array([6000.0, 90000.0]), "rpm"))
    for other in (in_rad, in_rpm):
        np.testing.assert_allclose(other.frequency.hz, [100.0, 1500.0], rtol=1e-14)
        np.testing.assert_allclose(other.data, at_hz.data, rtol=1e-9)
    with pytest.raises(InvalidValueError, match="expected frequencies"):
        assembly.receptance("tool.tip", frequency=Q_(np.array([6000.0]), "mm"))
    ok = assembly.receptance("tool.tip:y", frequency=Q_(np.array([0.1, 0.2]), "kHz"))
    np.testing.assert_array_equal(ok.frequency.hz, [100.0, 200.0])


def test_a_joint_model_by_protocol_is_accepted(grid):
    """Any object with name, between, rigid and dynamic_stiffness is a joint."""
    holder, tool = make_holder(), make_tool()

    class Hysteretic:
        name, between, rigid = "ht", ("holder.tip", "tool.base"), False

        def dynamic_stiffness(self, f):
            k = np.diag([1.4e7, 8e4]) * (1 + 0.05j)
            return np.repeat(k[:, :, None], np.size(f), axis=2)

    asm = Assembly("h", components=(holder, tool), joints=(Hysteretic(),))
    same = Assembly("h", components=(holder, tool)).connect(
        "holder.tip", "tool.base", name="ht", k={"yf": "1.4e7 N/m", "tm": "8e4 N*m/rad"}
    )
    a = asm.receptance("tool.tip:y", frequency=grid).data
    b = same.receptance("tool.tip:y", frequency=grid).data
    assert not np.allclose(a, b)  # the loss factor acts
    with pytest.raises(InvalidValueError, match=r"joints\[0\].*not a joint"):
        Assembly("bad", components=(holder, tool), joints=("holder.tip",))
    from substructure import dumps_assembly

    with pytest.raises(InvalidValueError, match="cannot hold"):
        dumps_assembly(asm)


def test_duplicate_support_names_are_errors():
    with pytest.raises(AssemblyError, match="support names used twice"):
        make_assembly().support(Support("tool@10 mm", k={"yf": "1e5 N/m"}, name="band")).support(
            Support("tool@20 mm", k={"yf": "1e5 N/m"}, name="band")
        )


def test_prepared_frf_equals_full_computation(assembly, grid):
    prepared = assembly.attach(Sensor("acc", "tool.tip", "2 g")).prepare("tool.tip", frequency=grid)
    joint = Joint("holder-tool", ("holder.tip", "tool.base"), k={"yf": "3e7 N/m", "tm": "5e4 N*m/rad"},
                  c={"yf": "60 N*s/m"})
    sensor = Sensor("acc", "tool.tip", "5 g")
    got = prepared.evaluate(joints={"holder-tool": joint}, sensors={"acc": sensor})
    expected = assembly.with_joint(joint).attach(sensor).receptance("tool.tip", frequency=grid)
    np.testing.assert_allclose(got.data, expected.data, rtol=1e-12)
    assert got.outputs == expected.outputs
    with pytest.raises(UnknownPointError, match="no joint"):
        prepared.evaluate(joints={"nope": joint})
    with pytest.raises(InvalidValueError, match="same points"):
        prepared.evaluate(sensors={"acc": Sensor("acc", "tool.base", "1 g")})


def test_prepared_frf_with_a_replaced_component(assembly, grid):
    prepared = assembly.prepare("tool.tip:y", frequency=grid)
    shorter = make_tool(50.0)
    got = prepared.evaluate(components={"tool": shorter})
    # the same points by name: tool.tip is now at 50 mm
    expected = assembly.with_component(shorter).receptance("tool.tip:y", frequency=grid)
    np.testing.assert_allclose(got.data, expected.data, rtol=1e-12)
    with pytest.raises(UnknownPointError, match="no component"):
        prepared.evaluate(components={"nope": shorter})
