"""Start-up of the command (issue 12): a one-shot ``substructure frf`` against ``python -c "import numpy"``.

Figures, each from whole-process runs in this one ``make bench`` run:

* ``cli_frf_warm_over_python_numpy``: ``substructure frf <default assembly>
  --at tool.tip --json`` over ``python -c "import numpy"``, both run in turn
  15 times after two warm-up runs each, medians of the wall times (goal: at
  most 4);
* ``cli_frf_cold_over_warm``: the first run after a fresh installation over
  a warm run (goal: at most 1.3).  The installation is made here, as a user
  makes it: ``pip install`` of this checkout into a new virtual environment
  (which borrows this one's dependencies; pip compiles the C kernels and the
  bytecode), then the preparation step that
  ``make`` runs (``python -m substructure._prepare``, which builds the unit
  registry's cache), with an empty cache folder of its own.  The first run
  of the command is the cold one; the warm figure is the median of the next
  seven.  ``cli_frf_cold_unprepared_over_warm`` is the same first run
  without the preparation step (a plain ``pip install``): the unit
  registry's cache is then built by that run.
"""

from __future__ import annotations

import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
ASSEMBLY = ROOT / "substructure" / "data" / "default_assembly.toml"
ARGS = ["frf", str(ASSEMBLY), "--at", "tool.tip", "--json"]


def _command(bin_dir: Path | None = None) -> list[str]:
    """The ``substructure`` script next to this Python (or in ``bin_dir``), else ``python -m substructure``."""
    script = (bin_dir or Path(sys.executable).parent) / "substructure"
    return [str(script)] if script.exists() else [sys.executable, "-m", "substructure"]


def _run(cmd: list[str], env: dict | None = None, cwd: Path | None = None) -> float:
    t0 = time.perf_counter()
    subprocess.run(cmd, stdout=subprocess.DEVNULL, check=True, env=env, cwd=cwd)
    return time.perf_counter() - t0


def _warm_over_numpy() -> dict:
    cli = _command() + ARGS
    numpy = [sys.executable, "-c", "import numpy"]
    for _ in range(2):
        _run(cli)
        _run(numpy)
    t_cli, t_np = [], []
    for _ in range(15):
        t_cli.append(_run(cli))
        t_np.append(_run(numpy))
    a, b = statistics.median(t_cli), statistics.median(t_np)
    return {"cli_frf_warm_seconds": a, "python_import_numpy_seconds": b, "cli_frf_warm_over_python_numpy": a / b}


_warm_over_numpy.names = ("cli_frf_warm_over_python_numpy",)


def _fresh_environment(tmp: Path) -> Path:
    """A new virtual environment that sees this one's dependencies but not its ``substructure``.

    The dependencies (numpy, scipy, pint, ...) are taken from this
    environment's site-packages through a path file; this environment's own
    (editable) installation of the package is not visible, so the package
    imported there is the one installed fresh.
    """
    import sysconfig

    venv = tmp / "venv"
    subprocess.run([sys.executable, "-m", "venv", "--without-pip", str(venv)], check=True)
    python = venv / "bin" / "python"
    site = subprocess.run([str(python), "-c", "import sysconfig; print(sysconfig.get_paths()['purelib'])"],
                          check=True, capture_output=True, text=True).stdout.strip()
    Path(site, "dependencies.pth").write_text(sysconfig.get_paths()["purelib"] + "\n")
    subprocess.run([sys.executable, "-m", "pip", "--python", str(python), "install", "--quiet", "--no-deps",
                    str(ROOT)], check=True, stdout=subprocess.DEVNULL, cwd=tmp)
    where = subprocess.run([str(python), "-c", "import substructure; print(substructure.__file__)"],
                           check=True, capture_output=True, text=True, cwd=tmp).stdout.strip()
    if not where.startswith(site):
        raise RuntimeError(f"the fresh installation is not the one imported ({where})")
    return venv / "bin"


def _cold_over_warm() -> dict:
    tmp = Path(tempfile.mkdtemp(prefix="substructure-bench-"))
    try:
        bin_dir = _fresh_environment(tmp)
        cli = _command(bin_dir) + ARGS
        # a plain pip install: the first run builds the unit registry's cache itself
        unprepared = dict(os.environ, SUBSTRUCTURE_UNITS_CACHE=str(tmp / "units-unprepared"))
        cold_unprepared = _run(cli, unprepared, tmp)
        # the installation as make does it: pip install, then the preparation step
        env = dict(os.environ, SUBSTRUCTURE_UNITS_CACHE=str(tmp / "units"))
        subprocess.run([str(bin_dir / "python"), "-m", "substructure._prepare"], env=env, check=True,
                       stdout=subprocess.DEVNULL, cwd=tmp)
        cold = _run(cli, env, tmp)
        warm = statistics.median(_run(cli, env, tmp) for _ in range(7))
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    return {"cli_frf_cold_seconds": cold, "cli_frf_cold_over_warm": cold / warm,
            "cli_frf_cold_unprepared_over_warm": cold_unprepared / warm}


_cold_over_warm.names = ("cli_frf_cold_over_warm",)


def figures():
    yield "cli_warm", _warm_over_numpy
    yield "cli_cold", _cold_over_warm
