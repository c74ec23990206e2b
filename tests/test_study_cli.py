"""``substructure study``: the command, its checks, its files, a real process killed and resumed."""

from __future__ import annotations

import contextlib
import io
import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pandas as pd
import pytest

pytest.importorskip("distributed")

from study_files import write_study  # noqa: E402

from substructure.cli import main  # noqa: E402
from substructure.errors import FileFormatError  # noqa: E402
from substructure.study import Study  # noqa: E402

ROOT = Path(__file__).resolve().parent.parent


def _run(*argv: str) -> tuple[int, str, str]:
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        code = main(list(argv))
    return code, out.getvalue(), err.getvalue()


def _command(*argv: str, **kw) -> subprocess.Popen:
    env = {**os.environ, "MPLBACKEND": "Agg", "PYTHONPATH": str(ROOT / "tests")}
    return subprocess.Popen([sys.executable, "-m", "substructure", *argv], env=env, stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True, **kw)


def test_the_command_writes_the_table_and_says_what_is_best(tmp_path):
    path = write_study(tmp_path / "s", n=3, bad=True)
    out = tmp_path / "out"
    code, stdout, stderr = _run("study", str(path), "--out", str(out), "--scheduler", "local:2")
    assert code == 0, stderr
    assert "study: 1/5 done" in stderr and "study: 5/5 done, 2 rows failed in" in stderr
    assert "Dask dashboard" in stderr
    assert "10 rows" in stdout and "8 ok, 2 failed" in stdout and "best by material removal rate" in stdout
    assert "failed: bad joint on bench / aluminium:" in stdout and "line" in stdout
    table = pd.read_parquet(out / "table.parquet")
    assert len(table) == 10 and (out / "table.csv").exists() and (out / "summary.png").exists()
    code, stdout, _ = _run("study", str(path), "--out", str(out), "--resume", "--json", "--quiet",
                           "--scheduler", "serial")
    data = json.loads(stdout)
    assert code == 0 and data["rows"] == 10 and data["ok"] == 8 and data["failed"] == 2
    assert data["best"][0]["cut"] == "aluminium" and data["failures"][0]["combination"] == "bad joint"
    assert data["files"]["table_parquet"].endswith("table.parquet")


@pytest.mark.parametrize("argv, status, message", [
    (["--resume", "--overwrite"], 2, "choose one"),
    (["--scheduler", "threads:2"], 2, "argument --scheduler"),
    (["--scheduler", "processes:0"], 2, "1 to 4096"),
])
def test_misuse_of_the_command_line_is_status_2(tmp_path, argv, status, message):
    path = write_study(tmp_path / "s", n=1)
    code, stdout, stderr = _run("study", str(path), "--out", str(tmp_path / "out"), *argv)
    assert code == status and message in stderr and not stdout


def test_an_existing_study_is_neither_replaced_nor_repeated_unasked(tmp_path):
    path = write_study(tmp_path / "s", n=1)
    out = tmp_path / "out"
    assert _run("study", str(path), "--out", str(out), "--scheduler", "serial", "--quiet")[0] == 0
    code, _, stderr = _run("study", str(path), "--out", str(out), "--scheduler", "serial")
    assert code == 1 and "--resume" in stderr and "--overwrite" in stderr
    (tmp_path / "file").write_text("x")
    code, _, stderr = _run("study", str(path), "--out", str(tmp_path / "file"))
    assert code == 2 and "is a file" in stderr


@pytest.mark.parametrize("edit, message", [
    (lambda t: t.replace('radial_depth = "3 mm"', 'radial_depth = "3 kg"'), "line 23: cuts[0].radial_depth:"),
    (lambda t: t.replace('milling = "down"', 'milling = "down"\ndepth = "1 mm"'),
     "line 25: cuts[0].depth: unknown key"),
    (lambda t: t.replace('name = "bench"\n', ''), "machines[0].name: missing"),
    (lambda t: t.replace('lobes', 'lobes').replace('figures = false', 'figures = false\nlobes = ["fem"]'),
     "compute.lobes: got 'fem'"),
    (lambda t: t.replace('workpiece = "aluminium-7075"', 'workpiece = "unobtainium"'), "known: aluminium-6061"),
    (lambda t: t.replace('name = "explicit 12 mm"', 'name = "explicit 12 mm"\nmachines = ["mill"]'),
     "'mill' is not a machine of the study"),
    (lambda t: t.replace('name = "steel slot"', 'name = "aluminium"'), "names must be unique"),
    (lambda t: t.replace('[[cuts]]\nname = "steel slot"', '[[cuts]]\nname = "steel slot"\nfeed_per_tooth = "0.1 mm"'
                         ).replace('feed_per_tooth = "0.08 mm"', ''), None),
    (lambda t: t.replace('feed_per_tooth = "0.08 mm"', ''), "line 27: cuts[1]: feed_per_tooth: missing; machine"),
    (lambda t: t.replace('features = { tool_diameter = "tool.diameter"', 'features = { tool_diameter = "tool.size"'),
     "surrogate.features.tool_diameter: got 'tool.size'"),
    (lambda t: t.replace('table = "joints.csv"', 'table = "nope.csv"'), "surrogate.table: 'nope.csv': no such file"),
    (lambda t: t + "\n[[combinations]]\nname = \"x\"\ntool = { diameter = \"12 mm\" }\n",
     "tool.overhang: missing"),
])
def test_errors_in_the_study_file_name_the_file_line_and_key(tmp_path, edit, message):
    path = write_study(tmp_path / "s", n=1)
    path.write_text(edit(path.read_text()))
    if message is None:  # the edit is fine
        Study.from_file(path)
        return
    with pytest.raises(FileFormatError) as info:
        Study.from_file(path)
    assert str(info.value).startswith(str(path)) and message in str(info.value), str(info.value)


@pytest.mark.parametrize("header, row, message", [
    ("name,tool.diameter [mm],tool.overhang [mm],tool.teeth", "A,12,x,4", "line 3: tool.overhang: got 'x'"),
    ("name,tool.diameter [mm],tool.overhang [mm]", "A,12,nan", "expected a finite number"),
    ("name,tool.diameter [mm],tool.overhang [mm],tool.teeth", "A,12,70,four", "tool.teeth: got 'four'"),
    ("name,tool.diam [mm],tool.overhang [mm]", "A,12,70", "tool.diam: unknown key"),
    ("name,tool.diameter [mm],bogus", "A,12,x", "column 'bogus': unknown"),
    ("name,tool.diameter [mm],joint.k.yf", "A,12,1e7", "a joint entry needs its unit"),
    ("name,tool.diameter [mm],tool.overhang [mm]", "A,12", "2 cells; the header has 3 columns"),
])
def test_errors_in_the_combinations_csv_name_the_line_and_column(tmp_path, header, row, message):
    path = write_study(tmp_path / "s", n=1)
    (tmp_path / "s" / "tools.csv").write_text(f"# my tools\n{header}\n{row}\n")
    with pytest.raises(FileFormatError) as info:
        Study.from_file(path)
    assert "tools.csv" in str(info.value) and message in str(info.value), str(info.value)


def _results(out: Path) -> list:
    """The finished combinations: result files, not the temporary file of one being written."""
    return [p for p in (out / "results").glob("*.json") if not p.name.startswith(".")]


def _wait_for_results(out: Path, count: int, process: subprocess.Popen, timeout: float = 240.0) -> int:
    start = time.monotonic()
    while time.monotonic() - start < timeout:
        found = len(_results(out)) if (out / "results").is_dir() else 0
        if found >= count or process.poll() is not None:
            return found
        time.sleep(0.05)
    return -1


def test_a_study_killed_halfway_and_resumed_equals_an_uninterrupted_one(tmp_path):
    """A real process killed with SIGKILL (nothing to clean up after it), then --resume."""
    path = write_study(tmp_path / "s", n=10, figures=True)
    out = tmp_path / "out"
    process = _command("study", str(path), "--out", str(out), "--scheduler", "local:2", "--quiet")
    found = _wait_for_results(out, 2, process)
    process.send_signal(signal.SIGKILL)
    process.communicate(timeout=60)
    assert 2 <= found < 11 and process.returncode == -signal.SIGKILL
    saved = len(_results(out))
    assert saved < 11 and not list(out.glob("table.*"))
    code, _, stderr = _run("study", str(path), "--out", str(out), "--resume", "--scheduler", "local:2")
    assert code == 0, stderr
    assert f"{saved} finished before, {11 - saved} to compute" in stderr
    resumed = pd.read_parquet(out / "table.parquet")
    whole = Study.from_file(path).run(scheduler="serial", progress=False)
    pd.testing.assert_frame_equal(resumed, whole, check_exact=True)
    assert len(list((out / "figures").glob("*.png"))) == 11  # every combination drawn once
    assert not list(out.rglob(".*.part.*"))  # no temporary file of the killed run is left


def test_sigterm_stops_a_process_cluster_and_leaves_a_table_with_pending_rows(tmp_path):
    path = write_study(tmp_path / "s", n=6, figures=True)
    out = tmp_path / "out"
    process = _command("study", str(path), "--out", str(out), "--scheduler", "processes:2")
    found = _wait_for_results(out, 1, process)
    process.send_signal(signal.SIGTERM)
    _, stderr = process.communicate(timeout=120)
    if found >= 7 or process.returncode == 0:
        pytest.skip("the study finished before the signal")
    assert process.returncode == 130, stderr
    assert "interrupted" in stderr and "--resume" in stderr
    table = pd.read_parquet(out / "table.parquet")
    assert (table["status"] == "pending").any() and (table["status"] == "ok").any()
    code, _, stderr = _run("study", str(path), "--out", str(out), "--resume", "--scheduler", "serial")
    assert code == 0, stderr
    pd.testing.assert_frame_equal(pd.read_parquet(out / "table.parquet"),
                                  Study.from_file(path).run(scheduler="serial", progress=False), check_exact=True)


def test_neither_the_package_nor_the_parser_nor_frf_imports_dask_or_pandas():
    probe = ("import sys, json, io, contextlib\nimport substructure.study\nfrom substructure.cli import _parser, main\n"
             "_parser()\nwith contextlib.redirect_stdout(io.StringIO()):\n"
             f"    main(['frf', {str(ROOT / 'substructure' / 'data' / 'default_assembly.toml')!r}, '--at', 'tool.tip',"
             " '--json'])\nprint(json.dumps(sorted(sys.modules)))")
    done = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True, check=True,
                          env={**os.environ, "MPLBACKEND": "Agg"})
    loaded = set(json.loads(done.stdout.strip().splitlines()[-1]))
    for name in ("dask", "distributed", "pandas", "pyarrow"):
        assert name not in loaded, name


# -- the documentation's contract -------------------------------------------------------------


def test_every_column_of_the_table_is_in_the_contract():
    from substructure.study import COLUMNS

    text = (ROOT / "docs" / "file-formats.md").read_text(encoding="utf-8")
    section = text[text.index("### `substructure study`"):]
    for name, kind, _ in COLUMNS:
        assert f"| `{name}` | {kind} |" in section, name


def test_the_study_file_of_the_contract_loads(tmp_path):
    import re
    import shutil

    text = (ROOT / "docs" / "file-formats.md").read_text(encoding="utf-8")
    section = text[text.index("**The study file (TOML)**"):]
    toml = re.search(r"```toml\n(.*?)```", section, flags=re.DOTALL).group(1)
    csv_block = re.search(r"```\n(name,.*?)```", section, flags=re.DOTALL).group(1)
    (tmp_path / "study.toml").write_text(toml)
    (tmp_path / "library.csv").write_text(csv_block)
    shutil.copy(ROOT / "substructure" / "data" / "default_assembly.toml", tmp_path / "dmu50.toml")
    from study_files import JOINTS

    (tmp_path / "joints.csv").write_text(JOINTS)
    study = Study.from_file(tmp_path / "study.toml")
    assert [c.name for c in study.combinations] == ["T12 ER32 76", "T10-65", "T12-90"]
    assert study.machines[0].limits.max_speed == 18000 and study.compute.quantiles == (0.025, 0.5, 0.975)
    assert study.combinations[2].joint is None and study.combinations[1].joint == {"k": {"yf": "9.7e6 N/m"}}
