"""Identification benchmark (issue 3): band fit over 2,500 lines with a bootstrap.

Target on a 2-core machine: under 2 s.
"""

from __future__ import annotations

import numpy as np

from substructure import Frequency, Sensor, default_assembly
from substructure.identify import JointIdentifier
from substructure.synthetic import simulate

POINTS = ["tool.tip", "tool.tip-20 mm", "tool.tip-40 mm"]


def _setup():
    truth = default_assembly().attach(Sensor("accelerometer", "tool.tip", "2 g"))
    grid = Frequency.from_hz(np.linspace(100.0, 5000.0, 2500))
    data = list(simulate(truth, POINTS, "tool.tip", frequency=grid, noise=0.02, seed=0, sensors=["accelerometer"]))
    start = truth.with_joint(truth.joint("holder-tool").with_parameters(k={"yf": "0.7e7 N/m"}))
    return start, data


def _identify(inputs):
    start, data = inputs
    return JointIdentifier("holder-tool", bootstrap=20).fit(start, data)


def benchmarks():
    yield ("identify_band_fit_2500_lines_bootstrap_20", _setup, _identify, 5)
