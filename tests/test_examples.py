"""Smoke tests of the teaching scripts: every ``examples/[0-9]*.py`` runs to the end.

Each script runs in a subprocess with the interpreter of the test run, in a
temporary directory, with the Agg backend and its figures sent to that
directory.  It must exit with status 0, print what it does and write at
least one PNG.  New numbered examples are picked up without editing this file.
"""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

EXAMPLES = sorted((Path(__file__).resolve().parent.parent / "examples").glob("[0-9]*.py"))


def test_there_are_examples():
    assert EXAMPLES, "no examples/[0-9]*.py found"


@pytest.mark.parametrize("script", EXAMPLES, ids=[p.name for p in EXAMPLES])
def test_example_runs_prints_and_writes_figures(script, tmp_path):
    env = {**os.environ, "MPLBACKEND": "Agg", "SUBSTRUCTURE_EXAMPLES_OUT": str(tmp_path)}
    # -W error: as in the test run, a warning an example does not handle itself fails it.
    done = subprocess.run([sys.executable, "-W", "error", str(script)], cwd=tmp_path, env=env,
                          capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, f"{script.name} failed:\n{done.stdout}\n{done.stderr}"
    assert done.stdout.strip(), f"{script.name} printed nothing"
    assert "Traceback" not in done.stderr
    assert list(tmp_path.glob("**/*.png")), f"{script.name} wrote no PNG into {tmp_path}"
