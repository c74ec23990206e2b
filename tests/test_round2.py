"""Nothing silently wrong, round two: each case a tester or a user found, with the input they used.

The diagnosis of a tool whose fluted tip is thinner than the model must not
turn its own trial values into the user's error; parameter paths refuse
what they do not name; the suspension springs honour the order of the ends
named; a resumed study refuses or recomputes a result file it cannot trust;
names with control characters or dollar signs reach the report page and the
figures as plain text; a title that is not UTF-8 is cleaned where it enters;
an interrupted study says so in one line.
"""

from __future__ import annotations

import re

import attrs
import numpy as np
import pytest

import hidden_data as hd
from substructure import Flutes, Segment, Sensor, Support, save_assembly
from substructure.cli import main
from substructure.diagnose import diagnose
from substructure.synthetic import simulate, write_measurement_set


# -- the diagnosis never turns its own trials into the user's error ------------------------------------------


def _thin_tip(model, diameter: str = "9.6 mm", length: float = 0.030):
    """The model's tool with its last ``length`` an equivalent cylinder of ``diameter`` (a fluted tip)."""
    tool = model.component("tool")
    keep = tool.length_m - length
    segments = [Segment(f"{keep * 1e3!r} mm", "12 mm", material="carbide"),
                Segment(f"{length * 1e3!r} mm", diameter, material="carbide")]
    return model.with_component(attrs.evolve(tool, segments=segments))


def test_a_thinner_tool_tip_is_diagnosed_not_refused_as_a_unit_error(tmp_path, capsys):
    """The bench of the report: the fitted fluted length lay within a micrometre of the 46 mm step."""
    model = hd.nominal_model()
    taps = simulate(_thin_tip(model), ["tool.tip"], frequency=hd.GRID, noise=0.015, seed=0, name="tap")
    write_measurement_set(taps, tmp_path)
    save_assembly(model, tmp_path / "model.toml")
    code = main(["diagnose", str(tmp_path / "model.toml"), str(tmp_path / "measurements.toml"), "--quiet",
                 "--save-model", str(tmp_path / "improved.toml")])
    out, err = capsys.readouterr()
    assert code == 0, err
    assert "fluted-section at tool" in out and "check the unit" not in err
    from substructure import load_assembly

    tool = load_assembly(tmp_path / "improved.toml").component("tool")
    assert min(s.length_m for s in tool.segments) >= 1e-6  # no sliver cut at the step
    assert tool.length_m == pytest.approx(model.component("tool").length_m, abs=1e-9)


def test_flutes_cut_near_a_step_leave_no_sliver():
    """A fluted length within a micrometre of a segment's end cuts at that end (the beam model holds >= 1 um)."""
    from substructure.diagnose.catalogue import flute_tip

    tool = hd.nominal_model().component("tool")  # 46 mm + 30 mm
    for length in (0.030 + 3.7e-7, 0.030 - 3.7e-7, 0.076 - 2e-7):
        cut = flute_tip(tool, length, 0.8)
        assert min(s.length_m for s in cut.segments) >= 1e-6
        assert cut.length_m == pytest.approx(0.076, abs=1e-12)
        fluted = sum(s.length_m for s in cut.segments if s.flutes is not None)
        assert fluted == pytest.approx(length, abs=1e-6)
    cut = flute_tip(tool, 0.010, 0.7)  # an ordinary cut inside the last segment
    assert [round(s.length_m * 1e3, 9) for s in cut.segments] == [46.0, 20.0, 10.0]
    assert [s.flutes for s in cut.segments] == [None, None, Flutes(0.7)]


def test_a_fit_steps_back_from_a_trial_the_model_refuses():
    """A trial value a library check refuses is a large misfit inside the fit, not an error of the fit."""
    from substructure.updating.fit import INFEASIBLE, fit
    from substructure.updating.likelihood import Likelihood, measured_frfs
    from substructure.updating.parameters import model_parameters, parameter_change

    model = hd.nominal_model()
    truth = model.with_joint(model.joint("holder-tool").with_parameters(k={"yf": "1e7 N/m", "tm": "8e4 N*m/rad"}))
    taps = simulate(truth, ["tool.tip"], frequency=hd.GRID, noise=0.01, seed=1)
    measured, _ = measured_frfs(taps)
    lik = Likelihood(model, measured).subsample(4)
    param = next(p for p in model_parameters(model) if p.path == "joints.holder-tool.k.yf")
    change = parameter_change(param)
    refused = []

    class Picky(type(change)):
        """The same change, refusing the first two steps toward the truth as a library check would."""

        def apply_si(self, structure, values):
            if values["value"] < 2e7 and len(refused) < 2:
                refused.append(values["value"])
                raise ValueError("length: got '2.23e-07 m'; expected a length from 1 um to 1 km")
            return super().apply_si(structure, values)

    result = fit(lik, [(Picky(param), {"value": 3e7})])
    assert len(refused) == 2  # the optimiser did try values the model refused, and went on
    assert result.changes[0][1]["value"] == pytest.approx(1e7, rel=0.05)
    assert result.chi2 < INFEASIBLE


_EFFECTS = ("thin-tip", "sensor", "joint", "springs", "overhang", "neck", "material")


def _hidden(model, rng):
    """The model with one or two random hidden effects (the truth a tap test measures)."""
    truth = model
    for kind in rng.choice(_EFFECTS, size=int(rng.integers(1, 3)), replace=False):
        if kind == "thin-tip":
            truth = _thin_tip(truth, f"{float(rng.uniform(8.0, 11.9))!r} mm", float(rng.uniform(0.005, 0.045)))
        elif kind == "sensor":
            truth = truth.attach(Sensor("acc", "tool.tip", f"{float(rng.uniform(0.5, 8.0))!r} g", always_on=True))
        elif kind == "joint":
            j = truth.joint("holder-tool")
            truth = truth.with_joint(j.with_parameters(k={"yf": f"{1.43e7 * float(rng.uniform(0.3, 3.0))!r} N/m",
                                                          "tm": "8e4 N*m/rad"}))
        elif kind == "springs":
            k = f"{10 ** float(rng.uniform(3.0, 6.0))!r} N/m"
            for x in rng.uniform(0.01, 0.32, size=2).tolist():
                truth = truth.support(Support(f"spindle@{x * 1e3!r} mm", k={"yf": k}))
        elif kind == "overhang":
            tool = truth.component("tool")
            segs = list(tool.segments)
            segs[0] = attrs.evolve(segs[0], length=f"{segs[0].length_m * 1e3 + float(rng.uniform(-8.0, 8.0))!r} mm")
            truth = truth.with_component(attrs.evolve(tool, segments=segs))
        elif kind == "neck":
            tool = truth.component("tool")
            first, rest = tool.segments[0], tool.segments[1:]
            a = float(rng.uniform(0.002, 0.6 * first.length_m))
            b = float(rng.uniform(0.001, first.length_m - a - 0.001))
            neck = [attrs.evolve(first, length=f"{a * 1e3!r} mm"),
                    attrs.evolve(first, length=f"{b * 1e3!r} mm", od=f"{float(rng.uniform(7.0, 11.5))!r} mm"),
                    attrs.evolve(first, length=f"{(first.length_m - a - b) * 1e3!r} mm")]
            truth = truth.with_component(attrs.evolve(tool, segments=[*neck, *rest]))
        else:
            tool = truth.component("tool")
            hss = attrs.evolve(tool.segments[0].material, name="hss", E="210 GPa", rho="8100 kg/m^3", nu=0.29)
            truth = truth.with_component(attrs.evolve(tool, segments=[attrs.evolve(s, material=hss)
                                                                      for s in tool.segments]))
    return truth


@pytest.mark.robustness
@pytest.mark.parametrize("seed", range(12))
def test_the_diagnosis_of_random_hidden_effects_never_fails(seed):
    """Robustness: a dozen random benches (one or two hidden effects each) on small budgets; any exception fails."""
    rng = np.random.default_rng(1000 + seed)
    model = hd.nominal_model()
    taps = simulate(_hidden(model, rng), ["tool.tip", "holder.tip"], "tool.tip", frequency=hd.GRID.hz[::4],
                    noise=0.015, seed=seed)
    result = diagnose(model, taps, budget=150, max_steps=2)
    assert np.isfinite(result.baseline_error)


# -- parameter paths name what exists, or are refused with what does -------------------------------------------


@pytest.mark.parametrize("path, value, message", [
    ("components.tool.segments.-1.od", 0.01, "segment index of 'tool' '-1': valid indices are 0 to 1"),
    ("components.tool.segments.2.od", 0.01, "valid indices are 0 to 1"),
    ("joints.holder-tool.q.yf", 5.0, "unknown key 'q' after 'joints.holder-tool'; expected one of k, c"),
    ("materials.carbide.colour", 0.5, "unknown key 'colour' after 'materials.carbide'; expected one of E, nu, rho, "
                                      "loss_factor"),
    ("materials.carbide.e", 0.3, "unknown key 'e'"),
    ("joints.holder-tool.k.xx", 1.0, "unknown key 'xx' after 'joints.holder-tool.k'; expected one of yf, ym, tf, tm"),
    ("components.gremlin.segments.0.od", 0.01, "expected one of holder, spindle, tool"),
    ("components.tool.segments.0.banana", 0.01, "expected one of length, od, id"),
    ("components.tool.colour", 1.0, "expected one of segments, overhang, E"),
    ("components.tool.material.e", 1.0, "unknown key 'e' after 'components.tool.material'"),
    ("components.holder.overhang", 0.1, "'holder' has no overhang"),
    ("components.tool.segments.0.insert.od", 0.01, "segment 0 of 'tool' has no insert"),
    ("materials.unobtainium.E", 1e9, "materials of the parts: carbide, steel"),
    ("supports.0.k.yf", 1.0, "support index '0': there are none"),
    ("sensors.acc.mass", 0.001, "unknown key 'acc' after 'sensors'"),
    ("gremlins.x", 1.0, "not a parameter path"),
])
def test_a_path_naming_nothing_is_refused_with_the_keys_that_exist(path, value, message):
    from substructure import UnknownPointError, default_assembly
    from substructure.updating.parameters import set_parameters

    model = default_assembly()
    with pytest.raises(UnknownPointError, match=f"parameter {path!r}: .*" if "joint" in path else None) as caught:
        set_parameters(model, {path: value})
    assert message in str(caught.value) and f"parameter {path!r}" in str(caught.value)
    if "." in path.split(".", 1)[1]:  # reading names the same problem
        from substructure.updating.parameters import get_parameter

        with pytest.raises(UnknownPointError, match=re.escape(message)):
            get_parameter(model, path)


def test_a_valid_path_changes_what_it_names_and_nothing_else():
    from substructure import default_assembly
    from substructure.updating.parameters import set_parameters

    model = default_assembly()
    tool = model.component("tool")
    last = set_parameters(model, {"components.tool.segments.1.od": 0.0096}).component("tool")
    assert [s.od.m_as("m") for s in last.segments] == pytest.approx([tool.segments[0].od.m_as("m"), 0.0096])
    joint = set_parameters(model, {"joints.holder-tool.c.yf": 5.0}).joint("holder-tool")
    assert joint.c.values[0, 0] == 5.0 and joint.k.values[0, 0] == model.joint("holder-tool").k.values[0, 0]
    cross = set_parameters(model, {"joints.holder-tool.k.tf": 3e5}).joint("holder-tool")
    assert cross.k.values[0, 1] == cross.k.values[1, 0] == 3e5  # one number: tf sets ym as well
    carbide = set_parameters(model, {"materials.carbide.loss_factor": 0.01, "materials.carbide.E": 6e11})
    mat = carbide.component("tool").segments[0].material
    assert mat.name == "carbide" and carbide.component("holder").segments[2].insert.material == mat
    assert mat.loss_factor == 0.01 and mat.E.m_as("Pa") == 6e11


def test_the_si_form_refuses_the_same_paths():
    from substructure import UnknownPointError, default_assembly
    from substructure.updating.parameters import apply_path_si, model_parameters, parameter_change
    from substructure.updating.structure import Structure

    model = default_assembly()
    structure = Structure.from_assembly(model)
    for path in ("components.tool.segments.-1.od", "joints.holder-tool.k.xx", "materials.carbide.colour"):
        with pytest.raises(UnknownPointError, match="valid indices|unknown key"):
            apply_path_si(structure, path, 0.01)
    # tf and ym are one number on the SI form too: the same FRF as on the assembly
    from substructure.updating.parameters import set_parameters

    params = {p.path: p for p in model_parameters(model)}
    change = parameter_change(params["joints.holder-tool.k.ym"])
    a = apply_path_si(structure, "joints.holder-tool.k.tf", 1e5)
    b = change.apply_si(structure, {"value": 1e5})
    i, link_a = a.link(("joints", "holder-tool"))
    _, link_b = b.link(("joints", "holder-tool"))
    assert np.array_equal(link_a.K, link_b.K) and link_a.K[0, 1] == link_a.K[1, 0] == 1e5
    assert set_parameters(model, {"joints.holder-tool.k.tf": 1e5}).joint("holder-tool").k.values[1, 0] == 1e5


@pytest.mark.parametrize("path, value, what", [
    ("components.holder.segments.2.od", 0.011, "a bore as wide as the section"),  # the bore is 12 mm
    ("components.holder.segments.2.insert.od", 0.013, "an insert wider than its bore"),
    ("components.tool.segments.0.length", 5e-7, "a segment shorter than 1 um"),
    ("components.tool.segments.0.od", float("nan"), "a size that is not a finite number"),
    ("components.tool.overhang", 0.030, "a segment shorter than 1 um"),  # 46 mm + 30 mm fluted: 30 mm leaves none
])
def test_the_si_form_refuses_a_section_the_assembly_refuses(path, value, what):
    """So that a value a fit keeps always writes back to the assembly (a trial beyond it is infeasible)."""
    from substructure import InvalidValueError
    from substructure.updating.parameters import apply_path_si, set_parameters
    from substructure.updating.structure import Structure

    model = hd.nominal_model(flutes=(0.030, 0.8))
    with pytest.raises(InvalidValueError, match=f"parameter {re.escape(repr(path))}: the value makes {what}"):
        apply_path_si(Structure.from_assembly(model), path, value)
    with pytest.raises(Exception):
        set_parameters(model, {path: value})  # the assembly refuses it as well


# -- support springs honour the order of the ends named ------------------------------------------------------


def test_support_springs_measure_inset_from_the_first_end_named():
    from substructure import InvalidValueError
    from substructure.diagnose.effects import registry
    from substructure.points import parse_point
    from substructure.updating.evaluator import Evaluator
    from substructure.updating.structure import Structure

    springs = registry()["support-springs"]
    model = hd.nominal_model()
    length = model.component("spindle").length_m
    tip_first = springs("spindle.tip,spindle.base", k_yf=1e5, inset=0.1, inset_tip=0.3)
    base_first = springs("spindle.base,spindle.tip", k_yf=1e5, inset=0.3, inset_tip=0.1)
    placed = tip_first.apply(model)
    at = {s.name: model.component("spindle").position(parse_point(s.at)) for s in placed.supports}
    assert at == pytest.approx({"diagnosed-spindle-1": 0.9 * length, "diagnosed-spindle-2": 0.3 * length})
    f = hd.GRID.hz[::20]
    a = placed.frf(["tool.tip"], ["tool.tip"], f).data
    b = base_first.apply(model).frf(["tool.tip"], ["tool.tip"], f).data
    np.testing.assert_allclose(a, b, rtol=1e-10)  # the same two springs, named from the other end
    si = Evaluator(["tool.tip:y"], ["tool.tip:y"], f)(tip_first.apply_si(Structure.from_assembly(model)))
    np.testing.assert_allclose(si[:, 0, 0], a[:, 0, 0], rtol=1e-8)
    for where in ("spindle.tip,spindle.tip", "spindle.base", "spindle.base,holder.tip", "spindle.base,spindle.tip,x"):
        with pytest.raises(InvalidValueError, match="two ends of one component in either order"):
            springs(where, k_yf=1e5).apply(model)


# -- a resumed study trusts only whole result files ----------------------------------------------------------


@pytest.fixture(scope="module")
def finished_study(tmp_path_factory):
    pytest.importorskip("distributed")
    from study_files import write_study

    from substructure.study import Study

    folder = tmp_path_factory.mktemp("study")
    path = write_study(folder / "s", n=3)
    study = Study.from_file(path)
    whole = study.run(scheduler="serial", progress=False)
    return path, whole


def _copy_out(tmp_path, path):
    from substructure.study import Study

    out = tmp_path / "out"
    Study.from_file(path).run(scheduler="serial", out=out, progress=False)
    return out, sorted((out / "results").glob("*.json"))


@pytest.mark.parametrize("damage, message", [
    (lambda record: {**record, "rows": record["rows"] + record["rows"][:1]}, "3 rows for 2 cuts"),
    (lambda record: {k: v for k, v in record.items() if k != "rows"}, "no 'rows' list"),
    (lambda record: {**record, "rows": "none"}, "no 'rows' list"),
])
def test_resume_over_a_damaged_result_file_recomputes_it_and_says_so(finished_study, tmp_path, damage, message):
    import json

    import pandas as pd

    from substructure.errors import SubstructureWarning
    from substructure.study import Study

    path, whole = finished_study
    out, results = _copy_out(tmp_path, path)
    record = json.loads(results[1].read_text())
    results[1].write_text(json.dumps(damage(record)))
    for attempt in range(2):  # the second resume finds the file rewritten whole
        if attempt == 0:
            with pytest.warns(SubstructureWarning, match=f"{results[1].name}: {message}.*computed again"):
                table = Study.from_file(path).run(scheduler="serial", out=out, resume=True, progress=False)
        else:
            table = Study.from_file(path).run(scheduler="serial", out=out, resume=True, progress=False)
        assert len(table) == len(whole) == 2 * 4  # four combinations, two cuts: no row twice
        pd.testing.assert_frame_equal(table, whole, check_exact=True)


# -- names reach the page and the figures as plain text ------------------------------------------------------

ODD = "bench \x01\x0b\x1f\x7f $\\frac{1}{0}$ <b>&amp; \ud800 end"
"""A name with C0 controls, DEL, mathtext that does not parse, markup and a lone surrogate."""


def _no_mathtext(fig) -> list[str]:
    """The texts of a figure matplotlib would read as mathtext (none may be)."""
    from matplotlib.text import Text

    fig.canvas.draw()  # every text laid out: a mathtext error would raise here
    return [t.get_text() for t in fig.findobj(Text)  # tick labels are matplotlib's own mathtext (10^-9)
            if t.get_text() and not t.get_text().startswith("$\\mathdefault{") and t._preprocess_math(t.get_text())[1]]


def test_a_report_of_a_model_with_control_characters_in_its_name_is_xml():
    import xml.etree.ElementTree as ET

    from substructure import default_assembly
    from substructure.report import report

    model = attrs.evolve(default_assembly(), name=ODD)
    page = report(model).to_html()
    root = ET.fromstring(page.split("\n", 1)[1])  # XML 1.0: no control character, even escaped
    title = root.find("head/title").text
    assert title == "Tool report: bench \ufffd\ufffd\ufffd\ufffd $\\frac{1}{0}$ <b>&amp; \ufffd end"
    assert "<b>" not in page and page.encode("utf-8")  # markup escaped; the page encodes (no lone surrogate)


def test_names_with_dollar_signs_are_drawn_as_plain_text(tmp_path):
    import matplotlib.pyplot as plt

    from substructure import default_assembly
    from substructure._text import plain_text
    from substructure.stability import MillingCut, zoa
    from substructure.stability.plotting import plot_lobes

    assert plain_text("a $x$ \x07") == "a \\$x\\$ \ufffd"
    model = attrs.evolve(default_assembly(), name="cutter $\\frac{1}{0}$")
    frf = model.frf(["tool.tip"], ["tool.tip"], np.linspace(50.0, 5000.0, 200))
    fig = frf.plot(title=f"{model.name}: tool.tip", label="T$1$ \x01")
    assert _no_mathtext(fig) == []
    assert fig.get_suptitle().replace("\\$", "$") == "cutter $\\frac{1}{0}$: tool.tip"  # drawn as written
    plt.close(fig)
    cut = MillingCut.for_workpiece(4, "12 mm", "aluminium-7075", radial_depth="3 mm", feed_per_tooth="0.05 mm",
                                   milling="down")
    from substructure.stability import assembly_structure, spindle_speeds

    lobes = zoa(assembly_structure(model, "tool.tip:y", model.frequency)[0], cut,
                spindle_speeds("5000 rpm", "20000 rpm", "500 rpm")).with_label("$x$ lobes")
    fig = plot_lobes([lobes], title="Stability of $tool$")
    assert _no_mathtext(fig) == []
    plt.close(fig)
    save_assembly(model, tmp_path / "m.toml")
    code = main(["frf", str(tmp_path / "m.toml"), "--at", "tool.tip", "--plot", str(tmp_path / "frf.png")])
    assert code == 0 and (tmp_path / "frf.png").stat().st_size > 0


def test_a_study_with_dollar_signs_and_controls_in_its_names_draws_and_resumes(tmp_path, capsys):
    pytest.importorskip("distributed")
    from study_files import write_study

    odd = ('[[combinations]]\nname = "cutter $\\\\nosuchsymbol$ \\u0007"\n'
           'tool = { diameter = "12 mm", overhang = "70 mm", flute_length = "30 mm", teeth = 4 }\n'
           'joint = { k = { yf = "1.43e7 N/m" } }\n')
    path = write_study(tmp_path / "s", n=1, figures=True, extra_combinations=odd)
    out = tmp_path / "out"
    code = main(["study", str(path), "--out", str(out), "--scheduler", "serial", "--quiet"])
    err = capsys.readouterr().err
    assert code == 0, err
    assert (out / "summary.png").stat().st_size > 0 and len(list((out / "figures").glob("*.png"))) == 3
    code = main(["study", str(path), "--out", str(out), "--scheduler", "serial", "--quiet", "--resume"])
    assert code == 0, capsys.readouterr().err


def test_the_study_summary_figure_draws_names_as_plain_text():
    pytest.importorskip("pandas")
    from substructure.study.table import empty_row, make_table, summary_figure

    rows = []
    for i, (name, machine) in enumerate([("T$1$", "mill $a$"), ("T\x07$2", "mill $b$")]):
        row = empty_row()
        row.update(combination=name, machine=machine, cut="c$ut$", status="ok", key=f"k{i}",
                   spindle_speed_rpm=10000.0 + i, depth_m=1e-3 * (i + 1), tool_mode_hz=2000.0,
                   mrr_m3_per_s=1e-6 * (i + 1))
        rows.append(row)
    failed = empty_row()
    failed.update(combination="bad $x$", machine="mill $a$", cut="c$ut$", status="failed", key="k9", error="no")
    fig = summary_figure(make_table(rows + [failed]), title="study $s$: ranked")
    assert _no_mathtext(fig) == []


def test_a_latin1_title_is_cleaned_where_it_enters_and_the_page_is_written(tmp_path):
    """Bytes that are not UTF-8 on the command line (a Latin-1 terminal): U+FFFD, a warning, the page written."""
    import os
    import subprocess
    import sys
    from pathlib import Path

    from substructure import default_assembly

    save_assembly(default_assembly(), tmp_path / "m.toml")
    out = tmp_path / "r.html"
    argv = [os.fsencode(sys.executable), b"-m", b"substructure", b"report", os.fsencode(tmp_path / "m.toml"),
            b"--out", os.fsencode(out), b"--quiet", b"--title", b"Rapport d'\xe9t\xe9 \xa7 5"]
    root = Path(__file__).resolve().parents[1]
    env = {**os.environ, "MPLBACKEND": "Agg", "PYTHONPATH": str(root), "LC_ALL": "C.UTF-8", "PYTHONUTF8": "1"}
    done = subprocess.run(argv, capture_output=True, env=env, timeout=300)
    err = done.stderr.decode("utf-8", "replace")
    assert done.returncode == 0, err
    assert "warning: --title: bytes that are not UTF-8 (0xa7, 0xe9)" in err
    page = out.read_text(encoding="utf-8")
    assert "<title>Rapport d&#x27;\ufffdt\ufffd \ufffd 5</title>" in page
    assert "Rapport d'\ufffdt\ufffd \ufffd 5" in done.stdout.decode("utf-8")


# -- an interrupted study says so in one line ------------------------------------------------------------------


@pytest.mark.parametrize("quiet", [False, True])
def test_an_interrupted_study_says_what_is_saved_in_one_line(tmp_path, capsys, monkeypatch, quiet):
    """The main process's part: Ctrl-C after the first combination (the serial runner interrupted)."""
    pytest.importorskip("distributed")
    from study_files import write_study

    import substructure.study.runner as runner

    serial = runner._serial

    def interrupted(tasks):
        for k, done in enumerate(serial(tasks)):
            if k == 1:
                raise KeyboardInterrupt
            yield done

    monkeypatch.setattr(runner, "_serial", interrupted)
    path = write_study(tmp_path / "s", n=3)
    out = tmp_path / "out"
    code = main(["study", str(path), "--out", str(out), "--scheduler", "serial", *(["--quiet"] if quiet else [])])
    err = capsys.readouterr().err
    assert code == 130
    lines = [line for line in err.splitlines() if "interrupted" in line]
    assert lines == [f"{'substructure' if quiet else 'study'}: interrupted: 1 of 4 combinations saved in {out}; "
                     "--resume (resume=True) to continue"], err
    assert "Traceback" not in err and len(list((out / "results").glob("*.json"))) == 1


def test_ctrl_c_on_a_process_cluster_prints_no_worker_traceback(tmp_path):
    """SIGINT to the whole process group, as a terminal's Ctrl-C: the workers ignore it, the command says one line."""
    pytest.importorskip("distributed")
    import os
    import signal
    import subprocess
    import sys
    import time
    from pathlib import Path

    from study_files import write_study

    path = write_study(tmp_path / "s", n=8, figures=True)
    out = tmp_path / "out"
    root = Path(__file__).resolve().parents[1]
    env = {**os.environ, "MPLBACKEND": "Agg", "PYTHONPATH": f"{root}{os.pathsep}{root / 'tests'}"}
    process = subprocess.Popen([sys.executable, "-m", "substructure", "study", str(path), "--out", str(out),
                                "--scheduler", "processes:2"], env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                               text=True, start_new_session=True)
    start = time.monotonic()
    while time.monotonic() - start < 240 and process.poll() is None:
        if (out / "results").is_dir() and any((out / "results").glob("*.json")):
            break
        time.sleep(0.05)
    os.killpg(process.pid, signal.SIGINT)
    _, err = process.communicate(timeout=180)
    if process.returncode == 0:
        pytest.skip("the study finished before the signal")
    assert process.returncode == 130, err
    assert "Traceback" not in err and "KeyboardInterrupt" not in err, err
    lines = [line for line in err.splitlines() if "interrupted" in line]
    assert len(lines) == 1 and "combinations saved in" in lines[0] and "--resume" in lines[0], err
