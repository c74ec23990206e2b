"""Study guards: combinations whose numbers would be silently wrong fail or are flagged with their reason.

A joint override that makes the structure non-passive, a tool whose first
mode lies below the frequency grid, a tool wider than the machine holder's
bore; results of another study or edited by hand in the output directory.
"""

from __future__ import annotations

import io
import json

import attrs
import pytest

from substructure.errors import OutputExistsError


from substructure.study import Combination, Compute, Cut, Grid, Machine, Study

GRID = Grid(frequency=("100 Hz", "5000 Hz", "10 Hz"), speeds=("5000 rpm", "20000 rpm", "200 rpm"))
CUT = Cut("alu", workpiece="aluminium-7075", radial_depth="3 mm", milling="down", feed_per_tooth="0.05 mm")
TOOL = {"diameter": "12 mm", "overhang": "76 mm", "flute_length": "30 mm", "teeth": 4}


def _study(combos, grid=GRID, name="guards") -> Study:
    return Study(name, [Machine("bench", limits={"max_speed": "20000 rpm"})], combos, [CUT], Compute(figures=False),
                 grid)


def _rows(table) -> dict:
    return {c: (s, e) for c, s, e in zip(table["combination"], table["status"], table["error"])}


def test_a_joint_override_that_is_not_passive_fails_its_row_naming_the_entry_and_value():
    combos = [Combination("good", tool=TOOL, joint={"k": {"yf": "1.43e7 N/m"}}),
              Combination("negative k", tool=TOOL, joint={"k": {"yf": "-1e7 N/m"}}),
              Combination("zero k", tool=TOOL, joint={"k": {"tm": "0 N*m/rad"}}),
              Combination("negative c", tool=TOOL, joint={"k": {"yf": "1.43e7 N/m"}, "c": {"yf": "-500 N*s/m"}}),
              Combination("zero c", tool=TOOL, joint={"k": {"yf": "1.43e7 N/m"}, "c": {"yf": "0 N*s/m"}})]
    table = _study(combos).run(scheduler="serial", progress=False)
    rows = _rows(table)
    assert rows["good"][0] == "ok" and rows["zero c"][0] == "ok"
    for name, entry, value in (("negative k", "joint.k.yf", "'-1e7 N/m'"), ("zero k", "joint.k.tm", "'0 N*m/rad'"),
                               ("negative c", "joint.c.yf", "'-500 N*s/m'")):
        status, error = rows[name]
        assert status == "failed", (name, error)
        assert f"combination {name!r}" in error and f"{entry}: got {value}" in error and "not passive" in error
    failed = table[table["status"] == "failed"]
    assert failed["depth_m"].isna().all() and failed["spindle_speed_rpm"].isna().all()


def test_a_non_passive_joint_in_the_csv_names_the_file_line_and_column(tmp_path):
    (tmp_path / "lib.csv").write_text("name,tool.diameter [mm],tool.overhang [mm],tool.flute_length [mm],"
                                      "tool.teeth,joint.k.yf [N/m],joint.c.yf [N*s/m]\n"
                                      "A,12,76,30,4,1.43e7,\nnegc,12,76,30,4,1.43e7,-500\n")
    (tmp_path / "study.toml").write_text(STUDY_TOML)
    table = Study.from_file(tmp_path / "study.toml").run(scheduler="serial", progress=False)
    rows = _rows(table)
    assert rows["A"][0] == "ok"
    assert rows["negc"][0] == "failed"
    assert "lib.csv, line 3" in rows["negc"][1] and "joint.c.yf: got '-500 N*s/m'" in rows["negc"][1]


STUDY_TOML = """\
name = "probe"
combinations_csv = "lib.csv"

[grid]
frequency = { start = "100 Hz", stop = "5000 Hz", step = "10 Hz" }
speeds = { start = "5000 rpm", stop = "20000 rpm", step = "200 rpm" }

[compute]
figures = false

[[machines]]
name = "bench"
limits = { max_speed = "20000 rpm", power = "11 kW" }

[[cuts]]
name = "alu"
workpiece = "aluminium-7075"
radial_depth = "3 mm"
milling = "down"
feed_per_tooth = "0.05 mm"
"""


def _tool(diameter: int, overhang: int) -> dict:
    return {"diameter": f"{diameter} mm", "overhang": f"{overhang} mm", "flute_length": "30 mm", "teeth": 4}


def test_a_tool_whose_first_mode_lies_below_the_grid_fails_saying_the_grid_must_start_lower():
    """A 12 mm tool 2 m out (first mode near 9 Hz) on a grid from 100 Hz; the usual tools are not touched."""
    joint = {"k": {"yf": "1.43e7 N/m"}}
    normal = [(10, 65), (12, 76), (16, 92), (20, 106), (6, 60), (12, 150)]
    combos = [Combination("2 m", tool=_tool(12, 2000), joint=joint)]
    combos += [Combination(f"{d}x{o}", tool=_tool(d, o), joint=joint,
                           holder={"catalog": "BT40 ER32"} if d > 12 else None) for d, o in normal]
    table = _study(combos).run(scheduler="serial", progress=False)
    rows = _rows(table)
    status, error = rows["2 m"]
    assert status == "failed"
    assert "below the frequency grid's first line (100 Hz)" in error and "grid.frequency.start" in error
    assert "near 8.75 Hz" in error
    assert table.loc[table["combination"] == "2 m", "depth_m"].isna().all()
    assert all(rows[f"{d}x{o}"] == ("ok", "") for d, o in normal), rows
    # a grid that starts below the mode computes it
    low = Grid(frequency=("4 Hz", "600 Hz", "2 Hz"), speeds=("5000 rpm", "20000 rpm", "200 rpm"))
    again = _rows(_study(combos[:1], grid=low).run(scheduler="serial", progress=False))
    assert again["2 m"] == ("ok", "")


def test_a_tool_wider_than_the_bore_of_the_machines_holder_fails_its_row():
    """The built-in machine's holder has a 12 mm bore: a 40 mm tool cannot go in; 10 and 12 mm tools can."""
    combos = [Combination("40 mm", tool=_tool(40, 300)), Combination("12 mm", tool=_tool(12, 76)),
              Combination("10 mm", tool=_tool(10, 65)),
              Combination("40 mm in a catalogue holder", tool=_tool(40, 300), holder={"catalog": "BT40 ER32"})]
    rows = _rows(_study(combos).run(scheduler="serial", progress=False))
    assert rows["12 mm"] == ("ok", "") and rows["10 mm"] == ("ok", "")
    status, error = rows["40 mm"]
    assert status == "failed"
    assert "combination '40 mm'" in error and "holder: the machine's holder has a 12 mm bore" in error
    assert "shank is 40 mm" in error and "holder.catalog" in error
    status, error = rows["40 mm in a catalogue holder"]  # checked by the catalogue, as before
    assert status == "failed" and "holder: bore" in error


def test_resume_into_a_directory_of_another_study_is_refused_and_keeps_its_results(tmp_path):
    out = tmp_path / "out"
    combos = [Combination("A", tool=TOOL, joint={"k": {"yf": "1.43e7 N/m"}})]
    _study(combos, name="first").run(scheduler="serial", out=out, progress=False)
    before = {p: p.stat().st_mtime_ns for p in out.rglob("*")}
    renamed = _study(combos, name="second")
    with pytest.raises(OutputExistsError, match=r"holds the results of study 'first'.*not of the study given "
                                                r"\('second'.*another --out.*--overwrite"):
        renamed.run(scheduler="serial", out=out, resume=True, progress=False)
    regridded = _study(combos, grid=attrs.evolve(GRID, frequency=("100 Hz", "5000 Hz", "5 Hz")), name="first")
    with pytest.raises(OutputExistsError, match=r"study 'first' on another grid \(frequency 100 Hz to 5000 Hz by "
                                                r"10 Hz.*not of the study given \('first', frequency 100 Hz to "
                                                r"5000 Hz by 5 Hz"):
        regridded.run(scheduler="serial", out=out, resume=True, progress=False)
    assert {p: p.stat().st_mtime_ns for p in out.rglob("*")} == before
    # the same study resumes; --overwrite replaces the other study's results
    _study(combos, name="first").run(scheduler="serial", out=out, resume=True, progress=False)
    table = renamed.run(scheduler="serial", out=out, overwrite=True, progress=False)
    assert list(table["status"]) == ["ok"]


@pytest.mark.parametrize("edit, message", [
    (lambda r: r["rows"][0].update(depth_m=0.5), "depth_m: got 0.5; above the row's stability limit"),
    (lambda r: r["rows"][0].update(depth_m=0.5, limit_depth_m=None), "depth_m: got 0.5; deeper than the largest"),
    (lambda r: r["rows"][0].update(status="weird"), "status: got 'weird'; expected 'ok' or 'failed'"),
    (lambda r: r["rows"][0].update(depth_m=-0.001), "depth_m: got -0.001; expected a number >= 0"),
    (lambda r: r["rows"][0].update(spindle_speed_rpm=0), "spindle_speed_rpm: got 0; expected a positive number"),
    (lambda r: r["rows"][0].update(depth_m="2 mm"), "depth_m: got '2 mm'; expected a finite number"),
    (lambda r: r["rows"][0].update(teeth=4.5), "teeth: got 4.5; expected a whole number"),
    (lambda r: r["rows"][0].update(error="x"), "status: 'ok' with an error"),
])
def test_a_hand_edited_result_is_not_trusted_on_resume_and_is_computed_again(tmp_path, edit, message):
    out = tmp_path / "out"
    study = _study([Combination("A", tool=TOOL, joint={"k": {"yf": "1.43e7 N/m"}})])
    first = study.run(scheduler="serial", out=out, progress=False)
    path = next((out / "results").glob("*.json"))
    record = json.loads(path.read_text())
    edit(record)
    path.write_text(json.dumps(record))
    with pytest.warns(UserWarning) as caught:
        again = study.run(scheduler="serial", out=out, resume=True, progress=False)
    text = " ".join(str(w.message) for w in caught)
    assert str(path) in text and message in text and "computed again" in text, text
    assert again.equals(first)


def test_a_truncated_result_file_is_computed_again_with_a_warning(tmp_path):
    out = tmp_path / "out"
    study = _study([Combination("A", tool=TOOL, joint={"k": {"yf": "1.43e7 N/m"}})])
    first = study.run(scheduler="serial", out=out, progress=False)
    path = next((out / "results").glob("*.json"))
    path.write_text(path.read_text()[:200])
    lines = io.StringIO()
    with pytest.warns(UserWarning, match="not a whole result file") as caught:
        again = study.run(scheduler="serial", out=out, resume=True, progress=lines)
    assert str(path) in str(caught[0].message)
    assert "0 finished before, 1 to compute" in lines.getvalue()
    assert again.equals(first)


def _cli(*argv: str) -> tuple[int, str, str]:
    import contextlib

    from substructure.cli import main

    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        code = main(list(argv))
    return code, out.getvalue(), err.getvalue()


def test_the_summary_marks_a_best_row_whose_joint_prediction_is_an_extrapolation(tmp_path):
    from study_files import JOINTS

    (tmp_path / "joints.csv").write_text(JOINTS)
    (tmp_path / "lib.csv").write_text("name,tool.diameter [mm],tool.overhang [mm],tool.flute_length [mm],tool.teeth\n"
                                      "far out,12,150,30,4\n")
    (tmp_path / "study.toml").write_text(STUDY_TOML + '\n[surrogate]\ntable = "joints.csv"\nfeatures = { '
                                         'tool_diameter = "tool.diameter", gauge_length = "tool.overhang" }\n')
    code, stdout, stderr = _cli("study", str(tmp_path / "study.toml"), "--out", str(tmp_path / "out"), "--scheduler",
                                "serial", "--quiet")
    assert code == 0, stderr
    line = next(x for x in stdout.splitlines() if "far out on bench" in x)
    assert "(extrapolated: gauge_length = 150 mm outside the joint table's 65-106 mm" in line, stdout
    assert "not to be trusted" in line
    code, stdout, _ = _cli("study", str(tmp_path / "study.toml"), "--out", str(tmp_path / "out"), "--resume",
                           "--json", "--quiet", "--scheduler", "serial")
    best = json.loads(stdout)["best"][0]
    assert best["extrapolated"] == ["gauge_length = 150 mm outside the joint table's 65-106 mm"]


HEADER = "name,tool.diameter [mm],tool.overhang [mm],tool.flute_length [mm],tool.teeth\n"


@pytest.mark.parametrize("edit, message", [
    (lambda t: t.replace('max_speed = "20000 rpm"', 'max_speed = "20000 Hz"'),
     "study.toml, line 13: machines[0].limits.max_speed: got a speed in Hz"),
    (lambda t: t.replace('step = "200 rpm"', 'step = "-200 rpm"'),
     "study.toml, line 6: grid.speeds.step: expected finite, positive spindle speeds; got -200 rpm"),
    (lambda t: t.replace('step = "10 Hz"', 'step = "-10 Hz"'), "study.toml, line 5: grid.frequency."),
])
def test_errors_of_the_study_file_name_the_whole_key_path(tmp_path, edit, message):
    (tmp_path / "lib.csv").write_text(HEADER + "A,12,76,30,4\n")
    (tmp_path / "study.toml").write_text(edit(STUDY_TOML))
    code, _, stderr = _cli("study", str(tmp_path / "study.toml"), "--out", str(tmp_path / "out"), "--quiet")
    assert code != 0 and message in stderr and "Traceback" not in stderr, stderr


@pytest.mark.parametrize("header, message", [
    ("name,tool.diameter [N],tool.overhang [mm]", "line 2: column 'tool.diameter [N]': the unit 'N' is not that of "
                                                  "a length (tool.diameter [mm])"),
    ("name,tool.diameter [mm],tool.overhang [mm],joint.k.yf [N]", "column 'joint.k.yf [N]': the unit 'N' is not "
                                                                  "that of a stiffness (joint.k.yf [N/m])"),
    ("name,tool.diameter [mm],tool.overhang [mm],joint.c.yf [N/m]", "not that of a damping (joint.c.yf [N*s/m])"),
    ("name,tool.diameter [mm],tool.overhang [mm],holder.gauge_length [kg]", "not that of a length"),
    ("name,tool.diameter [mm],tool.overhang [bananas]", "is not a unit"),
])
def test_a_wrong_unit_in_the_csv_header_is_refused_when_the_header_is_read(tmp_path, header, message):
    from substructure.errors import FileFormatError

    cells = ",".join(["A"] + ["12"] * (header.count(",")))
    (tmp_path / "lib.csv").write_text(f"# tools\n{header}\n{cells}\n")
    (tmp_path / "study.toml").write_text(STUDY_TOML)
    with pytest.raises(FileFormatError) as info:
        Study.from_file(tmp_path / "study.toml")
    assert "lib.csv" in str(info.value) and message in str(info.value), str(info.value)


def test_a_negative_tool_diameter_names_the_key_and_the_value_as_written(tmp_path):
    (tmp_path / "lib.csv").write_text(HEADER + "A,-12,76,30,4\nB,12,76,-30,4\n")
    (tmp_path / "study.toml").write_text(STUDY_TOML)
    rows = _rows(Study.from_file(tmp_path / "study.toml").run(scheduler="serial", progress=False))
    assert rows["A"][0] == "failed" and "line 2" in rows["A"][1]
    assert "tool.diameter: got '-12 mm'; expected a positive length" in rows["A"][1], rows["A"][1]
    assert "tool.flute_length: got '-30 mm'; expected a positive length" in rows["B"][1], rows["B"][1]
    assert "Quantity" not in rows["A"][1] + rows["B"][1]


def test_a_cut_whose_every_row_failed_has_no_best_in_the_summary(tmp_path):
    (tmp_path / "lib.csv").write_text(HEADER + "A,12,76,30,4\nB,10,65,25,4\n")
    (tmp_path / "study.toml").write_text(STUDY_TOML.replace('radial_depth = "3 mm"', 'radial_depth = "30 mm"'))
    code, stdout, stderr = _cli("study", str(tmp_path / "study.toml"), "--out", str(tmp_path / "out"), "--scheduler",
                                "serial", "--quiet")
    assert code == 0, stderr
    assert "best" not in stdout.replace("no best", "")
    assert "no best for cut 'alu': no row succeeded" in stdout and "failed: A on bench / alu" in stdout
    code, stdout, _ = _cli("study", str(tmp_path / "study.toml"), "--out", str(tmp_path / "out"), "--resume",
                           "--json", "--quiet", "--scheduler", "serial")
    data = json.loads(stdout)
    assert data["best"] == [] and data["no_ok_row"] == ["alu"]


def test_a_tool_value_that_is_not_finite_fails_its_row_and_not_the_study():
    # the tasks' fingerprint refused infinity as JSON: the whole study stopped with an internal error
    combos = [Combination("good", tool=TOOL, joint={"k": {"yf": "1.43e7 N/m"}}),
              Combination("infinite teeth", tool={**TOOL, "teeth": float("inf")}, joint={"k": {"yf": "1.43e7 N/m"}}),
              Combination("nan overhang", tool={**TOOL, "overhang": float("nan")}, joint={"k": {"yf": "1.43e7 N/m"}})]
    rows = _rows(_study(combos).run(scheduler="serial", progress=False))
    assert rows["good"][0] == "ok", rows
    assert rows["infinite teeth"][0] == "failed" and "teeth: got inf; expected a whole number of teeth" \
        in rows["infinite teeth"][1], rows
    assert rows["nan overhang"][0] == "failed" and "overhang" in rows["nan overhang"][1], rows


def test_a_study_written_on_windows_names_its_tables_with_backslashes(tmp_path):
    # 'tables\\tools.csv' was "no such file" on Linux and macOS
    from study_files import write_study

    path = write_study(tmp_path, n=3)
    (tmp_path / "tables").mkdir()
    for name in ("tools.csv", "joints.csv"):
        (tmp_path / name).rename(tmp_path / "tables" / name)
    text = path.read_text().replace('"tools.csv"', "'tables\\tools.csv'")
    path.write_text(text.replace('"joints.csv"', "'tables\\joints.csv'"))
    study = Study.from_file(path)
    assert [c.name for c in study.combinations][-3:] == ["T00", "T01", "T02"]
