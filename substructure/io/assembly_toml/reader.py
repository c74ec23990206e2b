"""Reading assembly files: :func:`load_assembly`, :func:`loads_assembly`, :func:`default_assembly`.

The TOML text is parsed by ``substructure._toml.loads_toml``, then read table by table into
value objects; every problem raises :class:`~substructure.errors.FileFormatError`
naming the file, the line where it can be found and the key path
(``components[2].segments[1].od``), what was given and what was expected.
Component types are looked up in the registry, and a class's own
``from_toml`` hook reads its table.
"""

from __future__ import annotations

import importlib.resources
import os
import re
import warnings

import numpy as np

from .. import read_text
from ...assembly import Assembly
from ...beams import Flutes, Insert, Segment
from ...components import COMPONENT_TYPES, Beam
from ..._toml import TomlDocument, key_path, loads_toml
from ...errors import SubstructureError, SubstructureWarning
from ...frf import Frequency
from ...joints import DAMPING_UNITS, STIFFNESS_UNITS, Joint, JointProvenance, Mass, Sensor, Support
from ...materials import CATALOG, Material
from ...points import parse_point
from ...units import check_number_text, dimensionless, to_si
from ._schema import (_CATALOG_KEYS, _COMPONENT_KEYS, _FLUTES_KEYS, _FREQUENCY_KEYS, _INSERT_KEYS, _JOINT_KEYS,
                      _MASS_KEYS, _MATERIAL_KEYS, _MATRIX_KEYS, _SEGMENT_KEYS, _SENSOR_KEYS, _SUPPORT_KEYS,
                      _TOP_KEYS, MAX_JOINT_ENTRY, MAX_TAPER_STEPS, PLAUSIBLE, SIZE_OUTLIER, SIZE_OUTLIER_FLOOR_M,
                      MACHINE_SIZE_M, SIZE_RANGE_M, _extra_fields, _init_fields)

_NUMBER_FIRST = re.compile(r"\s*[-+]?\.?\d")  # a value written as a number (and its unit)


class _Reader:
    """Builds an assembly from parsed TOML, naming the key path in every error."""

    def __init__(self, doc: TomlDocument):
        self.data, self.doc, self.error, self.table = doc.data, doc, doc.error, doc.table
        self.materials: dict[str, Material] = dict(CATALOG)
        self.sizes: list[tuple[str, list, object, float]] = []  # (length or diameter, key path, as written, m)

    def call(self, parts, factory, *args, **kwargs):
        """``factory(*args, **kwargs)``, its errors and the package's warnings at the file, line and key path."""
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always", SubstructureWarning)
            try:
                result = factory(*args, **kwargs)
            except SubstructureError as exc:  # the constructor's field merged into the key path
                raise self.doc.wrap(parts, str(exc)) from None
        for w in caught:  # "joint 'holder-tool': not positive semi-definite" said where in which file
            message = w.message
            if isinstance(message, SubstructureWarning):
                message = type(message)(str(self.doc.wrap(parts, str(message))))
            warnings.warn(message, stacklevel=3)
        return result

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
            self.plausible(table, parts)
            custom.append(self.call(parts, Material, name, **table))
            self.materials[name] = custom[-1]
        items = {key: self.array(data.get(key, []), [key], f"[[{key}]] tables")
                 for key in ("components", "joints", "supports", "sensors", "masses")}
        components = self.unique([self.component(c, ["components", i]) for i, c in enumerate(items["components"])],
                                 "components")
        self.outlying_sizes()
        base = self.call([], Assembly, data["name"], components, frequency=frequency, materials=custom)
        joints = self.unique([self.joint(j, ["joints", i], base) for i, j in enumerate(items["joints"])], "joints")
        supports = [self.support(s, ["supports", i], base) for i, s in enumerate(items["supports"])]
        self.unique([s for s in supports if s.name is not None], "supports")
        sensors = self.unique([self.point_mass(Sensor, _SENSOR_KEYS, s, ["sensors", i], base)
                               for i, s in enumerate(items["sensors"])], "sensors")
        masses = self.unique([self.point_mass(Mass, _MASS_KEYS, m, ["masses", i], base)
                              for i, m in enumerate(items["masses"])], "masses")
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
            return self.call(parts, cls.from_toml, table, dict(self.materials), key_path(parts))
        if not (isinstance(cls, type) and issubclass(cls, Beam)):
            raise self.error(parts + ["type"], f"components of type {kind!r} cannot be described in an assembly file")
        extra = _extra_fields(cls)
        with_segments = "segments" in _init_fields(cls)
        allowed = (_COMPONENT_KEYS if with_segments else ("name", "type")) + tuple(
            f for f in extra if f not in _COMPONENT_KEYS)
        self.table(table, parts, allowed, ("name", "type", "segments") if with_segments else ("name", "type"))
        kwargs = {f: table[f] for f in extra if f in table and f not in _COMPONENT_KEYS}
        self.number_texts(kwargs, parts)
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
        from ...components import Holder
        from ...holders import catalog_parameters, design

        if not (isinstance(cls, type) and issubclass(cls, Holder)):
            raise self.error(parts + ["catalog"], f"only holders come from the catalogue; this component's "
                             f"type is {table['type']!r} (use type = \"holder\")")
        entry = table["catalog"]
        allowed = _CATALOG_KEYS + self.call(parts, catalog_parameters, entry)
        self.table(table, parts, allowed, ("name", "type", "catalog"))
        params = {k: v for k, v in table.items() if k not in _CATALOG_KEYS}
        self.number_texts(params, parts)
        for key, default in (("material", "steel"), ("tool_material", "carbide")):  # the catalogue's defaults
            if key not in params and self.materials[default] is not CATALOG[default]:
                params[key] = default  # the file's [materials.steel] counts, as for every segment
        for key in ("material", "tool_material"):
            if key in params and not (key == "tool_material" and params[key] == "none"):
                params[key] = self.material(params[key], parts + [key])
        resolved = self.call(parts, design, entry, **params)
        return self.call(parts, resolved.holder, table["name"], cls)

    def number_texts(self, values: dict, parts) -> None:
        """Refuse a value written as a number that pint would misread (``helix = "3,5 deg"`` is 35 deg to pint).

        The fields of components (a tool's ``helix``, a catalogue holder's
        angles) may reach pint without :func:`~substructure.units.quantity`.
        """
        for key, value in values.items():
            if isinstance(value, str) and _NUMBER_FIRST.match(value):
                self.call(parts, check_number_text, value, key, "one number and its unit")

    def plausible(self, table: dict, parts) -> None:
        """Refuse a material's or a body's value outside the range the models compute right (:data:`PLAUSIBLE`).

        ``E = "1e-100 Pa"`` gave a raw OverflowError, ``mass = "1e60 kg"``
        receptances of rounding noise; a negative value (or 0 where it must
        be positive) is left to the constructor, which says why.
        """
        for key in [k for k in PLAUSIBLE if k in table]:
            unit, lo, hi, words = PLAUSIBLE[key]
            value = self.call(parts, to_si, table[key], key, unit) if unit else \
                self.call(parts, dimensionless, table[key], key)
            if value < 0 or (value == 0 and lo > 0):
                continue  # the constructor says what is wrong with it
            if not lo <= value <= hi:
                raise self.error(parts + [key], f"got {table[key]!r}; expected {words} (the range the models "
                                 "compute right): check the value and its unit")

    def size(self, value, parts) -> None:
        """Refuse a length outside the range the beam model is made for (a wrong unit, or a typo)."""
        try:
            metres = to_si(value, key_path(parts), "m")
        except SubstructureError:
            return  # the constructor says what is wrong with it
        if metres > 0 and not SIZE_RANGE_M[0] <= metres <= SIZE_RANGE_M[1]:
            raise self.error(parts, f"got {value!r}; expected a length from 1 um to 1 km (the range of the "
                             "beam model): check the unit")
        self.sizes.append(("length" if parts[-1] == "length" else "diameter", parts, value, metres))

    def outlying_sizes(self) -> None:
        """Refuse a segment's size far beyond the file's others and beyond any machine tool's (:data:`SIZE_OUTLIER`):
        ``od = "12 m"`` for 12 mm read as a tool 12 metres across."""
        for kind, floor in SIZE_OUTLIER_FLOOR_M.items():
            sizes = [(parts, value, m) for k, parts, value, m in self.sizes if k == kind and m > 0]
            if len(sizes) < 3:
                continue
            median = float(np.median([m for _, _, m in sizes]))
            for parts, value, m in sizes:
                if m > floor and m > SIZE_OUTLIER * median:
                    raise self.error(parts, f"got {value!r}, {m / median:.3g} times the median {kind} of the file's "
                                     f"segments ({median * 1e3:.4g} mm) and over {floor:g} m: a unit typo? (m for mm)")
        lengths: dict[tuple, float] = {}  # a component's length, by its key path
        for kind, parts, _, m in self.sizes:
            if kind == "length":
                lengths[tuple(parts[:2])] = lengths.get(tuple(parts[:2]), 0.0) + m
        large = [(f"{m:.4g} m long", list(at)) for at, m in lengths.items() if m > MACHINE_SIZE_M["length"]]
        large += [(f"{m:.4g} m across", parts) for kind, parts, _, m in self.sizes
                  if kind == "diameter" and m > MACHINE_SIZE_M["diameter"]]
        if large:
            said, parts = large[0]
            warnings.warn(SubstructureWarning(str(self.doc.wrap(parts, (
                f"{said}; no spindle, holder or tool is over {MACHINE_SIZE_M['length']:g} m long or "
                f"{MACHINE_SIZE_M['diameter']:g} m across: sizes in m written for mm? (read as written)")))),
                stacklevel=4)

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
        """The ``k`` and ``c`` tables, each entry at most :data:`MAX_JOINT_ENTRY` in SI units.

        ``yf = "1e300 N/m"`` gave a numpy overflow in the coupling and then
        "coupling through joint ... is singular: a rigid joint that closes a
        loop", which it is not.
        """
        out = {}
        for key, units in (("k", STIFFNESS_UNITS), ("c", DAMPING_UNITS)):
            if key not in table:
                continue
            out[key] = self.table(table[key], parts + [key], _MATRIX_KEYS)
            for entry, value in out[key].items():
                try:
                    si = to_si(value, entry, units[entry])
                except SubstructureError:
                    continue  # the joint says what is wrong with it
                if abs(si) > MAX_JOINT_ENTRY:
                    raise self.error(parts + [key, entry], f"got {value!r}; expected at most {MAX_JOINT_ENTRY:g} "
                                     f"{units[entry]} in magnitude (beyond, the coupling's products of entries "
                                     "overflow; a joint without flexibility is rigid = true)")
        return out

    def joint(self, table, parts, base: Assembly) -> Joint:
        table = self.table(table, parts, _JOINT_KEYS, ("name", "between"))
        between = table["between"]
        if not isinstance(between, list) or len(between) != 2:
            raise self.error(parts + ["between"], f"got {between!r}; expected two point names")
        points = [self.point(p, parts + ["between", m], base) for m, p in enumerate(between)]
        if points[0] != points[1] and base.node_key(parse_point(points[0])) == base.node_key(parse_point(points[1])):
            raise self.error(parts + ["between"], f"{between[0]!r} and {between[1]!r} are the same point; a joint "
                             "connects two different points")
        if table.get("prior", False) is not False:
            return self.prior_joint(table, parts, base, points)
        stated = {key: table[key] for key in ("provenance", "source", "uncertainty") if key in table}
        if stated and "provenance" not in stated:
            raise self.error(parts + [next(iter(stated))], "goes with provenance = \"identified\", \"predicted\", "
                             "\"borrowed\" or \"prior\"")
        if "provenance" in stated and table.get("rigid", False):
            raise self.error(parts + ["provenance"], "a rigid joint has no values to come from anywhere")
        for key, kind in (("source", str), ("provenance", str)):
            if key in stated and not isinstance(stated[key], kind):
                raise self.error(parts + [key], f"got {stated[key]!r}; expected a string")
        provenance = self.call(parts, JointProvenance, stated["provenance"], stated.get("source", ""),
                               stated.get("uncertainty")) if stated else None
        return self.call(parts, Joint, table["name"], points, rigid=table.get("rigid", False),
                         provenance=provenance, **self.matrices(table, parts))

    def prior_joint(self, table, parts, base: Assembly, points) -> Joint:
        """``prior = true``: the documented prior of the catalogue holder the joint touches."""
        from ...joint_priors import prior_for

        if table["prior"] is not True:
            raise self.error(parts + ["prior"], f"got {table['prior']!r}; expected true (or leave it out)")
        clash = [key for key in ("k", "c", "rigid", "provenance", "source", "uncertainty") if key in table]
        if clash:
            raise self.error(parts + [clash[0]], "prior = true takes its values and provenance from the prior "
                             "table; give one or the other")
        probe = Joint(table["name"], points, rigid=True)
        prior = self.call(parts, prior_for, base, probe)
        if prior is None:
            raise self.error(parts + ["prior"], "priors exist for the holder-tool and spindle-holder joints of a "
                             "catalogue holder (catalog = \"...\"); this joint is not one: give k and c")
        return prior

    def support(self, table, parts, base: Assembly) -> Support:
        table = self.table(table, parts, _SUPPORT_KEYS, ("at",))
        at = self.point(table["at"], parts + ["at"], base)
        return self.call(parts, Support, at, name=table.get("name"), **self.matrices(table, parts))

    def point_mass(self, cls, keys, table, parts, base: Assembly):
        """A sensor or a mass (``cls``) of the table of ``keys``; a mass has no ``always_on``."""
        table = self.table(table, parts, keys, ("name", "at", "mass"))
        self.plausible(table, parts)
        at = self.point(table["at"], parts + ["at"], base)
        extra = {key: table[key] for key in ("inertia", "always_on") if key in table}
        return self.call(parts, cls, table["name"], at, table["mass"], **extra)


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
    return _Reader(loads_toml(text, source, "assembly")).assembly()


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
    try:
        path = os.fsdecode(path)  # a str, bytes or os.PathLike name, as messages show it
    except TypeError:
        pass  # read_text refuses what is not a file name, naming it
    return loads_assembly(read_text(path, "assembly file"), source=path)


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

