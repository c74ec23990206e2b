"""The model-updating core: parameters by path, the SI evaluation, noise, fits, the tests of selection."""

import re
import warnings

import numpy as np
import pytest

import hidden_data as hd
from substructure import (FRF, Assembly, Flutes, Insert, InvalidValueError, Joint, Mass,
                          MeasuredComponent, Segment, Sensor, Support, Tool, default_assembly, dumps_assembly,
                          loads_assembly)
from substructure.beams import stepped_beam_receptance, stepped_beam_receptance_si
from substructure.updating.elements import AddedMass, GroundSpring, SectionChange
from substructure.updating.fit import fit
from substructure.updating.likelihood import Likelihood, measured_frfs
from substructure.updating.noise import estimate_noise
from substructure.updating.parameters import (ParameterChange, apply_path_si, get_parameter,
                                              material_changes, model_parameters, parameter_change,
                                              set_parameters)
from substructure.updating.selection import consistency, indifferent, significance
from substructure.updating.evaluator import Evaluator
from substructure.updating.structure import Structure

F = np.linspace(20.0, 5000.0, 400)
OUT, IN = ["tool.tip:y", "holder.tip:y", "spindle@100 mm:y"], ["tool.tip:y"]


def _rich_model() -> Assembly:
    """The built-in assembly with supports, a sensor and a permanent body: every kind of parameter."""
    return (default_assembly()
            .support(Support("spindle@50 mm", k={"yf": "1e6 N/m"}, c={"yf": "10 N*s/m"}))
            .support(Support("spindle@250 mm", k={"yf": "2e6 N/m", "tm": "1e4 N*m/rad"}))
            .support(Support("spindle@300 mm", k={"yf": "2e6 N/m"}))
            .attach(Sensor("acc", "tool.tip", "3 g", "1e-8 kg*m^2"))
            .attach(Mass("nut", "holder@30 mm", "100 g", "2e-5 kg*m^2")))


def test_the_si_beam_receptance_is_the_segments_one():
    segs = [Segment("40 mm", "40 mm", "12 mm", insert=Insert("12 mm", "carbide")), Segment("30 mm", "25 mm"),
            Segment("30 mm", "12 mm", material="carbide", flutes=Flutes(0.8))]
    ref = stepped_beam_receptance(segs, [0.0, 0.05, 0.1], F)
    sec = [s.section() for s in segs]
    got = stepped_beam_receptance_si(np.array([s.EI for s in sec]), np.array([s.kGA for s in sec]),
                                     np.array([s.rhoA for s in sec]), np.array([s.rhoI for s in sec]),
                                     np.array([s.length_m for s in segs]), [0.0, 0.05, 0.1], F)
    np.testing.assert_allclose(got, ref, rtol=1e-12, atol=1e-15 * np.abs(ref).max())


def test_the_si_beam_receptance_of_a_long_beam_cut_into_chains_is_the_segments_one():
    """A beam whose k L exceeds one chain's limit at the highest line takes the SI form's other path (cut
    into chains joined by the coupling engine); it must still equal the segments' receptance."""
    segs = [Segment("250 mm", "40 mm", "10 mm"), Segment("200 mm", "25 mm"), Segment("150 mm", "12 mm")]
    f = np.linspace(50.0, 20000.0, 300)
    positions = [0.6, 0.0, 0.31, 0.45]
    ref = stepped_beam_receptance(segs, positions, f)
    sec = [s.section() for s in segs]
    got = stepped_beam_receptance_si(np.array([s.EI for s in sec]), np.array([s.kGA for s in sec]),
                                     np.array([s.rhoA for s in sec]), np.array([s.rhoI for s in sec]),
                                     np.array([s.length_m for s in segs]), positions, f)
    np.testing.assert_allclose(got, ref, rtol=1e-9, atol=1e-12 * np.abs(ref).max())


def test_every_parameter_moves_the_si_form_as_it_moves_the_assembly():
    model = _rich_model()
    params = model_parameters(model)
    paths = {p.path for p in params}
    assert {"components.tool.segments.1.flutes.diameter_ratio", "components.holder.segments.2.insert.od",
            "materials.carbide.E", "joints.holder-tool.k.ym", "supports.1.k.tm", "supports.0.at",
            "sensors.acc.mass", "masses.nut.at", "components.tool.overhang", "components.tool.E",
            "joints.holder-tool.c", "components.spindle.supports.k", "supports.1+2.k",
            "components.tool.segments.0.end"} <= paths
    structure = Structure.from_assembly(model)
    evaluate = Evaluator(OUT, IN, F)
    base = model.frf(OUT, IN, F).data
    np.testing.assert_allclose(evaluate(structure), base, rtol=1e-12, atol=1e-14 * np.abs(base).max())
    moved = 0
    for p in params:
        value = p.nominal * 1.1 if p.nominal != 0 else 0.3 * p.upper
        value = float(np.clip(value, p.lower, p.upper))
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            changed = set_parameters(model, {p.path: value})
        ref = changed.frf(OUT, IN, F).data
        got = evaluate(apply_path_si(structure, p.path, value))
        assert np.abs(got - ref).max() <= 1e-10 * np.abs(ref).max(), p.path
        moved += np.abs(ref - base).max() > 1e-6 * np.abs(base).max()
        assert get_parameter(changed, p.path) == pytest.approx(value if not p.linked or p.unit != "dimensionless"
                                                               else 1.0, rel=1e-9, abs=1e-12), p.path
    assert moved >= len(params) - 2  # only an unloaded insert bore and the like can leave the FRF alone
    # "this part is made of another material": E, rho and nu of a component's own material together
    changes = {c.where: c for c in material_changes(model)}
    assert set(changes) == {"components.tool.material", "components.holder.material"}  # a spindle shaft is steel
    steel = {"E": 210e9, "rho": 7850.0, "nu": 0.29}
    assert steel in [dict(t) for t in changes["components.tool.material"].trials]  # the library's materials
    for change in changes.values():
        values = {s.name: float(np.clip(s.nominal * 0.9, s.lower, s.upper)) for s in change.specs}
        ref = change.apply(model, values).frf(OUT, IN, F).data
        got = evaluate(change.apply_si(structure, values))
        assert np.abs(got - ref).max() <= 1e-10 * np.abs(ref).max(), change.where
        assert np.abs(ref - base).max() > 1e-6 * np.abs(base).max(), change.where


def test_a_changed_model_saves_and_reads_back_with_its_new_values():
    model = _rich_model()
    changed = set_parameters(model, {"components.tool.E": 1.1, "materials.steel.rho": 7800.0,
                                     "components.tool.overhang": 0.080, "masses.nut.at": 0.04,
                                     "joints.holder-tool.k.ym": 2e5})
    again = loads_assembly(dumps_assembly(changed))
    np.testing.assert_allclose(again.frf(OUT, IN, F).data, changed.frf(OUT, IN, F).data, rtol=1e-12)
    assert again.component("tool").length_m == pytest.approx(0.080)
    assert again.mass("nut").at == changed.mass("nut").at
    with pytest.raises(Exception, match="not a parameter"):
        set_parameters(model, {"gremlins.x": 1.0})


def test_a_step_between_segments_moves_and_the_component_keeps_its_length():
    model = hd.nominal_model()
    params = {p.path: p for p in model_parameters(model)}
    step = params["components.holder.segments.1.end"]  # the collar (10 mm) meets the bore with the tool's shank
    assert step.linked and step.nominal == pytest.approx(0.026)
    assert (step.lower, step.upper) == pytest.approx((0.016 + 0.2 * 0.010, 0.066 - 0.2 * 0.040))
    assert "components.spindle.segments.0.end" in params  # 70 mm to 90 mm: a step
    deeper = set_parameters(model, {"components.holder.segments.1.end": 0.036})
    holder = deeper.component("holder")
    assert [s.length_m for s in holder.segments] == pytest.approx([0.016, 0.020, 0.030])
    assert holder.length_m == pytest.approx(0.066) and get_parameter(deeper, step.path) == pytest.approx(0.036)
    same = hd.nominal_model().with_component(Tool("tool", [Segment("46 mm", "12 mm", material="carbide"),
                                                           Segment("30 mm", "12 mm", material="carbide")]))
    assert "components.tool.segments.0.end" not in {p.path for p in model_parameters(same)}  # no step to move
    with pytest.raises(Exception, match="no step"):
        set_parameters(model, {"components.holder.segments.2.end": 0.05})
    for outside in (0.016, 0.1, -1.0, float("nan")):  # the step stays between where the two segments lie
        with pytest.raises(InvalidValueError, match="16 mm to 66 mm from the base of 'holder'"):
            set_parameters(model, {"components.holder.segments.1.end": outside})


def test_components_and_joints_the_si_form_cannot_hold_take_part_as_they_are():
    model = default_assembly()
    spindle_holder = model.without("tool")
    measured = MeasuredComponent("sh", spindle_holder.frf(["holder.tip"], frequency=F))

    class Stiffer(Joint):  # a joint model of its own
        def dynamic_stiffness(self, frequency_hz):
            return 2.0 * super().dynamic_stiffness(frequency_hz)

    tool_joint = model.joint("holder-tool")
    mixed = Assembly("mixed", components=(measured, model.component("tool")),
                     joints=(Stiffer(tool_joint.name, tool_joint.between, k=tool_joint.k, c=tool_joint.c),))
    ref = mixed.frf(["tool.tip:y"], ["tool.tip:y"], F).data
    got = Evaluator(["tool.tip:y"], ["tool.tip:y"], F)(Structure.from_assembly(mixed))
    np.testing.assert_allclose(got, ref, rtol=1e-10)


@pytest.mark.parametrize("element, values", [
    (AddedMass("holder", 0.066, 1.0), {"mass": 0.12, "inertia": 3e-5, "position": 0.03}),
    (GroundSpring("spindle", 0.33), {"k_yf": 2e5, "position": 0.1}),
    (SectionChange("tool", 0.076), {"diameter_ratio": 0.75, "start": 0.026, "length": 0.02}),
])
def test_elements_act_alike_on_the_si_form_and_on_the_assembly(element, values):
    model = default_assembly()
    ref = element.apply(model, values).frf(OUT, IN, F).data
    got = Evaluator(OUT, IN, F)(element.apply_si(Structure.from_assembly(model), values))
    np.testing.assert_allclose(got, ref, rtol=1e-10, atol=1e-14 * np.abs(ref).max())
    assert np.abs(ref - model.frf(OUT, IN, F).data).max() > 1e-3 * np.abs(ref).max()
    again = loads_assembly(dumps_assembly(element.apply(model, values)))  # written in the file's usual forms
    np.testing.assert_allclose(again.frf(OUT, IN, F).data, ref, rtol=1e-12)


@pytest.fixture(scope="module")
def clean():
    """The FE rig's tool-tip FRF without noise (noise is added per test)."""
    return hd.measure(noise=0.0, phase_deg=0.0, floor=0.0)[0]


def _noisy(clean: FRF, rel: float, phase_deg: float, floor: float, seed: int) -> FRF:
    rng = np.random.default_rng(seed)
    h = clean.data
    n = h.shape
    level = floor * np.median(np.abs(h))
    data = (h * (1 + rel * rng.standard_normal(n)) * np.exp(1j * np.radians(phase_deg) * rng.standard_normal(n))
            + level * (rng.standard_normal(n) + 1j * rng.standard_normal(n)) / np.sqrt(2))
    return FRF(clean.frequency, data, clean.outputs, clean.inputs)


@pytest.mark.parametrize("rel, phase, floor", [(0.015, 0.5, 1e-3), (0.04, 0.2, 1e-3), (0.005, 0.5, 1e-2)])
def test_the_noise_model_finds_the_noise_put_in(clean, rel, phase, floor):
    """Relative, phase and additive noise recovered from the data; the truth's chi^2/nu is about 1."""
    model = hd.nominal_model()
    h_true = clean.data[:, 0, 0]
    for seed in range(3):
        frf = _noisy(clean, rel, phase, floor, seed)
        noise = estimate_noise(frf)
        assert np.sqrt(noise.relative[0]) == pytest.approx(rel, rel=0.12)
        assert np.sqrt(noise.relative[1]) == pytest.approx(np.radians(phase), rel=0.12)
        assert np.sqrt(noise.additive) == pytest.approx(floor * np.median(np.abs(h_true)), rel=0.3)
        lik = Likelihood(model, measured_frfs([frf])[0])
        r = lik.residual([])
        bound = 3.09 * np.sqrt(2 / r.size + noise.scale_error**2)
        assert abs(float(r @ r) / r.size - 1.0) < bound


def test_a_dead_channel_is_refused_by_name():
    dead = FRF(hd.GRID, np.zeros((hd.GRID.n, 1, 1)), ("tool.tip:y",), ("tool.tip:y",))
    with pytest.raises(InvalidValueError, match=r"tool.tip:y / tool.tip:y.*zero"):
        estimate_noise(dead)
    with pytest.raises(InvalidValueError, match=r"tool.tip:y / tool.tip:y.*dead channel"):
        measured_frfs([dead])


def test_a_band_half_inside_the_data_says_which_end_is_outside(clean):
    with pytest.raises(InvalidValueError, match="ends at 6000 Hz, above the last measured line"):
        measured_frfs([clean], (1000, 6000))
    with pytest.raises(InvalidValueError, match="starts at 1 Hz, below the first measured line"):
        measured_frfs([clean], (1, 3000))
    with pytest.raises(InvalidValueError, match="outside the measured data"):
        measured_frfs([clean], (6000, 9000))


def test_fitted_standard_deviations_cover_the_truth(clean):
    """The soft holder-tool joint of the FE rig (k_yf / 3) fitted in 12 noisy trials: within 3 sigma."""
    soft = hd.measure(ht_scale=1 / 3, noise=0.0, phase_deg=0.0, floor=0.0)[0]
    model = hd.nominal_model()
    change = ParameterChange(next(p for p in model_parameters(model) if p.path == "joints.holder-tool.k.yf"))
    inside, errors = 0, []
    for seed in range(12):
        lik = Likelihood(model, measured_frfs([_noisy(soft, 0.015, 0.5, 1e-3, seed)], (500, 3000))[0])
        result = fit(lik, [(change, {"value": 1.0e7})])
        value, std = result.changes[0][1]["value"], result.std[0]["value"]
        errors.append(abs(value / (1.43e7 / 3) - 1))
        inside += abs(value - 1.43e7 / 3) <= 3 * std
        assert result.chi2_reduced < 1.1
    assert max(errors) < 0.01
    assert inside >= 11


def test_the_consistency_test_accepts_the_truth_and_rejects_a_one_percent_error(clean):
    model = hd.nominal_model()
    change = ParameterChange(next(p for p in model_parameters(model) if p.path == "joints.holder-tool.k.yf"))
    for seed in range(4):
        lik = Likelihood(model, measured_frfs([_noisy(clean, 0.015, 0.5, 1e-3, seed)])[0])
        assert consistency(lik, lik.log_ratios([]), 0).consistent
        off = consistency(lik, lik.log_ratios([(change, {"value": 1.43e7 * 1.01})]), 0)
        assert not off.consistent
        # the line where the change moves the model most, relative to the noise, lies in a failing band
        w = lik.residual([(change, {"value": 1.43e7 * 1.01})]) - lik.residual([])
        n = clean.frequency.n
        worst = clean.frequency.hz[np.argmax(w[:n] ** 2 + w[n:] ** 2)]
        assert any(b.lo_hz <= worst <= b.hi_hz for b in off.bands)


def test_a_failing_band_s_share_of_the_error_is_a_fraction_where_chi2_is_below_its_mean(clean):
    """The rest of the band quieter than its noise (chi^2 < nu) and one block far off: the share reported
    for the block is its part of the error, not its excess over chi^2 - nu (which is negative here: the
    share was 1e300 times the excess)."""
    model = hd.nominal_model()
    lik = Likelihood(model, measured_frfs([_noisy(clean, 0.015, 0.5, 1e-3, 0)])[0])
    (r,) = lik.log_ratios([])
    quiet = 0.5 * r  # a quarter of the noise's chi^2 everywhere
    lines = slice(r.size // 2, r.size // 2 + 30)
    quiet[lines] += 0.04 + 0.04j  # thirty lines 4 % and 0.04 rad off
    c = consistency(lik, [quiet], 0)
    assert c.chi2_reduced < 1.0 and not c.consistent and c.bands
    shares = [b.share for b in c.bands]
    assert all(0.0 < s <= 1.0 for s in shares) and sum(shares) <= 1.0 + 1e-12
    f = clean.frequency.hz[lines]
    top = c.bands[0]
    assert top.lo_hz <= f[-1] and f[0] <= top.hi_hz
    assert top.share > 0.5


def test_the_band_bound_of_scores_whose_variance_is_estimated_follows_the_f_distribution():
    """A line's score over a variance known to nu degrees of freedom is F(2, nu): the capped mean has
    the closed form 2 (1 - 1 / (1 + c / 2)) for nu = 4, and blocks of such scores exceed the bound at
    its level (Monte Carlo), while the exponential's bound would be exceeded far more often."""
    from substructure.updating.selection import LINE_CAP, _block_bound, _line_moments

    c = LINE_CAP
    mean4, _ = _line_moments(np.array([4.0]), 1)
    assert mean4 == pytest.approx(2.0 * (1.0 - 1.0 / (1.0 + c / 2.0)), rel=2e-3)
    big, _ = _line_moments(np.array([1e7]), 1)
    assert big == pytest.approx(1.0 - np.exp(-c), rel=1e-9)
    rng = np.random.default_rng(5)
    size, alpha, trials = 48, 0.01, 20000
    scores = 0.5 * rng.chisquare(2, (trials, size)) / (rng.chisquare(4, (trials, size)) / 4.0)
    means = np.minimum(scores, c).mean(axis=1)
    rate = float(np.mean(means > _block_bound(size, alpha, np.full(size, 4.0))))
    assert 0.4 * alpha < rate < 2.0 * alpha, rate
    assert float(np.mean(means > _block_bound(size, alpha))) > 0.5


def test_the_noise_of_a_few_taps_has_the_degrees_of_freedom_of_its_coherence(clean):
    measured = _noisy(clean, 0.015, 0.5, 1e-3, 0)
    rng = np.random.default_rng(2)
    coherence = np.clip(1.0 - 1e-3 * rng.chisquare(4, clean.frequency.n) / 4.0, 0.0, 1.0)
    few = estimate_noise(measured, coherence=coherence, averages=3)
    none = estimate_noise(measured)
    assert none.dof is None
    assert few.dof is not None and np.all(few.dof >= 4.0 - 1e-9)
    assert np.all(few.select(np.arange(5)).dof == few.dof[:5])


def test_significance_and_indifference_follow_their_definitions():
    n = 10000
    assert significance(1000.0, 1000.0 - 2 * np.log(n) - 1, 2, n, 2).significant
    assert not significance(1000.0, 1000.0 - 2 * np.log(n) + 1, 2, n, 2).significant
    misfit = significance(40000.0, 20000.0, 1, n, 1)  # chi^2/nu = 2: the ratio is halved
    assert misfit.statistic == pytest.approx(20000.0 / (20000.0 / (n - 1)))
    assert indifferent(5000.0, 2, 5009.0, 2, n) and not indifferent(5000.0, 2, 5011.0, 2, n)


def test_a_tapered_tool_takes_part_as_it_is():
    """A tapered tool is held in the SI arrays (its segments' tip diameters), evaluated as the objects are."""
    from substructure import Segment, Tool

    model = default_assembly()
    taper = Tool("tool", [Segment("46 mm", "12 mm", material="carbide"),
                          Segment("30 mm", "12 mm", material="carbide", od_tip="10 mm")])
    tapered = model.with_component(taper)
    structure = Structure.from_assembly(tapered)
    assert "tool" in structure.beams and "tool" not in structure.opaque
    assert structure.beam("tool").tapered.tolist() == [False, True]
    ref = tapered.frf(OUT, IN, F).data
    np.testing.assert_allclose(Evaluator(OUT, IN, F)(structure), ref, rtol=1e-10)
    # its numbers are candidates too, set in the SI arrays
    params = {p.path: p for p in model_parameters(tapered) if p.path.startswith("components.tool.")}
    tip = params["components.tool.segments.1.od_tip"]
    assert tip.nominal == pytest.approx(0.010) and tip.lower < 0.010 < tip.upper
    assert {"components.tool.segments.0.od", "components.tool.segments.1.length",
            "components.tool.overhang"} <= set(params)
    change = parameter_change(tip)
    lik_model = tapered.with_component(Tool("tool", [Segment("46 mm", "12 mm", material="carbide"),
                                                     Segment("30 mm", "12 mm", material="carbide", od_tip="9 mm")]))
    expected = lik_model.frf(OUT, IN, F).data
    changed = change.apply_si(structure, {"value": 0.009})
    assert "tool" in changed.beams and changed.component("tool") == lik_model.component("tool")
    evaluator = Evaluator(OUT, IN, F)
    np.testing.assert_allclose(evaluator(structure), ref, rtol=1e-10)
    np.testing.assert_allclose(evaluator(changed), expected, rtol=1e-10)
    np.testing.assert_allclose(evaluator(structure), ref, rtol=1e-10)  # the first one's receptances kept
    for value in (0.0095, 0.0085, 0.0095):  # rebuilt and dropped at each evaluation, as in a fit: never stale
        got = evaluator(change.apply_si(structure, {"value": value}))
        np.testing.assert_allclose(got, change.apply(tapered, {"value": value}).frf(OUT, IN, F).data, rtol=1e-10)


@pytest.mark.parametrize("before", [{}, {"components.tool.segments.0.od": 0.0115},
                                    {"materials.carbide.E": 5.5e11, "components.holder.segments.2.insert.od": 0.0119},
                                    {"components.tool.segments.1.flutes.diameter_ratio": 0.75}],
                         ids=["alone", "after-its-od", "after-material-and-insert", "after-flutes"])
def test_a_taper_set_on_a_uniform_segment_is_the_assemblys_taper_in_the_si_form(before):
    """``od_tip`` and ``id_tip`` of a uniform segment make it tapered on the assembly, and in the SI form's
    arrays, with the changes they carry (they once set the flutes' ratio instead, 350 times off)."""
    model = _rich_model()
    evaluate = Evaluator(OUT, IN, F)
    for path, value in (("components.tool.segments.0.od_tip", 0.0105), ("components.tool.segments.1.od_tip", 0.011),
                        ("components.holder.segments.2.od_tip", 0.036), ("components.spindle.segments.0.id_tip", 0.03),
                        ("components.holder.segments.0.id_tip", 0.004)):
        values = {**before, path: value}
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            changed = set_parameters(model, values)
        name = path.split(".")[1]
        segment = changed.component(name).segments[int(path.split(".")[3])]
        assert segment.is_tapered, path
        ref = changed.frf(OUT, IN, F).data
        structure = Structure.from_assembly(model)
        for p, v in values.items():
            structure = apply_path_si(structure, p, v)
        assert name in structure.beams and structure.beam(name).tapered.any() and not structure.opaque
        got = evaluate(structure)
        assert np.abs(got - ref).max() <= 1e-10 * np.abs(ref).max(), path
        assert np.abs(ref - evaluate(Structure.from_assembly(set_parameters(model, before)))).max() \
            > 1e-4 * np.abs(ref).max(), path  # the taper moved the FRF
        # and a number set after the taper is set on the (now tapered) component, as on the assembly
        length = {f"components.{name}.segments.0.length": 1.05 * changed.component(name).segments[0].length_m}
        after = apply_path_si(structure, *next(iter(length.items())))
        np.testing.assert_allclose(evaluate(after), set_parameters(changed, length).frf(OUT, IN, F).data, rtol=1e-9,
                                   err_msg=path)


def test_the_coupling_steps_an_evaluator_reuses_give_what_a_fresh_evaluator_gives(monkeypatch):
    """Coupling steps whose components and links are unchanged are taken from earlier evaluations: the same
    numbers, bit for bit, as an evaluator that computes everything, in any order of structures, and fewer
    coupling steps computed."""
    from substructure import _kernels

    model = _rich_model()
    structure = Structure.from_assembly(model)
    tip_mass = AddedMass("tool", 0.076, 0.05, (0.0, 0.076), 1e-6)
    section = SectionChange("tool", 0.076)
    variants = [structure,
                tip_mass.apply_si(structure, {"mass": 0.002, "position": 0.07, "inertia": 0.0}),
                tip_mass.apply_si(structure, {"mass": 0.004, "position": 0.07, "inertia": 0.0}),
                section.apply_si(structure, {"diameter_ratio": 0.8, "start": 0.03, "length": 0.04}),
                apply_path_si(structure, "joints.holder-tool.k.yf", 3e7),
                apply_path_si(structure, "sensors.acc.mass", 0.005)]
    calls = []
    couple = _kernels.couple_link
    monkeypatch.setattr(_kernels, "couple_link", lambda *a: calls.append(1) or couple(*a))
    fresh = [Evaluator(OUT, IN, F)(s) for s in variants]
    computed = len(calls)
    calls.clear()
    evaluator = Evaluator(OUT, IN, F)
    for order in (range(len(variants)), reversed(range(len(variants))), [1, 3, 1, 2, 0, 2]):
        for i in order:
            assert np.array_equal(evaluator(variants[i]), fresh[i]), i
    assert len(calls) < computed  # three times as many evaluations
    # a different mass where the memo holds a coupled cluster with the first one: not the stale numbers
    ref = tip_mass.apply(model, {"mass": 0.003, "position": 0.07, "inertia": 0.0}).frf(OUT, IN, F).data
    got = evaluator(tip_mass.apply_si(structure, {"mass": 0.003, "position": 0.07, "inertia": 0.0}))
    assert np.abs(got - ref).max() <= 1e-10 * np.abs(ref).max()


def test_the_structures_a_likelihood_keeps_give_what_applying_the_changes_gives(clean):
    """The structure after the same changes with the same values is kept between evaluations (the changes
    already added, during a scan): the same residuals, bit for bit, as a likelihood that applies every change
    every time, and a values dict changed in place after a call is not taken for the old values."""
    model = hd.nominal_model()
    measured = measured_frfs([_noisy(clean, 0.015, 0.5, 1e-3, 0)])[0]
    joint = ParameterChange(next(p for p in model_parameters(model) if p.path == "joints.holder-tool.k.yf"))
    section = SectionChange("tool", model.component("tool").length_m)
    body = AddedMass("tool", model.component("tool").length_m, 0.05, (0.0, model.component("tool").length_m), 1e-6)
    held = {"diameter_ratio": 0.8, "start": 0.03, "length": 0.04}
    lists = [[(section, held), (body, {"mass": m, "position": 0.05, "inertia": 0.0})] for m in (0.002, 0.004)]
    lists += [[(joint, {"value": 1.2e7}), (section, held)], [(section, held)], [(joint, {"value": 1.2e7})]]
    kept = Likelihood(model, measured)
    for changes in lists + lists[::-1]:
        assert np.array_equal(kept.residual(changes), Likelihood(model, measured).residual(changes))
    values = {"diameter_ratio": 0.8, "start": 0.03, "length": 0.04}
    first = kept.residual([(section, values)])
    values["diameter_ratio"] = 0.9  # the same dict, another value
    second = kept.residual([(section, values)])
    assert np.array_equal(second, Likelihood(model, measured).residual([(section, {**held, "diameter_ratio": 0.9})]))
    assert not np.array_equal(first, second)


def test_models_evaluated_together_give_what_each_gives_alone(clean, monkeypatch):
    """A scan's trials evaluated together (their lines side by side in one coupling) give the residuals of
    one-by-one evaluations bit for bit, the places of the trials alike or not; a model that cannot be evaluated
    raises the error the one-by-one evaluation raises, with the models before it counted."""
    model = hd.nominal_model()
    measured = measured_frfs([_noisy(clean, 0.015, 0.5, 1e-3, 1)])[0]
    joint = ParameterChange(next(p for p in model_parameters(model) if p.path == "joints.holder-tool.k.yf"))
    length = model.component("tool").length_m
    body = AddedMass("tool", length, 0.05, (0.0, length), 1e-6)
    held = [(SectionChange("tool", length), {"diameter_ratio": 0.8, "start": 0.03, "length": 0.04})]
    lists = [held + [(body, {"mass": m, "position": x, "inertia": 0.0})] for x in (0.02, 0.05) for m in (1e-3, 4e-3)]
    lists += [held + [(joint, {"value": v})] for v in (5e6, 1e7, 3e7)] + [[(joint, {"value": 2e7})], []]
    # the tool differs between these (the spindle and holder coupled once for all of them)
    lists += [[(held[0][0], {**held[0][1], "diameter_ratio": r}), (joint, {"value": 2e7})] for r in (0.7, 0.9, 1.1)]
    together = Likelihood(model, measured)
    from substructure.updating import evaluator as si_evaluator

    calls = []
    engine = si_evaluator.couple_substructures
    monkeypatch.setattr(si_evaluator, "couple_substructures", lambda *a, **k: calls.append(1) or engine(*a, **k))
    beams_at_once = []
    kernel = si_evaluator.stepped_beam_receptances_si
    monkeypatch.setattr(si_evaluator, "stepped_beam_receptances_si",
                        lambda sections, *a: beams_at_once.append(len(sections)) or kernel(sections, *a))
    got = together.residuals(lists)
    assert len(calls) <= 6  # together (not one by one after a failure): one call per layout of points and links
    assert beams_at_once and max(beams_at_once) >= 3  # the tools of one layout in one kernel call
    alone = Likelihood(model, measured)
    assert together.evaluations == len(lists)
    for changes, w in zip(lists, got):
        assert np.array_equal(w, alone.residual(changes))
    assert not np.array_equal(got[0], got[1]) and not np.array_equal(got[0], got[2])
    od = ParameterChange(next(p for p in model_parameters(model) if p.path == "components.tool.segments.0.od"))
    outside = held + [(od, {"value": -0.01})]  # a negative diameter
    with pytest.raises(InvalidValueError) as one:
        Likelihood(model, measured).residual(outside)
    counted = Likelihood(model, measured)
    with pytest.raises(type(one.value), match=re.escape(str(one.value))):
        counted.residuals(lists[:2] + [outside] + lists[2:])
    assert counted.evaluations == 3


def test_evolved_beams_sections_are_those_computed_from_scratch():
    """A beam evolved from another takes the sections of its unchanged segments from it: every section is the
    one its arrays give computed anew, to the bit (sizes, materials, flutes, inserts, lengths changed)."""
    from substructure import default_assembly
    from substructure.updating.structure import Structure, _segment_sections

    structure = Structure.from_assembly(default_assembly())
    rng = np.random.default_rng(0)
    for beam in structure.beams.values():
        beam.sections()
        m = beam.od.size
        for k in range(40):
            row = np.arange(m) == rng.integers(m)
            change = [{"od": beam.od * np.where(row, 1.0 + 0.1 * rng.normal(), 1.0)},
                      {"material": beam.material * np.where(row[:, None], 1.0 + 0.1 * rng.random(4), 1.0)},
                      {"length": beam.length * 1.1},
                      {"ratio": np.where(row, 0.8, beam.ratio)},
                      {"insert": beam.insert * np.where(row[:, None], 1.0 + 0.01 * rng.random(6), 1.0)}][k % 5]
            evolved = beam.evolve(**change)
            got = evolved.sections()
            fresh = _segment_sections(evolved.od, evolved.ratio, evolved.id, evolved.material, evolved.insert)
            assert all(np.array_equal(g, f) for g, f in zip(got, fresh)), change
            assert not got[0].flags.writeable  # shared between beams: never changed in place
