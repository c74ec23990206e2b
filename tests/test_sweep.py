"""Sweeps give the same receptances as the assemblies one by one."""

import numpy as np
import pytest

from conftest import make_assembly, make_tool, rel_err
from substructure import Frequency, InvalidValueError, Sensor
from substructure.sweep import sweep


def test_overhang_sweep_equals_single_assemblies():
    grid = Frequency.from_range("20 Hz", "5000 Hz", "10 Hz")
    base = make_assembly()
    variants = [base.with_component(make_tool(L)) for L in (40.0, 55.0, 70.0, 85.0)]
    result = sweep(variants, "tool.tip", frequency=grid, chunk_lines=2 * len(grid))  # 2 chunks
    assert result.data.shape == (4, len(grid), 2, 2)
    for i, asm in enumerate(variants):
        single = asm.receptance("tool.tip", frequency=grid)
        assert rel_err(result[i].data, single.data) < 1e-12
        assert result[i].outputs == single.outputs


def test_sweep_over_joint_and_sensor_values():
    grid = Frequency.from_range("100 Hz", "5000 Hz", "20 Hz")
    base = make_assembly().attach(Sensor("acc", "tool.tip", "1 g"))
    variants = [
        base.with_component(make_tool(60.0)).without_sensors().attach(Sensor("acc", "tool@50 mm", f"{m} g"))
        for m in (0.0, 1.0, 3.0)
    ]
    result = sweep(variants, ["tool.tip:y"], ["tool@50 mm:y"], frequency=grid)
    for i, asm in enumerate(variants):
        single = asm.frf(["tool.tip:y"], ["tool@50 mm:y"], frequency=grid)
        assert rel_err(result[i].data, single.data) < 1e-12


def test_sweep_needs_one_structure():
    a = make_assembly()
    with pytest.raises(InvalidValueError, match="another structure"):
        sweep([a, a.attach(Sensor("acc", "tool.tip", "1 g"))], "tool.tip:y", frequency=[100.0, 200.0])
    with pytest.raises(InvalidValueError, match="no assemblies"):
        sweep([], "tool.tip")
