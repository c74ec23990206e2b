"""Build of the compiled kernels, ``substructure._ckernels`` (the rest of the metadata is in pyproject.toml).

The kernels are a plain C extension (C99 with the GCC/Clang vector
extensions, the Python headers, no numpy headers), compiled when the package
is installed, so that no program compiles anything at run time.  Flags:
optimised, IEEE arithmetic without reassociation (no ``-ffast-math``) and
without contraction into fused multiply-adds (``-ffp-contract=off``): the
compensated determinants of the kernels need exact products and sums, and
the results then do not depend on the processor.  On x86-64 the line loop is
also compiled for AVX2, chosen when the module loads (``target_clones``).

The SHA-256 of the source is compiled in, so that a checkout whose
``_ckernels.c`` was edited after the build is told to rebuild
(:mod:`substructure._kernels`).
"""

import hashlib
from pathlib import Path

from setuptools import Extension, setup

SOURCE = "substructure/_ckernels.c"
FLAGS = ["-O3", "-std=gnu99", "-fno-fast-math", "-ffp-contract=off", "-fno-math-errno"]

digest = hashlib.sha256(Path(__file__).with_name("substructure").joinpath("_ckernels.c").read_bytes()).hexdigest()

setup(
    ext_modules=[
        Extension(
            "substructure._ckernels",
            sources=[SOURCE],
            extra_compile_args=FLAGS,
            define_macros=[("KERNELS_SOURCE_SHA256", f'"{digest}"')],
        )
    ],
)
