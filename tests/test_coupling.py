"""The generic coupling engine against the thesis's equations and its own inverses."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from conftest import make_holder, make_spindle, make_tool, rel_err, thesis_joints
from substructure import (
    Assembly,
    Frequency,
    Joint,
    MeasuredComponent,
    Segment,
    Sensor,
    Tool,
    add_mass,
    decouple,
    remove_mass,
)
from substructure.errors import SubstructureWarning


def stacked(frf):
    return frf.data  # (n, 2, 2) frequency first, for np.linalg


def test_generic_engine_equals_thesis_eq_2_1_and_2_2(assembly, grid):
    """[SH11] = H11 - H12 [H22 + K_sh^-1 + S11]^-1 H21; [SHT11] likewise (1e-10 relative)."""
    sh, ht = thesis_joints()
    inv = np.linalg.inv
    s11 = stacked(make_spindle().receptance(grid, ["tip"]))
    h = stacked(make_holder().receptance(grid, ["tip", "base"]))
    t = stacked(make_tool().receptance(grid, ["tip", "base"]))
    k_sh = np.moveaxis(sh.dynamic_stiffness(grid.hz), -1, 0)
    k_ht = np.moveaxis(ht.dynamic_stiffness(grid.hz), -1, 0)
    sh11 = h[:, :2, :2] - h[:, :2, 2:] @ inv(h[:, 2:, 2:] + inv(k_sh) + s11) @ h[:, 2:, :2]
    sht11 = t[:, :2, :2] - t[:, :2, 2:] @ inv(t[:, 2:, 2:] + inv(k_ht) + sh11) @ t[:, 2:, :2]

    sub = assembly.without("tool").receptance("holder.tip", frequency=grid)
    assert rel_err(sub.data, sh11) < 1e-10
    full = assembly.receptance("tool.tip", frequency=grid)
    assert rel_err(full.data, sht11) < 1e-10
    assert full.outputs == ("tool.tip:y", "tool.tip:theta")


def test_coupled_receptances_are_reciprocal(assembly, grid):
    frf = assembly.frf(["tool.tip", "holder@20 mm", "spindle@100 mm"], frequency=grid)
    y = frf.data
    assert np.abs(y - y.transpose(0, 2, 1)).max() < 1e-12 * np.abs(y).max()


def test_subassembly_as_component_equals_flat_assembly(assembly, grid):
    """A spindle-holder subassembly coupled to the tool as one component (thesis eq. 2.2)."""
    sh_joint, ht_joint = thesis_joints()
    sub = Assembly("spindle-holder", components=(make_spindle(), make_holder()), joints=(sh_joint,))
    nested = Assembly("nested", components=(sub, make_tool()), joints=(ht_joint,))
    flat = assembly.receptance("tool.tip", frequency=grid)
    assert rel_err(nested.receptance("tool.tip", frequency=grid).data, flat.data) < 1e-12


def test_measured_subassembly_coupled_to_tool_model(assembly, grid):
    """Eq. 2.2 with [SH11] given as data (as from a tap test) gives the model's tool point FRF."""
    _, ht_joint = thesis_joints()
    sh11 = assembly.without("tool").receptance("holder.tip", frequency=grid)
    measured = MeasuredComponent("spindle-holder", sh11)
    semi = Assembly("semi-analytical", components=(measured, make_tool()), joints=(ht_joint,))
    flat = assembly.receptance("tool.tip", frequency=grid)
    assert rel_err(semi.receptance("tool.tip", frequency=grid).data, flat.data) < 1e-12


def test_decoupling_undoes_coupling(assembly, grid):
    """Removing the tool (and its joint) from the assembly's receptances gives [SH11]."""
    _, ht_joint = thesis_joints()
    coupled = assembly.frf(["holder.tip"], frequency=grid)
    tool_y = make_tool().receptance(grid, ["base"])
    alone = decouple(coupled, tool_y, [("holder.tip", "tool.base", ht_joint)])
    expected = assembly.without("tool").receptance("holder.tip", frequency=grid)
    assert rel_err(alone.data, expected.data) < 1e-9


def test_rigid_decoupling(grid):
    holder, tool = make_holder(), make_tool()
    asm = Assembly("rigid", components=(holder, tool), joints=(Joint.rigid_between("j", "holder.tip", "tool.base"),))
    coupled = asm.frf(["holder.base", "holder.tip"], frequency=grid)
    alone = decouple(coupled, tool.receptance(grid, ["base"]), [("holder.tip", "tool.base", None)])
    expected = holder.receptance(grid, ["base", "tip"]).with_labels(coupled.outputs, coupled.inputs)
    assert rel_err(alone.data, expected.data) < 1e-8


def test_sensor_mass_equals_structural_modification(assembly, grid):
    """An accelerometer in the assembly = thesis eq. 5.1 on the sensor-free FRF; removing it = eq. 5.4."""
    sensor = Sensor("accelerometer", "tool.tip", "2 g", "5e-8 kg*m^2")
    with_sensor = assembly.attach(sensor).receptance("tool.tip", frequency=grid)
    without = assembly.receptance("tool.tip", frequency=grid)
    added = add_mass(without, "tool.tip", "2 g", "5e-8 kg*m^2")
    assert rel_err(added.data, with_sensor.data) < 1e-10
    removed = remove_mass(with_sensor, "tool.tip", "2 g", "5e-8 kg*m^2")
    assert rel_err(removed.data, without.data) < 1e-10
    # the tool mode moves down with the mass (thesis ch. 5)
    f0 = without.peaks("tool.tip:y", "tool.tip:y")
    f1 = with_sensor.peaks("tool.tip:y", "tool.tip:y")
    assert f1[np.argmax(f0 - f1[: len(f0)])] < f0[np.argmax(f0 - f1[: len(f0)])]


def test_scalar_mass_modification_is_thesis_eq_5_3(assembly, grid):
    h = assembly.receptance("tool.tip:y", frequency=grid)
    m = 0.002
    w2 = grid.omega**2
    expected = h.data[:, 0, 0] / (1 - w2 * m * h.data[:, 0, 0])
    assert rel_err(add_mass(h, "tool.tip", "2 g").data[:, 0, 0], expected) < 1e-13
    back = remove_mass(add_mass(h, "tool.tip", "2 g"), "tool.tip", "2 g")
    assert rel_err(back.data, h.data) < 1e-12
    with pytest.raises(Exception, match="theta"):
        add_mass(h, "tool.tip", "2 g", "1e-8 kg*m^2")


def test_stiff_joint_tends_to_rigid(grid):
    holder, tool = make_holder(), make_tool()
    rigid = Assembly("r", components=(holder, tool), joints=(Joint.rigid_between("j", "holder.tip", "tool.base"),))
    stiff = Assembly(
        "s", components=(holder, tool),
        joints=(Joint("j", ("holder.tip", "tool.base"), k={"yf": "1e16 N/m", "tm": "1e14 N*m/rad"}),),
    )
    a = rigid.receptance("tool.tip", frequency=grid).data
    b = stiff.receptance("tool.tip", frequency=grid).data
    assert rel_err(b, a) < 1e-6


def test_rigid_coupling_of_two_pieces_equals_single_beam(grid):
    whole = Tool("tool", [Segment("30 mm", "12 mm", material="carbide"), Segment("45 mm", "16 mm", material="carbide")])
    a = Tool("a", [Segment("30 mm", "12 mm", material="carbide"), Segment("20 mm", "16 mm", material="carbide")])
    b = Tool("b", [Segment("25 mm", "16 mm", material="carbide")])
    asm = Assembly("pieces", components=(a, b), joints=(Joint.rigid_between("j", "a.tip", "b.base"),))
    got = asm.frf(["b.tip", "a.base", "a@10 mm"], frequency=grid).data
    ref = whole.receptance(grid, ["tip", "base", "@10 mm"]).data
    assert rel_err(got, ref) < 1e-11


def test_loop_and_branch_topologies(grid):
    """Two parallel beams joined rigidly at both ends (a loop) behave as one beam with
    the summed section; a branch (two beams on one point) is reciprocal."""
    one = Tool("one", [Segment("50 mm", "20 mm")])
    left = Tool("left", [Segment("50 mm", "20 mm")])
    right = Tool("right", [Segment("50 mm", "20 mm")])
    loop = Assembly(
        "loop", components=(left, right),
        joints=(Joint.rigid_between("j1", "left.base", "right.base"),
                Joint.rigid_between("j2", "left.tip", "right.tip")),
    )
    # Two identical beams tied at both ends: same frequencies as one, receptance halved.
    got = loop.receptance("left.tip", frequency=grid).data
    ref = one.receptance(grid, ["tip"]).data / 2
    assert rel_err(got, ref) < 1e-10
    # A second rigid joint between points already tied is redundant: a clear error.
    from substructure import AssemblyError

    with pytest.raises(AssemblyError, match="singular"):
        loop.connect("left.tip", "right.tip", rigid=True, name="again").receptance("left.tip", frequency=grid)
    branch = Assembly(
        "branch", components=(one, left, right),
        joints=(Joint("a", ("one.tip", "left.base"), k={"yf": "1e8 N/m", "tm": "1e5 N*m/rad"}),
                Joint("b", ("one.tip", "right.base"), k={"yf": "2e8 N/m", "tm": "2e5 N*m/rad"})),
    )
    y = branch.frf(["left.tip", "right.tip"], frequency=grid).data
    assert np.abs(y - y.transpose(0, 2, 1)).max() < 1e-12 * np.abs(y).max()


def test_disconnected_components_have_zero_cross_receptance(grid):
    a = Tool("a", [Segment("50 mm", "20 mm")])
    b = Tool("b", [Segment("50 mm", "20 mm")])
    with pytest.warns(SubstructureWarning, match=r"'apart' falls into 2 pieces that no joint connects \(a; b\)"):
        frf = Assembly("apart", components=(a, b)).frf(["a.tip"], ["b.tip"], frequency=grid)
    assert np.all(frf.data == 0)


def test_a_joint_left_out_is_warned_of_naming_the_pieces():
    """The built-in assembly without its holder-tool joint: the tool floats free (its own receptance at the tip),
    and the warning names the pieces; the SI form the fits evaluate warns the same way."""
    from substructure import default_assembly
    from substructure.updating import Structure

    d = default_assembly()
    apart = Assembly("x", components=tuple(d.components), joints=(d.joint("spindle-holder"),))
    with pytest.warns(SubstructureWarning, match=r"'x' falls into 2 pieces .* \(spindle, holder; tool\)"):
        h = apart.receptance("tool.tip:y", frequency=[500.0]).data.ravel()
    alone = Assembly("t", components=(d.component("tool"),)).receptance("tool.tip:y", frequency=[500.0])
    np.testing.assert_allclose(h, alone.data.ravel())
    with pytest.warns(SubstructureWarning, match="falls into 2 pieces"):
        Structure.from_assembly(apart)


@settings(max_examples=15, deadline=None)
@given(
    overhang=st.floats(30, 90),
    k_yf=st.floats(1e6, 1e9),
    k_tm=st.floats(1e4, 1e7),
    mass_g=st.floats(0.5, 20),
)
def test_couple_decouple_and_mass_invariants(overhang, k_yf, k_tm, mass_g):
    grid = Frequency.from_range("50 Hz", "6000 Hz", "50 Hz")
    holder, tool = make_holder(), make_tool(overhang)
    joint = Joint("ht", ("holder.tip", "tool.base"), k={"yf": f"{k_yf} N/m", "tm": f"{k_tm} N*m/rad"},
                  c={"yf": "50 N*s/m", "tm": "2 N*m*s/rad"})
    asm = Assembly("a", components=(holder, tool), joints=(joint,))
    coupled = asm.frf(["holder.tip", "tool.tip"], frequency=grid)
    y = coupled.data
    assert np.abs(y - y.transpose(0, 2, 1)).max() < 1e-11 * np.abs(y).max()
    # decoupling the tool returns the holder alone
    alone = decouple(coupled.select(coupled.outputs[:2], coupled.inputs[:2]), tool.receptance(grid, ["base"]),
                     [("holder.tip", "tool.base", joint)])
    assert rel_err(alone.data, holder.receptance(grid, ["tip"]).data) < 1e-8
    # adding then removing a sensor returns the original
    m = f"{mass_g} g"
    back = remove_mass(add_mass(coupled, "tool.tip", m, "1e-8 kg*m^2"), "tool.tip", m, "1e-8 kg*m^2")
    assert rel_err(back.data, coupled.data) < 1e-10


def test_stiff_joint_converges_to_rigid_as_its_compliance_and_eq_2_2_with_no_compliance_is_rigid(grid):
    """examples/13_rigid_joints.py: thesis eq. 2.2 with [K]^-1 = 0 (numpy) is the rigid joint, and an
    elastic joint's difference to it falls tenfold per decade of stiffness (its compliance, 1/k)."""
    holder, tool = make_holder(), make_tool()
    rigid = Assembly("r", components=(holder, tool), joints=(Joint.rigid_between("j", "holder.tip", "tool.base"),))
    h_rigid = rigid.receptance("tool.tip", frequency=grid).data
    H = holder.receptance(grid, ["tip"]).data
    T = tool.receptance(grid, ["tip", "base"]).data
    eq = T[:, :2, :2] - T[:, :2, 2:] @ np.linalg.inv(T[:, 2:, 2:] + H) @ T[:, 2:, :2]
    assert rel_err(eq, h_rigid) < 1e-10
    diffs = []
    for k in (1e11, 1e12, 1e13, 1e14):
        joint = Joint("j", ("holder.tip", "tool.base"), k={"yf": f"{k:g} N/m", "tm": f"{k / 100:g} N*m/rad"},
                      c={"yf": "100 N*s/m", "tm": "1 N*m*s/rad"})
        diffs.append(rel_err(rigid.with_joint(joint).receptance("tool.tip", frequency=grid).data, h_rigid))
    ratios = np.array(diffs[:-1]) / np.array(diffs[1:])
    assert np.all((ratios > 9.0) & (ratios < 11.0)), ratios
