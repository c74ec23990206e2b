"""Diagnosis benchmark: the open-world diagnosis of 3 FRFs x 2,500 lines.

``bench: diagnose_in_process SECONDS``: ``diagnose`` in this process, every
candidate of the open world (every model parameter, bodies, springs and
section changes at fitted positions, the catalogue), on a tap test of the
built-in assembly at three points (tool tip, 20 mm back, holder tip) on
2,500 lines with 1.5 % noise.  The model's tool has no flutes and the test
had a 2 g sensor on the tip that the record does not mention: two effects,
two refinement steps and one more that finds nothing.  Target on a 2-core
machine: under 10 s.
"""

from __future__ import annotations

import numpy as np

from substructure import Frequency, Sensor, default_assembly
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


def benchmarks():
    yield ("diagnose_in_process", _setup, _diagnose, 3)
