"""Studies on Dask: the table of a 2-worker cluster against a serial run and against the library called directly,
resuming after a partial run, a bad joint and a lost worker failing their own rows, progress lines.

The rows are checked against the stability and surrogate APIs called here on
the same assembly (an independent path through the public functions), and
the tool mode band against a Monte Carlo of the predicted joint.
"""

from __future__ import annotations

import io
import json
import logging
import os
import warnings

import numpy as np
import pandas as pd
import pytest

distributed = pytest.importorskip("distributed")

from study_files import write_study  # noqa: E402

from substructure import Frequency, Tool, default_assembly  # noqa: E402
from substructure.errors import OutputExistsError  # noqa: E402
from substructure.stability import (  # noqa: E402
    MachineLimits, MillingCut, assembly_structure, recommend, spindle_speeds, xy_frf, zoa)
from substructure.study import Combination, Compute, Cut, Machine, Study  # noqa: E402
from substructure.study.task import joint_at_quantile  # noqa: E402


@pytest.fixture(scope="module")
def client():
    """A local Dask cluster of 2 workers (threads of this process: fast to start on a busy machine)."""
    from distributed import Client, LocalCluster

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # start-up chatter of the cluster is not the study's business
        cluster = LocalCluster(n_workers=2, threads_per_worker=1, processes=False, dashboard_address=None,
                               scheduler_kwargs={"dashboard_address": ":0"}, silence_logs=logging.ERROR)
        c = Client(cluster, set_as_default=False)
    yield c
    c.close()
    cluster.close()


@pytest.fixture(scope="module")
def library(tmp_path_factory):
    folder = tmp_path_factory.mktemp("library")
    return Study.from_file(write_study(folder, n=6, bad=True))


@pytest.fixture(scope="module")
def serial(library):
    return library.run(scheduler="serial", progress=False)


def test_the_table_of_a_two_worker_cluster_equals_a_serial_run_row_by_row(library, serial, client):
    on_dask = library.run(client, progress=False)
    pd.testing.assert_frame_equal(on_dask, serial, check_exact=True)
    # one row per combination and cut, in the study's order
    names = [c.name for c in library.combinations]
    assert list(serial["combination"]) == [n for n in names for _ in range(2)]
    assert list(serial["cut"]) == ["aluminium", "steel slot"] * len(names)
    ok = serial[serial["combination"] != "bad joint"]
    assert (ok["status"] == "ok").all(), ok[ok["status"] != "ok"][["combination", "cut", "error"]]


def test_a_row_is_what_the_library_gives_for_that_tool(serial):
    """The explicit 12 mm tool: its assembly, FRF, lobes and recommendation made here with the public API."""
    row = serial[(serial["combination"] == "explicit 12 mm") & (serial["cut"] == "aluminium")].iloc[0]
    tool = Tool.end_mill("12 mm", "76 mm", "30 mm", teeth=4)
    base = default_assembly().with_component(tool)
    assembly = base.with_joint(base.joint("holder-tool").with_parameters(k={"yf": "1.43e7 N/m"}))
    grid = Frequency.from_range("100 Hz", "5000 Hz", "5 Hz")
    frf, band = assembly_structure(assembly, "tool.tip:y", grid)
    cut = MillingCut.for_workpiece(4, "12 mm", "aluminium-7075", radial_depth="3 mm", milling="down",
                                   feed_per_tooth="0.05 mm")
    lobes = zoa(xy_frf(frf), cut, spindle_speeds("5000 rpm", "20000 rpm", "100 rpm"), band=band)
    best = recommend(lobes, cut, MachineLimits(max_speed="20000 rpm", power="11 kW", max_depth="30 mm"))
    assert row["spindle_speed_rpm"] == best.spindle_speed_rpm
    assert row["depth_m"] == best.depth_m and row["limit_depth_m"] == best.limit_depth_m
    assert row["chatter_frequency_hz"] == best.chatter_frequency_hz and row["mrr_m3_per_s"] == best.mrr_m3_per_s
    assert row["zoa_absolute_limit_m"] == lobes.absolute_limit_m
    assert row["joint_source"] == "explicit" and row["joint_k_yf_n_per_m"] == 1.43e7
    assert np.isnan(row["tool_mode_lo_hz"]) and row["band_members"] == 1  # no band without a prediction
    # the tool mode: the highest peak of |H|, against a 0.05 Hz grid around it (the study's grid is 5 Hz)
    f0 = row["tool_mode_hz"]
    fine = assembly.receptance("tool.tip:y", frequency=Frequency.from_range(f"{f0 - 10} Hz", f"{f0 + 10} Hz",
                                                                             "0.05 Hz"))
    h = np.abs(fine.data[:, 0, 0])
    assert abs(fine.frequency.hz[np.argmax(h)] - f0) < 0.5
    assert row["tool_mode_compliance_m_per_n"] == pytest.approx(h.max(), rel=2e-3)


def test_a_predicted_joint_gives_bands_that_hold(library, serial):
    """The tool mode band covers the tool modes of sampled joints; the depth keeps its margin at every quantile."""
    task = next(t for t in library.tasks() if t["combination"] == "T01")
    row = serial[(serial["combination"] == "T01") & (serial["cut"] == "aluminium")].iloc[0]
    assert row["joint_source"] == "surrogate" and row["band_members"] == 3
    lo, hi = row["tool_mode_lo_hz"], row["tool_mode_hi_hz"]
    assert lo < row["tool_mode_hz"] < hi
    prediction = task["prediction"]
    m, s = prediction["log_mean"]["k_yf"], prediction["log_std"]["k_yf"]
    assert row["joint_k_yf_lo_n_per_m"] == pytest.approx(np.exp(m - 1.96 * s), rel=1e-3)
    # Monte Carlo: tool modes of joints drawn from the prediction, found on a fine grid
    tool = Tool.end_mill("12 mm", "72 mm", "30 mm", teeth=4)
    base = default_assembly().with_component(tool)
    template = base.joint("holder-tool")
    rng = np.random.default_rng(7)
    grid = Frequency.from_range(f"{lo - 150} Hz", f"{hi + 150} Hz", "1 Hz")
    modes = []
    for k in np.exp(m + s * rng.standard_normal(60)):
        frf = base.with_joint(template.with_parameters(k={"yf": f"{float(k)!r} N/m"})).receptance("tool.tip:y",
                                                                                           frequency=grid)
        modes.append(grid.hz[np.argmax(np.abs(frf.data[:, 0, 0]))])
    inside = np.mean((np.array(modes) >= lo - 1) & (np.array(modes) <= hi + 1))
    assert inside >= 0.88, (lo, hi, sorted(modes))
    # the recommended depth keeps the margin on the lobes of every quantile, over the whole speed window
    cut = MillingCut.for_workpiece(4, "12 mm", "aluminium-7075", radial_depth="3 mm", milling="down",
                                   feed_per_tooth="0.05 mm")
    window = np.linspace(row["window_lo_rpm"], row["window_hi_rpm"], 41)
    study_grid = Frequency.from_range("100 Hz", "5000 Hz", "5 Hz")
    for q in (0.025, 0.5, 0.975):
        assembly = base.with_joint(joint_at_quantile(template, prediction, q))
        frf, band = assembly_structure(assembly, "tool.tip:y", study_grid)
        limit = zoa(xy_frf(frf), cut, spindle_speeds("5000 rpm", "20000 rpm", "100 rpm"), band=band).limit_on(window)[0]
        assert row["depth_m"] <= (1 - row["margin"]) * limit.min() * (1 + 1e-9)


def test_a_bad_joint_fails_its_rows_only(library, serial):
    bad = serial[serial["combination"] == "bad joint"]
    assert list(bad["status"]) == ["failed", "failed"]
    message = bad["error"].iloc[0]
    assert "study.toml, line" in message and "joint: k.yf" in message and "N/m" in message
    # the other rows are those of the study without it
    good = Study(library.name, library.machines, [c for c in library.combinations if c.name != "bad joint"],
                 library.cuts, library.compute, library.grid, library.surrogate)
    alone = good.run(scheduler="serial", progress=False)
    pd.testing.assert_frame_equal(serial[serial["combination"] != "bad joint"].reset_index(drop=True), alone,
                                  check_exact=True)


def test_a_study_run_in_two_parts_equals_an_uninterrupted_one(library, serial, client, tmp_path):
    """Half the combinations, then the whole study with resume: the finished half is not computed again."""
    out = tmp_path / "out"
    half = Study(library.name, library.machines, library.combinations[:3], library.cuts, library.compute,
                 library.grid, library.surrogate, source=library.source, inputs=library.inputs)
    half.run(client, out=out, progress=False)
    before = {p.name: p.stat().st_mtime_ns for p in (out / "results").iterdir()}
    assert len(before) == 3
    lines = io.StringIO()
    resumed = library.run(client, out=out, resume=True, progress=lines)
    pd.testing.assert_frame_equal(resumed, serial, check_exact=True)
    assert "3 finished before, 5 to compute" in lines.getvalue()
    assert {p.name: p.stat().st_mtime_ns for p in (out / "results").iterdir() if p.name in before} == before
    on_disk = pd.read_parquet(out / "table.parquet")
    pd.testing.assert_frame_equal(on_disk, serial, check_exact=True)
    from_csv = pd.read_csv(out / "table.csv", keep_default_na=False, na_values=[""])
    assert np.array_equal(from_csv["depth_m"].to_numpy(), serial["depth_m"].to_numpy(), equal_nan=True)
    # a second resume computes nothing
    again = io.StringIO()
    library.run(scheduler="serial", out=out, resume=True, progress=again)
    assert "every combination was finished before" in again.getvalue()


def test_resume_recomputes_what_changed_and_refuses_to_overwrite_unasked(tmp_path):
    folder = tmp_path / "s"
    path = write_study(folder, n=2)
    out = tmp_path / "out"
    Study.from_file(path).run(scheduler="serial", out=out, progress=False)
    with pytest.raises(OutputExistsError, match="--resume"):
        Study.from_file(path).run(scheduler="serial", out=out, progress=False)
    times = {p.name: p.stat().st_mtime_ns for p in (out / "results").iterdir()}
    (folder / "tools.csv").write_text((folder / "tools.csv").read_text().replace("T01,12,72", "T01,12,74"))
    lines = io.StringIO()
    table = Study.from_file(path).run(scheduler="serial", out=out, resume=True, progress=lines)
    changed = [n for n, t in times.items() if (out / "results" / n).stat().st_mtime_ns != t]
    assert len(changed) == 1 and "T01" in changed[0]
    assert table.loc[table["combination"] == "T01", "overhang_m"].iloc[0] == pytest.approx(0.074)
    record = json.loads((out / "results" / changed[0]).read_text())
    assert record["format"] == "substructure-study-result/1" and record["status"] == "done"


def test_progress_lines_say_done_total_rate_and_time_left(library, client):
    lines = io.StringIO()
    small = Study(library.name, library.machines, library.combinations[:4], library.cuts,
                  Compute(figures=False), library.grid, library.surrogate)
    small.run(client, progress=lines)
    text = lines.getvalue()
    assert "study: 'test library': 4 combinations on their machines, 2 cuts" in text
    assert "Dask dashboard" in text
    assert "study: 1/4 done" in text and "combinations/s, about" in text and "left" in text
    assert "study: 4/4 done, 2 rows failed in" in text


def test_figures_and_frf_files_are_written_per_combination(tmp_path):
    path = write_study(tmp_path / "s", n=2, figures=True, frf_files=True)
    out = tmp_path / "out"
    table = Study.from_file(path).run(scheduler="local:2", out=out, progress=False)
    keys = list(dict.fromkeys(table["key"]))
    for key in keys:
        assert (out / "figures" / f"{key}.png").read_bytes().startswith(b"\x89PNG")
        text = (out / "frf" / f"{key}.csv").read_text().splitlines()
        assert text[0] == "frequency_hz,real,imag" and len(text) > 900
    assert (out / "summary.png").read_bytes().startswith(b"\x89PNG")


def test_a_lost_worker_fails_that_combination_and_the_study_goes_on(tmp_path):
    """A worker process killed while computing (os._exit in a plugin component): crashed rows, the rest computed."""
    import dask
    from distributed import Client, LocalCluster

    import study_crash_plugin  # noqa: F401  (registers the type here, for the driver's checks)

    crashing = (tmp_path / "crashing.toml")
    crashing.write_text(default_assembly_text().replace('type = "spindle"', 'type = "crashing-spindle"'))
    machines = f'\n[[machines]]\nname = "crashing"\nassembly = "{crashing}"\n'
    combos = ('\n[[combinations]]\nname = "on the crashing machine"\nmachines = ["crashing"]\n'
              'tool = { diameter = "12 mm", overhang = "70 mm", teeth = 4 }\n'
              'joint = { k = { yf = "1.4e7 N/m" } }\n')
    path = write_study(tmp_path / "s", n=2, extra_top='plugins = ["study_crash_plugin"]\n',
                       extra_machines=machines, extra_combinations=combos)
    text = path.read_text().replace("combinations_csv", "#")
    text = text.replace('name = "explicit 12 mm"', 'name = "explicit 12 mm"\nmachines = ["bench"]')
    path.write_text(text)
    study = Study.from_file(path)
    with dask.config.set({"distributed.scheduler.allowed-failures": 0}), warnings.catch_warnings():
        warnings.simplefilter("ignore")
        cluster = LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None,
                               scheduler_kwargs={"dashboard_address": ":0"}, silence_logs=logging.CRITICAL)
        c = Client(cluster, set_as_default=False)
        try:
            table = study.run(c, progress=False)
        finally:
            c.close()
            cluster.close()
    crashed = table[table["combination"] == "on the crashing machine"]
    assert list(crashed["status"]) == ["crashed", "crashed"]
    assert "the worker computing it was lost" in crashed["error"].iloc[0] and "resume" in crashed["error"].iloc[0]
    good = Study(study.name, study.machines[:1], study.combinations[:1], study.cuts, study.compute, study.grid,
                 study.surrogate)
    pd.testing.assert_frame_equal(table[table["status"] != "crashed"].reset_index(drop=True),
                                  good.run(scheduler="serial", progress=False), check_exact=True)


def default_assembly_text() -> str:
    from importlib import resources

    return (resources.files("substructure") / "data" / "default_assembly.toml").read_text()


def test_a_study_built_in_python_equals_the_one_read_from_its_file(library):
    cuts = [Cut("aluminium", workpiece="aluminium-7075", radial_depth="3 mm", milling="down",
                feed_per_tooth="0.05 mm"), Cut("steel slot", kt="2000 MPa", kr=0.3, immersion=1.0,
                                               feed_per_tooth="0.08 mm")]
    assert list(library.cuts) == cuts
    assert library.machines[0] == Machine("bench", limits={"max_speed": "20000 rpm", "power": "11 kW"})
    assert library.combinations[0] == Combination("explicit 12 mm", tool={
        "diameter": "12 mm", "overhang": "76 mm", "flute_length": "30 mm", "teeth": 4},
        joint={"k": {"yf": "1.43e7 N/m"}})
    csv_row = library.combinations[2]
    assert csv_row.tool == {"diameter": "10 mm", "overhang": "65 mm", "flute_length": "30 mm", "teeth": 3}
    assert csv_row.where.endswith("tools.csv, line 2")
    assert library.combinations[0].where.endswith("study.toml, line 34: combinations[0]")
    # seeds and keys come from the names, not from the order
    tasks = {t["combination"]: t for t in library.tasks()}
    reordered = Study(library.name, library.machines, list(reversed(library.combinations)), library.cuts,
                      library.compute, library.grid, library.surrogate)
    for t in reordered.tasks():
        assert t["seed"] == tasks[t["combination"]]["seed"] and t["fingerprint"] == tasks[t["combination"]][
            "fingerprint"]
    assert len({t["seed"] for t in tasks.values()}) == len(tasks)


def test_semi_discretization_rows(tmp_path):
    """Both methods; the recommendation from semi-discretization (modes fitted below 3 kHz, a few speeds)."""
    path = write_study(tmp_path / "s", n=1)
    text = path.read_text().replace("frf_files = false", 'frf_files = false\nlobes = ["zoa", "sdm"]\nband = false')
    text = text.replace('step = "5 Hz" }', 'step = "5 Hz" }\nsdm_speeds = { start = "13000 rpm", stop = "15000 rpm", '
                        'step = "250 rpm" }').replace('stop = "5000 Hz"', 'stop = "3000 Hz"')
    text = text.replace('name = "explicit 12 mm"', 'name = "explicit 12 mm"\ncuts = ["aluminium"]')
    path.write_text(text.replace("combinations_csv", "#"))
    table = Study.from_file(path).run(scheduler="serial", progress=False)
    assert list(table["cut"]) == ["aluminium"]
    row = table.iloc[0]
    assert row["status"] == "ok", row["error"]
    assert row["method"] == "sdm" and 13000 * 1.03 <= row["spindle_speed_rpm"] <= 15000 / 1.03
    assert np.isfinite(row["sdm_min_limit_m"]) and np.isfinite(row["zoa_min_limit_m"])
    assert "modal fit" in row["notes"]
    # the zero order's lowest limit over 5000-20000 rpm is at most a little above semi-discretization's over
    # 13000-15000 rpm (at the floors of the lobes the zero order is 6 % below, docs/stability.md)
    assert row["zoa_min_limit_m"] <= 1.1 * row["sdm_min_limit_m"]


def test_the_table_files_are_not_written_onto_an_input(tmp_path):
    path = write_study(tmp_path / "s", n=1)
    out = tmp_path / "s"
    (tmp_path / "s" / "table.csv").write_text("mine")
    text = path.read_text().replace('combinations_csv = "tools.csv"', 'combinations_csv = "table.csv"')
    (tmp_path / "s" / "table.csv").write_text((tmp_path / "s" / "tools.csv").read_text())
    path.write_text(text)
    with pytest.raises(ValueError, match="onto the input"):
        Study.from_file(path).run(scheduler="serial", out=out, overwrite=True, progress=False)
    assert os.path.getsize(tmp_path / "s" / "table.csv") > 10


@pytest.mark.parametrize("build, message", [
    (lambda: Compute(lobes=["fem"]), "lobes: got 'fem'"),
    (lambda: Compute(recommend=True, lobes=[]), "a recommendation needs lobes"),
    (lambda: Compute(quantiles=[0.9, 0.1]), "increasing probabilities"),
    (lambda: Compute(at="tool.tip:theta"), "translational"),
    (lambda: Machine("m", assembly="no-such-file.toml"), "no such file"),
    (lambda: Machine("m", limits={"max_rpm": "1 rpm"}), "limits.max_rpm: unknown key"),
    (lambda: Combination("c", tool={"diameter": "12 mm"}), "tool.overhang: missing"),
    (lambda: Combination("c", tool={"diameter": "12 mm", "overhang": "70 mm", "colour": "red"}), "tool.colour"),
    (lambda: Combination("c", holder={"catalog": "BT40 ER32", "segments": []}), "not both"),
    (lambda: Combination("c", joint={"k": {"xx": "1 N/m"}}), "joint.k.xx: unknown entry"),
    (lambda: Cut("c", radial_depth="3 mm"), "give workpiece"),
    (lambda: Cut("c", kt="600 MPa", kn="100 MPa"), "radial_depth"),
    (lambda: Cut("c", kt="600 MPa", kn="100 MPa", immersion=1.5), "immersion: got 1.5"),
    (lambda: Cut("c", kt="600 N", kn="100 MPa", immersion=0.5), "kt"),
    (lambda: Study("s", [], [Combination("c")]), "at least one machine"),
    (lambda: Study("s", [Machine("m")], [Combination("c", cuts=["x"])]), "'x' is not a cut"),
    (lambda: Study("s", [Machine("m")], [Combination("c")], joint="spindle-tool"), "no joint 'spindle-tool'"),
])
def test_bad_definitions_are_refused_where_they_enter(build, message):
    with pytest.raises((ValueError, TypeError), match=message.replace("(", r"\(").replace(")", r"\)")):
        build()


def test_a_holder_that_cannot_take_the_tool_or_a_cut_too_wide_fails_only_its_rows():
    machine = Machine("bench")
    cuts = [Cut("narrow", kt="700 MPa", kr=0.3, radial_depth="3 mm"),
            Cut("wide", kt="700 MPa", kr=0.3, radial_depth="14 mm")]
    combos = [Combination("ok", tool={"diameter": "12 mm", "overhang": "70 mm", "teeth": 4},
                          holder={"catalog": "BT40 ER32"}, joint={"k": {"yf": "1.4e7 N/m"}}),
              Combination("16 mm in an ER16", tool={"diameter": "16 mm", "overhang": "70 mm", "teeth": 4},
                          holder={"catalog": "BT40 ER16"}, joint={"k": {"yf": "2e7 N/m"}})]
    table = Study("s", [machine], combos, cuts, Compute(figures=False)).run(scheduler="serial", progress=False)
    status = dict(zip(zip(table["combination"], table["cut"]), table["status"]))
    errors = dict(zip(zip(table["combination"], table["cut"]), table["error"]))
    assert status == {("ok", "narrow"): "ok", ("ok", "wide"): "failed", ("16 mm in an ER16", "narrow"): "failed",
                      ("16 mm in an ER16", "wide"): "failed"}
    assert "holder: bore" in errors[("16 mm in an ER16", "narrow")] and "ER16" in errors[("16 mm in an ER16", "narrow")]
    assert "cut 'wide'" in errors[("ok", "wide")] and "radial" in errors[("ok", "wide")]
