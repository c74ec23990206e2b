"""Build of the compiled kernels, ``substructure._ckernels`` (the rest of the metadata is in pyproject.toml).

The kernels are a plain C extension (C99, the Python headers, no numpy
headers), compiled when the package is installed, so that no program compiles
anything at run time.  Flags: optimised, IEEE arithmetic without
reassociation (no ``-ffast-math``) and without contraction into fused
multiply-adds (``-ffp-contract=off``): the compensated determinants of the
kernels need exact products and sums, and results then do not depend on the
processor.
"""

from setuptools import Extension, setup
from setuptools.command.build_ext import build_ext

UNIX_FLAGS = ["-O3", "-std=c99", "-fno-fast-math", "-ffp-contract=off", "-fno-math-errno"]
MSVC_FLAGS = ["/O2", "/fp:precise"]


class BuildKernels(build_ext):
    """``build_ext`` with the floating-point flags of the compiler in use."""

    def build_extensions(self):
        flags = MSVC_FLAGS if self.compiler.compiler_type == "msvc" else UNIX_FLAGS
        for ext in self.extensions:
            ext.extra_compile_args = list(flags)
        super().build_extensions()


setup(
    ext_modules=[Extension("substructure._ckernels", sources=["substructure/_ckernels.c"])],
    cmdclass={"build_ext": BuildKernels},
)
