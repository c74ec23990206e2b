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

from typing import Any, Sequence

import attrs
import numpy as np

from ._engine import (
    Connection,
    Link,
    apply_connection,
    couple,
    couple_substructures,
    interface_update,
)
from .errors import FrequencyAxisMismatchError, InvalidValueError, UnknownPointError
from .units import items_of
from .frf import FRF
from .points import parse_point

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


# ---------------------------------------------------------------------------
# FRF-level operations


def _receptance(frf: Any, field: str) -> FRF:
    """The FRF as receptances: a mobility or an accelerance divided by ``i omega`` or ``-omega^2``."""
    if not isinstance(frf, FRF):
        raise InvalidValueError(f"{field}: got {type(frf).__name__}; expected an FRF")
    return frf.to_receptance()


def _as_quantity(receptance: FRF, quantity: str) -> FRF:
    """Receptances back in ``quantity``: times ``i omega`` for a mobility, ``-omega^2`` for an accelerance."""
    if quantity == "receptance":
        return receptance
    omega = receptance.frequency.omega
    factor = 1j * omega if quantity == "mobility" else -(omega**2)
    return attrs.evolve(receptance, data=receptance.data * factor[:, None, None], quantity=quantity)


def _point_dofs(frf: FRF, at: str) -> list[str]:
    ref = parse_point(at)  # spaces and all, as everywhere: "tool.tip :y" is tool.tip:y
    point = str(ref.point)
    labels = [f"{point}:y", f"{point}:theta"] if ref.dof is None else [f"{point}:{ref.dof}"]
    present = [lbl for lbl in labels if lbl in frf.outputs and lbl in frf.inputs]
    if not present:
        raise UnknownPointError(
            f"point {at}: a modification there needs the point's DOFs among both the FRF's outputs and its inputs "
            f"(a driving point: {' or '.join(labels)}); outputs are {', '.join(frf.outputs)}, inputs are "
            f"{', '.join(frf.inputs)}"
        )
    return present


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
        for the present DOFs is used; in N/m on y, N m/rad on theta.

    Returns
    -------
    FRF
        The modified FRF, same labels, quantity and units (a mobility or an
        accelerance is modified as the receptance it is).
    """
    given = frf
    frf = _receptance(frf, "frf")
    dofs = _point_dofs(frf, at)
    f = frf.frequency.hz
    dz = np.asarray(delta_stiffness(f) if callable(delta_stiffness) else delta_stiffness)
    if dz.ndim not in (2, 3) or dz.shape[0] != dz.shape[1] or dz.shape[0] not in (1, 2) or (
            dz.ndim == 3 and dz.shape[-1] not in (1, f.size)):
        raise InvalidValueError(
            f"delta_stiffness: got an array of shape {dz.shape}; expected (r, r) or (r, r, {f.size}) with r = 1 or 2 "
            f"DOFs (y, theta), one slice per frequency line"
        )
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
    dz = np.broadcast_to(dz.reshape(dz.shape[:2] + (-1,)), dz.shape[:2] + (n,))
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        w = interface_update(s, dz)
        uw = np.einsum("mkn,kjn->mjn", u, w)
        out = y - np.einsum("mkn,kjn->mjn", uw, v)
    if not np.all(np.isfinite(out)):
        raise InvalidValueError(f"modification at {at} is singular at some frequency line")
    return _as_quantity(attrs.evolve(frf, data=np.moveaxis(out, -1, 0)), given.quantity)


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

    Parameters
    ----------
    frf : FRF
        Receptances in m/N, m/(N m), rad/N, rad/(N m), with the point's DOFs among the
        outputs and the inputs (a driving point).
    at : str
        The point (``"tool.tip"``).
    mass : str or pint.Quantity
        The mass, e.g. ``"2 g"``.
    inertia : str or pint.Quantity, optional
        Rotary inertia about the bending axis, e.g. ``"0.1 kg*mm^2"``; default none.

    Returns
    -------
    FRF
        The modified FRF, same labels and units.
    """
    m, j = _mass_si(mass, inertia)
    return modify(frf, at, _mass_stiffness(-1.0, m, j))


def remove_mass(frf: FRF, at: str, mass, inertia=None) -> FRF:
    """FRF with a rigid mass (and rotary inertia) removed from a point (thesis eq. 5.4).

    Use it to make an accelerometer measurement look like a laser measurement.

    Parameters
    ----------
    frf : FRF
        Receptances in m/N, m/(N m), rad/N, rad/(N m), with the point's DOFs among the
        outputs and the inputs (a driving point).
    at : str
        The point (``"tool.tip"``).
    mass : str or pint.Quantity
        The mass, e.g. ``"2 g"``.
    inertia : str or pint.Quantity, optional
        Rotary inertia about the bending axis, e.g. ``"0.1 kg*mm^2"``; default none.

    Returns
    -------
    FRF
        The modified FRF, same labels and units.
    """
    m, j = _mass_si(mass, inertia)
    return modify(frf, at, _mass_stiffness(+1.0, m, j))


def decouple(coupled: FRF, removed: FRF, interface: Sequence[tuple[str, str, Any]]) -> FRF:
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
        Receptances of the remaining substructure alone, with the labels and
        the quantity of ``coupled`` (a mobility or an accelerance, of either
        FRF, is decoupled as the receptance it is).

    Notes
    -----
    Dual decoupling: the removed substructure enters with ``-Y`` and its
    joints with ``-K``; the same engine as coupling.
    """
    given = coupled
    items = items_of(interface, "interface", "(point_in_coupled, point_in_removed, joint or None)")
    coupled, removed = _receptance(coupled, "coupled"), _receptance(removed, "removed")
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
    for i, item in enumerate(items):
        if not isinstance(item, (tuple, list)) or len(item) != 3:
            raise InvalidValueError(f"interface[{i}]: got {item!r}; expected (point_in_coupled, point_in_removed, "
                                    "joint or None)")
        pa, pb, joint = item
        dofs_a, dofs_b = _point_dofs(coupled, pa), _point_dofs(removed, pb)
        kinds = [lbl.rsplit(":", 1)[1] for lbl in dofs_a]
        if kinds != [lbl.rsplit(":", 1)[1] for lbl in dofs_b]:
            raise InvalidValueError(f"decouple: points {pa} and {pb} have different DOFs")
        a = [labels.index(lbl) for lbl in dofs_a]
        b = [labels.index("removed/" + lbl) for lbl in dofs_b]
        if joint is None or getattr(joint, "rigid", False):
            k = None
        else:
            k = -joint.dynamic_stiffness(coupled.frequency.hz)
            if len(a) == 1:  # the joint's entry on that DOF: k_yf for y, k_tm for theta
                d = 0 if kinds[0] == "y" else 1
                k = k[d : d + 1, d : d + 1]
        conns.append(Connection(tuple(a), tuple(b), k, f"{pa}-{pb}"))
    out = couple(y, conns)[:na, :na]
    return _as_quantity(attrs.evolve(coupled, data=np.moveaxis(out, -1, 0)), given.quantity)
