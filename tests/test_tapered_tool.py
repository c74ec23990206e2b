"""The ``tapered-tool`` effect: a tool whose diameter falls linearly along it, which the model has as a cylinder.

Without it, the diagnosis explained the FE rig's tapered tool (12 mm to 10 mm over its 76 mm) with two
invented changes that together reach the noise (flutes over the last 27 mm at 0.85 and a section change at
0.94 over 37 mm).  The data come from the independent FE rig of hidden_data.py; the taper there is made of
uniform pieces (hidden_data.measure's ``taper``), not of the library's tapered segments.
"""

import numpy as np
import pytest

import hidden_data as hd
from substructure import Flutes, Segment, Tool
from substructure.diagnose import diagnose
from substructure.diagnose.effects import EFFECTS, effect_change
from substructure.updating.elements import SectionChange
from substructure.updating.evaluator import Evaluator
from substructure.updating.structure import Structure

F = np.linspace(20.0, 5000.0, 300)
OUT, IN = ["tool.tip:y", "tool@40 mm:y", "holder.tip:y"], ["tool.tip:y"]


def _taper(where="tool", ratio=0.8):
    return EFFECTS["tapered-tool"](where, tip_ratio=ratio)


def test_the_taper_falls_linearly_along_the_tool_and_leaves_flutes_and_bores_alone():
    tool = Tool("tool", [Segment("46 mm", "12 mm", "2 mm", material="carbide"),
                         Segment("30 mm", "12 mm", material="carbide", flutes=Flutes(0.8))])
    from substructure.diagnose.catalogue import taper_tool

    out = taper_tool(tool, 0.75)
    first, fluted = out.segments
    assert first.od.m_as("m") == pytest.approx(0.012)
    assert first.od_tip.m_as("m") == pytest.approx(0.012 * (1 - 0.25 * 46 / 76))
    assert first.id.m_as("m") == pytest.approx(0.002) and not fluted.is_tapered
    assert fluted == tool.segments[1]
    plain = taper_tool(Tool("tool", [Segment("40 mm", "12 mm"), Segment("36 mm", "10 mm")]), 0.5)
    a, b = plain.segments
    assert a.od_tip.m_as("m") == pytest.approx(0.012 * (1 - 0.5 * 40 / 76))  # each segment its own od, scaled
    assert b.od.m_as("m") == pytest.approx(0.010 * (1 - 0.5 * 40 / 76))
    assert b.od_tip.m_as("m") == pytest.approx(0.005)


@pytest.mark.parametrize("model_kw, before", [
    ({}, None),
    (dict(flutes=(0.03, 0.8)), None),
    ({}, (SectionChange("tool", 0.076), {"diameter_ratio": 0.8, "start": 0.02, "length": 0.015})),
], ids=["cylinder", "fluted", "after-a-section-change"])
@pytest.mark.parametrize("ratio", [0.7, 0.95])
def test_the_si_form_tapers_the_tool_as_the_assembly_does(model_kw, before, ratio):
    model = hd.nominal_model(**model_kw)
    structure = Structure.from_assembly(model)
    if before is not None:  # the tool's arrays already split by another change: their changes kept
        element, values = before
        model, structure = element.apply(model, values), element.apply_si(structure, values)
    effect = _taper(ratio=ratio)
    ref = effect.apply(model).frf(OUT, IN, F).data
    got = Evaluator(OUT, IN, F)(effect.apply_si(structure))
    np.testing.assert_allclose(got, ref, rtol=1e-9, atol=1e-14 * np.abs(ref).max())
    base = model.frf(OUT, IN, F).data
    assert np.abs(ref - base).max() > 1e-3 * np.abs(base).max()


def test_the_effect_is_offered_for_tools_of_uniform_segments_only():
    assert EFFECTS["tapered-tool"].places(hd.nominal_model(), ["tool.tip"]) == ["tool"]
    assert EFFECTS["tapered-tool"].places(hd.nominal_model(taper=0.010), ["tool.tip"]) == []  # tapered already
    change = effect_change(EFFECTS["tapered-tool"], "tool", hd.nominal_model())
    assert [(p.name, p.lower, p.upper) for p in change.specs] == [("tip_ratio", 0.5, 1.0)]


@pytest.mark.parametrize("hidden, model_kw, ratio, seed", [
    (dict(taper=0.010, taper_pieces=32), {}, 10 / 12, 41),
    (dict(taper=0.011, taper_pieces=32), {}, 11 / 12, 42),
    (dict(taper=0.010, taper_pieces=32, flutes=(0.03, 0.8)), dict(flutes=(0.03, 0.8)), 10 / 12, 43),
], ids=["to-10-mm", "to-11-mm", "fluted-tip"])
def test_a_tapered_tool_modelled_as_a_cylinder_is_the_taper_and_nothing_else(hidden, model_kw, ratio, seed):
    d = diagnose(hd.nominal_model(**model_kw), hd.measure(seed=seed, **hidden))
    assert d.explained, d.report
    assert [(e.name, e.where) for e in d.effects] == [("tapered-tool", "tool")], [repr(e) for e in d.effects]
    assert d.effects[0].values["tip_ratio"] == pytest.approx(ratio, abs=0.01)
    assert d.final_error <= 1.5 * d.noise_floor


def test_a_taper_is_not_what_flutes_or_a_longer_overhang_are():
    """Neighbours the taper must not take: flutes the model lacks, a longer tool."""
    for hidden, name in ((dict(flutes=(0.03, 0.8)), "fluted-section"), (dict(tool_length=0.080), "model-parameter")):
        d = diagnose(hd.nominal_model(), hd.measure(seed=44, **hidden))
        assert d.explained and [e.name for e in d.effects] == [name], [repr(e) for e in d.effects]


def test_the_tapered_model_saves_reads_back_and_explains_new_taps_with_nothing():
    from substructure import dumps_assembly, loads_assembly

    d = diagnose(hd.nominal_model(), hd.measure(seed=41, taper=0.010, taper_pieces=32))
    text = dumps_assembly(d.refined_assembly)
    assert 'od = "12 mm", od_tip = "0.0107' in text  # the base as written, the taper's diameters in metres
    again = loads_assembly(text)
    points = ["tool.tip:y"]
    np.testing.assert_array_equal(again.frf(points, points, hd.GRID).data,
                                  d.refined_assembly.frf(points, points, hd.GRID).data)
    later = diagnose(again, hd.measure(seed=45, taper=0.010, taper_pieces=32))
    assert later.explained and not later.effects
