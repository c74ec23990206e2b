"""The numerical coupling engine (internal): Woodbury updates on frequency-last arrays.

``Y_c = Y - (Y B^T) W (B Y)`` with ``W = (B Y B^T + K^-1)^-1`` written as
``K (I + B Y B^T K)^-1`` (no ``K^-1`` needed) or ``(B Y B^T)^-1`` for a rigid
connection.  :func:`couple_substructures` applies links to substructures
cluster by cluster, keeping only the points still needed (the bookkeeping
here, the update of each link, line by line, in the compiled kernel
``substructure._kernels.couple_link``); :func:`apply_connection` is the
same update on a square matrix at DOF level, with numpy (any number of DOFs:
decoupling and structural modification).  It depends only on
:mod:`substructure._blocks` and :mod:`substructure._kernels`, so that beams
(to join long chains in well-conditioned pieces), assemblies and the
FRF-level operations of :mod:`substructure.coupling` share it.  See
:mod:`substructure.coupling` for the method.
"""

from __future__ import annotations

from typing import Sequence

import attrs
import numpy as np

from . import _blocks as bk
from .errors import AssemblyError

__all__ = ["Connection", "Link", "interface_update", "apply_connection", "couple", "couple_substructures"]


@attrs.frozen
class Connection:
    """A connection between DOF groups of a receptance matrix.

    Parameters
    ----------
    a : tuple of int
        DOF indices on one side.
    b : tuple of int or None
        DOF indices on the other side (same length), or ``None`` for the ground.
    stiffness : ndarray or None
        Dynamic stiffness ``(r, r, n_freq)`` acting on ``u_a - u_b``;
        ``None`` for a rigid connection.
    label : str
        For messages.
    """

    a: tuple[int, ...]
    b: tuple[int, ...] | None
    stiffness: np.ndarray | None = attrs.field(eq=False)
    label: str = ""


def _identity(r: int, n: int) -> np.ndarray:
    eye = np.zeros((r, r, n), dtype=complex)
    for i in range(r):
        eye[i, i] = 1.0
    return eye


def _mul(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    if a.shape[0] == a.shape[1] == b.shape[0] == b.shape[1] == 2:
        return bk.mul2(a, b)
    return np.einsum("ikn,kjn->ijn", a, b)


def interface_update(s: np.ndarray, stiffness: np.ndarray | None) -> np.ndarray:
    """``W`` of the update ``Y_c = Y - (Y B^T) W (B Y)`` for ``S = B Y B^T``.

    ``W = S^-1`` for a rigid connection (``stiffness`` None), else
    ``W = K (I + S K)^-1``, which equals ``(S + K^-1)^-1`` without inverting a
    possibly singular ``K``.  Shapes ``(r, r, n)``, frequency last.
    """
    r, n = s.shape[0], s.shape[-1]
    if stiffness is None:
        return bk.inv(s)
    k = stiffness if stiffness.shape[-1] == n else np.broadcast_to(stiffness, stiffness.shape[:2] + (n,))
    return _mul(k, bk.inv(_identity(r, n) + _mul(s, k)))


def apply_connection(y: np.ndarray, conn: Connection) -> np.ndarray:
    """One coupling step on a frequency-last receptance matrix ``(M, M, n)``.

    Parameters
    ----------
    y : ndarray
        Complex receptances, shape ``(M, M, n_freq)`` (m/N, m/(N m), rad/N, rad/(N m)).
    conn : Connection
        The connection.

    Returns
    -------
    ndarray
        The coupled receptances, same shape and units.
    """
    a = list(conn.a)
    if conn.b is None:
        u = y[:, a]  # Y B^T
        v = y[a, :]  # B Y
    else:
        b = list(conn.b)
        u = y[:, a] - y[:, b]
        v = y[a, :] - y[b, :]
    s = v[:, a] if conn.b is None else v[:, a] - v[:, list(conn.b)]  # B Y B^T
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        w = interface_update(s, conn.stiffness)
        uw = _mul(u, w) if u.shape[0] == 2 else np.einsum("mkn,kjn->mjn", u, w)
        out = y.copy()
        for j in range(len(a)):
            out -= uw[:, j][:, None, :] * v[j][None, :, :]
    if not np.all(np.isfinite(out)):
        raise AssemblyError(
            f"coupling through {conn.label or 'a connection'} is singular: a rigid joint that closes a "
            "loop of rigid joints (redundant), a zero frequency, or a connection to a point with no "
            "flexibility"
        )
    return out


def couple(y: np.ndarray, connections: Sequence[Connection]) -> np.ndarray:
    """Apply connections one after the other.

    Parameters
    ----------
    y : ndarray
        Complex receptances, shape ``(M, M, n_freq)``.
    connections : sequence of Connection
        The connections, applied in order.

    Returns
    -------
    ndarray
        The coupled ``(M, M, n_freq)`` matrix, same units.
    """
    for conn in connections:
        y = apply_connection(y, conn)
    return y


@attrs.frozen
class Link:
    """A connection between two points (2 DOFs each) of substructures, or to the ground.

    Parameters
    ----------
    a : object
        Node key of the first point.
    b : object or None
        Node key of the second point; None for the ground.
    stiffness : ndarray or None
        Dynamic stiffness ``(2, 2, n_freq)`` acting on ``u_a - u_b`` (or ``u_a``), in N/m,
        N/rad, N m/m and N m/rad; None for a rigid connection.
    label : str
        For messages.
    """

    a: object
    b: object | None
    stiffness: np.ndarray | None = attrs.field(eq=False)
    label: str = ""


_NO_STIFFNESS = np.zeros((2, 2, 1), dtype=complex)  # placeholder of a rigid link for the kernel


def _blk(y: np.ndarray, i: int, j: int) -> np.ndarray:
    return y[2 * i : 2 * i + 2, 2 * j : 2 * j + 2]


def couple_substructures(blocks, links: Sequence[Link], outputs: Sequence[object], memo=None,
                         tokens: tuple | None = None, copies: int = 1, lines: int | None = None,
                         pick: tuple | None = None) -> np.ndarray:
    """Couple substructures through links and return the receptances at ``outputs``.

    Parameters
    ----------
    blocks : sequence of (keys, y)
        Each substructure's point keys and its receptance matrix
        ``(2m, 2m, n)`` (frequency last), DOFs ``(y, theta)`` per point.
    links : sequence of Link
        Joints, supports and modifications, applied in order.
    outputs : sequence of keys
        Points whose receptances are wanted (in this order).
    memo : mapping, optional
        Coupled clusters of earlier calls, kept by the caller between calls
        (``get`` and item assignment; the caller bounds its size): a step
        whose two clusters and link are those of an earlier step is taken
        from it, not computed again (the same inputs give the same result).
    tokens : (sequence, sequence), optional
        With ``memo``: a hashable identity of each block's receptances and of
        each link's stiffness (None: not the same as any other; nothing
        coupled with it is reused).
    copies : int
        Several models coupled at once, their lines side by side: a block or
        stiffness of ``copies * lines`` lines differs between them, one of
        ``lines`` lines (or a stiffness of one) is the same in every one;
        steps of only such are computed once and repeated where they meet
        one that differs (each line computed as alone).
    lines : int, optional
        The lines of one model (needed with ``copies`` above 1).
    pick : (sequence of int, sequence of int), optional
        Only these rows and columns of the result (DOF indices ``2 i + d``
        over ``outputs``): the last step, when it joins every output,
        computes just those entries (the same numbers).

    Returns
    -------
    ndarray ``(2p, 2p, n)``, or ``(len(rows), len(cols), n)`` with ``pick``
        Zero between points of substructures that end up unconnected
        (``n = copies * lines`` with copies).

    Notes
    -----
    Substructures are merged cluster by cluster, and after each link only the
    points that the outputs or later links need are kept, so the working
    matrices stay as small as the interfaces.  Each step is the update of
    :func:`apply_connection`, with the zero off-diagonal blocks of two
    uncoupled clusters skipped, computed by
    ``substructure._kernels.couple_link`` (the 2x2 determinants
    compensated near singular lines, so that a line next to a natural
    frequency is not lost to rounding).
    """
    from . import _kernels

    if copies > 1 and lines is None:
        raise ValueError("couple_substructures: copies > 1 needs the lines of one copy")
    n = blocks[0][1].shape[-1] if copies == 1 or lines is None else int(lines)
    full = n * copies

    def spread(y):  # an array the same in every copy, repeated for each (the kernel's inputs and outputs)
        return y if copies == 1 or y.shape[-1] != n else np.tile(y, copies)

    clusters: dict[int, tuple[list, np.ndarray]] = {}
    where: dict[object, int] = {}
    # what each cluster was computed from (None: not reusable); only with a memo
    made: dict[int, object] = {}
    block_tokens, link_tokens = tokens if memo is not None and tokens is not None else ((), ())
    for cid, (keys, y) in enumerate(blocks):
        clusters[cid] = (list(keys), _kernels.c_array(y, complex))
        made[cid] = block_tokens[cid] if cid < len(block_tokens) else None
        for k in keys:
            where[k] = cid
    # the points each link and the outputs need, from the last link backwards
    needed_after = [set(outputs)]
    for link in reversed(links[1:]):
        later = set(needed_after[-1])
        later.add(link.a)
        if link.b is not None:
            later.add(link.b)
        needed_after.append(later)
    needed_after.reverse()
    picked = None  # the result, when the last step computed only the entries of pick
    for step, link in enumerate(links):
        needed = needed_after[step]
        ca = where[link.a]
        cb = None if link.b is None else where[link.b]
        if cb is None or cb == ca:
            keys, ya = clusters.pop(ca)
            yb = ya
            a = (0, keys.index(link.a))
            b = (-1, 0) if link.b is None else (0, keys.index(link.b))
            kept = [(0, i) for i, k in enumerate(keys) if k in needed]
            new_keys = [keys[i] for _, i in kept]
        else:
            ka, ya = clusters.pop(ca)
            kb, yb = clusters.pop(cb)
            a, b = (0, ka.index(link.a)), (1, kb.index(link.b))
            kept = [(0, i) for i, k in enumerate(ka) if k in needed]
            kept += [(1, i) for i, k in enumerate(kb) if k in needed]
            new_keys = [(ka, kb)[src][i] for src, i in kept]
        key: tuple | None = None
        # the last step, joining every output: only the entries wanted
        rows = cols = None
        wanted: tuple = ()
        if pick is not None and step == len(links) - 1 and set(outputs) <= set(new_keys):
            at = [new_keys.index(k) for k in outputs]
            wanted = (tuple(2 * at[r // 2] + r % 2 for r in pick[0]), tuple(2 * at[c // 2] + c % 2 for c in pick[1]))
            rows, cols = (np.array(w, dtype=np.int64) for w in wanted)
        link_token = link_tokens[step] if step < len(link_tokens) else None
        parts = (made[ca], None if cb is None else made[cb], link_token)
        if parts[0] is not None and (cb is None or parts[1] is not None) and link_token is not None:
            key = (parts, link.a, link.b, tuple(new_keys)) + wanted
            found = memo.get(key)
            if found is not None and rows is not None:
                picked = found
                continue
            if found is not None:
                cid = min(ca, cb if cb is not None else ca)
                clusters[cid], made[cid] = (new_keys, found), key
                for k in new_keys:
                    where[k] = cid
                continue
        rigid = link.stiffness is None
        stiffness = _NO_STIFFNESS if rigid else _kernels.c_array(link.stiffness, complex)
        if stiffness.shape[:2] != (2, 2) or stiffness.shape[-1] not in (1, n, full) or stiffness.ndim != 3:
            raise ValueError(
                f"{link.label or 'a link'}: stiffness of shape {stiffness.shape}; expected (2, 2, {n}) or (2, 2, 1)"
            )
        if copies > 1 and full in (ya.shape[-1], yb.shape[-1], stiffness.shape[-1]):
            # a step with a part that differs between the copies: every part for every copy, not kept
            same = yb is ya
            ya, stiffness, key = spread(ya), spread(stiffness), None
            yb = ya if same else spread(yb)
        src = np.array([p for p, _ in kept], dtype=np.int64)
        idx = np.array([i for _, i in kept], dtype=np.int64)
        out, finite = _kernels.couple_link(ya, yb, a[0], a[1], b[0], b[1], src, idx, stiffness, rigid, rows, cols)
        if not finite:
            if not rigid:  # an elastic link: its stiffness is beyond what floating point holds beside the rest
                with np.errstate(invalid="ignore", over="ignore"):
                    largest = float(np.nanmax(np.abs(stiffness)))
                raise AssemblyError(
                    f"coupling through {link.label or 'a connection'} is singular in floating point: its dynamic "
                    f"stiffness reaches {largest:.3g} (SI); a joint that stiff is rigid: give it as rigid "
                    "(Joint(..., rigid=True))"
                )
            raise AssemblyError(
                f"coupling through {link.label or 'a connection'} is singular: a rigid joint that "
                "closes a loop of rigid joints (redundant), or a connection to a point with no "
                "flexibility"
            )
        if key is not None:
            memo[key] = out
        if rows is not None:
            picked = out
            continue
        cid = min(ca, cb if cb is not None else ca)
        clusters[cid], made[cid] = (new_keys, out), key
        for k in new_keys:
            where[k] = cid
    if picked is not None:
        return spread(picked)
    result = np.zeros((2 * len(outputs), 2 * len(outputs), full), dtype=complex)
    for i, ki in enumerate(outputs):
        ci = where[ki]
        keys_i, y_i = clusters[ci]
        for j, kj in enumerate(outputs):
            if where[kj] == ci:
                result[2 * i : 2 * i + 2, 2 * j : 2 * j + 2] = spread(_blk(y_i, keys_i.index(ki), keys_i.index(kj)))
    if pick is not None:
        return result[np.ix_(list(pick[0]), list(pick[1]))]
    return result
