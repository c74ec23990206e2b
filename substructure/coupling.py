"""The coupling engine: receptance coupling, decoupling and structural modification.

One operation serves every topology.  Given the uncoupled receptances ``Y``
(block diagonal over substructures) and a connection ``B`` (signed Boolean:
``B u = u_a - u_b``, or ``u_a`` for a connection to the ground) carrying the
dynamic stiffness ``K``,

``Y_c = Y - Y B^T K (I + B Y B^T K)^-1 B Y = Y - Y B^T (B Y B^T + K^-1)^-1 B Y``

(dual assembly, LM-FBS).  The first form needs no ``K^-1`` and so also takes
singular joints (a support with only ``k_yf``) and masses without rotary
inertia; a rigid connection (``K^-1 = 0``) uses
``Y_c = Y - Y B^T (B Y B^T)^-1 B Y``.  Connections are applied one after the
other, which is exact (each step is a Woodbury identity on the coupled
impedance), so chains, branches and loops need no special case.

The same update run with other signs is:

* structural modification (thesis eq. 5.1-5.4): a connection to the ground
  with ``K = Delta Z``, e.g. ``-omega^2 diag(m, J)`` to add a sensor and
  ``+omega^2 diag(m, J)`` to remove it;
* decoupling: the known substructure enters with ``-Y`` and its joint with
  ``-K``, which undoes the coupling exactly.

Arrays here are frequency-last, ``(M, M, n_freq)``; the FRF-level functions
at the bottom take and return :class:`~substructure.frf.FRF` objects.
"""

from __future__ import annotations

from typing import Sequence

import attrs
import numpy as np

from . import _blocks as bk
from .errors import AssemblyError, FrequencyAxisMismatchError, InvalidValueError, UnknownPointError
from .frf import FRF

__all__ = [
    "Connection",
    "apply_connection",
    "couple",
    "Link",
    "couple_substructures",
    "modify",
    "add_mass",
    "remove_mass",
    "decouple",
]


@attrs.frozen
class Connection:
    """A connection between DOF groups of a receptance matrix.

    Attributes
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
    """One coupling step on a frequency-last receptance matrix ``(M, M, n)``."""
    a = list(conn.a)
    n = y.shape[-1]
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
    """Apply connections one after the other; returns the coupled ``(M, M, n)`` matrix."""
    for conn in connections:
        y = apply_connection(y, conn)
    return y


@attrs.frozen
class Link:
    """A connection between two points (2 DOFs each) of substructures, or to the ground.

    ``stiffness`` is ``(2, 2, n_freq)`` acting on ``u_a - u_b`` (or ``u_a``), or
    ``None`` for a rigid connection.
    """

    a: object
    b: object | None
    stiffness: np.ndarray | None = attrs.field(eq=False)
    label: str = ""


def _blk(y: np.ndarray, i: int, j: int) -> np.ndarray:
    return y[2 * i : 2 * i + 2, 2 * j : 2 * j + 2]


def couple_substructures(blocks, links: Sequence[Link], outputs: Sequence[object]) -> np.ndarray:
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

    Returns
    -------
    ndarray ``(2p, 2p, n)``
        Zero between points of substructures that end up unconnected.

    Notes
    -----
    Substructures are merged cluster by cluster, and after each link only the
    points that the outputs or later links need are kept, so the working
    matrices stay as small as the interfaces.  Each step is the update of
    :func:`apply_connection`, with the zero off-diagonal blocks of two
    uncoupled clusters skipped.
    """
    n = blocks[0][1].shape[-1]
    clusters: dict[int, tuple[list, np.ndarray]] = {}
    where: dict[object, int] = {}
    for cid, (keys, y) in enumerate(blocks):
        clusters[cid] = (list(keys), y)
        for k in keys:
            where[k] = cid
    for step, link in enumerate(links):
        needed = set(outputs)
        for later in links[step + 1 :]:
            needed.add(later.a)
            if later.b is not None:
                needed.add(later.b)
        ca = where[link.a]
        cb = None if link.b is None else where[link.b]
        if cb is None or cb == ca:
            keys, y = clusters.pop(ca)
            ia = keys.index(link.a)
            ib = None if link.b is None else keys.index(link.b)

            def u_of(i, keys=keys, y=y, ia=ia, ib=ib):
                return _blk(y, i, ia) if ib is None else _blk(y, i, ia) - _blk(y, i, ib)

            def v_of(j, keys=keys, y=y, ia=ia, ib=ib):
                return _blk(y, ia, j) if ib is None else _blk(y, ia, j) - _blk(y, ib, j)

            s = u_of(ia) if ib is None else u_of(ia) - u_of(ib)
            kept = [i for i, k in enumerate(keys) if k in needed]
            us = [u_of(i) for i in kept]
            vs = [v_of(j) for j in kept]
            base = [[_blk(y, i, j) for j in kept] for i in kept]
            new_keys = [keys[i] for i in kept]
        else:
            ka, ya = clusters.pop(ca)
            kb, yb = clusters.pop(cb)
            ia, ib = ka.index(link.a), kb.index(link.b)
            s = _blk(ya, ia, ia) + _blk(yb, ib, ib)
            kept_a = [i for i, k in enumerate(ka) if k in needed]
            kept_b = [i for i, k in enumerate(kb) if k in needed]
            us = [_blk(ya, i, ia) for i in kept_a] + [-_blk(yb, i, ib) for i in kept_b]
            vs = [_blk(ya, ia, j) for j in kept_a] + [-_blk(yb, ib, j) for j in kept_b]
            zero = None
            base = [[_blk(ya, i, j) for j in kept_a] + [zero] * len(kept_b) for i in kept_a]
            base += [[zero] * len(kept_a) + [_blk(yb, i, j) for j in kept_b] for i in kept_b]
            new_keys = [ka[i] for i in kept_a] + [kb[i] for i in kept_b]
        with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
            w = interface_update(s, link.stiffness)
            uw = [bk.mul2(u, w) for u in us]
            m = len(new_keys)
            out = np.empty((2 * m, 2 * m, n), dtype=complex)
            for i in range(m):
                for j in range(m):
                    blk = -bk.mul2(uw[i], vs[j])
                    if base[i][j] is not None:
                        blk += base[i][j]
                    out[2 * i : 2 * i + 2, 2 * j : 2 * j + 2] = blk
        if not np.all(np.isfinite(out)):
            raise AssemblyError(
                f"coupling through {link.label or 'a connection'} is singular: a rigid joint that "
                "closes a loop of rigid joints (redundant), or a connection to a point with no "
                "flexibility"
            )
        cid = min(ca, cb if cb is not None else ca)
        clusters[cid] = (new_keys, out)
        for k in new_keys:
            where[k] = cid
    result = np.zeros((2 * len(outputs), 2 * len(outputs), n), dtype=complex)
    for i, ki in enumerate(outputs):
        ci = where[ki]
        keys_i, y_i = clusters[ci]
        for j, kj in enumerate(outputs):
            if where[kj] == ci:
                result[2 * i : 2 * i + 2, 2 * j : 2 * j + 2] = _blk(y_i, keys_i.index(ki), keys_i.index(kj))
    return result


# ---------------------------------------------------------------------------
# FRF-level operations


def _point_dofs(frf: FRF, at: str) -> list[str]:
    point = at.split(":")[0]
    labels = [f"{point}:y", f"{point}:theta"] if ":" not in at else [at]
    present = [lbl for lbl in labels if lbl in frf.outputs and lbl in frf.inputs]
    if not present:
        raise UnknownPointError(
            f"point {at}: not among the FRF's DOFs; outputs are {', '.join(frf.outputs)}"
        )
    return present


def _square_view(frf: FRF) -> tuple[list[str], np.ndarray]:
    """The FRF as a square matrix over the union of its labels, frequency-last.

    Entries that are not in the FRF are unknown; they are filled with NaN and
    must not be needed by the operation (checked by the caller).
    """
    labels = list(dict.fromkeys(frf.outputs + frf.inputs))
    n = len(frf.frequency)
    y = np.full((len(labels), len(labels), n), np.nan, dtype=complex)
    oi = [labels.index(lbl) for lbl in frf.outputs]
    ii = [labels.index(lbl) for lbl in frf.inputs]
    y[np.ix_(oi, ii)] = np.moveaxis(frf.data, 0, -1)
    return labels, y


def modify(frf: FRF, at: str, delta_stiffness) -> FRF:
    """Structural modification: add the dynamic stiffness ``Delta Z`` at a point.

    ``Y_mod = Y - Y_:p Delta Z (I + Y_pp Delta Z)^-1 Y_p:`` (thesis eq. 5.1),
    which needs the FRF's columns and rows at the point: the point's DOFs must
    be among both outputs and inputs (a driving point).

    Parameters
    ----------
    frf : FRF
        Receptances (outputs x inputs) that include the point ``at`` as a
        driving point.
    at : str
        Point name; with a DOF suffix only that DOF is modified.
    delta_stiffness : ndarray or callable
        ``(r, r, n_freq)`` with ``r`` the number of the point's DOFs present
        (y first), or a callable ``f(frequency_hz) -> (2, 2, n)`` whose block
        for the present DOFs is used.
    """
    dofs = _point_dofs(frf, at)
    f = frf.frequency.hz
    dz = delta_stiffness(f) if callable(delta_stiffness) else np.asarray(delta_stiffness)
    if dz.shape[0] == 2 and len(dofs) == 1:
        idx = 0 if dofs[0].endswith(":y") else 1
        extra = dz[1 - idx, 1 - idx]
        coupled_terms = dz[idx, 1 - idx]
        if np.any(extra != 0) or np.any(coupled_terms != 0):
            missing = "theta" if idx == 0 else "y"
            raise InvalidValueError(
                f"modification at {at}: it acts on the {missing} DOF too, which the FRF does not "
                f"have; give the {missing} receptances (e.g. by finite differences) or a modification "
                "of the present DOF only"
            )
        dz = dz[idx : idx + 1, idx : idx + 1]
    if dz.shape[:2] != (len(dofs), len(dofs)):
        raise InvalidValueError(
            f"modification at {at}: expected a {len(dofs)}x{len(dofs)} dynamic stiffness for DOFs "
            f"{dofs}, got shape {dz.shape[:2]}"
        )
    labels = list(frf.outputs)
    cols = list(frf.inputs)
    y = np.moveaxis(frf.data, 0, -1)
    o_idx = [labels.index(d) for d in dofs]
    i_idx = [cols.index(d) for d in dofs]
    u = y[:, i_idx]  # Y_:p  (outputs x r)
    v = y[o_idx, :]  # Y_p:  (r x inputs)
    s = y[np.ix_(o_idx, i_idx)]
    n = f.size
    dz = np.broadcast_to(dz, dz.shape[:2] + (n,)) if dz.shape[-1] != n else dz
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        w = interface_update(s, dz)
        uw = np.einsum("mkn,kjn->mjn", u, w)
        out = y - np.einsum("mkn,kjn->mjn", uw, v)
    if not np.all(np.isfinite(out)):
        raise InvalidValueError(f"modification at {at} is singular at some frequency line")
    return attrs.evolve(frf, data=np.moveaxis(out, -1, 0))


def _mass_stiffness(sign: float, mass: float, inertia: float):
    def dz(f):
        w2 = (2.0 * np.pi * f) ** 2
        out = np.zeros((2, 2, f.size), dtype=complex)
        out[0, 0] = sign * w2 * mass
        out[1, 1] = sign * w2 * inertia
        return out

    return dz


def _mass_si(mass, inertia) -> tuple[float, float]:
    from .units import to_si

    m = to_si(mass, "mass", "kg")
    j = 0.0 if inertia is None else to_si(inertia, "inertia", "kg*m^2")
    if m < 0 or j < 0:
        raise InvalidValueError(f"mass/inertia: got {mass!r}, {inertia!r}; expected values >= 0")
    return m, j


def add_mass(frf: FRF, at: str, mass, inertia=None) -> FRF:
    """FRF with a rigid mass (and rotary inertia) added at a point (thesis eq. 5.3).

    With only the ``y`` DOF of the point in the FRF, a mass without inertia is
    the scalar form ``H / (1 - omega^2 m H)``.
    """
    m, j = _mass_si(mass, inertia)
    return modify(frf, at, _mass_stiffness(-1.0, m, j))


def remove_mass(frf: FRF, at: str, mass, inertia=None) -> FRF:
    """FRF with a rigid mass (and rotary inertia) removed from a point (thesis eq. 5.4).

    Use it to make an accelerometer measurement look like a laser measurement.
    """
    m, j = _mass_si(mass, inertia)
    return modify(frf, at, _mass_stiffness(+1.0, m, j))


def decouple(coupled: FRF, removed: FRF, interface: Sequence[tuple[str, str, object]]) -> FRF:
    """Remove a known substructure from a coupled system's receptances.

    Parameters
    ----------
    coupled : FRF
        Square receptance matrix of the coupled system at the points of the
        remaining substructure that are wanted, including the interface
        points (both DOFs each).
    removed : FRF
        Square receptance matrix of the substructure to remove, at its
        interface points.
    interface : sequence of (point_in_coupled, point_in_removed, joint)
        How they were connected; ``joint`` is ``None`` (or a rigid
        :class:`~substructure.joints.Joint`) for a rigid connection, else an
        object with ``dynamic_stiffness(frequency_hz)``.

    Returns
    -------
    FRF
        Receptances of the remaining substructure alone, with the labels of
        ``coupled``.

    Notes
    -----
    Dual decoupling: the removed substructure enters with ``-Y`` and its
    joints with ``-K``; the same engine as coupling.
    """
    if coupled.frequency != removed.frequency:
        raise FrequencyAxisMismatchError(
            "decouple: the coupled and removed FRFs are on different frequency axes; "
            "interpolate one of them first"
        )
    for name, frf in (("coupled", coupled), ("removed", removed)):
        if frf.outputs != frf.inputs:
            raise InvalidValueError(f"decouple: {name} must be a square receptance matrix")
    na = len(coupled.outputs)
    labels = list(coupled.outputs) + [f"removed/{lbl}" for lbl in removed.outputs]
    n = len(coupled.frequency)
    y = np.zeros((len(labels), len(labels), n), dtype=complex)
    y[:na, :na] = np.moveaxis(coupled.data, 0, -1)
    y[na:, na:] = -np.moveaxis(removed.data, 0, -1)
    conns = []
    for pa, pb, joint in interface:
        a = [labels.index(lbl) for lbl in _point_dofs(coupled, pa)]
        b = [labels.index("removed/" + lbl) for lbl in _point_dofs(removed, pb)]
        if len(a) != len(b):
            raise InvalidValueError(f"decouple: points {pa} and {pb} have different DOFs")
        if joint is None or getattr(joint, "rigid", False):
            k = None
        else:
            k = -joint.dynamic_stiffness(coupled.frequency.hz)
            if len(a) == 1:
                k = k[:1, :1]
        conns.append(Connection(tuple(a), tuple(b), k, f"{pa}-{pb}"))
    out = couple(y, conns)[:na, :na]
    return attrs.evolve(coupled, data=np.moveaxis(out, -1, 0))
