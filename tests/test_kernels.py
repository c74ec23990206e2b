"""Compiled kernels: threads, signatures, exact poles, reciprocity (proposed tests/test_kernels.py)."""

import numpy as np
import pytest

from substructure import Frequency, Segment, Sensor
from substructure import _kernels as kernels
from substructure.beams import segment_transfer_matrix, stepped_beam_receptance
from substructure.io.assembly_toml import default_assembly


@pytest.fixture
def one_thread(monkeypatch):
    def use():
        monkeypatch.setattr(kernels, "threads", lambda: 1)
    return use


def test_threads_give_bit_identical_results(one_thread):
    asm = default_assembly().attach(Sensor("acc", "tool.tip", "2 g"))
    grid = Frequency.from_hz(np.linspace(20.0, 8000.0, 12000))  # several tasks per call
    points = ["tool.tip", "tool.tip-20 mm", "holder@30 mm"]
    split = asm.frf(points, frequency=grid).data
    one_thread()
    assert np.array_equal(split, asm.frf(points, frequency=grid).data)


def test_one_compiled_signature_per_kernel_even_for_read_only_inputs():
    omega = np.linspace(1.0, 5000.0, 50)
    omega.flags.writeable = False
    sec = Segment("46 mm", "12 mm", material="carbide").section()
    segment_transfer_matrix(sec, 0.046, omega)
    y = stepped_beam_receptance([Segment("46 mm", "12 mm")], [0.0, 0.046], omega)
    y.flags.writeable = False
    from substructure._engine import Link, couple_substructures

    couple_substructures([([1, 2], y), ([3, 4], y)], [Link(2, 3, None)], [1, 4])
    for kernel in (kernels.segment_coefficients, kernels.chain_lines, kernels.couple_lines):
        assert len(kernel.signatures) == 1


def test_blocks_between_points_are_exact_transposes():
    """Below the diagonal from reciprocity (one piece: k L <= 8 at the highest line)."""
    segs = [Segment("120 mm", "70 mm", "40 mm"), Segment("150 mm", "90 mm", "40 mm")]
    y = stepped_beam_receptance(segs, [0.27, 0.0, 0.1, 0.2], np.linspace(10.0, 3000.0, 500))
    for i in range(4):
        for j in range(4):
            if i != j:
                assert np.array_equal(y[2 * i : 2 * i + 2, 2 * j : 2 * j + 2],
                                      y[2 * j : 2 * j + 2, 2 * i : 2 * i + 2].transpose(1, 0, 2))


def test_lines_next_to_a_pole_stay_finite():
    """The compensated determinant: a root finder may land on a natural frequency's last bit."""
    segs = [Segment("120 mm", "70 mm", "40 mm"), Segment("150 mm", "90 mm", "40 mm"),
            Segment("60 mm", "110 mm", "40 mm")]
    length = sum(s.length_m for s in segs)
    f0 = 3153.11368672156  # found by brentq on the tip receptance of this (lossy) spindle: near a pole
    f = f0 * (1.0 + np.arange(-50, 51) * 2.2e-16)
    y = stepped_beam_receptance(segs, [length], f)
    assert np.all(np.isfinite(y))
