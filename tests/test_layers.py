"""The import contracts of the layers catch what they are for (docs/architecture.md, "What CI enforces").

A copy of the package is checked with the project's own contracts (``[tool.importlinter]`` in
pyproject.toml): as it is, every contract is kept; with one import from a lower layer to a
higher one (a function-level import, which counts), or with a circle between two sibling
modules, ``lint-imports`` fails naming the contract and the import.  The check needs the
``lint`` extra (``make lint`` installs it, and CI runs ``make lint`` before ``make test``).
"""

from __future__ import annotations

import shutil
import subprocess
import sys
from pathlib import Path

import pytest

pytest.importorskip("importlinter", reason="the layer check needs import-linter (pip install -e '.[lint]')")

ROOT = Path(__file__).resolve().parent.parent


def _lint(tmp_path: Path, edit=None) -> subprocess.CompletedProcess:
    shutil.copytree(ROOT / "substructure", tmp_path / "substructure",
                    ignore=shutil.ignore_patterns("__pycache__", "*.so", "*.c", "data"))
    shutil.copy(ROOT / "pyproject.toml", tmp_path / "pyproject.toml")
    if edit is not None:
        edit(tmp_path / "substructure")
    script = "import sys; from importlinter.cli import lint_imports_command; sys.exit(lint_imports_command())"
    return subprocess.run([sys.executable, "-c", script, "--no-cache"], cwd=tmp_path, capture_output=True,
                          text=True, env={"PYTHONPATH": str(tmp_path), "PATH": "/usr/bin:/bin"}, timeout=300)


def test_the_package_keeps_its_contracts(tmp_path):
    done = _lint(tmp_path)
    assert done.returncode == 0, done.stdout + done.stderr
    assert "Contracts: 3 kept, 0 broken." in done.stdout


def test_an_import_from_a_lower_layer_to_a_higher_one_breaks_a_contract(tmp_path):
    def upward(package: Path) -> None:
        with open(package / "units.py", "a") as f:  # the lowest layer reaching up to the command line
            f.write("\n\ndef _main():\n    from .cli import main\n    return main\n")

    done = _lint(tmp_path, upward)
    assert done.returncode == 1
    assert "BROKEN" in done.stdout and "substructure.units -> substructure.cli" in done.stdout


def test_a_circle_between_sibling_modules_breaks_a_contract(tmp_path):
    def circle(package: Path) -> None:  # two modules of one layer importing each other
        with open(package / "materials.py", "a") as f:
            f.write("\n\ndef _points():\n    from . import points\n    return points\n")
        with open(package / "points.py", "a") as f:
            f.write("\n\ndef _materials():\n    from . import materials\n    return materials\n")

    done = _lint(tmp_path, circle)
    assert done.returncode == 1
    assert "no circles between sibling modules" in done.stdout and "BROKEN" in done.stdout
