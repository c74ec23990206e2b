"""Model parameters set by their path in the assembly file: one parser, two forms of the model.

A path is read once, against the assembly (:func:`check_path`: every key must
name something, else the error lists the keys that exist), into a *target*:
what it names (a component's number, a material, a joint's or a support's
matrix, a body).  The table :data:`_SETTERS` holds, for each kind of target,
how to set it on an :class:`~substructure.assembly.Assembly`
(:func:`set_parameters`: a normal model that saves as usual) and on its SI
form :class:`~substructure.updating.structure.Structure`
(:func:`apply_path_si`: the same paths and values without building any
object, the fits' fast path; the tests check that both give the same FRFs to
rounding).  The paths are listed by
:func:`substructure.updating.parameters.model_parameters`.
"""

from __future__ import annotations

import warnings
from typing import Mapping

import attrs
import numpy as np

from ..errors import InvalidValueError, NonPassiveJointWarning, UnknownPointError
from ..joints import DAMPING_UNITS, STIFFNESS_UNITS
from ..materials import E_RANGE, LOSS_FACTOR_MAX, RHO_RANGE, Material
from ..units import Q_, format_quantity
from .structure import assembly_checked

__all__ = ["apply_path_si", "set_parameters", "check_path"]


_MAT_COLUMN = {"E": 0, "nu": 1, "rho": 2, "loss_factor": 3}


_MAT_LIMITS = (("E", "Pa", *E_RANGE), ("nu", "", -1.0, 0.5), ("rho", "kg/m^3", *RHO_RANGE),
               ("loss_factor", "", 0.0, LOSS_FACTOR_MAX))
"""Per column of the SI material arrays: the name, the unit and the range :class:`Material` takes (nu open)."""


def _materials_checked(path: str, value: float, *arrays) -> None:
    """The SI form's material rows (``E, nu, rho, loss factor``; an insert's from its third column) in the ranges
    :class:`Material` takes, as :func:`set_parameters` refuses them through the objects."""
    for rows in arrays:
        for column, (name, unit, lo, hi) in enumerate(_MAT_LIMITS):
            v = rows[:, column]
            inside = (v > lo) & (v < hi) if name == "nu" else (v >= lo) & (v <= hi)
            if not inside.all():
                got, unit = float(v[~inside][0]), " " + unit if unit else ""
                left, right = ("(", ")") if name == "nu" else ("[", "]")
                raise InvalidValueError(f"parameter {path!r} = {value!r}: makes {name} {got:g}{unit}; expected {name} "
                                        f"in {left}{lo:g}, {hi:g}{right}{unit}")


def _arrays_of(component):
    from .structure import BeamArrays

    return BeamArrays.from_beam(component)


def _bore_inserts_si(structure, path: str, name: str, od: float, material: str, value: float):
    """A part's bore made in its shank where another plain beam holds it (an insert of its material and od)."""
    value = 0.0 if value < 1e-6 else value
    out = structure
    for other in structure.beams.values():
        if other.name == name:
            continue
        hit = np.array([n == material for n in other.insert_names]) & np.isclose(other.insert[:, 0], od)
        if hit.any():
            ins = other.insert.copy()
            ins[hit, 1] = value
            out = out.with_beam(_section_checked(path, other.evolve(insert=ins), other))
    for other in structure.opaque.values():
        bored = None if other.name == name else _bored_shank(other, material, od, value)
        if bored is not None:
            out = out.with_opaque(bored)
    return out


def _geometry(beam, path: str, rest: list[str], value: float):
    """The beam arrays with a segment's size or the overhang set (``rest``: the path after the component)."""
    if rest == ["overhang"]:
        i = _overhang_index(beam)
        length = beam.length.copy()
        length[i] += value - beam.total_length
        return beam.evolve(length=length)
    i = _index(path, rest[1], beam.length.size, f"segment index of {beam.name!r}")
    what = ".".join(rest[2:])
    if what in ("length", "od", "id", "od_tip", "id_tip"):
        if what == "id_tip" and value < 1e-6:  # a bore under a micrometre is no bore, as on the objects
            value = 0.0
        arr = getattr(beam, what).copy()
        arr[i] = value
        return beam.evolve(**{what: arr})
    if what == "end":  # the step to the next segment moves, the component's length kept
        length = beam.length.copy()
        shift = value - float(length[:i + 1].sum())
        length[i] += shift
        length[i + 1] -= shift
        return beam.evolve(length=length)
    if what in ("insert.od", "insert.id"):
        ins = beam.insert.copy()
        ins[i, 0 if what == "insert.od" else 1] = value
        return beam.evolve(insert=ins)
    ratio = beam.ratio.copy()
    ratio[i] = value
    return beam.evolve(ratio=ratio)


def _problems(beam) -> tuple:
    """``(what, mask)`` of every check of :class:`~substructure.beams.Segment` on the beam's arrays."""
    insert_od, insert_id = beam.insert[:, 0], beam.insert[:, 1]
    sizes = np.concatenate([beam.length, beam.od, beam.id, beam.ratio, insert_od, insert_id])
    thin, wide = beam.od < 1e-6, beam.id >= beam.od * beam.ratio
    tapered_bore = np.zeros(thin.shape, dtype=bool)
    if not beam.no_tips:  # the tip ends' sizes too (Segment's checks of a taper)
        od1, id1 = beam.tips
        sizes = np.concatenate([sizes, od1, id1])
        thin, wide = thin | (od1 < 1e-6), wide | (id1 >= od1 * beam.ratio)
        tapered_bore = (insert_od > 0) & ~np.isclose(id1, beam.id, rtol=1e-12, atol=0.0)
    return (("a size that is not a finite number", ~np.isfinite(sizes)),
            ("a segment shorter than 1 um", beam.length < 1e-6),
            ("an outer diameter under 1 um", thin),
            ("a bore as wide as the section", wide),
            ("an insert wider than its bore", (insert_od > 0) & (insert_od > beam.id)),
            ("an insert's bore as wide as the insert", (insert_od > 0) & (insert_id >= insert_od)),
            ("an insert in a tapered bore", tapered_bore))


def _section_checked(path: str, beam, before=None):
    """``beam`` if every segment is one the assembly holds (the checks of :class:`~substructure.beams.Segment`),
    else an error naming the value: the SI form refuses what the assembly would (a fit counts the trial as
    infeasible), so that a fitted value always writes back.  Given the beam ``before`` the value was set (of
    the same segments), only what the value makes is refused: a sliver that a change added earlier cut (a
    section change or flutes starting within a micrometre of a segment's end; written back without it) does
    not refuse every later value on the beam."""
    old = _problems(before) if before is not None and before.length.size == beam.length.size else None
    for k, (what, bad) in enumerate(_problems(beam)):
        if old is not None and old[k][1].shape == bad.shape:  # (the sizes of a beam given tips just now: more)
            bad = bad & ~old[k][1]
        if np.any(bad):
            raise InvalidValueError(f"parameter {path!r}: the value makes {what} in {beam.name!r}")
    return beam


def _component_of(point) -> str:
    from ..points import parse_point

    return point[0] if isinstance(point, tuple) else parse_point(point).component


def _overhang_index(beam) -> int:
    for i, r in enumerate(beam.ratio):
        if r == 1.0:
            return i
    raise UnknownPointError(f"{beam.name!r} has no segment without flutes")


# ---------------------------------------------------------------------------
# The same on an assembly


def _si(value: float, unit: str) -> str:
    return format_quantity(Q_(float(value), unit))


def _plain(component) -> bool:
    """A plain beam of uniform segments: the parts whose materials ``materials.NAME.X`` changes."""
    from .structure import uniform_beam

    return uniform_beam(component)


def _segmented(component) -> bool:
    """A beam of plain segments, tapered ones allowed, whatever physics its type adds (a nut on a holder):
    its segments' numbers are set on the object."""
    from ..beams import Segment
    from ..components import Beam

    return isinstance(component, Beam) and all(type(s) is Segment for s in component.segments)


def bore_segments(comp) -> list[int] | None:
    """The segments a component's common bore (``components.C.bore``) runs through, or None.

    A bore through the whole part: every segment without an insert, when none is tapered and they
    share one bore diameter (0 for a solid part).  Setting it bores the part's shank where another
    part holds it too (an insert of the part's material and outer diameter, as a holder's insert
    stands for the tool's shank).
    """
    segs = getattr(comp, "segments", None)
    if not segs or any(seg.is_tapered for seg in segs):
        return None
    free = [i for i, seg in enumerate(segs) if seg.insert is None]
    if not free or len({segs[i].id.m_as("m") for i in free}) != 1:
        return None
    return free


def _overhang_segment(tool) -> int | None:
    """The segment whose length a tool's overhang changes: the first without flutes."""
    for i, seg in enumerate(tool.segments):
        if seg.flutes is None:
            return i
    return None


def _on_beam(assembly, point: str):
    from ..points import parse_point

    ref = parse_point(point)
    try:
        comp = assembly.component(ref.component)
    except UnknownPointError:
        return None, 0.0, 0.0
    if not _segmented(comp):
        return None, 0.0, 0.0
    return comp.name, comp.position(ref), comp.length_m




def _parts(path: str) -> list[str]:
    if not isinstance(path, str) or not path.strip():
        raise InvalidValueError(f"path: got {path!r}; expected a parameter path such as 'joints.holder-tool.k.yf'")
    return path.strip().split(".")


def _unknown(path: str, why: str) -> UnknownPointError:
    return UnknownPointError(f"parameter {path!r}: {why}")


_HEADS = ("components", "materials", "joints", "supports", "sensors", "masses")
"""The first key of a parameter path."""
_SEGMENT_KEYS = ("length", "od", "id", "od_tip", "id_tip", "end", "insert.od", "insert.id", "flutes.diameter_ratio")
"""The values of ``components.C.segments.I``."""
_COMPONENT_KEYS = ("segments", "overhang", "E", "rho", "loss_factor", "material", "supports", "bore")
"""The keys after ``components.C``."""
_MATERIAL_KEYS = tuple(_MAT_COLUMN)
"""The values of a material (``materials.M.*``, ``components.C.material.*``): case-sensitive."""
_MATRIX_KEYS = ("k", "c")
"""A joint's or a support's stiffness and damping."""
_ENTRIES = ("yf", "ym", "tf", "tm")
"""The entries of a stiffness or damping matrix (``ym`` and ``tf`` are one number: either sets both)."""


def _expected(keys) -> str:
    return ", ".join(str(k) for k in keys) or "none"


def _key(path: str, where: str, got: str, allowed) -> None:
    """Refuse ``got`` after ``where`` unless it is one of ``allowed`` (case-sensitive)."""
    if got not in allowed:
        after = f"after {where!r}" if where else "at the start (not a parameter path)"
        raise _unknown(path, f"unknown key {got!r} {after}; expected one of {_expected(allowed)}")


def _index(path: str, text: str, count: int, what: str) -> int:
    """A list index as written in a path: ``0`` to ``count - 1``, no sign (``-1`` is refused, not the last)."""
    if not text.isdecimal() or not text.isascii() or int(text) >= count:
        if count == 0:
            raise _unknown(path, f"{what} {text!r}: there are none")
        valid = f"0 to {count - 1}" if count > 1 else "0"
        raise _unknown(path, f"{what} {text!r}: valid indices are {valid} (from 0; a negative index does not count "
                             "from the end)")
    return int(text)


def _length(path: str, parts: list[str], allowed: tuple[int, ...]) -> None:
    if len(parts) not in allowed:
        raise _unknown(path, "not a parameter path (see substructure.updating.parameters)")


def _materials_of_parts(assembly) -> list[str]:
    """The names of the materials the plain beam components' segments and inserts are made of."""
    return sorted({m.name for c in assembly.components if _plain(c) for seg in c.segments
                   for m in (seg.material, *((seg.insert.material,) if seg.insert is not None else ()))})


def check_path(assembly, path: str) -> list[str]:
    """The keys of ``path`` after checking that each names something of ``assembly``.

    Parameters
    ----------
    assembly : Assembly
        The model.
    path : str
        A parameter path (see :mod:`substructure.updating.parameters`).

    Returns
    -------
    list of str
        The path's keys.

    Raises
    ------
    UnknownPointError
        For a key that names nothing, with the keys that exist there (a
        negative index, an entry other than ``yf``, ``ym``, ``tf``,
        ``tm``, a material value other than ``E``, ``rho``, ``nu``,
        ``loss_factor``: keys are case-sensitive).
    """
    return _resolve(assembly, path)[0]


def _resolve(assembly, path: str) -> tuple[list[str], tuple]:
    """The path's keys and its target, ``(kind, *what)``, a key of :data:`_SETTERS` and its arguments."""
    parts = _parts(path)
    head = parts[0]
    _key(path, "", head, _HEADS)
    if head == "components":
        _length(path, parts, range(3, 7))
        _key(path, "components", parts[1], sorted(assembly.component_names))
        comp = assembly.component(parts[1])
        from ..components import own_parameters

        rest, where, own = parts[2:], f"components.{parts[1]}", tuple(p.name for p in own_parameters(comp))
        target = ("component", comp.name, tuple(rest))
        if len(rest) == 1 and rest[0] in own:  # a number the component's type adds
            return parts, target
        if not _segmented(comp):
            why = f"its own parameters are {_expected(own)}" if own else "it names no parameters of its own"
            raise _unknown(path, f"{parts[1]!r} is not a stepped beam, and {why}")
        _key(path, where, rest[0], _COMPONENT_KEYS + own)
        if rest[0] == "segments":
            _length(path, rest, (3, 4))
            i = _index(path, rest[1], len(comp.segments), f"segment index of {comp.name!r}")
            what, seg = ".".join(rest[2:]), comp.segments[i]
            _key(path, f"{where}.segments.{i}", what, _SEGMENT_KEYS)
            if what.startswith("insert.") and seg.insert is None:
                raise _unknown(path, f"segment {i} of {comp.name!r} has no insert")
            if what.startswith("flutes.") and seg.flutes is None:
                raise _unknown(path, f"segment {i} of {comp.name!r} has no flutes")
        elif rest[0] == "material":
            _length(path, rest, (2,))
            _key(path, f"{where}.material", rest[1], _MATERIAL_KEYS)
        elif rest[0] == "supports":
            _length(path, rest, (2,))
            _key(path, f"{where}.supports", rest[1], ("k",))
            on_it = tuple(("supports", i) for i, s in enumerate(assembly.supports)
                          if _on_beam(assembly, s.at)[0] == comp.name)
            return parts, ("link", on_it, ("k",))
        else:
            _length(path, rest, (1,))
            from ..components import Tool

            if rest[0] == "overhang" and (not isinstance(comp, Tool) or _overhang_segment(comp) is None):
                raise _unknown(path, f"{comp.name!r} has no overhang (a tool with a segment without flutes has)")
            if rest[0] == "bore" and bore_segments(comp) is None:
                raise _unknown(path, f"{comp.name!r} has no common bore (its segments without an insert, none "
                                     "tapered, with one bore diameter have)")
        return parts, target
    if head == "materials":
        _length(path, parts, range(3, 100))
        _key(path, ".".join(parts[:-1]), parts[-1], _MATERIAL_KEYS)
        name, made = ".".join(parts[1:-1]), _materials_of_parts(assembly)
        if name not in made:
            raise _unknown(path, f"no part is made of {name!r} (materials of the parts: {_expected(made)})")
        return parts, ("material", name, parts[-1])
    if head == "joints":
        _length(path, parts, (3, 4))
        joint = assembly.joint(parts[1])  # unknown: the joints there are listed
        from ..components import own_parameters

        own = tuple(p.name for p in own_parameters(joint))
        if not (len(parts) == 3 and parts[2] in own):  # else a number the joint model adds (a loss factor)
            _key(path, f"joints.{parts[1]}", parts[2], _MATRIX_KEYS + own)
            if len(parts) == 4:
                _key(path, f"joints.{parts[1]}.{parts[2]}", parts[3], _ENTRIES)
        return parts, ("link", (("joints", joint.name),), tuple(parts[2:]))
    if head == "supports":
        count = len(assembly.supports)
        _length(path, parts, (3, 4))
        if "+" in parts[1]:
            _length(path, parts, (3,))
            indices = tuple(_index(path, text, count, "support index") for text in parts[1].split("+"))
            _key(path, f"supports.{parts[1]}", parts[2], ("k",))
        else:
            indices = (_index(path, parts[1], count, "support index"),)
            where = f"supports.{parts[1]}"
            _key(path, where, parts[2], ("at",) if len(parts) == 3 else _MATRIX_KEYS)
            if len(parts) == 4:
                _key(path, f"{where}.{parts[2]}", parts[3], _ENTRIES)
        return parts, ("link", tuple(("supports", i) for i in indices), tuple(parts[2:]))
    _length(path, parts, (3,))
    _key(path, head, parts[1], [s.name for s in getattr(assembly, head)])
    _key(path, f"{head}.{parts[1]}", parts[2], ("mass", "inertia", "at") if head == "masses" else
         ("mass", "inertia"))
    return parts, ("link", ((head, parts[1]),), (parts[2],))


def _quiet(build):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", NonPassiveJointWarning)
        return build()


def _scaled_matrix(matrix, factor: float, units) -> dict:
    return {e: _si(matrix.get(e) * factor, units[e]) for e in ("yf", "ym", "tf", "tm") if matrix.get(e) != 0}


def _set_matrix(owner, kind: str, entry: str, value: float):
    units = STIFFNESS_UNITS if kind == "k" else DAMPING_UNITS
    entries = ("ym", "tf") if entry in ("ym", "tf") else (entry,)  # one number (reciprocity): either sets both
    update = {e: _si(value, units[e]) for e in entries}
    k, c = owner.k.as_dict(), owner.c.as_dict()
    (k if kind == "k" else c).update(update)
    return _quiet(lambda: attrs.evolve(owner, k=k, c=c))


def _with_material(seg, material, insert: bool):
    if insert:
        return attrs.evolve(seg, insert=attrs.evolve(seg.insert, material=material))
    return attrs.evolve(seg, material=material)


def _material_value(material: Material, prop: str, value: float) -> Material:
    if prop == "E":
        return attrs.evolve(material, E=_si(value, "Pa"))
    if prop == "rho":
        return attrs.evolve(material, rho=_si(value, "kg/m^3"))
    if prop == "nu":
        return attrs.evolve(material, nu=float(value))
    return attrs.evolve(material, loss_factor=float(value))


def _bored_shank(part, material: str, od: float, value: float):
    """``part`` with the bore of a shank it holds (an insert of ``material`` and diameter ``od``), or None."""
    if not _segmented(part):
        return None
    bore = _si(value, "m")
    new = [attrs.evolve(seg, insert=attrs.evolve(seg.insert, id=bore))
           if seg.insert is not None and seg.insert.material.name == material
           and abs(seg.insert.od.m_as("m") - od) <= 1e-9 * max(od, 1e-3) else seg
           for seg in part.segments]
    return None if new == list(part.segments) else attrs.evolve(part, segments=new)


def _set_component(comp, path: str, rest: list[str], value: float):
    """One number of one component set on the object (``rest``: the path after ``components.C``).

    The one setter of a component's own numbers: the assembly's paths use it, and so does the SI form for
    a component it evaluates through the component's own methods.
    """
    from ..components import own_parameters, with_parameter

    value = float(value)
    if len(rest) == 1 and rest[0] in {p.name for p in own_parameters(comp)}:
        return with_parameter(comp, rest[0], value)
    if not _segmented(comp):
        raise _unknown(path, f"{comp.name!r} is not a stepped beam")
    segs = list(comp.segments)
    if rest[0] == "segments" and len(rest) >= 3:
        i = int(rest[1])
        seg = segs[i]
        what = ".".join(rest[2:])
        if what in ("length", "od", "id", "od_tip", "id_tip"):
            if what in ("id", "id_tip") and value < 1e-6:  # a bore under a micrometre is no bore
                value = 0.0
            segs[i] = attrs.evolve(seg, **{what: _si(value, "m")})
        elif what == "end":
            if i + 1 >= len(segs):
                raise _unknown(path, f"segment {i} of {comp.name!r} is its last: it has no step to move")
            start = sum(x.length_m for x in segs[:i])
            stop = start + seg.length_m + segs[i + 1].length_m
            if not start < value < stop:
                raise InvalidValueError(
                    f"parameter {path!r}: got {value!r} m; expected a place strictly between where segment {i} "
                    f"begins and segment {i + 1} ends ({start * 1e3:.6g} mm to {stop * 1e3:.6g} mm from the "
                    f"base of {comp.name!r})")
            shift = value - start - seg.length_m
            segs[i] = attrs.evolve(seg, length=_si(seg.length_m + shift, "m"))
            segs[i + 1] = attrs.evolve(segs[i + 1], length=_si(segs[i + 1].length_m - shift, "m"))
        elif what in ("insert.od", "insert.id"):
            segs[i] = attrs.evolve(seg, insert=attrs.evolve(seg.insert, **{what[7:]: _si(value, "m")}))
        elif what == "flutes.diameter_ratio":
            segs[i] = attrs.evolve(seg, flutes=attrs.evolve(seg.flutes, diameter_ratio=value))
        else:
            raise _unknown(path, f"unknown segment value {what!r}")
    elif rest == ["bore"]:
        bore = _si(0.0 if value < 1e-6 else value, "m")  # a bore under a micrometre is no bore
        segs = [seg if seg.insert is not None else attrs.evolve(seg, id=bore) for seg in segs]
    elif rest == ["overhang"]:
        i = _overhang_segment(comp)
        segs[i] = attrs.evolve(segs[i], length=_si(segs[i].length_m + value - comp.length_m, "m"))
    elif rest in (["E"], ["rho"], ["loss_factor"]) or (len(rest) == 2 and rest[0] == "material"
                                                        and rest[1] in _MAT_COLUMN):
        own, prop = len(rest) == 1, rest[-1]
        renamed = {}
        for i, seg in enumerate(segs):
            m = seg.material
            if m.name not in renamed:
                current = {"E": m.E.m_as("Pa"), "rho": m.rho_si, "nu": m.nu, "loss_factor": m.loss_factor}[prop]
                new = _material_value(m, prop, current * value if own else value)
                suffix = f"-{comp.name}"
                renamed[m.name] = attrs.evolve(new, name=m.name if m.name.endswith(suffix) else m.name + suffix)
            segs[i] = attrs.evolve(seg, material=renamed[m.name])
    else:
        raise _unknown(path, "not a parameter path (see substructure.updating.parameters)")
    return attrs.evolve(comp, segments=segs)


def _set_joint(joint, rest: list[str], value: float):
    """One number of a joint set on the object: its ``k`` or ``c`` (an entry, or all as a factor), or a number
    its model adds (see :func:`substructure.components.own_parameters`)."""
    from ..components import own_parameters, with_parameter

    if len(rest) == 1 and rest[0] in {p.name for p in own_parameters(joint)}:
        return with_parameter(joint, rest[0], value)
    if len(rest) == 1:
        units = STIFFNESS_UNITS if rest[0] == "k" else DAMPING_UNITS
        matrix = joint.k if rest[0] == "k" else joint.c
        return _quiet(lambda: attrs.evolve(joint, **{rest[0]: _scaled_matrix(matrix, value, units)}))
    return _set_matrix(joint, rest[0], rest[1], value)


# ---------------------------------------------------------------------------
# Setting a target: on the assembly (objects) and on the SI form (arrays)


def _component_obj(assembly, path: str, name: str, rest: tuple, value: float):
    comp = assembly.component(name)
    out = assembly.with_component(_set_component(comp, path, list(rest), value))
    if rest == ("bore",):  # the part's shank clamped in another part (an insert of its material and od)
        od, material = comp.segments[0].od.m_as("m"), comp.segments[0].material.name
        for other in assembly.components:
            bored = None if other.name == name else _bored_shank(other, material, od, value)
            if bored is not None:
                out = out.with_component(bored)
    return out


def _component_si(structure, path: str, name: str, rest: tuple, value: float):
    if name in structure.opaque:  # a component evaluated by its own methods: changed as an object
        comp = _set_component(structure.opaque[name], path, list(rest), value)
        out = structure.with_opaque(comp)
        if rest == ("bore",):
            seg = comp.segments[0]
            out = _bore_inserts_si(out, path, name, seg.od.m_as("m"), seg.material.name, value)
        return out
    beam = structure.beam(name)
    if rest[0] in ("segments", "overhang"):
        return structure.with_beam(_section_checked(path, _geometry(beam, path, list(rest), value), beam))
    if rest == ("bore",):  # every segment without an insert: a coolant bore, a hollow shank
        value = 0.0 if value < 1e-6 else value
        bore = np.where(beam.insert[:, 0] > 0, beam.id, value)
        out = structure.with_beam(_section_checked(path, beam.evolve(id=bore), beam))
        return _bore_inserts_si(out, path, name, float(beam.od[0]), beam.material_names[0], value)
    if rest[0] in _COMPONENT_KEYS:  # its material: E, rho, loss_factor as factors, material.X as values
        mat, column = beam.material.copy(), _MAT_COLUMN[rest[-1]]
        mat[:, column] = mat[:, column] * value if len(rest) == 1 else value
        _materials_checked(path, value, mat)
        return structure.with_beam(beam.evolve(material=mat))
    source = structure.sources.get(name)  # a number the component's type adds
    if source is None:
        raise InvalidValueError(f"parameter {path!r}: set a component's own numbers before its segments'")
    return structure.with_beam(_arrays_of(_set_component(source, path, list(rest), value)))


def _material_obj(assembly, path: str, name: str, prop: str, value: float):
    comps = []
    for comp in assembly.components:
        if not _plain(comp):
            comps.append(comp)
            continue
        segs = list(comp.segments)
        for i, seg in enumerate(segs):
            if seg.material.name == name:
                segs[i] = _with_material(segs[i], _material_value(seg.material, prop, value), False)
            if seg.insert is not None and seg.insert.material.name == name:
                segs[i] = _with_material(segs[i], _material_value(seg.insert.material, prop, value), True)
        comps.append(attrs.evolve(comp, segments=segs))
    mats = tuple(_material_value(m, prop, value) if m.name == name else m for m in assembly.materials)
    return attrs.evolve(assembly, components=tuple(comps), materials=mats)


def _material_si(structure, path: str, name: str, prop: str, value: float):
    out, column = structure, _MAT_COLUMN[prop]
    for beam in structure.beams.values():
        if beam.has_taper:  # as on the objects: materials.NAME.X changes the parts of uniform segments
            continue
        hit = np.array([n == name for n in beam.material_names])
        ins_hit = np.array([n == name for n in beam.insert_names])
        if hit.any() or ins_hit.any():
            mat, ins = beam.material.copy(), beam.insert.copy()
            mat[hit, column] = value
            ins[ins_hit, 2 + column] = value
            _materials_checked(path, value, mat[hit], ins[ins_hit, 2:])
            out = out.with_beam(beam.evolve(material=mat, insert=ins))
    return out


def _link_obj(assembly, path: str, keys: tuple, rest: tuple, value: float):
    """A joint's, a support's or a body's number set on the objects (``keys``: the links it names)."""
    for head, key in keys:
        if head == "joints":
            assembly = assembly.with_joint(_set_joint(assembly.joint(key), list(rest), value))
            continue
        items = list(getattr(assembly, head))
        i = key if head == "supports" else [s.name for s in items].index(key)
        s = items[i]
        if rest == ("at",):
            items[i] = attrs.evolve(s, at=f"{_on_beam(assembly, s.at)[0]}@{_si(value, 'm')}")
        elif rest == ("mass",):
            items[i] = attrs.evolve(s, mass=_si(value, "kg"))
        elif rest == ("inertia",):
            items[i] = attrs.evolve(s, inertia=_si(value, "kg*m^2"))
        elif rest == ("k",):  # supports named together: their stiffness as one factor
            items[i] = _quiet(lambda s=s: attrs.evolve(s, k=_scaled_matrix(s.k, value, STIFFNESS_UNITS)))
        else:
            items[i] = _set_matrix(s, rest[0], rest[1], value)
        assembly = attrs.evolve(assembly, **{head: tuple(items)})
    return assembly


def _link_si(structure, path: str, keys: tuple, rest: tuple, value: float):
    for key in keys:
        i, link = structure.link(key)
        if link.custom is not None:  # a joint model of its own: changed as an object
            link = link.evolve(custom=_set_joint(link.custom, list(rest), value))
        elif rest == ("at",):
            link = link.evolve(a=(_component_of(link.a), value))
        elif rest[0] in ("mass", "inertia"):
            m, j = link.M.copy(), int(rest[0] == "inertia")
            m[j, j] = value
            link = link.evolve(M=m)
        elif len(rest) == 1:  # the whole matrix as a factor
            which = rest[0].upper()
            link = link.evolve(**{which: getattr(link, which) * value})
        else:
            m, j = getattr(link, rest[0].upper()).copy(), int(rest[1] == "tm")
            if rest[1] in ("ym", "tf"):  # one number (reciprocity): either sets both
                m[0, 1] = m[1, 0] = value
            else:
                m[j, j] = value
            link = link.evolve(**{rest[0].upper(): m})
        structure = structure.with_link(i, link)
    return structure


_SETTERS = {
    "component": (_component_obj, _component_si),
    "material": (_material_obj, _material_si),
    "link": (_link_obj, _link_si),
}
"""The one table of what a path names: how to set it on an assembly and on its SI form."""

_RESOLVED: dict = {}
"""Targets of paths already read, by the assembly they were read against (the fits set the same paths on
structures of the same configuration thousands of times)."""


def _target_of(assembly, path: str) -> tuple:
    hit = _RESOLVED.get((id(assembly), path))
    if hit is None or hit[0] is not assembly:
        try:
            target = _resolve(assembly, path)[1]
        except (InvalidValueError, UnknownPointError) as exc:  # refused again at each call, as the first time
            target = exc
        if len(_RESOLVED) >= 256:
            _RESOLVED.clear()
        hit = _RESOLVED[(id(assembly), path)] = (assembly, target)
    if isinstance(hit[1], Exception):
        raise hit[1].with_traceback(None)
    return hit[1]


def apply_path_si(structure, path: str, value: float):
    """Set the parameter at ``path`` on an SI structure (see :func:`set_parameters`).

    Parameters
    ----------
    structure : Structure
        The SI form of a configuration.
    path : str
        The parameter's path, read against the structure's assembly.
    value : float
        The value (SI, or a factor for linked parameters).

    Returns
    -------
    Structure
        The changed structure.

    Raises
    ------
    UnknownPointError
        When the path names nothing in the configuration.
    InvalidValueError
        For a value that is not a finite number, or one that makes what the
        objects refuse (a size under 1 um, a material outside the ranges of
        :class:`~substructure.materials.Material`), as :func:`set_parameters`
        refuses it.
    """
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, (int, float, np.integer, np.floating)):
        raise InvalidValueError(f"parameter {path!r}: got {value!r}; expected a finite number (SI, or a factor for a "
                                "linked parameter)")
    kind, *what = _target_of(structure.assembly, path)
    if kind == "link" and not np.isfinite(value):  # a component's sizes and materials are checked as they are made
        raise InvalidValueError(f"parameter {path!r}: got {value!r}; expected a finite number (SI, or a factor for a "
                                "linked parameter)")
    return _SETTERS[kind][1](structure, path, *what, value)


def set_parameters(assembly, values: Mapping[str, float]):
    """The assembly with parameters set (SI values by path; linked parameters as factors).

    Parameters
    ----------
    assembly : Assembly
        The model.
    values : mapping of str to float
        New values by path.

    Returns
    -------
    Assembly
        A new assembly, which :func:`substructure.save_assembly` writes normally
        (a changed material under its own name, a component's own material as
        ``NAME-COMPONENT``).

    Raises
    ------
    UnknownPointError
        When a path names nothing in the assembly.
    """
    assembly_checked(assembly)
    if not isinstance(values, Mapping):
        raise InvalidValueError(f"values: got {type(values).__name__}; expected a mapping of parameter paths to "
                                "numbers, e.g. {'joints.holder-tool.k.yf': 2e7}")
    for path, value in values.items():
        if isinstance(value, (bool, np.bool_)) or not isinstance(value, (int, float, np.integer, np.floating)):
            raise InvalidValueError(f"parameter {path!r}: got {value!r}; expected a number (SI, or a factor for a "
                                    "linked parameter)")
        try:
            kind, *what = _resolve(assembly, path)[1]
            assembly = _SETTERS[kind][0](assembly, path, *what, float(value))
        except InvalidValueError as exc:  # the value refused where the object checks it: named with its path
            if f"{path!r}" in str(exc):
                raise
            raise InvalidValueError(f"parameter {path!r} = {value!r}: {exc}") from None
        except (IndexError, ValueError, AttributeError) as exc:
            raise _unknown(path, f"cannot be set ({exc})") from None
    return assembly


