"""Core library benchmarks (issue 2): one tool point FRF, and an overhang sweep.

Targets on a 2-core machine: the default assembly's tool point FRF at 10,000
frequency lines under 20 ms; 1,000 tool overhangs at 2,500 lines under 2 s.
"""

from __future__ import annotations

import numpy as np

from substructure import Flutes, Frequency, Segment, Tool
from substructure.io.assembly_toml import default_assembly
from substructure.sweep import sweep


def _tool_point(inputs):
    assembly, grid = inputs
    return assembly.receptance("tool.tip:y", frequency=grid)


def _overhang_variants():
    base = default_assembly()
    grid = Frequency.from_hz(np.linspace(20.0, 5000.0, 2500))
    variants = []
    for overhang in np.linspace(40.0, 100.0, 1000):
        tool = Tool(
            "tool",
            [
                Segment(f"{overhang - 30.0} mm", "12 mm", material="carbide"),
                Segment("30 mm", "12 mm", material="carbide", flutes=Flutes(0.8)),
            ],
        )
        variants.append(base.with_component(tool))
    return variants, grid


def _sweep(inputs):
    variants, grid = inputs
    return sweep(variants, "tool.tip:y", frequency=grid)


def benchmarks():
    yield (
        "default_tool_point_frf_10000_lines",
        lambda: (default_assembly(), Frequency.from_hz(np.linspace(20.0, 5000.0, 10000))),
        _tool_point,
        21,
    )
    yield ("overhang_sweep_build_1000_assemblies", lambda: None, lambda _: _overhang_variants(), 3)
    yield ("overhang_sweep_1000x2500_lines", _overhang_variants, _sweep, 5)
