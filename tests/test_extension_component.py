"""The extension path of docs/extending.md keeps its promises: a holder subclass with a lumped nut.

``NutHolder`` is a registered :class:`Holder` subclass with two fields of its
own (the nut's mass and rotary inertia) and its own ``receptance_matrix``:
the beam's free-free receptances with the nut added at the tip by
structural modification.  It must give the same FRF as the plain holder with
the same body attached as a :class:`Sensor` (the engine's own coupling, an
independent path), through ``Assembly.receptance`` and after save/load; the
file keeps its fields (a 400 g nut does not reload as the 150 g default).
A subclass with a field a file cannot hold is refused on writing, naming the
field, rather than saved without it.  (Sweeps and FRF bands of such a
component are tested with the batched paths.)
"""

from __future__ import annotations

import attrs
import numpy as np
import pint
import pytest

from substructure import Assembly, Frequency, Holder, Segment, Sensor, register_component
from substructure.components import COMPONENT_TYPES
from substructure.errors import InvalidValueError
from substructure.io.assembly_toml import dumps_assembly, load_assembly, loads_assembly, save_assembly
from substructure.points import parse_point
from substructure.units import quantity

from conftest import make_spindle, make_tool, rel_err


def _mass(value):
    q = quantity(value, "nut_mass", "[mass]")
    if q.magnitude < 0:
        raise InvalidValueError(f"nut_mass: got {value!r}; expected a mass >= 0")
    return q


def _inertia(value):
    q = quantity(value, "nut_inertia", "[mass] * [length] ** 2")
    if q.magnitude < 0:
        raise InvalidValueError(f"nut_inertia: got {value!r}; expected a rotary inertia >= 0")
    return q


@attrs.frozen
class NutHolder(Holder):
    """A holder with a clamping nut at its tip: a rigid body of mass and rotary inertia."""

    nut_mass: pint.Quantity = attrs.field(default="150 g", kw_only=True, converter=_mass)
    nut_inertia: pint.Quantity = attrs.field(default="0 kg*m^2", kw_only=True, converter=_inertia)

    def receptance_matrix(self, refs, frequency_hz):
        f = np.asarray(frequency_hz, dtype=float)
        length = self.length_m
        at_tip = [i for i, r in enumerate(refs) if abs(self.position(r) - length) <= 1e-12 * length]
        points = list(refs) if at_tip else [*refs, parse_point(f"{self.name}.tip", allow_dof=False)]
        t = 2 * (at_tip[0] if at_tip else len(refs))
        beam = super().receptance_matrix(points, f)                 # (2q, 2q, n), frequency last
        w2 = (2 * np.pi * f) ** 2
        dz = np.zeros((2, 2, f.size), dtype=complex)                # the nut's dynamic stiffness -w^2 diag(m, J)
        dz[0, 0] = -w2 * self.nut_mass.m_as("kg")
        dz[1, 1] = -w2 * self.nut_inertia.m_as("kg*m^2")
        r_to_tip, r_from_tip, r_tt = beam[:, t:t + 2], beam[t:t + 2, :], beam[t:t + 2, t:t + 2]
        # R' = R - R[:, t] dZ (I + R_tt dZ)^-1 R[t, :], every line at once
        inner = np.linalg.inv(np.moveaxis(np.eye(2)[:, :, None] + np.einsum("ijn,jkn->ikn", r_tt, dz), -1, 0))
        update = np.einsum("ain,ijn,njk,kbn->abn", r_to_tip, dz, inner, r_from_tip)
        p = 2 * len(refs)
        return (beam - update)[:p, :p]


@pytest.fixture
def nut_holder_type():
    """Register the type for one test and restore the registry afterwards."""
    saved = dict(COMPONENT_TYPES)
    cls = register_component("test-nut-holder")(NutHolder)
    yield cls
    COMPONENT_TYPES.clear()
    COMPONENT_TYPES.update(saved)


SEGMENTS = [Segment("16 mm", "63 mm"), Segment("10 mm", "40 mm"), Segment("40 mm", "40 mm", "12 mm")]
JOINTS = (dict(name="spindle-holder", k={"yf": "4.1e7 N/m", "tm": "3.5e6 N*m/rad"}, c={"yf": "400 N*s/m"}),
          dict(name="holder-tool", k={"yf": "1.43e7 N/m", "tm": "8e4 N*m/rad"}, c={"yf": "12 N*s/m"}))
GRID = Frequency.from_range("50 Hz", "5000 Hz", "10 Hz")


def build(holder) -> Assembly:
    return (Assembly("with a nut", components=(make_spindle(), holder, make_tool()), frequency=GRID)
            .connect("spindle.tip", "holder.base", **JOINTS[0])
            .connect("holder.tip", "tool.base", **JOINTS[1]))


def test_the_nut_is_the_same_body_as_a_sensor_through_receptance(nut_holder_type):
    nut = nut_holder_type("holder", SEGMENTS, nut_mass="400 g", nut_inertia="2e-5 kg*m^2")
    with_nut = build(nut).receptance("tool.tip:y")
    reference = build(Holder("holder", SEGMENTS)).attach(
        Sensor("nut", "holder.tip", "400 g", inertia="2e-5 kg*m^2")).receptance("tool.tip:y")
    assert rel_err(with_nut.data, reference.data) < 1e-9
    plain = build(Holder("holder", SEGMENTS)).receptance("tool.tip:y")
    assert rel_err(plain.data, reference.data) > 0.05  # the nut matters: the test can fail
    # at points of the holder itself too (the component's own receptances are used)
    inner = build(nut).receptance("holder@30 mm", "tool.tip")
    inner_ref = build(Holder("holder", SEGMENTS)).attach(
        Sensor("nut", "holder.tip", "400 g", inertia="2e-5 kg*m^2")).receptance("holder@30 mm", "tool.tip")
    assert rel_err(inner.data, inner_ref.data) < 1e-9


def test_save_and_load_keep_the_nut(nut_holder_type, tmp_path):
    nut = nut_holder_type("holder", SEGMENTS, nut_mass="400 g", nut_inertia="2e-5 kg*m^2")
    assembly = build(nut)
    text = dumps_assembly(assembly)
    assert 'type = "test-nut-holder"' in text and 'nut_mass = "400 g"' in text
    save_assembly(assembly, tmp_path / "nut.toml")
    back = load_assembly(tmp_path / "nut.toml")
    assert back == assembly
    assert back.component("holder").nut_mass.m_as("g") == 400
    np.testing.assert_array_equal(back.receptance("tool.tip:y").data, assembly.receptance("tool.tip:y").data)
    # a file written by hand with the default: 150 g, as the class says
    default = loads_assembly(text.replace('nut_mass = "400 g"\n', ""))
    assert default.component("holder").nut_mass.m_as("g") == 150


def test_a_field_a_file_cannot_hold_is_refused_naming_it():
    saved = dict(COMPONENT_TYPES)
    try:
        @register_component("test-tabulated-holder")
        @attrs.frozen
        class TabulatedHolder(Holder):
            correction: tuple = attrs.field(default=(), kw_only=True, converter=lambda v: tuple(map(complex, v)))

        holder = TabulatedHolder("holder", SEGMENTS, correction=[1 + 2j, 3])
        with pytest.raises(InvalidValueError, match=r"'holder' .*field 'correction'.*to_toml/from_toml"):
            dumps_assembly(build(holder))

        @register_component("test-shifting-holder")
        @attrs.frozen
        class ShiftingHolder(Holder):
            """A converter that does not read its own value back the same: refused, not saved wrong."""

            offset: float = attrs.field(default=0.0, kw_only=True, converter=lambda v: float(v) + 1.0)

        with pytest.raises(InvalidValueError, match=r"'holder' \(ShiftingHolder\) would not read back equal.*offset"):
            dumps_assembly(build(ShiftingHolder("holder", SEGMENTS, offset=0.5)))
    finally:
        COMPONENT_TYPES.clear()
        COMPONENT_TYPES.update(saved)


def test_hooks_that_do_not_agree_are_refused():
    saved = dict(COMPONENT_TYPES)
    try:
        @register_component("test-forgetful-holder")
        @attrs.frozen
        class ForgetfulHolder(Holder):
            nut_mass: pint.Quantity = attrs.field(default="150 g", kw_only=True, converter=_mass)

            @classmethod
            def from_toml(cls, table, materials, key):
                return cls(table["name"], SEGMENTS)            # forgets the nut

            def to_toml(self):
                return {"nut_mass": f"{self.nut_mass.m_as('g')!r} g"}

        with pytest.raises(InvalidValueError,
                           match=r"'holder' \(ForgetfulHolder\) would not read back equal.*nut_mass"):
            dumps_assembly(build(ForgetfulHolder("holder", SEGMENTS, nut_mass="400 g")))
    finally:
        COMPONENT_TYPES.clear()
        COMPONENT_TYPES.update(saved)
