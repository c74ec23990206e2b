"""Component types of one's own in every workflow: a chuck with a nut (a beam with physics of its own) and a
lumped chuck (not a beam at all), tests/custom_components.py.

The model's one representation: the numbers a type adds are model parameters by path
(``components.NAME.FIELD``), set on the object by the same setter for the assembly and for the SI form the
fits evaluate; bodies and springs sit along any beam.  Checked against independent paths (the engine's own
coupling of a ``Mass``), on the independent FE rig (a heavier nut found as itself, at the cost of the built-in
equivalent in evaluations), and through the command line (frf, lobes, diagnose, report, predict with the
type registered as a plugin would).
"""

from __future__ import annotations

import json
import re

import numpy as np
import pytest

import hidden_data as hd
from custom_components import LumpedChuck, NutChuck
from substructure import FRF, Assembly, Frequency, Joint, Mass, default_assembly, register_component
from substructure.cli import main
from substructure.components import COMPONENT_TYPES, ComponentParameter, own_parameters
from substructure.diagnose import diagnose
from substructure.errors import InvalidValueError, UnknownPointError
from substructure.io.assembly_toml import dumps_assembly, loads_assembly, save_assembly
from substructure.sweep import sweep
from substructure.synthetic import simulate, write_measurement_set
from substructure.updating import AddedMass, Evaluator, Structure, model_parameters, set_parameters
from substructure.updating.paths import apply_path_si

F = Frequency.from_range("50 Hz", "5000 Hz", "10 Hz")
OUT = ("tool.tip:y", "tool.tip:theta", "holder.tip:y")
IN = ("tool.tip:y",)


@pytest.fixture
def registered():
    """The two types registered for one test (as a plugin would), the registry restored afterwards."""
    saved = dict(COMPONENT_TYPES)
    register_component("test-nut-chuck")(NutChuck)
    register_component("test-lumped-chuck")(LumpedChuck)
    yield
    COMPONENT_TYPES.clear()
    COMPONENT_TYPES.update(saved)


def _chuck(model: Assembly, grams: float) -> Assembly:
    return model.with_component(NutChuck("holder", model.component("holder").segments, nut_mass=f"{grams} g"))


def _plain(model: Assembly, grams: float) -> Assembly:
    return model.attach(Mass("nut", "holder.tip", f"{grams} g"))


def test_the_numbers_a_type_adds_are_parameters_by_path():
    model = _chuck(default_assembly(), 150)
    params = {p.path: p for p in model_parameters(model)}
    nut = params["components.holder.nut_mass"]
    assert (nut.unit, nut.nominal, nut.lower, nut.upper, nut.log) == ("kg", pytest.approx(0.15),
                                                                      pytest.approx(0.015), pytest.approx(1.5), True)
    assert "components.holder.nut_inertia" not in params  # zero: no scale to search on
    assert "components.holder.segments.2.length" in params  # its segments' numbers as any holder's
    # set by path: the same FRF as a plain holder with the nut as a Mass (the engine's own coupling)
    for grams in (90.0, 400.0):
        got = set_parameters(model, {"components.holder.nut_mass": grams / 1e3})
        assert got.component("holder").nut_mass.m_as("g") == pytest.approx(grams)
        np.testing.assert_allclose(got.frf(OUT, IN, F).data, _plain(default_assembly(), grams).frf(OUT, IN, F).data,
                                   rtol=1e-9)


def test_the_si_form_and_the_assembly_are_changed_by_one_setter():
    model = _chuck(default_assembly(), 150)
    structure, evaluate = Structure.from_assembly(model), Evaluator(OUT, IN, F.hz)
    assert "holder" in structure.opaque
    for path, value in (("components.holder.nut_mass", 0.3), ("components.holder.segments.2.length", 0.045),
                        ("components.holder.segments.0.od", 0.06), ("components.holder.E", 0.9),
                        ("components.holder.bore", 0.004), ("joints.holder-tool.k.yf", 2e7)):
        changed = set_parameters(model, {path: value})
        np.testing.assert_allclose(evaluate(apply_path_si(structure, path, value)), changed.frf(OUT, IN, F).data,
                                   rtol=1e-9, err_msg=path)
        if path != "components.holder.nut_mass":  # the nut kept through a change of the segments
            assert changed.component("holder").nut_mass.m_as("g") == pytest.approx(150)
    # the bore of the chuck's own part; a tool's bore reaches the shank the chuck holds
    bored = set_parameters(model, {"components.tool.bore": 0.003})
    assert bored.component("holder").segments[2].insert.id.m_as("mm") == pytest.approx(3)
    np.testing.assert_allclose(evaluate(apply_path_si(structure, "components.tool.bore", 0.003)),
                               bored.frf(OUT, IN, F).data, rtol=1e-9)


def test_a_body_sits_along_a_beam_of_any_type():
    model = _chuck(default_assembly(), 150)
    body = AddedMass("holder", model.component("holder").length_m, 1.0, (0.0, 0.066), 1e-3)
    evaluate = Evaluator(OUT, IN, F.hz)
    got = evaluate(body.apply_si(Structure.from_assembly(model), {"mass": 0.2, "inertia": 1e-5, "position": 0.03}))
    truth = model.attach(Mass("ring", "holder@30 mm", "200 g", inertia="1e-5 kg*m^2"))
    np.testing.assert_allclose(got, truth.frf(OUT, IN, F).data, rtol=1e-9)


def test_wrong_parameters_are_refused_where_they_enter():
    model = _chuck(default_assembly(), 150)
    with pytest.raises(UnknownPointError, match="nut_mas.*expected one of.*nut_mass"):
        set_parameters(model, {"components.holder.nut_mas": 0.2})
    lumped = default_assembly().with_component(LumpedChuck("holder"))
    with pytest.raises(UnknownPointError, match="not a stepped beam.*nose_mass, k_y, k_theta"):
        set_parameters(lumped, {"components.holder.segments.0.od": 0.05})
    with pytest.raises(InvalidValueError, match="nominal"):
        ComponentParameter("m", "kg", 2.0, 0.1, 1.0)

    class Broken(LumpedChuck):
        def parameters(self):
            raise RuntimeError("no table")

    broken = default_assembly().with_component(Broken("holder"))
    with pytest.raises(InvalidValueError, match=r"component 'holder': its parameters\(\) failed .*no table"):
        model_parameters(broken)

    class Wrong(LumpedChuck):
        def parameters(self):
            return ("nose_mass",)

    with pytest.raises(InvalidValueError, match="must give ComponentParameter entries"):
        model_parameters(default_assembly().with_component(Wrong("holder")))
    with pytest.raises(InvalidValueError, match="lower > 0"):
        ComponentParameter("m", "kg", 0.5, 0.0, 1.0)
    with pytest.raises(InvalidValueError, match="expected a value >= 0"):
        set_parameters(model, {"components.holder.nut_mass": -0.1})
    for value in (None, "0.2", True):  # not a number: refused where it enters, for every path
        with pytest.raises(InvalidValueError, match="expected a number"):
            set_parameters(model, {"components.holder.nut_mass": value})
    with pytest.raises(InvalidValueError, match="finite"):
        set_parameters(model, {"components.holder.nut_mass": float("nan")})


@pytest.fixture(scope="module")
def nut_on_the_rig():
    """The FE rig with a 350 g nut on the holder's tip; the model says 150 g, once as a chuck type of one's own,
    once as a plain holder with a Mass."""
    frfs = hd.measure(seed=5, nut=(0.35, 0.0, 0.066))
    nominal = hd.nominal_model()
    return frfs, diagnose(_chuck(nominal, 150), frfs), diagnose(_plain(nominal, 150), frfs)


def test_a_heavier_nut_on_a_chuck_of_ones_own_is_found_as_itself(nut_on_the_rig):
    _, custom, builtin = nut_on_the_rig
    assert custom.explained and builtin.explained, custom.report
    assert [e.where for e in custom.effects] == ["components.holder.nut_mass"], [repr(e) for e in custom.effects]
    assert [e.where for e in builtin.effects] == ["masses.nut.mass"]
    assert custom.effects[0].values["value"] == pytest.approx(0.35, rel=0.05)
    assert custom.effects[0].values["value"] == pytest.approx(builtin.effects[0].values["value"], rel=1e-3)
    # as fast as the built-in equivalent, counted in model evaluations (the time is make bench's)
    assert custom.search["evaluations"] <= 1.5 * builtin.search["evaluations"]
    assert custom.search["candidates"] <= builtin.search["candidates"] + 2


def test_a_lighter_nut_than_the_model_says_is_found_too():
    """The neighbouring case: 80 g on the rig where the model says 150 g (a change downwards)."""
    d = diagnose(_chuck(hd.nominal_model(), 150), hd.measure(seed=11, nut=(0.08, 0.0, 0.066)))
    assert d.explained and [e.where for e in d.effects] == ["components.holder.nut_mass"], d.report
    assert d.effects[0].values["value"] == pytest.approx(0.08, rel=0.05)


def test_the_model_it_saves_keeps_the_type_and_predicts_the_rotations(nut_on_the_rig, registered):
    _, custom, _ = nut_on_the_rig
    saved = custom.refined_assembly
    assert isinstance(saved.component("holder"), NutChuck)
    again = loads_assembly(dumps_assembly(saved))
    assert again.component("holder").nut_mass.m_as("kg") == pytest.approx(0.35, rel=0.05)
    truth = _plain(hd.nominal_model(), 350)
    grid = Frequency.from_range("20 Hz", "5000 Hz", "4 Hz")

    def error(model):
        a = model.frf(["tool.tip:theta"], ["tool.tip:theta"], grid).data
        return float(np.sqrt(np.mean(np.log(np.abs(a / truth.frf(["tool.tip:theta"], ["tool.tip:theta"],
                                                                  grid).data)) ** 2)))

    assert error(again) < 0.2 * error(_chuck(hd.nominal_model(), 150))


def _lumped_model(**changes) -> Assembly:
    model = default_assembly()
    return model.with_component(LumpedChuck("holder", **changes))


def test_a_lumped_chuck_is_a_component_like_any_other():
    """Its FRF by the assembly, by the SI form and by sweeps agree; its own parameters by path."""
    from substructure import sweep

    model = _lumped_model()
    assert {p.name for p in own_parameters(model.component("holder"))} == {"nose_mass", "k_y", "k_theta"}
    direct = model.frf(OUT, IN, F).data
    np.testing.assert_allclose(Evaluator(OUT, IN, F.hz)(Structure.from_assembly(model)), direct, rtol=1e-10)
    heavier = set_parameters(model, {"components.holder.nose_mass": 0.6})
    np.testing.assert_allclose(heavier.frf(OUT, IN, F).data, _lumped_model(nose_mass=0.6).frf(OUT, IN, F).data,
                               rtol=1e-12)
    swept = sweep([model, heavier], "tool.tip:y", frequency=F)
    np.testing.assert_allclose(swept[1].data[:, 0, 0], heavier.frf(["tool.tip:y"], IN, F).data[:, 0, 0], rtol=1e-9)
    # the lumped model's static check: the nose mass's mode moves down as the mass goes up
    assert np.argmax(np.abs(heavier.frf(["tool.tip:y"], IN, F).data[:, 0, 0])) <= np.argmax(np.abs(direct[:, 0, 0]))


def test_a_lumped_chuck_through_every_command(tmp_path, registered, capsys):
    model, truth = _lumped_model(), _lumped_model(nose_mass=0.55)
    save_assembly(model, tmp_path / "model.toml")
    save_assembly(truth, tmp_path / "truth.toml")
    grid = Frequency.from_range("20 Hz", "5000 Hz", "10 Hz")
    data = simulate(truth, ["tool.tip", "tool.tip-20 mm"], frequency=grid, noise=0.01, seed=3)
    taps = write_measurement_set(data, tmp_path / "taps")
    out = tmp_path / "out"
    out.mkdir()
    model_file = str(tmp_path / "model.toml")
    assert main(["frf", model_file, "--at", "tool.tip", "--out", str(out / "frf.csv")]) == 0
    np.testing.assert_allclose(FRF.from_csv(out / "frf.csv").data[:, 0, 0],
                               model.frf(["tool.tip:y"], ["tool.tip:y"], FRF.from_csv(out / "frf.csv").frequency)
                               .data[:, 0, 0], rtol=1e-6)
    assert main(["lobes", "--assembly", model_file, "--at", "tool.tip", "--teeth", "4", "--diameter", "12 mm",
                 "--radial-depth", "3 mm", "--kt", "625 MPa", "--kn", "100 MPa", "--plot", str(out / "lobes.png")]) == 0
    capsys.readouterr()
    code = main(["diagnose", model_file, str(taps), "--json", "--quiet", "--save-model", str(out / "fixed.toml")])
    text = capsys.readouterr().out
    assert code == 0, text
    found = json.loads(text)
    assert found["explained"] and [e["where"] for e in found["final_effects"]] == ["components.holder.nose_mass"], text
    fixed = loads_assembly((out / "fixed.toml").read_text())
    assert fixed.component("holder").nose_mass == pytest.approx(0.55, rel=0.02)
    assert main(["report", model_file, str(taps), "--out", str(out / "report.html")]) == 0
    assert (out / "report.html").stat().st_size > 10_000


def test_a_lumped_chuck_joint_is_identified_through_it():
    """identify: the holder-tool joint behind a lumped chuck, from taps on the model with the joint changed."""
    from substructure.identify import identify_joint

    model = _lumped_model()
    truth = set_parameters(model, {"joints.holder-tool.k.yf": 2.0e7})
    grid = Frequency.from_range("20 Hz", "5000 Hz", "4 Hz")
    data = simulate(truth, ["tool.tip", "tool.tip-20 mm"], frequency=grid, noise=0.005, seed=4)
    result = identify_joint(model, data, "holder-tool", parameters=("k_yf",))
    assert result.k["yf"] == pytest.approx(2.0e7, rel=0.03)


def test_a_type_that_cannot_take_part_is_refused_with_what_it_lacks():
    from substructure.errors import SubstructureError

    class NoPoints:
        name = "holder"
        component_names = ("holder",)

    with pytest.raises(SubstructureError, match="not a component .it has no 'node_key'"):
        Assembly("x", components=(default_assembly().component("spindle"), NoPoints()),
                 joints=(Joint("j", ("spindle.tip", "holder.base"), rigid=True),))


def _broken(kind, what):
    """A chuck (or a joint model) of one's own whose receptances (dynamic stiffness) break the protocol."""
    import attrs

    from custom_components import HystereticJoint

    def broken(h):
        if kind == "raises":
            raise KeyError("nut")
        if kind == "shape":
            return h[:, :, :-1]
        h = h.copy()
        h[..., 2] = np.nan  # one line of the band
        return h

    @attrs.frozen
    class Broken(NutChuck):
        def receptance_matrix(self, refs, frequency_hz):
            return broken(super().receptance_matrix(refs, frequency_hz))

    @attrs.frozen
    class BrokenJoint(HystereticJoint):
        def dynamic_stiffness(self, frequency_hz):
            return broken(super().dynamic_stiffness(frequency_hz))

    model = default_assembly()
    if what == "component":
        return model.with_component(Broken("holder", model.component("holder").segments)), "component 'holder' (Broken)"
    joint = model.joint("holder-tool")
    return model.with_joint(BrokenJoint(joint.name, joint.between, k=joint.k.as_dict(), c=joint.c.as_dict())), \
        "joint 'holder-tool' (BrokenJoint)"


@pytest.mark.parametrize("what, member, rows", [("component", "receptance_matrix", 4),
                                                ("joint", "dynamic_stiffness", 2)])
@pytest.mark.parametrize("kind, message", [
    ("raises", r"{member} failed \(KeyError: 'nut'\)"),
    ("shape", r"{member} gave an array of shape \({rows}, {rows}, 4\); expected \({rows}, {rows}, 5\)"),
    ("nan", r"{member} gave values that are not finite on 1 of 5 lines \(the first at 300 Hz\)"),
])
def test_a_type_breaking_the_protocol_is_named_where_its_arrays_enter(kind, message, what, member, rows):
    model, who = _broken(kind, what)
    message = re.escape(who) + ": " + message.format(member=member, rows=rows)
    grid = Frequency.from_hz([100.0, 200.0, 300.0, 400.0, 500.0])
    with pytest.raises(InvalidValueError, match=message):  # the FRF of the assembly
        model.frf("tool.tip", "tool.tip", grid)
    with pytest.raises(InvalidValueError, match=message):  # the prepared FRF of sweeps and fits
        model.prepare("tool.tip", frequency=grid).evaluate()
    with pytest.raises(InvalidValueError, match=message):  # a sweep of variants
        sweep([model, model], "tool.tip", frequency=grid)
    with pytest.raises(InvalidValueError, match=message):  # the SI form's evaluator (diagnosis, identification)
        Evaluator(["tool.tip"], ["tool.tip"], grid.hz)(Structure.from_assembly(model))


def test_a_chuck_of_ones_own_in_a_study(tmp_path, registered):
    """study: a machine whose holder is the custom chuck; a heavier nut moves its tool-point mode down."""
    from study_files import write_study
    from substructure.study import Study

    for grams in (150, 900):
        save_assembly(_chuck(default_assembly(), grams), tmp_path / f"chuck{grams}.toml")
    machines = "".join(f'\n[[machines]]\nname = "chuck{g}"\nassembly = "{tmp_path / f"chuck{g}.toml"}"\n'
                       for g in (150, 900))
    combos = "".join(f'\n[[combinations]]\nname = "on chuck{g}"\nmachines = ["chuck{g}"]\n'
                     'tool = { diameter = "12 mm", overhang = "76 mm", flute_length = "30 mm", teeth = 4 }\n'
                     'joint = { k = { yf = "1.43e7 N/m" } }\n' for g in (150, 900))
    path = write_study(tmp_path / "s", n=1, extra_machines=machines, extra_combinations=combos)
    text = path.read_text().replace("combinations_csv", "#")
    path.write_text(text.replace('name = "explicit 12 mm"', 'name = "explicit 12 mm"\nmachines = ["bench"]'))
    table = Study.from_file(path).run(scheduler="serial", progress=False)
    assert (table["status"] == "ok").all(), table[["combination", "cut", "error"]]
    rows = {c: table[table["combination"] == c].iloc[0] for c in ("on chuck150", "on chuck900")}
    modes = {c: r["tool_mode_hz"] for c, r in rows.items()}
    assert modes["on chuck900"] < modes["on chuck150"], modes


def _hysteretic(model: Assembly, eta: float) -> Assembly:
    from custom_components import HystereticJoint

    j = model.joint("holder-tool")
    return model.with_joint(HystereticJoint(j.name, j.between, k=j.k, c=j.c, loss_factor=eta))


def test_a_joint_model_of_ones_own_has_its_numbers_by_path_too():
    model = _hysteretic(default_assembly(), 0.02)
    params = {p.path: p for p in model_parameters(model)}
    assert params["joints.holder-tool.loss_factor"].nominal == pytest.approx(0.02)
    assert "joints.holder-tool.k.yf" in params
    structure, evaluate = Structure.from_assembly(model), Evaluator(OUT, IN, F.hz)
    for path, value in (("joints.holder-tool.loss_factor", 0.1), ("joints.holder-tool.k.yf", 2e7),
                        ("joints.holder-tool.k", 0.5)):
        changed = set_parameters(model, {path: value})
        np.testing.assert_allclose(evaluate(apply_path_si(structure, path, value)), changed.frf(OUT, IN, F).data,
                                   rtol=1e-9, err_msg=path)
    assert set_parameters(model, {"joints.holder-tool.loss_factor": 0.1}).joint("holder-tool").loss_factor == 0.1


def test_a_hysteretic_joint_is_diagnosed_in_its_own_terms():
    """The FE rig's holder-tool joint with a loss factor of 0.08 (damping that does not grow with frequency);
    the model's hysteretic joint says 0.02: found as its own loss factor."""
    frfs = hd.measure(seed=8, ht_loss=0.08)
    d = diagnose(_hysteretic(hd.nominal_model(), 0.02), frfs)
    assert d.explained, d.report
    assert [e.where for e in d.effects] == ["joints.holder-tool.loss_factor"], [repr(e) for e in d.effects]
    assert d.effects[0].values["value"] == pytest.approx(0.08, rel=0.1)
