"""Make an installation's first run as fast as the next ones: ``python -m substructure._prepare``.

pip compiles the C kernels when it installs the package, so nothing is ever
compiled while a program runs.  Two things are still made on first use and
kept on disk: Python's bytecode of the package's modules (pip writes it for a
regular install, not for an editable one) and the cache of the unit
registry (pint's parsed definitions, see :data:`substructure.units.CACHE_VARIABLE`).
This step makes both ahead of time and checks that the compiled kernels load.
``make`` runs it after installing (so ``make demo`` and ``make test`` on a
fresh clone leave the prepared state); after ``pip install`` it is optional:
without it the first run takes about 0.15 s longer, once.
"""

from __future__ import annotations

import compileall
import os
import sys
import time

__all__ = ["prepare", "main"]


def prepare(compile_modules: bool = True) -> list[str]:
    """Check the compiled kernels, build the unit registry's cache and compile the modules.

    Parameters
    ----------
    compile_modules : bool
        Write the bytecode of every module of the package (skipped where the
        package folder is not writable: an installer did it already).

    Returns
    -------
    list of str
        One line per step, with the time it took.
    """
    lines = []
    t0 = time.perf_counter()
    from . import _kernels

    lines.append(f"compiled kernels: {_kernels._c.__file__} ({(time.perf_counter() - t0) * 1e3:.0f} ms)")
    t0 = time.perf_counter()
    from . import units

    folder = units.cache_folder()
    lines.append(f"unit registry: cache {folder or 'off'} ({(time.perf_counter() - t0) * 1e3:.0f} ms)")
    if compile_modules:
        package = os.path.dirname(os.path.abspath(__file__))
        t0 = time.perf_counter()
        if os.access(package, os.W_OK):
            ok = compileall.compile_dir(package, quiet=1, workers=1)
            state = "written" if ok else "written, with errors"
        else:
            state = "skipped (package folder not writable)"
        lines.append(f"bytecode of {package}: {state} ({(time.perf_counter() - t0) * 1e3:.0f} ms)")
    return lines


def main() -> int:
    """Run :func:`prepare` and print what it did; returns the exit status."""
    for line in prepare():
        print(f"substructure: {line}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
