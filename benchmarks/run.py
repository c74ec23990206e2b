"""Run every benchmark of `benchmarks/bench_*.py` and print one line per figure.

Each line reads ``bench: NAME MEDIAN_SECONDS``.  Speed is measured here and
only here (the tests assert no timings).  Each ``bench_*.py`` module defines
``benchmarks()``, yielding ``(name, setup, run, repeats)``: ``setup()`` builds
the inputs (not timed), ``run(inputs)`` is timed ``repeats`` times and the
median printed.

Usage: ``make bench`` or ``python benchmarks/run.py [NAME_SUBSTRING ...]``.
"""

from __future__ import annotations

import importlib.util
import statistics
import sys
import time
from pathlib import Path


def _load(path: Path):
    spec = importlib.util.spec_from_file_location(path.stem, path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def main(argv: list[str]) -> int:
    here = Path(__file__).parent
    wanted = argv[1:]
    for path in sorted(here.glob("bench_*.py")):
        for name, setup, run, repeats in _load(path).benchmarks():
            if wanted and not any(w in name for w in wanted):
                continue
            inputs = setup()
            run(inputs)  # warm-up: imports, caches of numpy and pint
            times = []
            for _ in range(repeats):
                t0 = time.perf_counter()
                run(inputs)
                times.append(time.perf_counter() - t0)
            print(f"bench: {name} {statistics.median(times):.6f}", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
