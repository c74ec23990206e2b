"""Diagnosis benchmark (issue 4): a full diagnosis with all effects on 2,500 lines.

Target on a 2-core machine: under 10 s.  The data hide a 2 g sensor and
flutes at once (two refinement steps).
"""

from __future__ import annotations

import numpy as np

from substructure import Frequency, Sensor, default_assembly
from substructure.components import Tool
from substructure.beams import Segment
from substructure.diagnose import diagnose
from substructure.synthetic import simulate


def _setup():
    truth = default_assembly().attach(Sensor("hidden", "tool.tip", "2 g"))
    grid = Frequency.from_hz(np.linspace(20.0, 5000.0, 2500))
    data = [m.frf for m in simulate(truth, ["tool.tip"], frequency=grid, noise=0.015, seed=0, sensors=["hidden"])]
    plain = Tool("tool", [Segment("46 mm", "12 mm", material="carbide"), Segment("30 mm", "12 mm", material="carbide")])
    return default_assembly().with_component(plain), data


def _diagnose(inputs):
    model, data = inputs
    return diagnose(model, data, progress=False)


def benchmarks():
    yield ("diagnose_all_effects_2500_lines", _setup, _diagnose, 3)
