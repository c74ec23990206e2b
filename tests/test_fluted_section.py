"""The ``fluted-section`` effect on a tool the model already gives flutes: where they begin and how deep they are.

Before, the effect was offered only for tools without flutes.  On a second, larger FE rig
(hidden_data_large.py: a 20 mm end mill whose model has flutes over 40 mm at 0.8), real flutes of 60 mm at 0.75
came back as the fluted segment's start and its ``od`` (the flutes' ratio, preferred, stood behind the ``od`` in
the pool of pairs), under the real residual at three times its level as a section change from 90 to 147 mm, and
with a 3 g sensor besides as the flutes' start and a section change ending 10 mm short of the tip that stood in
for the sensor: "explained" without it.  The data are the independent FE rigs' exact FRFs times the residual of
a real tap test (real_noise.py).
"""

import numpy as np
import pytest

import hidden_data as hd
import hidden_data_large as hl
import real_noise
from substructure import Flutes, Mass, Segment, Tool
from substructure.diagnose import diagnose
from substructure.diagnose.catalogue import fluted_tip
from substructure.diagnose.effects import EFFECTS, effect_change
from substructure.updating.elements import SectionChange
from substructure.updating.evaluator import Evaluator
from substructure.updating.structure import Structure

F = np.linspace(20.0, 4000.0, 300)
OUT, IN = ["tool.tip:y", "tool@40 mm:y", "holder.tip:y"], ["tool.tip:y"]


def _flutes(ratio, length, where="tool"):
    return EFFECTS["fluted-section"](where, diameter_ratio=ratio, length=length)


def _summary(d):
    return [(e.name, e.where, {k: float(f"{v:.4g}") for k, v in e.values.items()}) for e in d.effects]


def test_the_flutes_replace_the_models_and_start_from_them():
    tool = hl.model().component("tool")
    assert fluted_tip(tool) == pytest.approx((0.040, 0.8))
    assert fluted_tip(Tool("t", [Segment("50 mm", "12 mm")])) == (0.0, 1.0)
    longer = _flutes(0.75, 0.060).apply(hl.model()).component("tool")
    assert [(round(s.length_m, 9), s.flutes) for s in longer.segments] == [
        (0.1, None), (0.02, Flutes(0.75)), (0.04, Flutes(0.75))]
    shorter = _flutes(0.85, 0.025).apply(hl.model()).component("tool")
    assert [(round(s.length_m, 9), s.flutes) for s in shorter.segments] == [
        (0.12, None), (0.015, None), (0.025, Flutes(0.85))]  # no flutes before the new ones
    change = effect_change(EFFECTS["fluted-section"], "tool", hl.model())
    assert {s.name: s.start for s in change.specs} == pytest.approx({"diameter_ratio": 0.8, "length": 0.040})
    assert len(change.trials) == 15 and all(0.5 <= t["diameter_ratio"] <= 1 and 1e-3 <= t["length"] <= 0.16
                                            for t in change.trials)


@pytest.mark.parametrize("model, before", [
    (hl.model, None),
    (lambda: hd.nominal_model(flutes=(0.03, 0.8)), None),
    (hd.nominal_model, None),
    (hl.model, (SectionChange("tool", 0.16), {"diameter_ratio": 0.9, "start": 0.05, "length": 0.03})),
], ids=["large-fluted", "fluted", "plain", "after-a-section-change"])
@pytest.mark.parametrize("ratio, length", [(0.75, 0.060), (0.85, 0.025), (0.8, 0.04)])
def test_the_si_form_flutes_the_tool_as_the_assembly_does(model, before, ratio, length):
    model = model()
    structure = Structure.from_assembly(model)
    if before is not None:
        element, values = before
        model, structure = element.apply(model, values), element.apply_si(structure, values)
    effect = _flutes(ratio, length)
    ref = effect.apply(model).frf(OUT, IN, F).data
    got = Evaluator(OUT, IN, F)(effect.apply_si(structure))
    np.testing.assert_allclose(got, ref, rtol=1e-9, atol=1e-14 * np.abs(ref).max())


@pytest.mark.parametrize("hidden, level, offset", [
    (dict(flutes=(0.060, 0.75)), 1.0, 700),
    (dict(flutes=(0.060, 0.75)), 3.0, 2100),
    (dict(flutes=(0.025, 0.85)), 1.0, 1400),
    (dict(flutes=(0.040, 0.75)), 1.0, 2800),
], ids=["longer-deeper", "longer-deeper-x3", "shorter-shallower", "deeper"])
def test_flutes_other_than_the_models_are_the_flutes_and_nothing_else(hidden, level, offset):
    d = diagnose(hl.model(), real_noise.with_real_noise(hl.measure(**hidden), offset, level))
    assert d.explained, d.report
    (found,) = d.effects
    assert (found.name, found.where) == ("fluted-section", "tool"), _summary(d)
    length, ratio = hidden["flutes"]
    assert found.values["length"] == pytest.approx(length, abs=1e-3)
    assert found.values["diameter_ratio"] == pytest.approx(ratio, abs=0.01)


@pytest.mark.parametrize("rig", ["large", "small"])
def test_other_flutes_with_a_sensor_are_both_and_predict_points_not_fitted(rig):
    """The pair that a section change ending short of the tip stood in for; the refined model then predicts the
    FE rig 50 mm back on the tool and at the holder's tip, which were not measured."""
    if rig == "large":
        model, flutes, measure = hl.model(), (0.060, 0.75), hl.measure
        truth = hl.measure(points=("tool.tip-50 mm", "holder.tip"), flutes=flutes, sensor_kg=0.003)
    else:
        model, flutes = hd.nominal_model(flutes=(0.03, 0.8)), (0.045, 0.75)

        def measure(**kw):
            return hd.measure(noise=0.0, phase_deg=0.0, floor=0.0, **kw)
        truth = measure(points=("tool.tip-50 mm", "holder.tip"), flutes=flutes, sensor_kg=0.003)
    d = diagnose(model, real_noise.with_real_noise(measure(flutes=flutes, sensor_kg=0.003), 900))
    assert d.explained, d.report
    assert sorted(e.name for e in d.effects) == ["fluted-section", "sensor-mass"], _summary(d)
    (found,) = [e for e in d.effects if e.name == "fluted-section"]
    assert found.values["length"] == pytest.approx(flutes[0], abs=1e-3)
    assert found.values["diameter_ratio"] == pytest.approx(flutes[1], abs=0.01)
    (sensor,) = [e for e in d.effects if e.name == "sensor-mass"]
    assert sensor.values["mass"] == pytest.approx(0.003, rel=0.05)
    given = model.attach(Mass("sensor", "tool.tip", "3 g"))  # the sensor known, the flutes as drawn
    for frf in truth:
        f = frf.frequency
        saved = d.refined_assembly.frf(frf.outputs[0], "tool.tip:y", f).data[:, 0, 0]
        drawn = given.frf(frf.outputs[0], "tool.tip:y", f).data[:, 0, 0]
        exact = frf.data[:, 0, 0]
        error, off = (float(np.sqrt(np.mean(np.abs(np.log(h / exact)) ** 2))) for h in (saved, drawn))
        assert error < 0.02 and error < 0.1 * off, (frf.outputs, error, off)


def test_a_preferred_name_replaces_its_equal_in_the_pool_of_pairs_even_after_the_pool_is_full():
    """The fluted segment's od (what the user measures) and the flutes' ratio (the model's guess) set the same
    section; the ratio ranked fifth, just after the od, and the pool of four pairs took the od."""
    from types import SimpleNamespace

    from substructure.diagnose.refine import _distinct
    from substructure.updating.likelihood import Likelihood, measured_frfs
    from substructure.updating.parameters import model_parameters, parameter_change

    model = hl.model()
    measured, _ = measured_frfs(hl.measure(flutes=(0.060, 0.75)), None)
    lik = Likelihood(model, measured)
    params = {p.path: p for p in model_parameters(model)}

    def single(path, value):
        change = parameter_change(params[path])
        return SimpleNamespace(change=change, values={"value": value},
                               fit=SimpleNamespace(changes=[(change, {"value": value})]))

    singles = [single("joints.holder-tool.k.yf", 2e7), single("components.tool.overhang", 0.17),
               single("joints.spindle-holder.k.tm", 3e6), single("components.tool.segments.1.od", 0.01875),
               single("components.tool.segments.1.flutes.diameter_ratio", 0.75)]
    pool = _distinct(lik.subsample(7), singles, 4)
    assert [s.change.where for s in pool] == ["joints.holder-tool.k.yf", "components.tool.overhang",
                                              "joints.spindle-holder.k.tm",
                                              "components.tool.segments.1.flutes.diameter_ratio"]
    assert [s.change.where for s in _distinct(lik.subsample(7), singles[:4], 4)][-1].endswith(".od")


@pytest.mark.parametrize("hidden, values, stays", [
    (dict(flutes=(0.030, 0.8)), {"diameter_ratio": 0.8, "start": 0.046, "length": 0.030}, False),
    (dict(neck=(0.026, 0.020, 0.009)), {"diameter_ratio": 0.75, "start": 0.026, "length": 0.020}, True),
], ids=["over-the-tip", "a-neck"])
def test_a_section_change_over_the_tools_tip_is_reported_as_the_flutes_it_is(hidden, values, stays):
    """The review tries the catalogue's effects on the element's component in its place: a section change at 0.8
    over a tool's last 30 mm is flutes there (a path that found it so was reported as a section change); a neck
    in the middle of the tool stays what it is."""
    from substructure.diagnose.refine import _review
    from substructure.updating.fit import fit
    from substructure.updating.likelihood import Likelihood, measured_frfs

    model = hd.nominal_model()
    measured, _ = measured_frfs(hd.measure(seed=5, **hidden), None)
    lik = Likelihood(model, measured)
    section = SectionChange("tool", 0.076)
    found = fit(lik, [(section, values)])
    cands = [effect_change(EFFECTS[name], "tool", model) for name in ("fluted-section", "tapered-tool")]
    kept, chi2, _ = _review(lik, list(found.changes), found.chi2, {}, {}, [], lambda changes: True, None,
                            cands=cands)
    ((change, got),) = kept
    if stays:
        assert change is section and chi2 == found.chi2
    else:
        assert change.key == cands[0].key and chi2 <= found.chi2 * (1 + 1e-6)
        assert got == pytest.approx({"diameter_ratio": 0.8, "length": 0.030}, rel=1e-3)


@pytest.mark.parametrize("path, value", [
    ("components.tool.overhang", 0.080), ("components.tool.bore", 0.002), ("components.tool.segments.0.od", 0.0118),
])
def test_a_sliver_left_by_flutes_does_not_refuse_later_values_on_the_tool(path, value):
    """Flutes whose start falls within a micrometre of a segment's end leave a sliver in the SI form (its cut is
    not moved to the end: that would stop the flutes' length from moving in a finite difference).  A later value
    on that tool was refused for the sliver ("a segment shorter than 1 um"): the overhang after flutes was never
    a candidate.  Now only what the value makes is refused, and the result is the assembly's (written back
    without the sliver)."""
    from substructure.updating.paths import apply_path_si, set_parameters

    model = hd.nominal_model()
    effect = _flutes(0.8, 0.030 + 3e-10)  # starts 0.3 nm before the step at 46 mm
    structure = effect.apply_si(Structure.from_assembly(model))
    assert structure.beams["tool"].length.min() < 1e-9
    got = Evaluator(OUT, IN, F)(apply_path_si(structure, path, value))
    ref = set_parameters(effect.apply(model), {path: value}).frf(OUT, IN, F).data
    np.testing.assert_allclose(got, ref, rtol=1e-6, atol=1e-12 * np.abs(ref).max())
    with pytest.raises(Exception, match="shorter than 1 um"):  # what the value itself makes is still refused
        apply_path_si(structure, "components.tool.segments.0.length", 5e-7)
