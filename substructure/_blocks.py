"""Small-matrix algebra vectorised over frequency lines (internal).

The numerical core works on arrays of shape ``(r, c, n_freq)`` (frequency
*last*), so that a 2x2 product or inverse is a handful of elementwise numpy
operations on contiguous arrays of length ``n_freq``.  For the 2x2 systems of
beam and joint algebra this is about ten times faster than numpy's batched
LAPACK calls (measured at 10,000 lines: inverse 0.18 ms vs 2.0 ms, product
0.06 ms vs 0.65 ms), and the closed-form inverse keeps an exactly symmetric
input exactly symmetric.  Larger systems use ``numpy.linalg`` (LAPACK, with
partial pivoting), frequency moved to the front.

The hot path of a model evaluation (beam receptances and the coupling of an
assembly) runs in the compiled kernels of :mod:`substructure._kernels`; these
numpy forms serve the FRF-level operations (decoupling, modification), the
closed-form identification and the segment dynamic stiffness.

:func:`checked_block` is the check of the arrays a component or joint type
of one's own gives, where they enter a computation (their shape
``(r, r, n_freq)`` is the one this module works on).  :func:`angular_lines`,
:func:`takes_decay` and :func:`at_decay` are the model at a complex frequency
``omega - i sigma`` (a tap test seen through an exponential window), for the
components and joints that can be evaluated there.
"""

from __future__ import annotations

import functools

import numpy as np

from .errors import InvalidValueError, SubstructureError

__all__ = ["mul2", "inv2", "inv", "to_front", "to_back", "CHUNK_LINES", "by_chunks", "checked_block", "angular_lines",
           "takes_decay", "at_decay"]

CHUNK_LINES = 16384
"""Frequency lines evaluated at once by an assembly (bounds the memory of intermediates).

The compiled kernels (:mod:`substructure._kernels`) work line by line and
need no chunking for speed; chunks only bound the size of the components'
receptance matrices, joint stiffnesses and coupling intermediates held at
once: about 1 kB per line for a spindle, holder and tool, so some 16 MB at
this size, whatever the number of lines.
"""


def by_chunks(compute, frequency_hz: np.ndarray) -> np.ndarray:
    """``compute(f)`` over chunks of at most :data:`CHUNK_LINES` lines, joined on the last axis.

    Parameters
    ----------
    compute : callable
        ``compute(f)`` returns an array ``(..., f.size)`` for frequency lines ``f`` in Hz.
    frequency_hz : ndarray
        All the lines [Hz].

    Returns
    -------
    ndarray
        ``(..., n)``: each chunk is written into one array allocated once
        (no list of parts joined at the end, which would hold the result twice).
    """
    f = np.asarray(frequency_hz, dtype=float)
    if f.size <= CHUNK_LINES:
        return compute(f)
    out: np.ndarray | None = None
    for i in range(0, f.size, CHUNK_LINES):
        part = compute(f[i : i + CHUNK_LINES])
        if out is None:
            out = np.empty(part.shape[:-1] + (f.size,), dtype=part.dtype)
        out[..., i : i + part.shape[-1]] = part
    assert out is not None  # f.size > CHUNK_LINES: at least one chunk
    return out


def mul2(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Product of two stacks of 2x2 matrices, shape ``(2, 2, n)``.

    Two broadcast products (column of ``a`` times row of ``b``) summed: the
    fastest form measured for n ~ 1e3-1e5 (about 3x an entry-by-entry loop).
    """
    out = a[:, 0, None, :] * b[None, 0, :, :]
    out += a[:, 1, None, :] * b[None, 1, :, :]
    return out


def inv2(a: np.ndarray) -> np.ndarray:
    """Inverse of a stack of 2x2 matrices, shape ``(2, 2, n)`` (closed form).

    The closed form keeps an exactly symmetric input exactly symmetric.
    """
    det = a[0, 0] * a[1, 1] - a[0, 1] * a[1, 0]
    out = np.empty_like(a, dtype=np.result_type(a, 1.0))
    out[0, 0] = a[1, 1] / det
    out[1, 1] = a[0, 0] / det
    out[0, 1] = -a[0, 1] / det
    out[1, 0] = -a[1, 0] / det
    return out


def to_front(a: np.ndarray) -> np.ndarray:
    """``(r, c, n)`` to ``(n, r, c)``."""
    return np.moveaxis(a, -1, 0)


def to_back(a: np.ndarray) -> np.ndarray:
    """``(n, r, c)`` to ``(r, c, n)``."""
    return np.moveaxis(a, 0, -1)


def inv(a: np.ndarray) -> np.ndarray:
    """Inverse of a stack of square matrices ``(m, m, n)``: closed form for ``m <= 2``, else LAPACK."""
    m = a.shape[0]
    if m == 1:
        return 1.0 / a
    if m == 2:
        return inv2(a)
    return to_back(np.linalg.inv(to_front(a)))


def checked_block(owner, kind: str, member: str, compute, rows: int, frequency_hz) -> np.ndarray:
    """The array ``compute()`` gives for ``owner``, checked when the owner's type is one of one's own.

    A component's receptances and a joint's dynamic stiffness enter every
    computation through here.  For a type defined outside the package, an
    error it raises, an array of another shape than ``(rows, rows, n)`` for
    ``n`` lines or a value that is not finite is refused naming the object
    and its type (not a bare traceback, nor a coupling error far from the
    cause); the package's own types are not checked (they are tested).

    Parameters
    ----------
    owner : object
        The component or joint (its ``name`` and type name the error).
    kind : str
        ``"component"`` or ``"joint"``.
    member : str
        The method ``compute`` calls, for the message.
    compute : callable
        Gives the array.
    rows : int
        The expected number of rows (and columns).
    frequency_hz : ndarray
        Frequencies [Hz] (one slice of the array per line).

    Returns
    -------
    ndarray
        The array, shape ``(rows, rows, n)``.

    Raises
    ------
    InvalidValueError
        When a type of one's own breaks the protocol.
    """
    if type(owner).__module__.split(".")[0] == __name__.split(".")[0]:
        return compute()
    who = f"{kind} {getattr(owner, 'name', '?')!r} ({type(owner).__name__})"
    try:
        out = np.asarray(compute())
    except SubstructureError:
        raise
    except Exception as exc:  # a type of one's own: its error named with it
        raise InvalidValueError(f"{who}: {member} failed ({type(exc).__name__}: {exc})") from exc
    f = np.atleast_1d(np.asarray(frequency_hz, dtype=float))
    expected = (rows, rows, f.size)
    if out.shape != expected:
        raise InvalidValueError(f"{who}: {member} gave an array of shape {out.shape}; expected {expected} "
                                f"(2 DOFs per point, one slice per frequency line)")
    bad = ~np.isfinite(out).all(axis=(0, 1))
    if bad.any():
        raise InvalidValueError(f"{who}: {member} gave values that are not finite on {int(bad.sum())} of "
                                f"{f.size} lines (the first at {f[bad][0]:g} Hz)")
    return out


def angular_lines(frequency_hz, decay: float = 0.0) -> np.ndarray:
    """The angular frequency of each line, ``2 pi f - i decay`` [rad/s].

    With ``decay = 0`` (the default) the real lines; with ``decay = 1/tau``
    the complex frequency at which a model is seen through an exponential
    window ``exp(-t/tau)`` applied to both channels of a tap test: the
    windowed FRF is ``H(omega - i/tau)`` exactly, whatever the force's shape
    (``x(t) = X exp(i omega t)``: a window multiplies the impulse response
    by ``exp(-t/tau)``).

    Parameters
    ----------
    frequency_hz : array_like
        Frequency lines [Hz].
    decay : float, optional
        ``sigma = 1/tau`` [1/s], finite and >= 0.

    Returns
    -------
    ndarray
        float64 when ``decay`` is 0, else complex128, one value per line.
    """
    omega = 2.0 * np.pi * np.asarray(frequency_hz, dtype=float).reshape(-1)
    decay = float(decay)
    if not np.isfinite(decay) or decay < 0:
        raise InvalidValueError(f"decay: got {decay!r}; expected a finite rate >= 0 in 1/s (1/tau of the window)")
    return omega - 1j * decay if decay else omega


def takes_decay(method) -> bool:
    """Whether a component's ``receptance_matrix`` or a joint model's ``dynamic_stiffness`` takes ``decay``.

    The protocol's optional keyword: a type that can be evaluated at the
    complex frequency ``omega - i decay`` (:func:`angular_lines`) says so by
    taking it; the package's beams, joints, supports and bodies do.

    Parameters
    ----------
    method : callable
        The bound method.

    Returns
    -------
    bool
    """
    function = getattr(method, "__func__", method)  # the class's function: one reading per type
    try:
        return _signature_has_decay(function)
    except TypeError:  # an object that cannot be a cache key
        return _signature_has_decay.__wrapped__(function)


@functools.lru_cache(maxsize=512)
def _signature_has_decay(function) -> bool:
    import inspect

    try:
        return "decay" in inspect.signature(function).parameters
    except (TypeError, ValueError):  # a builtin without a signature
        return False


def at_decay(owner, member: str, frequency_hz, decay: float):
    """``owner.member(frequency_hz)``'s arguments at ``decay``: a callable giving the array.

    Parameters
    ----------
    owner : object
        A component or joint model.
    member : str
        ``"receptance_matrix"`` or ``"dynamic_stiffness"``.
    frequency_hz : ndarray
        Frequencies [Hz].
    decay : float
        ``1/tau`` [1/s]; 0 calls the method as the protocol always has.

    Returns
    -------
    callable
        ``f(*args)`` calling the method with ``args``, the frequencies and, when
        ``decay`` is not 0, ``decay``.

    Raises
    ------
    InvalidValueError
        When ``decay`` is not 0 and the method does not take it: the type
        cannot be evaluated at a complex frequency.
    """
    method = getattr(owner, member)
    if not decay:
        return lambda *args: method(*args, frequency_hz)
    if not takes_decay(method):
        raise InvalidValueError(
            f"{type(owner).__name__} {getattr(owner, 'name', '')!r}: its {member} takes no decay, so it cannot be "
            "evaluated at a complex frequency (the model seen through an exponential window)")
    return lambda *args: method(*args, frequency_hz, decay=decay)
