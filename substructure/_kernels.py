"""Compiled kernels (internal): Timoshenko segments, free-free chains and coupling updates.

The numerical hot path of every model evaluation.  The kernels are a small C
extension, :mod:`substructure._ckernels` (source ``_ckernels.c`` next to this
file), compiled when the package is installed: nothing is compiled when a
program runs, so the first model evaluation after installing costs what every
later one does.  Each kernel runs one loop over frequency lines and does all
the work of a line in registers and small scratch arrays: the closed-form
transfer matrices of the segments, their product and the free-end receptance
formula (:func:`chain_receptance`), and the 2x2 update of the coupling engine
(:func:`couple_link`).  Nothing is allocated per line and no intermediate
array over all lines is formed.

The mathematics is the one documented in :mod:`substructure.beams` and
:mod:`substructure._engine`; those modules prepare the inputs (sections,
intervals, nodes, cluster bookkeeping) and call the functions here, which are
the only implementation of the formulas.  This module holds what is left in
Python: the checks of dtypes and layouts (:func:`c_array`), and the split of
the lines between threads (:func:`over_lines`).

Floating point (see ``_ckernels.c``): IEEE double arithmetic without
reassociation or fused multiply-adds, so that the compensated determinants
are exact and the results do not depend on the processor's instruction set;
a division by zero gives inf/nan as in numpy.

Every entry point takes SI arrays (float64 and complex128, C-contiguous) and
is stable: model-updating code may call :func:`chain_receptance` and
:func:`couple_link` directly.
"""

from __future__ import annotations

import contextlib
import importlib
import itertools
import os
import threading

import numpy as np

from .errors import InvalidValueError, SubstructureError

try:
    # The C extension by name: it imports nothing of the package, and a static reading of
    # `from . import _ckernels` (which cannot see an extension module) takes it for the package itself.
    _c = importlib.import_module("._ckernels", __package__)
except ImportError as exc:  # pragma: no cover - an installation problem, not a user's input
    raise SubstructureError(
        "the compiled kernels of substructure (substructure._ckernels) are missing or do not load "
        f"({exc}); they are built when the package is installed: run `make .venv/.installed` in a "
        "checkout, or `python -m pip install -e .` (a C compiler and the Python headers are needed)"
    ) from exc

def _check_build() -> None:
    """In a checkout (the C source next to this file), refuse a build older than the source."""
    import hashlib

    source = os.path.join(os.path.dirname(__file__), "_ckernels.c")
    try:
        with open(source, "rb") as fh:
            digest = hashlib.sha256(fh.read()).hexdigest()
    except OSError:  # an installed package ships the compiled module only
        return
    if digest != getattr(_c, "SOURCE_SHA256", None):
        raise SubstructureError(
            f"the compiled kernels (substructure._ckernels) were built from another version of {source}; "
            "rebuild them: `make .venv/.installed` in the checkout, or `python -m pip install -e .`"
        )


_check_build()

__all__ = [
    "transfer_matrices",
    "segment_coefficients",
    "chain_receptance",
    "couple_link",
    "threads",
    "c_array",
    "over_lines",
    "one_blas_thread",
]


def c_array(a, dtype) -> np.ndarray:
    """``a`` as a C-contiguous, writeable array of ``dtype``, copied only when needed.

    Parameters
    ----------
    a : array_like
        The values.
    dtype : dtype
        ``float``, ``complex`` or ``np.int64``: the kernels take float64,
        complex128 and int64 arrays only.

    Returns
    -------
    ndarray
        ``a`` itself when it already has the layout and dtype, else a copy.
    """
    if type(a) is np.ndarray and a.dtype == dtype and a.flags.c_contiguous and a.flags.writeable:
        return a  # the common case, without np.require's general checks (a kernel call takes several arrays)
    return np.require(a, dtype=dtype, requirements=("C", "W"))


MIN_LINES_PER_TASK = 2048
"""Lines below which a kernel call is not split between threads."""

THREADS_VARIABLE = "SUBSTRUCTURE_NUM_THREADS"
"""Environment variable with the number of threads of the kernels (default: the CPUs this process may use)."""

_pool_state: dict = {}


def threads() -> int:
    """Threads the kernels use: ``SUBSTRUCTURE_NUM_THREADS``, default the CPUs available to this process.

    Returns
    -------
    int
        At least 1.  A value that is not a positive integer is an error
        (:class:`~substructure.errors.InvalidValueError`).
    """
    text = os.environ.get(THREADS_VARIABLE, "").strip()
    if text:
        try:
            n = int(text)
        except ValueError:
            n = 0
        if n < 1:
            raise InvalidValueError(f"{THREADS_VARIABLE}: got {text!r}; expected a positive whole number")
        return n
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except (AttributeError, OSError):  # not on Linux
        return max(1, os.cpu_count() or 1)


_blas_state: dict = {}
_blas_lock = threading.Lock()


@contextlib.contextmanager
def one_blas_thread():
    """A context in which the BLAS libraries numpy and scipy load run on one thread.

    The linear algebra of a fit and of the semi-discretization works on small
    or tall, narrow matrices (a Jacobian of a few thousand residuals by a few
    parameters, eigenvalue problems of tens of states): there a second BLAS
    thread costs more in synchronisation than it computes, and on a machine
    whose cores are busy (other fits, the kernels' threads, other processes)
    it is several times slower.  Measured: a diagnosis of the FE rig took 14 s
    with one BLAS thread and 20 s with two, on two cores.  The libraries are
    looked up once per process (the first call, after numpy and scipy are
    loaded).

    The limit is the process's (BLAS has one thread count) and one thread
    holds it at a time (threadpoolctl, which sets it, lets one thread set
    limits so that threads do not fight over them): a context entered while
    another thread's holds the limit runs under that limit and neither sets
    nor restores it.  So threads that enter and leave in any order (fits in
    a study's worker threads) leave the process as it was; a thread still
    inside when the holder leaves finishes under the process's own setting.
    Nested contexts in one thread hold it until the outermost leaves.

    Returns
    -------
    context manager
    """
    me = threading.get_ident()
    with _blas_lock:
        pid = os.getpid()
        if _blas_state.get("pid") != pid:  # first call, or a forked child (the parent's holder is not its own)
            import scipy.linalg  # noqa: F401  (its BLAS too, loaded before the lookup)
            from threadpoolctl import ThreadpoolController  # only where linear algebra runs: light start-up

            _blas_state.update(controller=ThreadpoolController(), pid=pid, holder=None, depth=0, limiter=None)
        mine = _blas_state["holder"] in (None, me)
        if _blas_state["holder"] is None:
            _blas_state["limiter"] = _blas_state["controller"].limit(limits=1, user_api="blas").__enter__()
            _blas_state["holder"] = me
        _blas_state["depth"] += mine
    try:
        yield
    finally:
        if mine:
            with _blas_lock:
                _blas_state["depth"] -= 1
                if _blas_state["depth"] == 0:
                    _blas_state["limiter"].__exit__(None, None, None)
                    _blas_state.update(limiter=None, holder=None)


def _pool():
    """The helper threads (``threads() - 1``: the calling thread works too), one pool per process.

    A forked child gets its own pool (the parent's threads do not exist in it).
    """
    pid = os.getpid()
    n = max(1, threads() - 1)
    if _pool_state.get("pid") != pid or _pool_state.get("size") != n:
        from concurrent.futures import ThreadPoolExecutor  # only when a call is split: keeps start-up light

        _pool_state["pool"] = ThreadPoolExecutor(max_workers=n, thread_name_prefix="substructure-kernel")
        _pool_state["pid"] = pid
        _pool_state["size"] = n
    return _pool_state["pool"]


def over_lines(kernel, n: int, *args) -> bool:
    """Run ``kernel(*args, lo, hi)`` over the lines ``0 .. n - 1``, split between threads.

    The kernels release the GIL, so plain Python threads run them in
    parallel, each task writing its own lines of the output.  The lines are
    cut into a few tasks per thread; the calling thread and ``threads() - 1``
    helpers take tasks in turn until none is left, so that a thread slowed by
    other work on the machine just takes fewer.  Calls of fewer than
    ``2 * MIN_LINES_PER_TASK`` lines, or with one thread, run in the calling
    thread alone.  The result does not depend on the split: every line is
    computed by the same code from the same inputs.

    Parameters
    ----------
    kernel : callable
        A compiled kernel taking ``lo, hi`` last.
    n : int
        Number of lines.
    *args
        The kernel's other arguments.

    Returns
    -------
    bool
        The ``and`` of the kernel's results (True for kernels that return nothing).
    """
    if n < 2 * MIN_LINES_PER_TASK:  # the usual call of a fit: not split (and the environment not read)
        return kernel(*args, 0, n) is not False
    n_threads = threads()
    n_tasks = min(4 * n_threads, n // MIN_LINES_PER_TASK) if n_threads > 1 else 1
    if n_tasks <= 1:
        return kernel(*args, 0, n) is not False
    bounds = [n * k // n_tasks for k in range(n_tasks + 1)]
    claim = itertools.count()  # next() is atomic under the GIL

    def work() -> bool:
        ok = True
        for k in iter(claim.__next__, None):
            if k >= n_tasks:
                return ok
            ok = (kernel(*args, bounds[k], bounds[k + 1]) is not False) and ok
        return ok

    helpers = [_pool().submit(work) for _ in range(min(n_threads, n_tasks) - 1)]
    ok = work()
    # a helper still queued (behind other callers' helpers) has nothing left to do
    return all([h.cancel() or h.result() for h in helpers]) and ok


def segment_coefficients(ei, kga, rhoa, rhoi, omega_max):
    """Per-segment constants of the closed form, and each segment's largest wavenumber.

    Parameters
    ----------
    ei, kga : complex128 ndarray (n_u, n_c)
        Bending stiffness ``EI`` [N m^2] and shear stiffness ``kappa G A`` [N].
    rhoa, rhoi : float64 ndarray (n_u, n_c)
        Mass per length [kg/m] and rotary inertia per length [kg m].
    omega_max : float
        Angular frequency [rad/s] at which the wavenumbers are taken.

    Returns
    -------
    coef : complex128 ndarray (n_u, n_c, 5)
        ``a / omega^2, e / omega^2, rhoA / EI, 1 / EI, 1 / kGA``.
    k_max : float64 ndarray (n_u, n_c)
        ``sqrt(max(|s1|, |s2|))`` at ``omega_max`` [1/m]: where a chain is cut.
    """
    ei, kga = c_array(ei, complex), c_array(kga, complex)
    coef = np.empty(ei.shape + (5,), dtype=np.complex128)
    k_max = np.empty(ei.shape, dtype=np.float64)
    _c.segment_coefficients(ei, kga, c_array(rhoa, float), c_array(rhoi, float), float(omega_max), coef, k_max)
    return coef, k_max


chain_lines = _c.chain_lines
"""The chain kernel:
``chain_lines(omega, coef, rhoa, rhoi, length, slot, table, seg_of, nodes, place, out, table_only, lo, hi)``,
``omega`` float64 (real lines) or complex128 (``omega - i sigma``: the model seen through an exponential window)."""

couple_lines = _c.couple_lines
"""The coupling kernel:
``couple_lines(ya, yb, a_src, a_idx, b_src, b_idx, src, idx, stiffness, rigid, rows, cols, out, lo, hi)``."""

transcendental_floor = _c.transcendental_floor
"""``exp(x) + cos(y) + sin(y)`` summed over arrays: the floor of the beam kernel (benchmarks only)."""

_NO_NODES = np.zeros(0, dtype=np.int64)
_NO_OUT = np.zeros((0, 0, 0), dtype=np.complex128)
# the shared segments' transfer matrices: (n_shared, 16 entries row-major, n_f lines)


def _shared_table(omega, coef, rhoa, rhoi, length, shared):
    """``slot`` (place of each shared segment in the table, else -1) and the table of their transfer matrices."""
    slot = np.full(shared.size, -1, dtype=np.int64)
    slot[shared] = np.arange(int(np.count_nonzero(shared)))
    table = np.empty((int(np.count_nonzero(shared)), 16, omega.size), dtype=np.complex128)
    if table.size:
        over_lines(chain_lines, omega.size, omega, coef, rhoa, rhoi, length, slot, table,
                   _NO_NODES, _NO_NODES, _NO_NODES, _NO_OUT, True)
    return slot, table


def transfer_matrices(omega, ei, kga, rhoa, rhoi, length):
    """``T = exp(A L)`` of uniform segments at every line.

    Parameters
    ----------
    omega : float64 or complex128 ndarray (n_f,)
        Angular frequencies [rad/s]; complex for the model at a complex
        frequency (``omega - i sigma``: seen through an exponential window).
    ei, kga : complex128 ndarray (n_u, 1)
        ``EI`` [N m^2] and ``kappa G A`` [N] of each segment.
    rhoa, rhoi, length : float64 ndarray (n_u, 1)
        ``rho A`` [kg/m], ``rho I`` [kg m] and length [m].

    Returns
    -------
    complex128 ndarray (n_u, n_f, 4, 4)
        State ``[w, psi, V, M]``.
    """
    omega = c_array(omega, complex if np.iscomplexobj(omega) else float)
    rhoa, rhoi, length = (c_array(v, float) for v in (rhoa, rhoi, length))
    coef, _ = segment_coefficients(ei, kga, rhoa, rhoi, 0.0)
    _, table = _shared_table(omega, coef, rhoa, rhoi, length, np.ones(coef.shape[0], dtype=bool))
    return np.ascontiguousarray(np.moveaxis(table.reshape(coef.shape[0], 4, 4, omega.size), -1, 1))


def chain_receptance(omega, ei, kga, rhoa, rhoi, length, shared, seg_of, nodes, place, out=None):
    """Free-free receptances of chains of uniform intervals, for many configurations.

    Parameters
    ----------
    omega : float64 or complex128 ndarray (n_f,)
        Angular frequency lines [rad/s]; complex for the model at a complex
        frequency (``omega - i sigma``: seen through an exponential window).
    ei, kga : complex128 ndarray (n_u, n_c)
        ``EI`` [N m^2] and ``kappa G A`` [N] of each distinct segment ``u`` in
        each configuration ``c``.
    rhoa, rhoi, length : float64 ndarray (n_u, n_c)
        ``rho A`` [kg/m], ``rho I`` [kg m] and length [m].
    shared : bool ndarray (n_u,)
        Segment ``u`` is the same in every configuration: its transfer
        matrices are computed once per line and reused.
    seg_of : int64 ndarray (n_int,)
        The segment of each interval, base to tip.
    nodes : int64 ndarray (m,)
        Sorted, distinct node indices in ``0 .. n_int`` (node ``k`` is the
        base of interval ``k``; node ``n_int`` is the tip).
    place : int64 ndarray (m,)
        Where node ``i`` goes in the result (a permutation of ``0 .. m - 1``).
    out : complex128 ndarray (2m, 2m, n_c * n_f), optional
        Where to write the result (C-contiguous); a new array by default.

    Returns
    -------
    complex128 ndarray (2m, 2m, n_c * n_f)
        DOFs ``(y, theta)`` per node [m/N, 1/N, 1/(N m)]; the last axis runs
        over configurations first (``index = c * n_f + line``).
    """
    omega = c_array(omega, complex if np.iscomplexobj(omega) else float)
    rhoa, rhoi, length = (c_array(v, float) for v in (rhoa, rhoi, length))
    seg_of, nodes, place = (c_array(v, np.int64) for v in (seg_of, nodes, place))
    n_c = np.shape(ei)[1]
    m = nodes.size
    coef, _ = segment_coefficients(ei, kga, rhoa, rhoi, 0.0)
    slot, table = _shared_table(omega, coef, rhoa, rhoi, length, np.asarray(shared, dtype=bool))
    shape = (2 * m, 2 * m, n_c * omega.size)
    if out is None:
        out = np.empty(shape, dtype=np.complex128)
    elif out.shape != shape or out.dtype != np.complex128 or not out.flags.c_contiguous:
        raise ValueError(f"out: expected a C-contiguous complex128 array of shape {shape}")
    over_lines(chain_lines, out.shape[-1], omega, coef, rhoa, rhoi, length, slot, table, seg_of, nodes, place,
               out, False)
    return out


_NO_STIFFNESS = np.zeros((2, 2, 1), dtype=np.complex128)


def couple_link(ya, yb, a_src, a_idx, b_src, b_idx, src, idx, stiffness, rigid, rows=None, cols=None):
    """One link of the coupling engine on all lines: ``Y_c = Y - (Y B^T) W (B Y)``.

    ``Y`` is block diagonal, ``diag(ya, yb)``, with 2x2 blocks per point; a
    point is ``(src, idx)``, ``src`` 0 for ``ya`` and 1 for ``yb``.  The link
    acts on ``u_a - u_b`` (``b_src < 0``: to the ground) with ``W = S^-1``
    (``rigid``) or ``W = K (I + S K)^-1``, ``S = B Y B^T``.

    Parameters
    ----------
    ya, yb : complex128 ndarray (2p, 2p, n)
        The two clusters' receptances (``yb`` is ignored when every point is
        in ``ya``; pass ``ya`` again).
    a_src, a_idx, b_src, b_idx : int
        The link's two points.
    src, idx : int64 ndarray (k,)
        The points kept in the result.
    stiffness : complex128 ndarray (2, 2, n) or (2, 2, 1)
        The link's dynamic stiffness (ignored when ``rigid``).
    rigid : bool
        A rigid connection.
    rows, cols : int64 ndarray, optional
        Only these entries of the result: DOF indices ``2 j + d`` over the
        kept points (default every one); the entries are the same numbers as
        those of the whole result.

    Returns
    -------
    out : complex128 ndarray (2k, 2k, n), or (len(rows), len(cols), n)
        The coupled receptances between the kept points.
    finite : bool
        Whether every entry computed is finite.
    """
    ya = c_array(ya, complex)
    yb = ya if yb is ya else c_array(yb, complex)
    src, idx = c_array(src, np.int64), c_array(idx, np.int64)
    stiffness = _NO_STIFFNESS if rigid else c_array(stiffness, complex)
    every = np.arange(2 * src.size, dtype=np.int64)
    rows = every if rows is None else c_array(rows, np.int64)
    cols = every if cols is None else c_array(cols, np.int64)
    n = ya.shape[2]
    out = np.empty((rows.size, cols.size, n), dtype=np.complex128)
    finite = over_lines(couple_lines, n, ya, yb, int(a_src), int(a_idx), int(b_src), int(b_idx), src, idx,
                        stiffness, bool(rigid), rows, cols, out)
    return out, finite
