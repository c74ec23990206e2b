"""Core library benchmarks: one tool point FRF, an overhang sweep, and the ratios of issue 12.

Timed (median seconds): the default assembly's tool point FRF at 10,000
frequency lines (target under 20 ms on 2 cores), 1,000 tool overhangs at 2,500
lines (target under 2 s), and the building of those 1,000 variants.

Figures (each measured within one run, so that the load of the machine
weighs on both sides of a ratio alike):

* ``beam_kernel_over_floor``: the beam kernel's time per segment and line
  over the time of the transcendental functions the closed form needs
  (exp of both wavenumbers' real parts, cos and sin of their imaginary
  parts), both on one thread in this process (goal: at most 2);
* ``sweep_build_over_compute``: building 1,000 variants through the SI path
  (``Segment.from_si``, quantities parsed once) over evaluating them with
  ``sweep`` (goal: at most 0.5);
* ``frf_memory_bytes_per_line_above_result``: the peak memory of a 1-million-line
  tool point FRF beyond its own data, per line (goal: under 100 B).
"""

from __future__ import annotations

import os
import statistics
import time
import tracemalloc

import numpy as np

from substructure import Flutes, Frequency, Segment, Tool, get_material
from substructure.io.assembly_toml import default_assembly
from substructure.sweep import sweep

GRID_SWEEP = (20.0, 5000.0, 2500)
OVERHANGS_MM = np.linspace(40.0, 100.0, 1000)


def _tool_point(inputs):
    assembly, grid = inputs
    return assembly.receptance("tool.tip:y", frequency=grid)


def _overhang_variants():
    """The 1,000 variants from strings, as a user writes them one by one."""
    base = default_assembly()
    variants = []
    for overhang in OVERHANGS_MM:
        tool = Tool(
            "tool",
            [
                Segment(f"{overhang - 30.0} mm", "12 mm", material="carbide"),
                Segment("30 mm", "12 mm", material="carbide", flutes=Flutes(0.8)),
            ],
        )
        variants.append(base.with_component(tool))
    return variants


def _overhang_variants_si(base=None):
    """The same 1,000 variants through the SI path: every quantity parsed once."""
    base = default_assembly() if base is None else base
    carbide = get_material("carbide")
    fluted = Segment.from_si(0.030, 0.012, material=carbide, flutes=Flutes(0.8))
    return [
        base.with_component(Tool("tool", [Segment.from_si(overhang / 1000.0 - 0.030, 0.012, material=carbide), fluted]))
        for overhang in OVERHANGS_MM
    ]


def _sweep_grid() -> Frequency:
    return Frequency.from_hz(np.linspace(*GRID_SWEEP))


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
    yield ("overhang_sweep_build_1000_assemblies_si", lambda: None, lambda _: _overhang_variants_si(), 3)
    yield ("overhang_sweep_1000x2500_lines", lambda: (_overhang_variants_si(), _sweep_grid()), _sweep, 5)


# -- ratios ---------------------------------------------------------------------------------------


def _beam_kernel_over_floor() -> dict:
    """The default assembly's three beams (8 segments, 10,000 lines, 20 Hz to 5 kHz), one thread.

    Kernel: ``_kernels.chain_receptance`` on prepared SI arrays, the way
    ``beams`` calls it (spindle: its tip; holder and tool: base and tip),
    into preallocated outputs.  Floor: ``exp(x)``, ``cos(y)`` and ``sin(y)``
    of ``r L = x + i y`` for both wavenumbers ``r`` of every segment and
    line, the C library's functions called from compiled code in this
    process (``_kernels.transcendental_floor``).  The two are timed in turn,
    41 times each, in CPU time of this thread (``time.thread_time``: time
    the thread spends waiting for a core while other programs run is not
    counted); the medians are compared.
    """
    from substructure import _kernels

    asm = default_assembly()
    omega = 2.0 * np.pi * np.linspace(20.0, 5000.0, 10000)
    calls, xs, ys, n_seg = [], [], [], 0
    for name, nodes in (("spindle", "tip"), ("holder", "both"), ("tool", "both")):
        segs = asm.component(name).segments
        secs = [s.section() for s in segs]
        col = lambda values, dtype: np.array([[v] for v in values], dtype=dtype)  # noqa: E731
        ei, kga = col([s.EI for s in secs], complex), col([s.kGA for s in secs], complex)
        rhoa, rhoi = col([s.rhoA for s in secs], float), col([s.rhoI for s in secs], float)
        length = col([s.length_m for s in segs], float)
        node_list = [len(segs)] if nodes == "tip" else [0, len(segs)]
        args = (omega, ei, kga, rhoa, rhoi, length, np.zeros(len(segs), bool), np.arange(len(segs), dtype=np.int64),
                np.array(node_list, dtype=np.int64), np.arange(len(node_list), dtype=np.int64))
        calls.append((args, _kernels.chain_receptance(*args)))
        n_seg += len(segs)
        coef, _ = _kernels.segment_coefficients(ei, kga, rhoa, rhoi, 0.0)
        for u, seg in enumerate(segs):  # the wavenumbers r L of the closed form, as the kernel forms them
            ca, ce, cr = coef[u, 0, :3]
            w2 = omega**2
            a, e = w2 * ca, w2 * ce
            half = 0.5 * (a - e)
            root = np.sqrt(half * half + w2 * cr)
            for s in (0.5 * (a + e) + root, 0.5 * (a + e) - root):
                r = np.sqrt(s) * seg.length_m
                xs.append(r.real)
                ys.append(r.imag)
    x, y = np.concatenate(xs), np.concatenate(ys)
    saved = os.environ.get(_kernels.THREADS_VARIABLE)
    os.environ[_kernels.THREADS_VARIABLE] = "1"
    try:
        kernel, floor = [], []
        for _ in range(41):
            t0 = time.thread_time()
            for args, out in calls:
                _kernels.chain_receptance(*args, out=out)
            kernel.append(time.thread_time() - t0)
            t0 = time.thread_time()
            _kernels.transcendental_floor(x, y)
            floor.append(time.thread_time() - t0)
    finally:
        if saved is None:
            del os.environ[_kernels.THREADS_VARIABLE]
        else:
            os.environ[_kernels.THREADS_VARIABLE] = saved
    per_kernel = statistics.median(kernel) / (n_seg * omega.size)
    per_floor = statistics.median(floor) / (n_seg * omega.size)
    return {
        "beam_kernel_ns_per_segment_line": per_kernel * 1e9,
        "beam_kernel_floor_ns_per_segment_line": per_floor * 1e9,
        "beam_kernel_over_floor": per_kernel / per_floor,
    }


_beam_kernel_over_floor.names = ("beam_kernel_over_floor",)


def _sweep_build_over_compute() -> dict:
    """Building the 1,000 overhang variants (SI path, and from strings) over sweeping them; 3 turns each."""
    base = default_assembly()
    grid = _sweep_grid()
    variants = _overhang_variants_si(base)
    sweep(variants, "tool.tip:y", frequency=grid)  # warm-up
    build, build_strings, compute = [], [], []
    for _ in range(3):
        t0 = time.perf_counter()
        variants = _overhang_variants_si(base)
        build.append(time.perf_counter() - t0)
        t0 = time.perf_counter()
        _overhang_variants()
        build_strings.append(time.perf_counter() - t0)
        t0 = time.perf_counter()
        sweep(variants, "tool.tip:y", frequency=grid)
        compute.append(time.perf_counter() - t0)
    b, s, c = (statistics.median(v) for v in (build, build_strings, compute))
    return {"sweep_build_over_compute": b / c, "sweep_build_strings_over_compute": s / c}


_sweep_build_over_compute.names = ("sweep_build_over_compute",)


def _frf_memory() -> dict:
    """Peak memory (tracemalloc: numpy reports its buffers) of the tool point FRF at 1,000,000 lines.

    The grid exists before the measurement; the figure is the peak during
    ``Assembly.receptance`` minus the FRF's data (16 B per line), per line.
    """
    asm = default_assembly()
    n = 1_000_000
    grid = Frequency.from_hz(np.linspace(20.0, 5000.0, n))
    asm.receptance("tool.tip:y", frequency=grid.crop(20.0, 100.0))  # warm-up
    tracemalloc.start()
    try:
        frf = asm.receptance("tool.tip:y", frequency=grid)
        _, peak = tracemalloc.get_traced_memory()
    finally:
        tracemalloc.stop()
    return {"frf_memory_bytes_per_line_above_result": (peak - frf.data.nbytes) / n}


_frf_memory.names = ("frf_memory_bytes_per_line_above_result",)


def figures():
    yield "beam_kernel", _beam_kernel_over_floor
    yield "sweep_build", _sweep_build_over_compute
    yield "frf_memory", _frf_memory
