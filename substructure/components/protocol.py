"""The component protocol's shared machinery: the registry of types and the helpers of every component.

:data:`COMPONENT_TYPES` and :func:`register_component` name component
classes for assembly files; :func:`as_frequency` and :func:`dof_labels` are
what every component's ``receptance`` needs; :func:`is_plain_beam` tells
batched computations when a component's receptances are those of its
segments alone; :func:`receptances` is the checked call of a component's
``receptance_matrix`` every computation makes.
"""

from __future__ import annotations

import warnings
from typing import Any, Iterable

import numpy as np
import pint

from ..beams import Segment
from .._blocks import at_decay, checked_block
from ..errors import InvalidValueError, NonReciprocalWarning
from ..frf import FRF, Frequency
from ..points import DOFS

__all__ = ["COMPONENT_TYPES", "register_component", "as_frequency", "dof_labels", "is_plain_beam", "receptances"]

COMPONENT_TYPES: dict[str, type] = {}
"""Registered component types by their ``type`` name in assembly files."""


def register_component(kind: str):
    """Class decorator registering a component type under ``kind``.

    Parameters
    ----------
    kind : str
        The name of the type in assembly files (``type = "shrink-fit-holder"``).

    Returns
    -------
    callable
        The decorator: it sets ``cls.kind``, adds the class to
        :data:`COMPONENT_TYPES` and returns the class unchanged.

    Raises
    ------
    InvalidValueError
        When another class is already registered under ``kind``.

    Examples
    --------
    >>> @register_component("shrink-fit-holder")          # doctest: +SKIP
    ... @attrs.frozen
    ... class ShrinkFitHolder(Holder): ...
    """

    def decorate(cls):
        if kind in COMPONENT_TYPES and COMPONENT_TYPES[kind] is not cls:
            raise InvalidValueError(f"component type {kind!r} is already registered")
        cls.kind = kind
        COMPONENT_TYPES[kind] = cls
        return cls

    return decorate


def as_frequency(frequency) -> Frequency:
    """A :class:`Frequency` from a Frequency, an FRF, an array of frequencies in Hz or a quantity.

    A quantity in angular units is converted explicitly, as everywhere
    (:func:`substructure.units.frequency_hz`): rad/s divided by ``2*pi``,
    rpm by 60.

    Parameters
    ----------
    frequency : Frequency, FRF, pint.Quantity or array_like
        The frequency lines: a Frequency, the axis of an FRF, a quantity in Hz
        (rad/s and rpm converted: divided by 2*pi and by 60), or plain numbers in Hz.

    Returns
    -------
    Frequency
        The frequency axis, in Hz.
    """
    if isinstance(frequency, Frequency):
        return frequency
    if isinstance(frequency, FRF):
        return frequency.frequency
    if isinstance(frequency, pint.Quantity):
        from ..units import cycles_per_second, ureg

        q = frequency if frequency._REGISTRY is ureg else ureg.Quantity(frequency.magnitude, str(frequency.units))
        if not q.check("1 / [time]"):
            raise InvalidValueError(
                f"frequency: got a quantity in {q.units}; expected frequencies (Hz, or rad/s and rpm, "
                "which are divided by 2*pi and by 60)"
            )
        return Frequency.from_hz(np.atleast_1d(np.asarray(cycles_per_second(q, "frequency"), dtype=float)))
    if isinstance(frequency, str):
        raise InvalidValueError(
            f"frequency: got {frequency!r}; expected a Frequency (e.g. Frequency.from_range('20 Hz', "
            "'5000 Hz', '2 Hz')) or an array of frequencies in Hz"
        )
    try:
        given = np.asarray(frequency)
        if given.dtype.kind not in "iuf":  # booleans (True would be 1 Hz), texts ("500" without its unit)
            raise TypeError
        hz = np.atleast_1d(given.astype(float))
    except (TypeError, ValueError):
        raise InvalidValueError(
            f"frequency: got {frequency!r}; expected a Frequency (e.g. Frequency.from_range('20 Hz', '5000 Hz', "
            "'2 Hz')), a quantity of frequencies or an array of frequencies in Hz (plain numbers)") from None
    return Frequency.from_hz(hz)


def dof_labels(points: Iterable[str]) -> tuple[str, ...]:
    """DOF labels ``("p:y", "p:theta", ...)`` of point names.

    Parameters
    ----------
    points : iterable of str
        Point names (``"tool.tip"``).

    Returns
    -------
    tuple of str
        Two labels per point: the displacement ``y`` (m) and the slope ``theta`` (rad).
    """
    return tuple(f"{p}:{d}" for p in points for d in DOFS)


def _positive_frequencies(f: np.ndarray, who: str) -> None:
    if np.any(f <= 0):
        raise InvalidValueError(
            f"frequency: {who} is free-free and has no static receptance; "
            f"expected frequencies > 0 Hz, got {float(f.min())} Hz"
        )


def is_plain_beam(component: Any) -> bool:
    """Whether a component's receptances are those of its ``segments`` alone (the ``plain_beam`` member).

    Parameters
    ----------
    component : object
        Any component.

    Returns
    -------
    bool
        True only when the component says so with ``plain_beam = True`` and
        has a sequence of :class:`~substructure.beams.Segment` as
        ``segments``; batched paths (sweeps) may then compute it from the
        segments.  Everything else is computed through its
        ``receptance_matrix``.
    """
    if getattr(component, "plain_beam", False) is not True:
        return False
    segments = getattr(component, "segments", None)
    return isinstance(segments, tuple) and bool(segments) and all(isinstance(s, Segment) for s in segments)


def receptances(component: Any, refs: list, frequency_hz: np.ndarray, decay: float = 0.0) -> np.ndarray:
    """``component.receptance_matrix(refs, frequency_hz)``, checked when the component's type is one of one's own.

    A type defined outside the package is held to the protocol where its
    receptances enter a computation (the check of ``checked_block``):
    an error it raises, an array of another shape than ``(2q, 2q, n)`` for
    ``q`` points and ``n`` lines, or a value that is not finite is refused
    naming the component and its type.

    Parameters
    ----------
    component : object
        The component (or a group of components with one ``receptance_matrix``).
    refs : list of PointRef
        Its points.
    frequency_hz : ndarray
        Frequencies [Hz].
    decay : float, optional
        ``1/tau`` [1/s]: the receptances at the complex frequency
        ``omega - i decay`` (a tap test seen through an exponential window),
        from a ``receptance_matrix`` that takes ``decay``; default 0.

    Returns
    -------
    ndarray
        Complex receptances, shape ``(2q, 2q, n)``.

    Raises
    ------
    InvalidValueError
        When a component type of one's own breaks the protocol, or ``decay``
        is not 0 and its ``receptance_matrix`` does not take it.
    """
    call = at_decay(component, "receptance_matrix", frequency_hz, decay)
    y = checked_block(component, "component", "receptance_matrix", lambda: call(refs), 2 * len(refs), frequency_hz)
    if type(component).__module__.split(".")[0] != __name__.split(".")[0]:
        _check_reciprocal(component, y, refs, frequency_hz)
    return y


RECIPROCITY_TOLERANCE = 1e-6
"""Largest ``|Y_ij - Y_ji|`` over the largest ``|Y|`` of a line that a component type of one's own may give."""


def _check_reciprocal(component: Any, y: np.ndarray, refs: list, frequency_hz) -> None:
    """Warn when a component type of one's own gives receptances that are not symmetric (a linear elastic
    structure's are: ``H12 = H21``, ``L = N``); the coupled receptances would not be reciprocal either."""
    scale = np.abs(y).max(axis=(0, 1))
    asym = np.abs(y - np.swapaxes(y, 0, 1)).max(axis=(0, 1)) / np.where(scale > 0, scale, 1.0)
    worst = int(np.argmax(asym))
    if asym[worst] > RECIPROCITY_TOLERANCE:
        i, j = np.unravel_index(np.argmax(np.abs(y[..., worst] - y[..., worst].T)), y.shape[:2])
        f = np.atleast_1d(np.asarray(frequency_hz, dtype=float))
        a, b = (f"{refs[k // 2]}:{DOFS[k % 2]}" for k in (i, j))
        warnings.warn(
            f"component {getattr(component, 'name', '?')!r} ({type(component).__name__}): receptance_matrix gave a "
            f"matrix that is not symmetric ({a} / {b} and {b} / {a} differ by {asym[worst]:.2g} of its largest entry "
            f"at {f[worst]:g} Hz): a linear elastic structure's are (H12 = H21, L = N), and the coupled "
            "receptances will not be reciprocal",
            NonReciprocalWarning, stacklevel=3)
