"""Compiled kernels: threads, signatures, exact poles, reciprocity (proposed tests/test_kernels.py)."""

import numpy as np
import pytest

from substructure import Frequency, InvalidValueError, Segment, Sensor
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


def test_read_only_inputs_are_taken_and_bad_arrays_refused():
    """The wrappers copy what the compiled code cannot take; the compiled code checks what it gets."""
    omega = np.linspace(1.0, 5000.0, 50)
    omega.flags.writeable = False
    sec = Segment("46 mm", "12 mm", material="carbide").section()
    segment_transfer_matrix(sec, 0.046, omega)
    y = stepped_beam_receptance([Segment("46 mm", "12 mm")], [0.0, 0.046], omega)
    y.flags.writeable = False
    from substructure._engine import Link, couple_substructures

    coupled = couple_substructures([([1, 2], y), ([3, 4], y)], [Link(2, 3, None)], [1, 4])
    assert np.all(np.isfinite(coupled))
    # straight calls with arrays of the wrong dtype, dimension or size: an exception, never a read past the end
    ei = np.array([[sec.EI]], dtype=complex)
    coef = np.empty((1, 1, 5), dtype=complex)
    k_max = np.empty((1, 1))
    args = [ei, ei.copy(), np.array([[sec.rhoA]]), np.array([[sec.rhoI]]), 100.0, coef, k_max]
    kernels._c.segment_coefficients(*args)
    with pytest.raises(TypeError, match="k_max"):
        kernels._c.segment_coefficients(*args[:6], k_max.astype(np.float32))
    with pytest.raises(TypeError, match="coef"):
        kernels._c.segment_coefficients(*args[:5], coef[0], k_max)
    with pytest.raises(ValueError, match="inconsistent"):
        kernels._c.segment_coefficients(*args[:5], np.empty((1, 1, 4), dtype=complex), k_max)
    out = np.empty((2, 2, 10), dtype=complex)
    good = [omega.copy(), coef, args[2], args[3], np.array([[0.046]]), np.full(1, -1, dtype=np.int64),
            np.zeros((0, 16, 10), dtype=complex), np.zeros(1, dtype=np.int64), np.array([1], dtype=np.int64),
            np.zeros(1, dtype=np.int64), out, False, 0, 10]
    with pytest.raises(ValueError, match="inconsistent"):
        kernels._c.chain_lines(*good)  # omega has 50 lines, out 10
    good[0] = omega[:10].copy()
    kernels._c.chain_lines(*good)
    kernels._c.chain_lines(omega[:10] - 1j, *good[1:])  # complex lines: the model seen through a window
    with pytest.raises(TypeError, match="omega: expected a 1-dimensional float64 or complex128 array"):
        kernels._c.chain_lines(omega[:10].astype(np.float32), *good[1:])
    for bad_nodes in ([2], [-1]):  # beyond the chain's one interval
        with pytest.raises(ValueError, match="nodes"):
            kernels._c.chain_lines(*good[:8], np.array(bad_nodes, dtype=np.int64), *good[9:])
    with pytest.raises(ValueError, match="lo, hi"):
        kernels._c.chain_lines(*good[:12], 0, 11)


def test_thread_count_from_the_environment(monkeypatch):
    monkeypatch.setenv(kernels.THREADS_VARIABLE, "3")
    assert kernels.threads() == 3
    for bad in ("0", "-2", "many", "1.5"):
        monkeypatch.setenv(kernels.THREADS_VARIABLE, bad)
        with pytest.raises(InvalidValueError, match=kernels.THREADS_VARIABLE):
            kernels.threads()
    monkeypatch.delenv(kernels.THREADS_VARIABLE)
    assert kernels.threads() >= 1


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


def test_a_line_does_not_depend_on_the_lines_computed_with_it():
    """Lines are computed four at a time; each must come out as if computed alone (any grid, any split)."""
    segs = [Segment("16 mm", "63 mm"), Segment("10 mm", "40 mm"), Segment("140 mm", "40 mm", "12 mm")]
    length = sum(s.length_m for s in segs)
    f = np.linspace(10.0, 9000.0, 103)  # power series at the low lines, exponentials above
    full = stepped_beam_receptance(segs, [0.0, 0.05, length], f)
    for start, n in ((1, 37), (2, 1), (3, 6), (50, 53)):
        part = stepped_beam_receptance(segs, [0.0, 0.05, length], f[start : start + n])
        assert np.array_equal(part, full[..., start : start + n])


def _beams(n=400):
    omega = 2 * np.pi * np.linspace(50.0, 6000.0, n)
    a = stepped_beam_receptance([Segment("60 mm", "40 mm"), Segment("40 mm", "30 mm")], [0.0, 0.05, 0.1], omega)
    b = stepped_beam_receptance([Segment("50 mm", "12 mm", material="carbide")], [0.0, 0.03, 0.05], omega)
    return omega, a, b


@pytest.mark.parametrize("rigid, ground", [(False, False), (True, False), (False, True)])
def test_a_coupling_step_picked_entries_are_the_whole_steps_to_the_bit(rigid, ground):
    """couple_link(rows=, cols=): any rows and columns (repeated, out of order, one) are those entries of the whole
    result, the same floats, also for a rigid link and a link to the ground."""
    omega, a, b = _beams()
    k = np.broadcast_to(np.array([[4e7, 1e6], [1e6, 6.5e4]])[:, :, None] * (1 + 0.01j), (2, 2, omega.size)).copy()
    src, idx = np.array([0, 0, 1, 1], dtype=np.int64), np.array([0, 2, 1, 2], dtype=np.int64)
    args = (a, b, 0, 2, -1 if ground else 1, 0, src, idx, k, rigid)
    if ground:
        args = (a, a, 0, 2, -1, 0, np.array([0, 1], dtype=np.int64), np.array([0, 2], dtype=np.int64), k, rigid)
    whole, finite = kernels.couple_link(*args)
    assert finite and whole.shape[0] == whole.shape[1]
    size = whole.shape[0]
    for rows, cols in ([[0], [0]], [[size - 1, 0, 2], [1, 1]], [list(range(size)), [size - 2]]):
        part, ok = kernels.couple_link(*args, rows=np.array(rows), cols=np.array(cols))
        assert ok and np.array_equal(part, whole[np.ix_(rows, cols)])
    with pytest.raises(ValueError, match="rows"):
        kernels.couple_link(*args, rows=np.array([size]), cols=np.array([0]))
    with pytest.raises(ValueError, match="cols"):
        kernels.couple_link(*args, rows=np.array([0]), cols=np.array([-1]))


def test_the_engine_picks_the_same_numbers_with_its_memo_with_copies_and_with_unconnected_outputs():
    from substructure._engine import Link, couple_substructures

    omega, a, b = _beams()
    k = np.array([[4e7, 1e6], [1e6, 6.5e4]], dtype=complex)[:, :, None]
    blocks = [(["s0", "s1", "s2"], a), (["t0", "t1", "t2"], b)]
    links = [Link("s0", None, k * 10), Link("s2", "t0", k)]
    outputs = ["t2", "t1", "s1"]
    whole = couple_substructures(blocks, links, outputs)
    pick = ([0, 2, 5], [0])
    memo = {}
    tokens = (["a", "b"], ["g", "j"])
    for _ in range(2):  # the second call takes the last step from the memo
        got = couple_substructures(blocks, links, outputs, memo, tokens, pick=pick)
        assert np.array_equal(got, whole[np.ix_(*pick)])
    assert any(len(key) == 6 for key in memo)  # the picked step is kept under its own key
    # two copies side by side, the tool's block differing between them
    b2 = b * 1.01
    both = couple_substructures([blocks[0], (blocks[1][0], np.concatenate([b, b2], axis=-1))], links, outputs,
                                copies=2, lines=omega.size, pick=pick)
    other = couple_substructures([blocks[0], (blocks[1][0], b2)], links, outputs)
    assert np.array_equal(both, np.concatenate([whole[np.ix_(*pick)], other[np.ix_(*pick)]], axis=-1))
    # an output on a block nothing connects: picked from the whole result, zero between the two
    apart = couple_substructures(blocks + [(["u0"], a[:2, :2])], links, outputs + ["u0"], pick=([0, 6], [6, 0]))
    full = couple_substructures(blocks + [(["u0"], a[:2, :2])], links, outputs + ["u0"])
    assert np.array_equal(apart, full[np.ix_([0, 6], [6, 0])]) and not apart[0, 0].any()


def test_one_blas_thread_limits_every_blas_and_restores_it():
    """The fits' and the diagnosis's limit (``_kernels.one_blas_thread``): numpy's and scipy's BLAS on one thread
    inside, as they were after (read through threadpoolctl, the library that sets it)."""
    import scipy.linalg  # noqa: F401  (its BLAS loaded, as in a fit)
    from threadpoolctl import threadpool_info

    def blas():
        return sorted((i["filepath"], i["num_threads"]) for i in threadpool_info() if i["user_api"] == "blas")

    before = blas()
    assert before
    with kernels.one_blas_thread():
        inside = blas()
    assert [n for _, n in inside] == [1] * len(before) and [p for p, _ in inside] == [p for p, _ in before]
    assert blas() == before


def test_one_blas_thread_in_threads_that_enter_and_leave_in_turn_leaves_the_process_as_it_was():
    """The limit is the process's and one thread holds it: threads entering and leaving in turn (A in, B in,
    A out, B out) run on one BLAS thread while A holds it and leave the process as it was (before, B restored
    the limit it had found, A's, and left the process on one thread)."""
    import threading

    import scipy.linalg  # noqa: F401  (its BLAS loaded, as in a fit)
    from threadpoolctl import ThreadpoolController, threadpool_info

    def blas():
        return [i["num_threads"] for i in threadpool_info() if i["user_api"] == "blas"]

    def set_in_a_thread(n):  # set from a thread that then ends: no thread keeps threadpoolctl's control
        t = threading.Thread(target=lambda: ThreadpoolController().limit(limits=n, user_api="blas"))
        t.start()
        t.join()

    original = blas()
    set_in_a_thread(2)  # two threads before, whatever the machine's default
    a_in, b_in, a_out = threading.Event(), threading.Event(), threading.Event()
    seen = {}

    def first():
        with kernels.one_blas_thread():
            a_in.set()
            b_in.wait(10)
            seen["both inside"] = blas()
        a_out.set()

    def second():
        a_in.wait(10)
        with kernels.one_blas_thread():
            b_in.set()
            a_out.wait(10)

    try:
        before = blas()
        threads = [threading.Thread(target=first), threading.Thread(target=second)]
        for t in threads:
            t.start()
        for t in threads:
            t.join(30)
        after = blas()
    finally:
        for n in sorted(set(original)):
            set_in_a_thread(n)
    assert before == [2] * len(before)
    assert seen["both inside"] == [1] * len(before)
    assert after == before
