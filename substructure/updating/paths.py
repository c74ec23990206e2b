"""Model parameters set on the SI form of a structure, by their path in the assembly file.

:func:`apply_path_si` is the counterpart on
:class:`~substructure.updating.structure.Structure` of
:func:`substructure.updating.parameters.set_parameters` on an assembly: the
same paths, the same values, without building any object (the tests check
that both give the same FRFs to rounding).
"""

from __future__ import annotations

import numpy as np

from ..errors import UnknownPointError

__all__ = ["apply_path_si"]


_MAT_COLUMN = {"E": 0, "nu": 1, "rho": 2, "loss_factor": 3}


def apply_path_si(structure, path: str, value: float):
    """Set the parameter at ``path`` on an SI structure (see :func:`set_parameters`).

    Parameters
    ----------
    structure : Structure
        The SI form of a configuration.
    path : str
        The parameter's path.
    value : float
        The value (SI, or a factor for linked parameters).

    Returns
    -------
    Structure
        The changed structure.
    """
    parts = path.split(".")
    head = parts[0]
    if head == "components":
        beam = structure.beam(parts[1])
        rest = parts[2:]
        if rest[0] == "segments":
            i = int(rest[1])
            what = ".".join(rest[2:])
            if what in ("length", "od", "id"):
                arr = getattr(beam, what).copy()
                arr[i] = value
                return structure.with_beam(beam.evolve(**{what: arr}))
            if what in ("insert.od", "insert.id"):
                ins = beam.insert.copy()
                ins[i, 0 if what == "insert.od" else 1] = value
                return structure.with_beam(beam.evolve(insert=ins))
            ratio = beam.ratio.copy()
            ratio[i] = value
            return structure.with_beam(beam.evolve(ratio=ratio))
        if rest == ["overhang"]:
            i = _overhang_index(beam)
            length = beam.length.copy()
            length[i] += value - beam.total_length
            return structure.with_beam(beam.evolve(length=length))
        if rest in (["E"], ["rho"], ["loss_factor"]):
            mat = beam.material.copy()
            mat[:, _MAT_COLUMN[rest[0]]] *= value
            return structure.with_beam(beam.evolve(material=mat))
        if rest == ["supports", "k"]:
            out = structure
            for i, link in enumerate(structure.links):
                if link.key[0] == "supports" and _component_of(link.a) == parts[1]:
                    out = out.with_link(i, link.evolve(K=link.K * value))
            return out
    if head == "materials":
        name, column = ".".join(parts[1:-1]), _MAT_COLUMN[parts[-1]]
        out, found = structure, False
        for beam in structure.beams.values():
            hit = np.array([n == name for n in beam.material_names])
            ins_hit = np.array([n == name for n in beam.insert_names])
            if hit.any() or ins_hit.any():
                mat, ins = beam.material.copy(), beam.insert.copy()
                mat[hit, column] = value
                ins[ins_hit, 2 + column] = value
                out = out.with_beam(beam.evolve(material=mat, insert=ins))
                found = True
        if not found:
            raise UnknownPointError(f"no part made of {name!r} in this configuration")
        return out
    if head == "supports" and "+" in parts[1]:
        out = structure
        for index in (int(x) for x in parts[1].split("+")):
            i, link = out.link(("supports", index))
            out = out.with_link(i, link.evolve(K=link.K * value))
        return out
    if head in ("joints", "supports", "sensors", "masses"):
        key = (head, int(parts[1]) if head == "supports" else parts[1])
        i, link = structure.link(key)
        if head in ("joints", "supports"):
            if parts[2] == "at":
                return structure.with_link(i, link.evolve(a=(_component_of(link.a), value)))
            if len(parts) == 3:
                return structure.with_link(i, link.evolve(**{parts[2].upper(): getattr(link, parts[2].upper()) * value}))
            kind, entry = parts[2], parts[3]
            m = getattr(link, kind.upper()).copy()
            if entry == "ym":
                m[0, 1] = m[1, 0] = value
            else:
                m[(0, 1)[entry == "tm"], (0, 1)[entry == "tm"]] = value
            return structure.with_link(i, link.evolve(**{kind.upper(): m}))
        if parts[2] == "at":
            return structure.with_link(i, link.evolve(a=(_component_of(link.a), value)))
        m = link.M.copy()
        m[(0, 1)[parts[2] == "inertia"], (0, 1)[parts[2] == "inertia"]] = value
        return structure.with_link(i, link.evolve(M=m))
    raise UnknownPointError(f"parameter {path!r}: not a parameter path")


def _component_of(point) -> str:
    from ..points import parse_point

    return point[0] if isinstance(point, tuple) else parse_point(point).component


def _overhang_index(beam) -> int:
    for i, r in enumerate(beam.ratio):
        if r == 1.0:
            return i
    raise UnknownPointError(f"{beam.name!r} has no segment without flutes")
