"""Users' effects: registered for a block or passed per call; they never change a built-in answer."""

import attrs
import pytest

import hidden_data as hd
from substructure import Sensor, Tool
from substructure.diagnose import EFFECTS, Effect, Parameter, diagnose, registered


class ToolOverhang(Effect):
    """The tool sticks out further than the model says (docs/diagnose.md, section 8)."""

    name = "tool-overhang"
    parameters = (Parameter("extra_length", "m", -0.02, 0.02, 0.0, log=False),)
    explanation = "a longer overhang lowers the tool's bending modes"

    @classmethod
    def places(cls, assembly, measured_points):
        return [c.name for c in assembly.components if isinstance(c, Tool)]

    def apply(self, assembly):
        tool = assembly.component(self.where)
        shank = tool.segments[0]
        longer = attrs.evolve(shank, length=f"{shank.length_m + self.values['extra_length']!r} m")
        return assembly.with_component(attrs.evolve(tool, segments=[longer, *tool.segments[1:]]))


class HolderNut(Effect):
    """A body at the holder face (an effect without an SI form: fitted through apply)."""

    name = "holder-nut"
    parameters = (Parameter("mass", "kg", 0.005, 0.5, 0.05),)
    explanation = "a clamping nut adds mass at the holder face"

    @classmethod
    def places(cls, assembly, measured_points):
        return ["holder.tip"]

    def apply(self, assembly):
        return assembly.attach(Sensor("holder-nut", self.where, f"{self.values['mass']!r} kg", always_on=True))


@pytest.fixture(scope="module")
def sensor_data():
    return hd.measure(sensor_kg=0.002, seed=61)


def _answer(d):
    return [(e.name, e.where, round(e.values.get("mass", 0.0), 6)) for e in d.effects], d.explained


def test_a_registered_effect_does_not_change_the_built_in_answer(sensor_data):
    model = hd.nominal_model()
    plain = diagnose(model, sensor_data)
    assert plain.explained and plain.missing_effect == "sensor-mass"
    with registered(ToolOverhang, HolderNut):
        assert "tool-overhang" in EFFECTS
        crowded = diagnose(model, sensor_data)
    assert "tool-overhang" not in EFFECTS and "holder-nut" not in EFFECTS  # restored after the block
    assert _answer(crowded) == _answer(plain)


def test_effects_given_per_call_need_no_registration():
    data = hd.measure(tool_length=0.082, seed=62)
    d = diagnose(hd.nominal_model(), data, effects=[ToolOverhang, "sensor-mass"], open_world=False)
    assert "tool-overhang" not in EFFECTS
    assert d.explained and d.missing_effect == "tool-overhang"
    assert d.effects[0].values["extra_length"] == pytest.approx(0.006, abs=2e-4)
