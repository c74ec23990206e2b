"""Free-free receptances of chains of uniform intervals (internal): the transfer-matrix chain, cut where it loses
digits.

The machinery under :mod:`substructure.beams` and :mod:`substructure.tapers`:
an interval is a pair ``(section, length)`` of uniform Timoshenko beam;
:func:`_chain_single` hands a chain to the compiled kernel
(:func:`substructure._kernels.chain_receptance`), and :func:`_chain_receptance`
first cuts a chain whose ``k L`` exceeds 8 at its highest line into pieces
joined rigidly by the coupling engine, so that rounding stays near 3e-13.
"""

from __future__ import annotations

import math
from typing import Any, Sequence

import numpy as np

from ._engine import Link, couple_substructures
from .sections import Section

# An interval is a pair ``(section, length)``.  In a batch of ``n_config``
# configurations the fields of the section and the length are either scalars
# (the same in every configuration) or arrays of ``n_config`` values.


def _is_shared(sec: Section, length) -> bool:
    return not any(isinstance(v, np.ndarray) for v in (sec.EI, sec.kGA, sec.rhoA, sec.rhoI, length))


def _chain_single(intervals: list[tuple[Section, object]], nodes: list[int], omega: np.ndarray,
                  n_config: int = 1, place: list[int] | None = None) -> np.ndarray:
    """Free-free receptances of a chain of uniform intervals at some of its nodes.

    ``intervals[k]`` spans node ``k`` to node ``k + 1``; ``nodes`` are sorted,
    distinct node indices.  With the state ``z = [u; F]`` (``u = [w, psi]``,
    ``F = [V, M]``) a load ``g`` at node ``j`` makes ``F`` jump by ``-g``; the
    free ends give ``F = 0`` before the base and after the tip, so

    ``Y_ij = P_i,uu M_Fu^-1 S_j,FF - [x_i > x_j] T_(j->i),uF``

    with ``P_i = T(0 -> x_i)``, ``S_j = T(x_j -> L)`` and ``M = T(0 -> L)``.
    ``M_Fu`` is singular only at the free-free natural frequencies, and its
    ``omega^2`` factor carries the rigid-body modes exactly, so the result is
    well conditioned down to the lowest frequency line.  The blocks with
    ``x_i > x_j`` are taken from reciprocity, ``Y_ij = Y_ji^T``: evaluated
    from their own formula, whose two terms grow like ``exp(k (x_i - x_j))``
    and cancel, they would lose about ``exp(k L)`` more digits.

    Computed line by line by :func:`substructure._kernels.chain_receptance`.
    Intervals that are the same object (the equal pieces of a split segment)
    are one segment for the kernel, computed once per line; in a batch, a
    segment that is the same in every configuration is computed once per
    frequency line for all of them.  Node ``nodes[i]`` is put at position
    ``place[i]`` of the result (default: in order).  Returns
    ``(2m, 2m, n_config * n_freq)``.
    """
    from . import _kernels

    index: dict[tuple, int] = {}
    unique: list[tuple[Section, Any]] = []
    seg_of = []
    for sec, length in intervals:
        key = (id(sec), id(length) if isinstance(length, np.ndarray) else length)
        if key not in index:
            index[key] = len(unique)
            unique.append((sec, length))
        seg_of.append(index[key])
    n_u = len(unique)
    ei = np.empty((n_u, n_config), dtype=complex)
    kga = np.empty((n_u, n_config), dtype=complex)
    rhoa = np.empty((n_u, n_config))
    rhoi = np.empty((n_u, n_config))
    lengths = np.empty((n_u, n_config))
    shared = np.zeros(n_u, dtype=bool)
    for u, (sec, length) in enumerate(unique):
        ei[u], kga[u], rhoa[u], rhoi[u], lengths[u] = sec.EI, sec.kGA, sec.rhoA, sec.rhoI, length
        shared[u] = n_config > 1 and _is_shared(sec, length)
    return _kernels.chain_receptance(
        omega, ei, kga, rhoa, rhoi, lengths, shared,
        np.array(seg_of, dtype=np.int64), np.array(nodes, dtype=np.int64),
        np.arange(len(nodes), dtype=np.int64) if place is None else np.array(place, dtype=np.int64),
    )


_CHUNK_KL = 8.0  # largest k L of one transfer-matrix chain: rounding ~ 1e-16 exp(8) ~ 3e-13


def _phase(sec: Section, length, omega_max: float) -> float:
    """Largest ``k L`` of an interval at ``omega_max`` (over a batch: the maximum)."""
    from . import _kernels

    ei, kga, rhoa, rhoi, length = np.broadcast_arrays(
        *(np.atleast_1d(v) for v in (sec.EI, sec.kGA, sec.rhoA, sec.rhoI, length))
    )
    _, k_max = _kernels.segment_coefficients(
        _kernels.c_array(ei.reshape(1, -1), complex), _kernels.c_array(kga.reshape(1, -1), complex),
        _kernels.c_array(rhoa.reshape(1, -1), float), _kernels.c_array(rhoi.reshape(1, -1), float),
        float(omega_max),
    )
    return float(np.max(k_max[0] * length))


def _phases(intervals: list[tuple], omega_max: float) -> list[float]:
    """:func:`_phase` of every interval: one kernel call for intervals of plain numbers (the same numbers)."""
    from . import _kernels

    if not all(_is_shared(sec, length) for sec, length in intervals):
        return [_phase(sec, length, omega_max) for sec, length in intervals]
    ei, kga, rhoa, rhoi, length = (np.array([column]) for column in zip(
        *((sec.EI, sec.kGA, sec.rhoA, sec.rhoI, length) for sec, length in intervals)))
    _, k_max = _kernels.segment_coefficients(
        _kernels.c_array(ei, complex), _kernels.c_array(kga, complex), _kernels.c_array(rhoa, float),
        _kernels.c_array(rhoi, float), float(omega_max))
    return [float(x) for x in k_max[0] * length[0]]


def _chain_receptance(
    intervals: list[tuple], nodes: list[int], omega: np.ndarray, phases: list[float] | None = None,
    n_config: int = 1, place: list[int] | None = None,
) -> np.ndarray:
    """Free-free receptances of a chain at some of its nodes, for any length and frequency.

    The transfer-matrix rounding grows like ``exp(k L)`` (``k`` the evanescent
    bending wavenumber), so a chain with ``k L`` above 8 at the highest line is
    cut into pieces of ``k L <= 8``: each piece's receptances come from
    :func:`_chain_single` and the pieces are joined by rigid connections with
    the coupling engine, which is exact and well conditioned.  Short chains
    (the usual case) are one piece.  ``omega`` holds the frequency lines of
    one configuration; the result has ``n_config * omega.size`` lines.
    ``nodes`` are sorted; node ``nodes[i]`` is put at position ``place[i]``
    of the result (default: in order).
    """
    omega_max = float(np.max(np.abs(omega))) if omega.size else 0.0
    if phases is None:
        phases = _phases(intervals, omega_max)
    refined, node_map, piece_phases = [], [0], []
    for item, kl in zip(intervals, phases):
        n_sub = max(1, math.ceil(kl / _CHUNK_KL))
        piece = item if n_sub == 1 else (item[0], item[1] / n_sub)
        refined.extend([piece] * n_sub)
        piece_phases.extend([kl / n_sub] * n_sub)
        node_map.append(node_map[-1] + n_sub)
    phases = piece_phases
    nodes = [node_map[i] for i in nodes]
    bounds, acc = [0], 0.0
    for i, kl in enumerate(phases):
        if acc + kl > _CHUNK_KL and i > bounds[-1]:
            bounds.append(i)
            acc = 0.0
        acc += kl
    bounds.append(len(refined))
    if len(bounds) == 2:
        return _chain_single(refined, nodes, omega, n_config, place)
    blocks, links = [], []
    last = len(bounds) - 2
    for c, (n0, n1) in enumerate(zip(bounds[:-1], bounds[1:])):
        wanted = {nd for nd in nodes if n0 <= nd <= n1}
        if c > 0:
            wanted.add(n0)
            links.append(Link((c - 1, n0), (c, n0), None, "a beam's own cross-section"))
        if c < last:
            wanted.add(n1)
        local = sorted(wanted)
        y = _chain_single(refined[n0:n1], [nd - n0 for nd in local], omega, n_config)
        blocks.append(([(c, nd) for nd in local], y))
    outputs: list[tuple[int, int] | None] = [None] * len(nodes)
    for i, nd in enumerate(nodes):
        c = next(c for c, (n0, n1) in enumerate(zip(bounds[:-1], bounds[1:])) if n0 <= nd <= n1)
        outputs[i if place is None else place[i]] = (c, nd)
    return couple_substructures(blocks, links, outputs)


def _stack_sections(sections: Sequence[Section]) -> Section:
    """One Section whose fields are arrays over configurations."""
    return Section(
        EI=np.array([s.EI for s in sections], dtype=complex),
        kGA=np.array([s.kGA for s in sections], dtype=complex),
        rhoA=np.array([s.rhoA for s in sections], dtype=float),
        rhoI=np.array([s.rhoI for s in sections], dtype=float),
    )
