"""The plan of a computation: which points take part, the links, and the coupling of a chunk.

:func:`expand_points` turns point names into DOF labels; :func:`plan` finds,
for an assembly and the requested points, the nodes of each component
(deduplicated by physical node) and the links of its sensors, masses,
supports and joints; :func:`couple` asks each component for its receptances
at its nodes and runs the coupling engine on one chunk of frequency lines.
:class:`~substructure.assembly.Assembly`, :class:`~substructure.assembly.PreparedFRF`
and :func:`substructure.sweep.sweep` share them (assemblies of the same
structure give plans that match item by item).
"""

from __future__ import annotations

import warnings
from typing import Any, Sequence

import numpy as np

from ..components.protocol import receptances
from ..coupling import Link, couple_substructures
from ..errors import AssemblyError, InvalidValueError, SubstructureWarning
from ..joints import dynamic_stiffness
from ..points import DOFS, PointRef, parse_point

__all__ = ["point_names", "expand_points", "plan", "couple", "check_connected"]


def point_names(points: Any) -> list:
    """A list of the points given: one name, a sequence of names, or one thing that is no sequence (for
    :func:`~substructure.points.parse_point` to refuse by name, as it does a wrong item of a sequence)."""
    if isinstance(points, str):
        return [points]
    try:
        return list(points)
    except TypeError:  # a number, None, a scalar quantity
        return [points]


def expand_points(points: Sequence[str] | str):
    """DOF labels of point names, and where they sit: ``(labels, [(point, dof)], refs)``.

    A point without a DOF suffix stands for both of its DOFs ``(y, theta)``.

    Parameters
    ----------
    points : str or sequence of str
        Point names, with or without a DOF suffix (``"tool.tip"``, ``"tool.tip:y"``).

    Returns
    -------
    labels : list of str
        The DOF labels (``"tool.tip:y"``, ``"tool.tip:theta"``).
    dof_index : list of tuple
        For each label, ``(index of its point in refs, 0 for y or 1 for theta)``.
    refs : list of PointRef
        The points, in order.
    """
    points = point_names(points)
    if not points:
        raise InvalidValueError("expected at least one point")
    labels, dof_index, refs = [], [], []
    for p in points:
        ref = parse_point(p)
        refs.append(ref.point)
        base = str(ref.point)
        for d, name in enumerate(DOFS):
            if ref.dof is None or ref.dof == name:
                labels.append(f"{base}:{name}")
                dof_index.append((len(refs) - 1, d))
    return labels, dof_index, refs


def check_connected(assembly) -> None:
    """Warn of an assembly whose components fall into pieces that no joint connects.

    A component joined to nothing is computed as if it floated free: a tool whose joint to the holder was left
    out gives the free tool's receptance, a plausible number for the wrong structure.  Pieces apart are a model
    all the same (the receptances between them are zero), so this is a warning, not an error.  Supports to the
    ground, sensors and masses join nothing to anything.

    Parameters
    ----------
    assembly : Assembly
        The model.

    Warns
    -----
    SubstructureWarning
        Naming the pieces, when there are two or more.
    """
    names = [c.name for c in assembly.components]
    if len(names) < 2:
        return
    index = {n: c for c in assembly.components for n in c.component_names}
    parent = {n: n for n in names}

    def root(n: str) -> str:
        while parent[n] != n:
            parent[n] = parent[parent[n]]
            n = parent[n]
        return n

    for j in assembly.joints:
        a, b = (root(index[parse_point(p).component].name) for p in j.between)
        parent[a] = b
    pieces: dict[str, list[str]] = {}
    for n in names:
        pieces.setdefault(root(n), []).append(n)
    if len(pieces) > 1:
        listed = "; ".join(", ".join(piece) for piece in pieces.values())
        warnings.warn(
            f"assembly {assembly.name!r} falls into {len(pieces)} pieces that no joint connects ({listed}): each is "
            "computed as if it floated free, with no receptance between them; if a joint was left out, join every "
            "component to the others (Assembly.connect, [[joints]] in an assembly file)", SubstructureWarning,
            stacklevel=4)


def plan(assembly, refs: Sequence[PointRef]):
    """What a computation needs: the nodes per component and the links, in order.

    Assemblies of the same structure give plans that match item by item (used
    by sweeps).

    Parameters
    ----------
    assembly : Assembly
        The model.
    refs : sequence of PointRef
        The requested points.

    Returns
    -------
    groups : list of tuple
        ``(owner, [(key, ref), ...])``: every point that takes part,
        deduplicated by physical node, grouped by the component that owns it.
    out_keys : list
        The node key of each requested point.
    links : list of tuple
        ``(key_a, key_b or None, object, label)`` for sensors, masses,
        supports and joints.
    """
    check_connected(assembly)
    nodes: dict[Any, tuple[Any, PointRef]] = {}
    # component name -> component (names are unique in an assembly)
    index = {n: c for c in assembly.components for n in c.component_names}

    def node(point) -> Any:
        ref, owner, key = assembly._resolve(point, index=index)
        nodes.setdefault(key, (owner, ref.point))
        return key

    out_keys = [node(r) for r in refs]
    links = []
    for s in assembly.sensors:
        links.append((node(s.at), None, s, f"sensor {s.name!r}"))
    for m in assembly.masses:
        links.append((node(m.at), None, m, f"mass {m.name!r}"))
    for s in assembly.supports:
        links.append((node(s.at), None, s, s.name or f"support at {s.at}"))
    for j in assembly.joints:
        ka, kb = node(j.between[0]), node(j.between[1])
        if ka == kb:
            raise AssemblyError(f"joint {j.name!r} connects a point to itself")
        links.append((ka, kb, j, f"joint {j.name!r}"))
    groups: dict[int, list] = {}
    for k, (owner, ref) in nodes.items():
        groups.setdefault(id(owner), [owner, []])[1].append((k, ref))
    return [tuple(g) for g in groups.values()], out_keys, links


def couple(groups, out_keys, links, f: np.ndarray) -> np.ndarray:
    """The coupled receptances of one chunk of lines, from a plan (frequency last).

    Parameters
    ----------
    groups, out_keys, links
        A plan, as :func:`plan` returns it.
    f : ndarray
        Frequencies in Hz.

    Returns
    -------
    ndarray
        Complex, shape ``(2k, 2k, f.size)`` for the k keys of ``out_keys``,
        DOFs ``(y, theta)`` per key: m/N, m/(N m), rad/N and rad/(N m).
    """
    blocks = [
        ([k for k, _ in items], receptances(owner, [ref for _, ref in items], f))
        for owner, items in groups
    ]
    coupling_links = [
        Link(ka, kb, None if getattr(obj, "rigid", False) else dynamic_stiffness(obj, f), label)
        for ka, kb, obj, label in links
    ]
    return couple_substructures(blocks, coupling_links, out_keys)
