"""Assembly files (TOML): read and write assemblies in the format of docs/file-formats.md.

:func:`load_assembly` and :func:`loads_assembly` read a file or a string into
an :class:`~substructure.assembly.Assembly`; :func:`save_assembly` and
:func:`dumps_assembly` write one back, quantities with every digit
(:func:`~substructure.units.format_quantity`), so that
``loads_assembly(dumps_assembly(a)) == a``.  Every problem of a file raises
:class:`~substructure.errors.FileFormatError` whose message starts with the
file name (and the line, where it can be found) and names the key path, e.g.
``components[2].segments[1].od``, what was given and what was expected.

Component types are looked up in :data:`substructure.components.COMPONENT_TYPES`,
so registered user types work: a class with a classmethod
``from_toml(table, materials, key)`` and a method ``to_toml()`` reads and
writes its own table; any other :class:`~substructure.components.Beam`
subclass uses the generic ``name``/``type``/``material``/``segments`` table,
plus one key per further field of its class (quantities written with their
unit).  Writing checks that the text reads back to an equal assembly and
refuses, naming the component and the fields, what would not: a file never
silently loses a value.
"""

from __future__ import annotations

import importlib.resources
import os
import re
import tomllib
import warnings
from typing import Any

import attrs
import pint
import tomli_w

from . import read_text, write_text
from ..assembly import Assembly
from ..beams import Flutes, Insert, Segment
from ..components import COMPONENT_TYPES, Beam
from ..errors import FileFormatError, InvalidValueError, SubstructureError
from ..frf import Frequency
from ..joints import Joint, Mass, Sensor, Support
from ..materials import CATALOG, Material
from ..points import parse_point
from ..units import Q_, format_quantity, to_si

__all__ = ["load_assembly", "loads_assembly", "save_assembly", "dumps_assembly", "default_assembly"]

_TOP_KEYS = ("name", "frequency", "materials", "components", "joints", "supports", "sensors", "masses")
_FREQUENCY_KEYS = ("start", "stop", "step")
_MATERIAL_KEYS = ("E", "nu", "rho", "loss_factor")
_COMPONENT_KEYS = ("name", "type", "material", "segments", "description")
_CATALOG_KEYS = ("name", "type", "catalog")  # and the catalogue holder's parameters
SIZE_RANGE_M = (1e-6, 1e3)
"""Lengths and diameters of segments an assembly file may give [m]: 1 um to 1 km (checked on reading)."""

MAX_TAPER_STEPS = 10_000
"""The most steps ``taper_steps`` may ask for (each is a beam element at every frequency line)."""

_SEGMENT_KEYS = ("length", "od", "id", "material", "insert", "flutes", "od_tip", "id_tip", "taper_steps")
_INSERT_KEYS = ("od", "material", "id")
_FLUTES_KEYS = ("diameter_ratio",)
_JOINT_KEYS = ("name", "between", "k", "c", "rigid")
_SUPPORT_KEYS = ("name", "at", "k", "c")
_SENSOR_KEYS = ("name", "at", "mass", "inertia", "always_on")
_MASS_KEYS = ("name", "at", "mass", "inertia")
_MATRIX_KEYS = ("yf", "ym", "tf", "tm")
_MISSING = object()
_FIELD = re.compile(r"^([A-Za-z_][A-Za-z0-9_.\[\]]*): (.*)$", re.DOTALL)
_HEADER = re.compile(r"^\s*(\[\[?)\s*([^\[\]#]+?)\s*\]\]?\s*(?:#.*)?$")
_HEADER_COMMENT = "# substructure assembly file (docs/file-formats.md): units on every dimensional value\n"
_STANDARD_FIELDS = ("name", "segments", "description")


def _path(parts) -> str:
    text = ""
    for p in parts:
        text += f"[{p}]" if isinstance(p, int) else (f".{p}" if text else str(p))
    return text


class _Locator:
    """Best-effort line numbers of keys in TOML text, for error messages."""

    def __init__(self, text: str):
        self.lines = text.splitlines()
        self.headers = []  # (line index, dotted name, is an array of tables)
        for n, line in enumerate(self.lines):
            m = _HEADER.match(line)
            if m:
                self.headers.append((n, re.sub(r"[\s\"']", "", m.group(2)), m.group(1) == "[["))

    def _section(self, parts):
        start, rest = None, list(parts)
        if len(parts) >= 2 and isinstance(parts[0], str) and isinstance(parts[1], int):
            heads = [n for n, name, array in self.headers if array and name == parts[0]]
            if parts[1] < len(heads):
                start, rest = heads[parts[1]], list(parts[2:])
        else:
            for size in range(len(parts), 0, -1):
                if all(isinstance(p, str) for p in parts[:size]):
                    name = ".".join(parts[:size])
                    found = [n for n, h, array in self.headers if h == name and not array]
                    if found:
                        start, rest = found[0], list(parts[size:])
                        break
        following = [n for n, _, _ in self.headers if start is None or n > start]
        end = following[0] if following else len(self.lines)
        return start, end, rest

    def _find_key(self, key: str, start: int, end: int, value: Any = _MISSING) -> int | None:
        pattern = re.compile(r"(?:^|[\s{,.])" + re.escape(key) + r"\s*=")
        hits = [n for n in range(start, end) if pattern.search(self.lines[n])]
        if isinstance(value, str):
            exact = [n for n in hits if f'"{value}"' in self.lines[n] or f"'{value}'" in self.lines[n]]
            hits = exact or hits
        return hits[0] if hits else None

    def line(self, parts, value: Any = _MISSING) -> int | None:
        """1-based line of the key at ``parts`` (a list of names and indices), or None."""
        header, end, rest = self._section(parts)
        start = 0 if header is None else header
        i = 0
        while i < len(rest):
            if isinstance(rest[i], str) and i + 1 < len(rest) and isinstance(rest[i + 1], int):
                key_line = self._find_key(rest[i], start, end)
                if key_line is None:
                    break
                if i + 2 == len(rest):  # an element of an array of values: the key's line
                    return key_line + 1
                elements = [n for n in range(key_line, end) if "{" in self.lines[n]]
                if rest[i + 1] >= len(elements):
                    return key_line + 1
                start = elements[rest[i + 1]]
                end = start + 1
                i += 2
            else:
                i += 1
        keys = [p for p in rest if isinstance(p, str)]
        found = self._find_key(keys[-1], start, end, value) if keys else None
        if found is not None:
            return found + 1
        return None if header is None and start == 0 else start + 1


class _Reader:
    """Builds an assembly from parsed TOML, naming the key path in every error."""

    def __init__(self, source: str, text: str, data: dict):
        self.source, self.data, self.locator = source, data, _Locator(text)
        self.materials: dict[str, Material] = dict(CATALOG)

    def _value(self, parts) -> Any:
        value = self.data
        for p in parts:
            try:
                value = value[p]
            except (KeyError, IndexError, TypeError):
                return _MISSING
        return value

    def error(self, parts, message: str) -> FileFormatError:
        line = self.locator.line(parts, self._value(parts))
        where = f"{self.source}, line {line}" if line else self.source
        key = _path(parts)
        return FileFormatError(f"{where}: {key}: {message}" if key else f"{where}: {message}")

    def wrap(self, parts, exc: SubstructureError) -> FileFormatError:
        """A constructor's error with the container's key path merged into its field."""
        message = str(exc)
        if message.startswith(self.source):
            return FileFormatError(message)
        m = _FIELD.match(message)
        if not m:
            return self.error(parts, message)
        field = [int(i) if i else k for k, i in re.findall(r"([^.\[\]]+)|\[(\d+)\]", m.group(1))]
        full = m.group(1).startswith(_path(parts) + ".") or m.group(1) == _path(parts)  # a hook's own path
        return self.error(field if full and parts else list(parts) + field, m.group(2))

    def call(self, parts, factory, *args, **kwargs):
        try:
            return factory(*args, **kwargs)
        except SubstructureError as exc:
            raise self.wrap(parts, exc) from None

    def table(self, value, parts, allowed, required=(), what="a table") -> dict:
        if not isinstance(value, dict):
            raise self.error(parts, f"got {value!r}; expected {what}")
        for key in value:
            if key not in allowed:
                raise self.error(list(parts) + [key], f"unknown key; allowed keys: {', '.join(allowed)}")
        for key in required:
            if key not in value:
                raise self.error(list(parts) + [key], "missing; this value is required")
        return value

    def array(self, value, parts, what: str) -> list:
        if not isinstance(value, list):
            raise self.error(parts, f"got {value!r}; expected {what}")
        return value

    def material(self, name, parts) -> Material:
        if not isinstance(name, str) or name not in self.materials:
            known = ", ".join(self.materials)
            raise self.error(parts, f"unknown material {name!r}; known: {known} (add a [materials.NAME] table)")
        return self.materials[name]

    # -- the file, top down -------------------------------------------------------------
    def assembly(self) -> Assembly:
        data = self.table(self.data, [], _TOP_KEYS, required=("name",))
        frequency = None
        if "frequency" in data:
            grid = self.table(data["frequency"], ["frequency"], _FREQUENCY_KEYS, _FREQUENCY_KEYS)
            frequency = self.call(["frequency"], Frequency.from_range, grid["start"], grid["stop"], grid["step"])
            if frequency.hz[0] <= 0:
                raise self.error(["frequency", "start"], f"got {grid['start']!r}; expected a frequency > 0 Hz "
                                 "(a free-free assembly has no static receptance)")
        custom = []
        materials = data.get("materials", {})
        if not isinstance(materials, dict):
            raise self.error(["materials"], f"got {materials!r}; expected [materials.NAME] tables")
        for name, table in materials.items():
            parts = ["materials", name]
            table = self.table(table, parts, _MATERIAL_KEYS, ("E", "nu", "rho"))
            custom.append(self.call(parts, Material, name, **table))
            self.materials[name] = custom[-1]
        items = {key: self.array(data.get(key, []), [key], f"[[{key}]] tables")
                 for key in ("components", "joints", "supports", "sensors", "masses")}
        components = self.unique([self.component(c, ["components", i]) for i, c in enumerate(items["components"])],
                                 "components")
        base = self.call([], Assembly, data["name"], components, frequency=frequency, materials=custom)
        joints = self.unique([self.joint(j, ["joints", i], base) for i, j in enumerate(items["joints"])], "joints")
        supports = [self.support(s, ["supports", i], base) for i, s in enumerate(items["supports"])]
        self.unique([s for s in supports if s.name is not None], "supports")
        sensors = self.unique([self.sensor(s, ["sensors", i], base) for i, s in enumerate(items["sensors"])],
                              "sensors")
        masses = self.unique([self.mass(m, ["masses", i], base) for i, m in enumerate(items["masses"])], "masses")
        return self.call([], Assembly, data["name"], components, joints, supports, sensors, frequency, custom,
                         masses)

    def unique(self, items: list, section: str) -> list:
        seen: dict[str, int] = {}
        for i, item in enumerate(items):
            if item.name in seen:
                raise self.error([section, i, "name"], f"{item.name!r} is already the name of "
                                 f"{section}[{seen[item.name]}]; names must be unique")
            seen[item.name] = i
        return items

    def component(self, table, parts):
        if not isinstance(table, dict):
            raise self.error(parts, f"got {table!r}; expected a table")
        if "type" not in table:
            raise self.error(parts + ["type"], f"missing; expected one of {', '.join(COMPONENT_TYPES)}")
        kind = table["type"]
        cls = COMPONENT_TYPES.get(kind) if isinstance(kind, str) else None
        if cls is None:
            known = ", ".join(k for k, c in COMPONENT_TYPES.items() if hasattr(c, "from_toml") or issubclass(c, Beam))
            raise self.error(parts + ["type"], f"unknown component type {kind!r}; known: {known}")
        if "catalog" in table:
            return self.catalog_holder(table, parts, cls)
        if hasattr(cls, "from_toml"):
            return self.call(parts, cls.from_toml, table, dict(self.materials), _path(parts))
        if not (isinstance(cls, type) and issubclass(cls, Beam)):
            raise self.error(parts + ["type"], f"components of type {kind!r} cannot be described in an assembly file")
        extra = _extra_fields(cls)
        with_segments = "segments" in _init_fields(cls)
        allowed = (_COMPONENT_KEYS if with_segments else ("name", "type")) + tuple(
            f for f in extra if f not in _COMPONENT_KEYS)
        self.table(table, parts, allowed, ("name", "type", "segments") if with_segments else ("name", "type"))
        kwargs = {f: table[f] for f in extra if f in table and f not in _COMPONENT_KEYS}
        if not with_segments:
            if "material" in extra and "material" in table:
                kwargs["material"] = self.material(table["material"], parts + ["material"])
            return self.call(parts, cls, table["name"], **kwargs)
        material = self.material(table["material"], parts + ["material"]) if "material" in table else None
        segments = self.array(table["segments"], parts + ["segments"], "an array of segment tables, base to tip")
        segs = [self.segment(s, parts + ["segments", j], material) for j, s in enumerate(segments)]
        if "description" in table:
            kwargs["description"] = table["description"]
        return self.call(parts, cls, table["name"], segs, **kwargs)

    def catalog_holder(self, table, parts, cls):
        """A ``catalog = "..."`` component: a standard holder of the catalogue with overrides."""
        from ..components import Holder
        from ..holders import catalog_parameters, design

        if not (isinstance(cls, type) and issubclass(cls, Holder)):
            raise self.error(parts + ["catalog"], f"only holders come from the catalogue; this component's "
                             f"type is {table['type']!r} (use type = \"holder\")")
        entry = table["catalog"]
        allowed = _CATALOG_KEYS + self.call(parts, catalog_parameters, entry)
        self.table(table, parts, allowed, ("name", "type", "catalog"))
        params = {k: v for k, v in table.items() if k not in _CATALOG_KEYS}
        for key in ("material", "tool_material"):
            if key in params and not (key == "tool_material" and params[key] == "none"):
                params[key] = self.material(params[key], parts + [key])
        resolved = self.call(parts, design, entry, **params)
        return self.call(parts, resolved.holder, table["name"], cls)

    def size(self, value, parts) -> None:
        """Refuse a length outside the range the beam model is made for (a wrong unit, or a typo)."""
        try:
            metres = to_si(value, _path(parts), "m")
        except SubstructureError:
            return  # the constructor says what is wrong with it
        if metres > 0 and not SIZE_RANGE_M[0] <= metres <= SIZE_RANGE_M[1]:
            raise self.error(parts, f"got {value!r}; expected a length from 1 um to 1 km (the range of the "
                             "beam model): check the unit")

    def segment(self, table, parts, material):
        table = self.table(table, parts, _SEGMENT_KEYS, ("length", "od"), "a segment table {length, od, ...}")
        for key in ("length", "od", "id", "od_tip", "id_tip"):
            if key in table:
                self.size(table[key], parts + [key])
        for key in ("od", "id"):
            if isinstance(table.get("insert"), dict) and key in table["insert"]:
                self.size(table["insert"][key], parts + ["insert", key])
        steps = table.get("taper_steps")
        if isinstance(steps, int) and not isinstance(steps, bool) and steps > MAX_TAPER_STEPS:
            raise self.error(parts + ["taper_steps"], f"got {steps}; expected at most {MAX_TAPER_STEPS:,} steps "
                             "(substructure.io.assembly_toml.MAX_TAPER_STEPS; the default bound needs far fewer)")
        kw = {k: table[k] for k in ("length", "od", "id", "od_tip", "id_tip", "taper_steps") if k in table}
        if "material" in table:
            kw["material"] = self.material(table["material"], parts + ["material"])
        elif material is not None:
            kw["material"] = material
        else:  # the rule of Segment: steel unless said otherwise (a [materials.steel] of the file counts)
            kw["material"] = self.materials["steel"]
        if "insert" in table:
            ins = self.table(table["insert"], parts + ["insert"], _INSERT_KEYS, ("od", "material"))
            mat = self.material(ins["material"], parts + ["insert", "material"])
            extra = {"id": ins["id"]} if "id" in ins else {}
            kw["insert"] = self.call(parts, Insert, ins["od"], mat, **extra)
        if "flutes" in table:
            flutes = self.table(table["flutes"], parts + ["flutes"], _FLUTES_KEYS, _FLUTES_KEYS)
            kw["flutes"] = self.call(parts, Flutes, flutes["diameter_ratio"])
        return self.call(parts, Segment, **kw)

    def point(self, value, parts, base: Assembly) -> str:
        if not isinstance(value, str):
            raise self.error(parts, f"got {value!r}; expected a point name such as 'tool.tip'")
        ref = self.call(parts, parse_point, value, allow_dof=False)
        self.call(parts, base.node_key, ref)
        return str(ref)

    def matrices(self, table, parts) -> dict:
        return {key: self.table(table[key], parts + [key], _MATRIX_KEYS)
                for key in ("k", "c") if key in table}

    def joint(self, table, parts, base: Assembly) -> Joint:
        table = self.table(table, parts, _JOINT_KEYS, ("name", "between"))
        between = table["between"]
        if not isinstance(between, list) or len(between) != 2:
            raise self.error(parts + ["between"], f"got {between!r}; expected two point names")
        points = [self.point(p, parts + ["between", m], base) for m, p in enumerate(between)]
        return self.call(parts, Joint, table["name"], points, rigid=table.get("rigid", False),
                         **self.matrices(table, parts))

    def support(self, table, parts, base: Assembly) -> Support:
        table = self.table(table, parts, _SUPPORT_KEYS, ("at",))
        at = self.point(table["at"], parts + ["at"], base)
        return self.call(parts, Support, at, name=table.get("name"), **self.matrices(table, parts))

    def sensor(self, table, parts, base: Assembly) -> Sensor:
        table = self.table(table, parts, _SENSOR_KEYS, ("name", "at", "mass"))
        at = self.point(table["at"], parts + ["at"], base)
        extra = {"inertia": table["inertia"]} if "inertia" in table else {}
        if "always_on" in table:
            extra["always_on"] = table["always_on"]
        return self.call(parts, Sensor, table["name"], at, table["mass"], **extra)

    def mass(self, table, parts, base: Assembly) -> Mass:
        table = self.table(table, parts, _MASS_KEYS, ("name", "at", "mass"))
        at = self.point(table["at"], parts + ["at"], base)
        extra = {"inertia": table["inertia"]} if "inertia" in table else {}
        return self.call(parts, Mass, table["name"], at, table["mass"], **extra)


def _init_fields(cls) -> tuple[str, ...]:
    return tuple(f.name for f in attrs.fields(cls) if f.init) if attrs.has(cls) else _STANDARD_FIELDS


def _extra_fields(cls) -> tuple[str, ...]:
    """The init fields of a Beam subclass beyond ``name`` and ``segments``: one key each in its table."""
    return tuple(f for f in _init_fields(cls) if f not in _STANDARD_FIELDS)


def loads_assembly(text: str, source: str = "<string>") -> Assembly:
    """Read an assembly from TOML text.

    Parameters
    ----------
    text : str
        The TOML document (docs/file-formats.md, "Assembly file").
    source : str
        Name of the text in error messages, e.g. the file name.

    Raises
    ------
    FileFormatError
        For TOML syntax (with line and column), unknown keys, missing values,
        wrong units, non-physical values, unknown materials or component
        types and points that do not exist; the message starts with
        ``source`` and names the key path.

    Returns
    -------
    Assembly
        The assembly.
    """
    if not isinstance(text, str):
        raise FileFormatError(f"{source}: got {type(text).__name__}; expected the TOML text as a str")
    text = text.removeprefix("\ufeff")  # a byte-order mark left by an editor is not part of the document
    if not text.strip():
        raise FileFormatError(f"{source}: the file is empty; expected an assembly (docs/file-formats.md)")
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise FileFormatError(f"{source}: invalid TOML: {exc}") from None
    return _Reader(source, text, data).assembly()


def load_assembly(path: str | os.PathLike) -> Assembly:
    """Read an assembly file (TOML); see :func:`loads_assembly`.

    Parameters
    ----------
    path : str or os.PathLike
        The file.

    Returns
    -------
    Assembly
        The assembly; errors name the file and the key.
    """
    name = os.fspath(path)
    text = read_text(path)
    return loads_assembly(text, source=name)


def default_assembly() -> Assembly:
    """The built-in assembly: BT40-like holder and 12 mm carbide end mill on a free-free spindle.

    Read from ``substructure/data/default_assembly.toml``, which documents
    where its numbers come from.

    Returns
    -------
    Assembly
        The assembly, with its frequency grid (20 Hz to 5 kHz, 2 Hz).
    """
    resource = importlib.resources.files("substructure") / "data" / "default_assembly.toml"
    return loads_assembly(resource.read_text(encoding="utf-8"), source="default_assembly.toml")


# -- writing ---------------------------------------------------------------------------


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


def _matrices(item) -> dict:
    return {key: m.as_dict() for key, m in (("k", item.k), ("c", item.c)) if m}


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
            {"name": j.name, "between": list(j.between), **({"rigid": True} if j.rigid else _matrices(j))}
            for j in assembly.joints
        ]
    if assembly.supports:
        doc["supports"] = [
            {**({"name": s.name} if s.name is not None else {}), "at": s.at, **_matrices(s)}
            for s in assembly.supports
        ]
    if assembly.sensors:
        doc["sensors"] = [
            {"name": s.name, "at": s.at, "mass": format_quantity(s.mass),
             **({"inertia": format_quantity(s.inertia)} if s.inertia.magnitude != 0 else {}),
             **({"always_on": True} if s.always_on else {})}
            for s in assembly.sensors
        ]
    if assembly.masses:
        doc["masses"] = [
            {"name": m.name, "at": m.at, "mass": format_quantity(m.mass),
             **({"inertia": format_quantity(m.inertia)} if m.inertia.magnitude != 0 else {})}
            for m in assembly.masses
        ]
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
        try:
            same = bool(x == y)
        except Exception:  # e.g. arrays: no single truth value
            same = False
        if not same:
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
    text = dumps_assembly(assembly)
    write_text(path, text, overwrite=overwrite)
