"""Run the benchmarks of `benchmarks/bench_*.py` and print one line per figure.

Each line reads ``bench: NAME VALUE``.  Speed is measured here and only here
(the tests assert no timings).  A ``bench_*.py`` module defines either or both
of:

* ``benchmarks()``, yielding ``(name, setup, run, repeats)``: ``setup()``
  builds the inputs (not timed), ``run(inputs)`` is timed ``repeats`` times
  after one warm-up call and the median is printed in seconds;
* ``figures()``, yielding ``(name, compute)``: ``compute()`` measures
  something itself (a ratio of two timings taken in one run, a memory
  figure) and returns ``{NAME: VALUE, ...}``, each printed as one line.

Usage: ``make bench`` or ``python benchmarks/run.py [NAME_SUBSTRING ...]``
(a module's figures run when any of their names, or the group name, matches).
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


def _value(v) -> str:
    return f"{v:.6f}" if isinstance(v, float) else str(v)


def main(argv: list[str]) -> int:
    here = Path(__file__).parent
    sys.path.insert(0, str(here))
    wanted = argv[1:]

    def chosen(*names: str) -> bool:
        return not wanted or any(w in n for w in wanted for n in names)

    for path in sorted(here.glob("bench_*.py")):
        module = _load(path)
        for name, setup, run, repeats in getattr(module, "benchmarks", lambda: ())():
            if not chosen(name):
                continue
            inputs = setup()
            run(inputs)  # warm-up: imports, caches of numpy and pint
            times = []
            for _ in range(repeats):
                t0 = time.perf_counter()
                run(inputs)
                times.append(time.perf_counter() - t0)
            print(f"bench: {name} {statistics.median(times):.6f}", flush=True)
        for group, compute in getattr(module, "figures", lambda: ())():
            names = getattr(compute, "names", (group,))
            if not chosen(group, *names):
                continue
            for name, value in compute().items():
                print(f"bench: {name} {_value(value)}", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
