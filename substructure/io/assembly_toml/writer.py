"""Writing assembly files: :func:`dumps_assembly` and :func:`save_assembly`.

Quantities are written with every digit and their unit
(:func:`~substructure.units.format_quantity`); a registered type's own
``to_toml`` hook writes its table, any other beam kind the generic table
plus its further fields.  The text is read back and compared before it is
returned, and what would not read back equal is refused, naming the
component and the fields; files are written atomically.
"""

from __future__ import annotations

import os
import re
import warnings
from typing import Any

import attrs
import pint
import tomli_w

from .. import write_text
from ...assembly import Assembly
from ...beams import Segment
from ...components import COMPONENT_TYPES, Beam
from ...errors import FileFormatError, InvalidValueError, SubstructureError
from ...frf import Frequency
from ...joints import Joint
from ...materials import CATALOG, Material
from ...units import Q_, format_quantity
from ._schema import _extra_fields, _init_fields
from .reader import loads_assembly

_HEADER_COMMENT = "# substructure assembly file (docs/file-formats.md): units on every dimensional value\n"


def _hz(value: float) -> str:
    return format_quantity(Q_(value, "Hz"))


def _frequency_table(frequency: Frequency) -> dict:
    hz = frequency.hz
    if hz.size == 1:
        raise InvalidValueError(
            f"frequency: the grid {frequency!r} has one line; an assembly file's [frequency] is a range "
            "of at least two lines (Frequency.from_range)"
        )
    raw = [hz[1] - hz[0], (hz[-1] - hz[0]) / (hz.size - 1)]
    for step in raw + [float(f"{d:.{digits}g}") for d in raw for digits in (15, 12)]:
        table = {"start": _hz(hz[0]), "stop": _hz(hz[-1]), "step": _hz(float(step))}
        try:
            if Frequency.from_range(table["start"], table["stop"], table["step"]) == frequency:
                return table
        except SubstructureError:
            continue
    raise InvalidValueError(
        f"frequency: the grid {frequency!r} is not start + step*k; an assembly file holds only "
        "start, stop and step: save the assembly with a uniform grid (Frequency.from_range)"
    )


def _material_table(material: Material) -> dict:
    return {"E": format_quantity(material.E), "nu": material.nu,
            "rho": format_quantity(material.rho), "loss_factor": material.loss_factor}


def _collect_materials(assembly: Assembly) -> dict[str, Material]:
    """The materials the file must define: the assembly's own, then custom ones in use."""
    found: dict[str, Material] = {}
    seen: dict[str, Material] = {}

    def add(material: Material, declared: bool) -> None:
        name = material.name
        if seen.setdefault(name, material) != material:
            raise InvalidValueError(
                f"materials: two different materials are called {name!r}; a file names them "
                "once: rename one (attrs.evolve(material, name=...))"
            )
        if declared or CATALOG.get(name) != material:
            found.setdefault(name, material)

    for m in assembly.materials:
        add(m, True)
    for comp in assembly.components:
        for seg in getattr(comp, "segments", ()):
            if isinstance(seg, Segment):
                add(seg.material, False)
                if seg.insert is not None:
                    add(seg.insert.material, False)
        if isinstance(comp, Beam) and not hasattr(comp, "to_toml"):
            for field in _extra_fields(type(comp)):
                value = getattr(comp, field)
                if isinstance(value, Material):
                    add(value, False)
    return found


def _kind(component) -> str:
    for kind, cls in COMPONENT_TYPES.items():
        if cls is type(component):
            return kind
    raise InvalidValueError(
        f"components: {component.name!r} is a {type(component).__name__}, which is not a registered "
        "component type; register it with substructure.components.register_component"
    )


def _segment_table(seg: Segment, with_material: bool) -> dict:
    table = {"length": format_quantity(seg.length), "od": format_quantity(seg.od)}
    if seg.id.magnitude != 0:
        table["id"] = format_quantity(seg.id)
    if with_material:
        table["material"] = seg.material.name
    if seg.insert is not None:
        ins = seg.insert
        table["insert"] = {"od": format_quantity(ins.od), "material": ins.material.name}
        if ins.id.magnitude != 0:
            table["insert"]["id"] = format_quantity(ins.id)
    if seg.flutes is not None:
        table["flutes"] = {"diameter_ratio": seg.flutes.diameter_ratio}
    for key in ("od_tip", "id_tip"):  # tapered segments
        if getattr(seg, key) is not None:
            table[key] = format_quantity(getattr(seg, key))
    if seg.taper_steps is not None:
        table["taper_steps"] = seg.taper_steps
    return table


def _component_table(component) -> dict:
    kind = _kind(component)
    if hasattr(component, "to_toml"):
        return {"name": component.name, "type": kind, **component.to_toml()}
    if not isinstance(component, Beam):
        raise InvalidValueError(
            f"components: {component.name!r} ({kind}) cannot be written to an assembly file; "
            "give its class a to_toml method"
        )
    table = {"name": component.name, "type": kind}
    if getattr(component, "description", ""):
        table["description"] = component.description
    cls = type(component)
    if "segments" in _init_fields(cls):
        shared = all(s.material == component.segments[0].material for s in component.segments)
        if shared:
            table["material"] = component.segments[0].material.name
        table["segments"] = [_segment_table(s, not shared) for s in component.segments]
    defaults = {f.name: f.default for f in attrs.fields(cls)} if attrs.has(cls) else {}
    for field in _extra_fields(cls):
        if getattr(component, field) is None and defaults.get(field, attrs.NOTHING) is None:
            continue  # an optional field left unset (e.g. a tool's teeth): the default reads back
        if field in table:
            raise InvalidValueError(
                f"components: {component.name!r} ({kind}) has a field {field!r} that clashes with the key of "
                f"the segments' material; give {cls.__name__} to_toml/from_toml hooks (docs/extending.md)"
            )
        table[field] = _field_value(component, kind, field, getattr(component, field))
    return table


def _field_value(component, kind: str, field: str, value):
    """A field of a component subclass as a TOML value that its converter reads back."""
    if isinstance(value, pint.Quantity):
        if value.ndim != 0:
            raise InvalidValueError(
                f"components: {component.name!r} ({kind}) field {field!r} is an array quantity, which the "
                f"generic table cannot hold; give {type(component).__name__} to_toml/from_toml hooks"
            )
        return format_quantity(value)
    if isinstance(value, Material):
        return value.name
    if isinstance(value, (bool, int, float, str)):
        return value
    if isinstance(value, (tuple, list)) and all(isinstance(v, (bool, int, float, str)) for v in value):
        return list(value)
    raise InvalidValueError(
        f"components: {component.name!r} ({kind}) field {field!r} holds a {type(value).__name__}, which an "
        f"assembly file cannot hold; give {type(component).__name__} to_toml/from_toml hooks "
        "(docs/extending.md) rather than lose it"
    )


def _provenance(joint) -> dict:
    """The provenance keys of a joint (none when not stated); a prior is written out as its values."""
    p = getattr(joint, "provenance", None)
    if p is None:
        return {}
    return {"provenance": p.kind, **({"source": p.source} if p.source else {}),
            **({"uncertainty": p.uncertainty} if p.uncertainty is not None else {})}


def _matrices(item) -> dict:
    return {key: m.as_dict() for key, m in (("k", item.k), ("c", item.c)) if m}


def _point_mass(item) -> dict:
    """The table of a sensor or a mass: its name, point, mass and inertia (written when not 0)."""
    return {"name": item.name, "at": item.at, "mass": format_quantity(item.mass),
            **({"inertia": format_quantity(item.inertia)} if item.inertia.magnitude != 0 else {})}


def _key(key: str) -> str:
    return key if re.fullmatch(r"[A-Za-z0-9_-]+", key) else _inline(key)


def _inline(value) -> str:
    """One TOML value on one line (scalars formatted by tomli_w)."""
    if isinstance(value, dict):
        return "{ " + ", ".join(f"{_key(k)} = {_inline(v)}" for k, v in value.items()) + " }"
    if isinstance(value, (list, tuple)):
        return "[" + ", ".join(_inline(v) for v in value) + "]"
    return tomli_w.dumps({"v": value})[len("v = "):].rstrip("\n")


def _body(table: dict) -> list[str]:
    lines = []
    for key, value in table.items():
        if isinstance(value, list) and value and all(isinstance(v, dict) for v in value):
            lines += [f"{_key(key)} = ["] + [f"  {_inline(v)}," for v in value] + ["]"]
        else:
            lines.append(f"{_key(key)} = {_inline(value)}")
    return lines


def _emit(doc: dict) -> str:
    """The document laid out as docs/file-formats.md shows it: tables per section, segments one per line."""
    out = [f"{_key(k)} = {_inline(v)}" for k, v in doc.items() if not isinstance(v, (dict, list))]
    for key, value in doc.items():
        if isinstance(value, dict) and value and all(isinstance(v, dict) for v in value.values()):
            for name, table in value.items():
                out += ["", f"[{key}.{_key(name)}]", *_body(table)]
        elif isinstance(value, dict):
            out += ["", f"[{key}]", *_body(value)]
        elif isinstance(value, list):
            for table in value:
                out += ["", f"[[{key}]]", *_body(table)]
    return "\n".join(out) + "\n"


def dumps_assembly(assembly: Assembly) -> str:
    """Write an assembly as TOML text that :func:`loads_assembly` reads back equal.

    Custom materials (the assembly's ``materials`` and any non-catalogue
    material its segments use) are written to ``[materials.NAME]`` tables; a
    component's material is written once when all its segments share it.

    Parameters
    ----------
    assembly : Assembly
        The assembly.

    Returns
    -------
    str
        The TOML text, every dimensional value with its unit.

    Raises
    ------
    InvalidValueError
        For what a file cannot hold: a non-uniform frequency grid, two
        different materials of the same name, components of an unregistered
        type or without a file form (measured components, subassemblies),
        joint models other than :class:`Joint`.
    """
    if not isinstance(assembly, Assembly):
        raise InvalidValueError(f"assembly: got {type(assembly).__name__}; expected an Assembly")
    doc: dict[str, Any] = {"name": assembly.name}
    if assembly.frequency is not None:
        doc["frequency"] = _frequency_table(assembly.frequency)
    materials = _collect_materials(assembly)
    if materials:
        doc["materials"] = {name: _material_table(m) for name, m in materials.items()}
    doc["components"] = [_component_table(c) for c in assembly.components]
    for j in assembly.joints:
        if type(j) is not Joint:
            raise InvalidValueError(
                f"joints: {j.name!r} is a {type(j).__name__}, which an assembly file cannot hold "
                "(only Joint's k, c and rigid); save it another way rather than lose its parameters"
            )
    if assembly.joints:
        doc["joints"] = [
            {"name": j.name, "between": list(j.between), **({"rigid": True} if j.rigid else _matrices(j)),
             **_provenance(j)}
            for j in assembly.joints
        ]
    if assembly.supports:
        doc["supports"] = [
            {**({"name": s.name} if s.name is not None else {}), "at": s.at, **_matrices(s)}
            for s in assembly.supports
        ]
    if assembly.sensors:
        doc["sensors"] = [{**_point_mass(s), **({"always_on": True} if s.always_on else {})}
                          for s in assembly.sensors]
    if assembly.masses:
        doc["masses"] = [_point_mass(m) for m in assembly.masses]
    text = _HEADER_COMMENT + _emit(doc)
    _check_round_trip(assembly, text)
    return text


def _differences(a, b) -> list[str]:
    """The fields in which two components of one attrs class differ (all of them if that is unclear)."""
    if type(a) is not type(b):
        return [f"type {type(b).__name__} instead of {type(a).__name__}"]
    if not attrs.has(type(a)):
        return ["its value"]
    out = []
    for field in attrs.fields(type(a)):
        x, y = getattr(a, field.name), getattr(b, field.name)
        if not _equal(x, y):  # e.g. arrays: no single truth value, not equal
            out.append(f"{field.name} {x!r} read back as {y!r}")
    return out or ["its value"]


def _check_round_trip(assembly: Assembly, text: str) -> None:
    """Refuse to write what would not read back equal (a file never loses a value silently)."""
    try:
        with warnings.catch_warnings():  # the user saw them when the assembly was built
            warnings.simplefilter("ignore")
            back = loads_assembly(text, source="the written text")
    except FileFormatError as exc:
        raise InvalidValueError(
            f"assembly {assembly.name!r}: the file would not read back ({exc}); a component's to_toml and "
            "from_toml must agree"
        ) from None
    # materials in use are declared on writing: the list may grow, no value is lost
    declared = all(any(_equal(m, n) for n in back.materials) for m in assembly.materials)
    if declared:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            back = attrs.evolve(back, materials=assembly.materials)
        if _equal(back, assembly):
            return
    for mine, theirs in zip(assembly.components, back.components):
        if _equal(mine, theirs):
            continue
        problems = _differences(mine, theirs)
        raise InvalidValueError(
            f"components: {mine.name!r} ({type(mine).__name__}) would not read back equal from an assembly "
            f"file: {'; '.join(problems)}; give its class to_toml/from_toml hooks that keep every field "
            "(docs/extending.md), or save it another way"
        )
    if not declared:
        raise InvalidValueError("materials: would not read back equal from an assembly file; refusing to "
                                "write a file that loses a value")
    for what in ("frequency", "joints", "supports", "sensors", "masses", "name"):
        if not _equal(getattr(assembly, what), getattr(back, what)):
            raise InvalidValueError(f"{what}: would not read back equal from an assembly file; refusing to "
                                    "write a file that loses a value")
    raise InvalidValueError(f"assembly {assembly.name!r} would not read back equal from an assembly file")


def _equal(a, b) -> bool:
    try:
        return bool(a == b)
    except Exception:
        return False


def save_assembly(assembly: Assembly, path: str | os.PathLike, overwrite: bool = False) -> None:
    """Write an assembly file (TOML); see :func:`dumps_assembly`.

    The file is written through a temporary file in the same directory and
    an atomic rename (:func:`substructure.io.replacing`): a reader never sees
    half a file, and a failure leaves an existing file as it was.

    Parameters
    ----------
    assembly : Assembly
        The assembly; what a file cannot hold without loss is refused
        (:func:`dumps_assembly`).
    path : str or path-like
        The file to write.
    overwrite : bool, default False
        Replace an existing file; without it an existing file is an error,
        so that a user's input is never overwritten silently.

    Raises
    ------
    OutputExistsError
        When ``path`` exists and ``overwrite`` is False.
    InvalidValueError
        For what the file cannot hold (:func:`dumps_assembly`).
    """
    try:
        name = os.fsdecode(path)  # a str, bytes or os.PathLike name
    except TypeError:
        raise InvalidValueError(f"path: got {path!r} of type {type(path).__name__}; expected the name of the "
                                "assembly file (a str or os.PathLike)") from None
    write_text(name, dumps_assembly(assembly), overwrite=overwrite)
