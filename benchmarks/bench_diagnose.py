"""Diagnosis benchmark: the open-world diagnosis of 3 FRFs x 2,500 lines.

``bench: diagnose_in_process SECONDS``: ``diagnose`` in this process, every
candidate of the open world (every model parameter, bodies, springs and
section changes at fitted positions, the catalogue), on a tap test of the
built-in assembly at three points (tool tip, 20 mm back, holder tip) on
2,500 lines with 1.5 % noise.  The model's tool has no flutes and the test
had a 2 g sensor on the tip that the record does not mention: two effects,
two refinement steps and one more that finds nothing.  Target on a 2-core
machine: under 10 s.

``bench: diagnose_custom_over_builtin RATIO``: the same heavier clamping nut
(350 g where the model says 150 g) diagnosed on a chuck of a type of one's
own (``NutChuck`` of tests/custom_components.py, the holder of
docs/extending.md with its nut as a field, evaluated through its own
``receptance_matrix``) and on the built-in equivalent (a plain holder with a
150 g ``Mass`` at its tip), the ratio of the two times measured in one run
(median of three pairs).  Target: under 1.5.
"""

from __future__ import annotations

import numpy as np

import statistics
import sys
import time
from pathlib import Path

from substructure import Frequency, Mass, Sensor, default_assembly
from substructure.beams import Segment
from substructure.components import Tool
from substructure.diagnose import diagnose
from substructure.synthetic import simulate


def _setup():
    truth = default_assembly().attach(Sensor("hidden", "tool.tip", "2 g"))
    grid = Frequency.from_hz(np.linspace(20.0, 5000.0, 2500))
    data = [m.frf for m in simulate(truth, ["tool.tip", "tool.tip-20 mm", "holder.tip"], frequency=grid,
                                    noise=0.015, seed=0, sensors=["hidden"])]
    plain = Tool("tool", [Segment("46 mm", "12 mm", material="carbide"), Segment("30 mm", "12 mm", material="carbide")])
    return default_assembly().with_component(plain), data


def _diagnose(inputs):
    model, data = inputs
    result = diagnose(model, data, progress=False)
    assert result.explained and {e.name for e in result.effects} == {"fluted-section", "sensor-mass"}
    return result


def _custom_over_builtin() -> dict:
    sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))
    from custom_components import NutChuck

    truth = default_assembly().attach(Mass("nut", "holder.tip", "350 g"))
    grid = Frequency.from_hz(np.linspace(20.0, 5000.0, 2500))
    data = [m.frf for m in simulate(truth, ["tool.tip", "tool.tip-20 mm"], frequency=grid, noise=0.015, seed=1)]
    builtin = default_assembly().attach(Mass("nut", "holder.tip", "150 g"))
    holder = builtin.component("holder")
    custom = default_assembly().with_component(NutChuck("holder", holder.segments, nut_mass="150 g"))
    expected = {builtin: "masses.nut.mass", custom: "components.holder.nut_mass"}

    def seconds(model) -> float:
        t0 = time.perf_counter()
        result = diagnose(model, data, progress=False)
        elapsed = time.perf_counter() - t0
        assert result.explained and [e.where for e in result.effects] == [expected[model]], result.report
        return elapsed

    seconds(custom), seconds(builtin)  # warm-up
    ratios = [seconds(custom) / seconds(builtin) for _ in range(3)]
    return {"diagnose_custom_over_builtin": statistics.median(ratios)}


_custom_over_builtin.names = ("diagnose_custom_over_builtin",)


def benchmarks():
    yield ("diagnose_in_process", _setup, _diagnose, 3)


def figures():
    yield "diagnose_custom", _custom_over_builtin
