"""The benchmarks' inputs stay valid as the library's checks grow.

``make bench`` is not run by CI; a check added to the library that refuses a
benchmark's input (a study's tool that its holder cannot take, say) would
only show when someone runs it.  These tests build each benchmark's inputs
the way it does and compute a few of them.
"""

from __future__ import annotations

import importlib.util
import warnings
from pathlib import Path

import pytest

BENCHMARKS = Path(__file__).resolve().parents[1] / "benchmarks"


def _load(name: str):
    spec = importlib.util.spec_from_file_location(name, BENCHMARKS / f"{name}.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_the_study_benchmark_combinations_compute():
    from substructure.study.task import run_task

    study = _load("bench_study")._study(4)  # the four diameters, 10 to 20 mm
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        rows = [row for task in study.tasks() for row in run_task(task)["rows"]]
    assert len(rows) == 4
    assert [row["error"] for row in rows] == [""] * 4
    assert [row["status"] for row in rows] == ["ok"] * 4
    assert sorted(row["tool_diameter_m"] for row in rows) == pytest.approx([0.010, 0.012, 0.016, 0.020])
