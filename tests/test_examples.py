"""The teaching scripts ``examples/[0-9]*.py``: their form here, their run in the docs build.

Every example is a sphinx-gallery page: a module docstring whose first lines
are an RST title, then ``# %%`` blocks that explain each step, with figures
saved as PNG files to ``$SUBSTRUCTURE_EXAMPLES_OUT``.  New numbered examples
are picked up without editing this file.

Where the examples run: ``make docs`` (and so CI, which runs it after ``make
test``) executes every example once, with Python warnings as errors, and
fails when one raises, prints nothing, writes no figure or saves a figure
with an empty panel (docs/_ext/gallery_support.py, docs/_ext/figure_checks.py);
the test suite does not run them a second
time.  ``SUBSTRUCTURE_RUN_EXAMPLES=1 make test`` (or this file alone) runs
them here as well, each in a subprocess with the same checks, for work on an
example without building the docs.
"""

from __future__ import annotations

import ast
import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
EXAMPLES = sorted((ROOT / "examples").glob("[0-9]*.py"))
# Runs an example with every saved figure checked for empty panels, as the docs build does.
RUNNER = ("import runpy, sys; sys.path.insert(0, sys.argv[1]); import figure_checks; "
          "figure_checks.install(); runpy.run_path(sys.argv[2], run_name='__main__')")
RUN = os.environ.get("SUBSTRUCTURE_RUN_EXAMPLES") == "1"


def test_there_are_examples():
    assert EXAMPLES, "no examples/[0-9]*.py found"


@pytest.mark.parametrize("script", EXAMPLES, ids=[p.name for p in EXAMPLES])
def test_example_is_a_gallery_page(script):
    text = script.read_text(encoding="utf-8")
    doc = ast.get_docstring(ast.parse(text), clean=False)
    assert doc, f"{script.name}: no module docstring"
    lines = doc.strip("\n").splitlines()
    assert len(lines) >= 2 and re.fullmatch(r"=+", lines[1]) and len(lines[1]) >= len(lines[0].rstrip()), (
        f"{script.name}: the docstring must start with an RST title (a line, then '=' as long as it)")
    assert len(re.findall(r"^# %%", text, flags=re.M)) >= 2, f"{script.name}: no '# %%' blocks"
    assert "SUBSTRUCTURE_EXAMPLES_OUT" in text, f"{script.name}: figures are not saved to $SUBSTRUCTURE_EXAMPLES_OUT"
    assert re.search(r"thesis", text, flags=re.I), f"{script.name}: says nothing of the thesis step it teaches"


@pytest.mark.skipif(not RUN, reason="the examples run in the docs build (make docs); "
                                    "SUBSTRUCTURE_RUN_EXAMPLES=1 runs them here too")
@pytest.mark.parametrize("script", EXAMPLES, ids=[p.name for p in EXAMPLES])
def test_example_runs_prints_and_writes_figures(script, tmp_path):
    env = {**os.environ, "MPLBACKEND": "Agg", "SUBSTRUCTURE_EXAMPLES_OUT": str(tmp_path)}
    # -W error: as in the test run, a warning an example does not handle itself fails it.
    done = subprocess.run([sys.executable, "-W", "error", "-c", RUNNER, str(ROOT / "docs" / "_ext"), str(script)],
                          cwd=tmp_path, env=env,
                          capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, f"{script.name} failed:\n{done.stdout}\n{done.stderr}"
    assert done.stdout.strip(), f"{script.name} printed nothing"
    assert "Traceback" not in done.stderr
    assert list(tmp_path.glob("**/*.png")), f"{script.name} wrote no PNG into {tmp_path}"
