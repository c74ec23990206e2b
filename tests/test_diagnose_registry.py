"""Users' effects: registered for a block or passed per call; they never change a built-in answer."""

import re

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


def test_users_effects_have_slots_of_their_own_in_the_shortlist():
    """Eight user candidates that screen best leave the catalogue's and the model's candidates their slots."""
    from substructure.diagnose.effects import EffectChange
    from substructure.diagnose.search import Scored, shortlist
    from substructure.diagnose.settings import DEFAULT_SETTINGS
    from substructure.updating.parameters import model_parameters, parameter_change

    model = hd.nominal_model()
    user = [EffectChange(ToolOverhang, "tool", model) for _ in range(8)]
    catalogue = [EffectChange(EFFECTS["joint-stiffness"], where, model) for where in ("holder-tool", "spindle-holder")]
    params = [parameter_change(p) for p in model_parameters(model)[:3]]
    # screened chi^2 from 1000 (the current model) down: the users' first, all well above the share and significant
    scored = [Scored(c, {}, 100.0 + i) for i, c in enumerate(user + catalogue + params)]
    kept = shortlist(scored, 1000.0, 2000, 2000, 10, DEFAULT_SETTINGS)
    assert sum(s.change in user for s in kept) == DEFAULT_SETTINGS.shortlist_max
    assert all(any(s.change is c for s in kept) for c in catalogue + params)


@pytest.mark.parametrize("starts, message", [
    ([{"extra_length": float("nan")}], "scan_starts[0]['extra_length']: got nan; expected a finite number"),
    ([{"extra_length": "long"}], "scan_starts[0]['extra_length']: got 'long'; expected a finite number"),
    ([{"length": 0.01}], "scan_starts[0]: unknown parameters ['length']; expected some of extra_length"),
    ([0.01], "scan_starts[0]: got 0.01; expected a dict of parameter values"),
    ([{}], "scan_starts[0]: got {}; expected a dict"),
])
def test_an_effects_scan_starts_are_checked_where_they_enter(starts, message):
    """A user's effect that gives the scan bad starts is refused with what was wrong (the diagnosis skips the
    candidate and says so); good starts are clipped to the parameter's bounds at that place."""
    from substructure.diagnose.effects import effect_change
    from substructure.errors import InvalidValueError

    class Bad(ToolOverhang):
        @classmethod
        def scan_starts(cls, assembly, where):
            return starts

    with pytest.raises(InvalidValueError, match=re.escape(message)):
        effect_change(Bad, "tool", hd.nominal_model())

    class Good(ToolOverhang):
        @classmethod
        def scan_starts(cls, assembly, where):
            return [{"extra_length": 1e3}, {"extra_length": 0.002}]

    change = effect_change(Good, "tool", hd.nominal_model())
    (spec,) = change.specs
    assert change.trials == ({"extra_length": spec.upper}, {"extra_length": 0.002})
