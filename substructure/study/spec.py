"""What a study is made of: machines, tool/holder combinations, cuts, what to compute and on which grids.

The value objects here hold their inputs as plain data (strings with units,
numbers, tables), as a study file gives them, so that a combination can be
sent to any worker of a cluster as it is and built there
(:mod:`substructure.study.task`).  Constructors check the structure (known
keys, units of the values every combination shares); the values of one
combination (its tool, holder and joint) are checked when it is built, so
that a bad combination fails its own rows and the study goes on.
"""

from __future__ import annotations

import os
from collections.abc import Mapping
from typing import Any

import attrs
import pint

from ..errors import InvalidValueError, SubstructureError
from ..units import format_quantity

__all__ = ["Machine", "Combination", "Cut", "SurrogateSpec", "TOOL_KEYS", "HOLDER_KEYS", "JOINT_KEYS",
           "FEATURE_SOURCES", "plain"]

#: Keys of a combination's ``tool`` table.
TOOL_KEYS = ("diameter", "overhang", "flute_length", "teeth", "helix", "material", "diameter_ratio", "segments",
             "description")
#: Keys of a combination's ``holder`` table besides the catalogue's parameters (``bore``, ``gauge_length``, ...).
HOLDER_KEYS = ("catalog", "segments", "material", "description")
#: Keys of a combination's ``joint`` table (entries ``yf``, ``ym``, ``tf``, ``tm`` of each).
JOINT_KEYS = ("k", "c")
#: Where the surrogate's features may come from: values of the combination (``[surrogate] features``).
FEATURE_SOURCES = ("tool.diameter", "tool.overhang", "tool.flute_length", "tool.teeth", "tool.material",
                   "holder.catalog", "holder.gauge_length", "holder.clamp_length", "holder.bore", "machine")

_MATRIX_ENTRIES = ("yf", "ym", "tf", "tm")
_CUT_KEYS = ("name", "workpiece", "workpiece_table", "kt", "kn", "kr", "radial_depth", "immersion", "milling",
             "feed_per_tooth", "max_depth")


def plain(value: Any, field: str) -> Any:
    """``value`` as plain data a study file could hold: quantities as strings with their unit.

    Parameters
    ----------
    value : object
        A string, number, bool, quantity, or a list or mapping of them.
    field : str
        Key path for the message.

    Returns
    -------
    object
        Strings, numbers, bools, lists and dicts only.
    """
    if isinstance(value, pint.Quantity):
        if getattr(value, "ndim", 0) != 0:
            raise InvalidValueError(f"{field}: got an array quantity; expected one value with its unit")
        return format_quantity(value)
    if isinstance(value, os.PathLike):
        return os.fspath(value)
    if isinstance(value, bool) or value is None or isinstance(value, (str, int, float)):
        return value
    if isinstance(value, Mapping):
        return {str(k): plain(v, f"{field}.{k}") for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [plain(v, f"{field}[{i}]") for i, v in enumerate(value)]
    raise InvalidValueError(f"{field}: got a {type(value).__name__}; expected a value with its unit, a number or "
                            "a name")


def _table(value: Any, field: str, allowed: tuple[str, ...] | None) -> dict | None:
    if value is None:
        return None
    if not isinstance(value, Mapping):
        raise InvalidValueError(f"{field}: got {value!r}; expected a table")
    if allowed is not None:
        for key in value:
            if key not in allowed:
                raise InvalidValueError(f"{field}.{key}: unknown key; allowed keys: {', '.join(allowed)}")
    return plain(dict(value), field)


def _names(value: Any, field: str) -> tuple[str, ...] | None:
    if value is None:
        return None
    if isinstance(value, str):
        value = [value]
    if not isinstance(value, (list, tuple)) or not all(isinstance(v, str) and v for v in value):
        raise InvalidValueError(f"{field}: got {value!r}; expected a name or a list of names")
    return tuple(value)


def _name(value: Any, field: str = "name") -> str:
    if not isinstance(value, str) or not value.strip():
        raise InvalidValueError(f"{field}: got {value!r}; expected a non-empty name")
    return value


def _check_tool(tool: dict | None) -> dict | None:
    tool = _table(tool, "tool", TOOL_KEYS)
    if tool is None:
        return None
    if "segments" in tool:
        extra = [k for k in ("overhang", "flute_length", "diameter_ratio") if k in tool]
        if extra:
            raise InvalidValueError(f"tool.{extra[0]}: a tool given by its segments takes teeth, helix, diameter, "
                                    "material and description only")
    else:
        for key in ("diameter", "overhang"):
            if key not in tool:
                raise InvalidValueError(f"tool.{key}: missing; a tool is diameter and overhang (and flute_length, "
                                        "teeth, ...), or its segments")
    return tool


def _check_holder(holder: dict | None) -> dict | None:
    holder = _table(holder, "holder", None)
    if holder is None:
        return None
    if ("catalog" in holder) == ("segments" in holder):
        raise InvalidValueError("holder: give catalog (a standard holder, e.g. 'BT40 ER32', with its parameters) or "
                                "segments, not both or neither")
    if "segments" in holder:
        for key in holder:
            if key not in HOLDER_KEYS:
                raise InvalidValueError(f"holder.{key}: unknown key for a holder given by its segments; allowed: "
                                        "segments, material, description")
    elif not isinstance(holder["catalog"], str):
        raise InvalidValueError(f"holder.catalog: got {holder['catalog']!r}; expected a catalogue name such as "
                                "'BT40 ER32'")
    return holder


def _check_joint(joint: dict | None) -> dict | None:
    joint = _table(joint, "joint", JOINT_KEYS)
    if joint is None:
        return None
    if not joint:
        raise InvalidValueError("joint: an empty table; give k and/or c entries, e.g. k = { yf = '1.4e7 N/m' }")
    for kind, entries in joint.items():
        if not isinstance(entries, dict) or not entries:
            raise InvalidValueError(f"joint.{kind}: got {entries!r}; expected a table of entries yf, ym, tf, tm")
        for entry in entries:
            if entry not in _MATRIX_ENTRIES:
                raise InvalidValueError(f"joint.{kind}.{entry}: unknown entry; expected yf, ym, tf or tm")
    return joint


@attrs.frozen
class Combination:
    """One tool/holder combination of a study.

    Parameters
    ----------
    name : str
        Unique in the study; with the machine's name it is the combination's
        identity (its seed and its result file).
    tool : mapping, optional
        ``diameter``, ``overhang`` (lengths), ``flute_length`` (length),
        ``teeth``, ``helix`` (angle), ``material`` (default carbide),
        ``diameter_ratio`` (equivalent diameter of the flutes, default 0.8);
        or ``segments`` (as in assembly files) with ``teeth``, ``helix`` and
        ``diameter`` (cutting diameter).  Default: the machine's tool.
    holder : mapping, optional
        ``catalog`` (a standard holder, e.g. ``"BT40 ER32"``) and its
        parameters (``bore``, default the tool's diameter, ``gauge_length``,
        ...); or ``segments``.  Default: the machine's holder.
    joint : mapping, optional
        The holder-tool joint's entries, ``{"k": {"yf": "1.4e7 N/m"}, "c":
        {...}}``, replacing those of the machine's joint.  Without it the
        study's surrogate predicts the joint (or the machine's is kept).
    features : mapping, optional
        Features for the surrogate (with units, or names), besides those
        the study maps from the tool and holder.
    machines : sequence of str, optional
        The machines it runs on (default: every machine of the study).
    cuts : sequence of str, optional
        The cuts it is evaluated for (default: every cut).
    where : str, optional
        Where it was defined (file and line), for messages.
    """

    name: str = attrs.field(converter=_name)
    tool: dict | None = attrs.field(default=None, converter=_check_tool)
    holder: dict | None = attrs.field(default=None, converter=_check_holder)
    joint: dict | None = attrs.field(default=None, converter=_check_joint)
    features: dict | None = attrs.field(default=None, converter=lambda v: _table(v, "features", None))
    machines: tuple | None = attrs.field(default=None, converter=lambda v: _names(v, "machines"))
    cuts: tuple | None = attrs.field(default=None, converter=lambda v: _names(v, "cuts"))
    where: str = attrs.field(default="", eq=False)

    def feature_source(self, source: str) -> Any:
        """The value of one of :data:`FEATURE_SOURCES` for this combination (``None`` when it has none).

        Parameters
        ----------
        source : str
            E.g. ``"tool.diameter"``; ``"machine"`` is not answered here (the
            machine is not part of the combination).

        Returns
        -------
        object
            The value as given (a string with its unit, a number or a name).
        """
        part, _, key = source.partition(".")
        table = self.tool if part == "tool" else self.holder if part == "holder" else None
        if table is None:
            return None
        if part == "holder" and key == "bore" and "bore" not in table and self.tool is not None:
            return self.tool.get("diameter")
        return table.get(key)


def _limits(value: Any):
    from ..stability import MachineLimits

    if value is None or isinstance(value, MachineLimits):
        return value
    if not isinstance(value, Mapping):
        raise InvalidValueError(f"limits: got {value!r}; expected MachineLimits or a table of max_speed, min_speed, "
                                "power, torque")
    for key in value:
        if key not in ("max_speed", "min_speed", "power", "torque"):
            raise InvalidValueError(f"limits.{key}: unknown key; allowed keys: max_speed, min_speed, power, torque "
                                    "(the largest depth is the tool's flute length, or the cut's max_depth)")
    try:
        return MachineLimits(**{k: (tuple(tuple(p) for p in v) if isinstance(v, list) else v)
                                for k, v in value.items()})
    except SubstructureError as exc:  # "max_speed: ..." is limits.max_speed of the machine
        raise InvalidValueError(f"limits.{' '.join(str(exc).split())}") from None


def _supports(value: Any) -> tuple:
    if value is None:
        return ()
    if not isinstance(value, (list, tuple)):
        raise InvalidValueError(f"supports: got {value!r}; expected a list of tables {{at, k, c}}")
    out = []
    for i, s in enumerate(value):
        table = _table(s, f"supports[{i}]", ("at", "k", "c"))
        if "at" not in table:
            raise InvalidValueError(f"supports[{i}].at: missing; the point of the structure the support holds")
        out.append(table)
    return tuple(out)


@attrs.frozen
class Machine:
    """A machine of a study: a spindle assembly, optional supports and the machine's limits.

    Parameters
    ----------
    name : str
        Unique in the study.
    assembly : str, path or Assembly, default "default"
        ``"default"`` (the built-in assembly), an assembly file, or an
        :class:`~substructure.Assembly`.  It must have components named
        ``holder`` and ``tool`` (which combinations replace) and the study's
        holder-tool joint.
    supports : sequence of mapping, optional
        Supports added to the assembly's, ``{"at": "spindle@30 mm", "k":
        {"yf": "1e8 N/m"}, "c": {"yf": "200 N*s/m"}}`` (bearings of a base
        assembly).
    limits : MachineLimits or mapping, optional
        Speed range, power and torque (constants or curves); the largest
        depth is the tool's flute length or the cut's ``max_depth``.
    where : str, optional
        Where it was defined, for messages.
    """

    name: str = attrs.field(converter=_name)
    assembly: Any = attrs.field(default="default", eq=False)
    supports: tuple = attrs.field(default=(), converter=_supports)
    limits: Any = attrs.field(default=None, converter=_limits)
    where: str = attrs.field(default="", eq=False)
    text: str = attrs.field(init=False, repr=False)
    source: str = attrs.field(init=False, repr=False)

    def __attrs_post_init__(self) -> None:
        from ..assembly import Assembly
        from ..io import read_text
        from ..io.assembly_toml import dumps_assembly

        value = self.assembly
        if isinstance(value, Assembly):
            text, source = dumps_assembly(value), f"assembly {value.name!r}"
        elif isinstance(value, str) and value == "default":
            import importlib.resources

            resource = importlib.resources.files("substructure") / "data" / "default_assembly.toml"
            text, source = resource.read_text(encoding="utf-8"), "default_assembly.toml"
        elif isinstance(value, (str, os.PathLike)):
            text, source = read_text(value, "assembly file"), os.fspath(value)
        else:
            raise InvalidValueError(f"assembly: got {value!r}; expected 'default', an assembly file or an Assembly")
        object.__setattr__(self, "text", text)
        object.__setattr__(self, "source", source)
        self.build()  # the machine is checked once, here

    def build(self):
        """The machine's assembly with its supports.

        Returns
        -------
        Assembly
            The assembly file's assembly, the supports added.
        """
        from ..io.assembly_toml import loads_assembly

        assembly = loads_assembly(self.text, source=self.source)
        for i, s in enumerate(self.supports):
            try:
                assembly = assembly.support(s["at"], k=s.get("k"), c=s.get("c"))
            except Exception as exc:
                raise InvalidValueError(f"supports[{i}]: {exc}") from None
        return assembly

    def spec(self) -> dict:
        """Plain data for a worker: the assembly text, the supports and the limits.

        Returns
        -------
        dict
            ``name``, ``text``, ``source``, ``supports``, ``limits`` (SI
            numbers, :meth:`MachineLimits.to_json`, or ``None``).
        """
        return {"name": self.name, "text": self.text, "source": self.source, "supports": list(self.supports),
                "limits": None if self.limits is None else self.limits.to_json()}


def _optional_quantity(field: str, dimension: str):
    def convert(value: Any) -> str | None:
        if value is None:
            return None
        from ..units import quantity

        q = quantity(value, field, dimension)
        if not q.magnitude > 0:
            raise InvalidValueError(f"{field}: got {value!r}; expected a positive value")
        return value if isinstance(value, str) else format_quantity(q)

    return convert


@attrs.frozen
class Cut:
    """A milling cut of a study; its tooth count and diameter come from each combination's tool.

    Parameters
    ----------
    name : str
        Unique in the study.
    workpiece : str, optional
        A work material of the cutting-coefficient table (e.g.
        ``"aluminium-7075"``), instead of ``kt``.
    workpiece_table : str or path, optional
        A user table of workpieces, searched first.
    kt : str or quantity, optional
        Tangential cutting coefficient, a pressure.
    kn : str or quantity, optional
        Normal cutting coefficient, a pressure; or
    kr : float, optional
        The ratio ``Kn / Kt``.
    radial_depth : str or quantity, optional
        Radial depth of cut, a length; or
    immersion : float, optional
        ``a_e / D`` in (0, 1].
    milling : {"up", "down"}
        Up (default) or down milling.
    feed_per_tooth : str or quantity, optional
        Feed per tooth, a length (removal rate, power, Kienzle entries).
    max_depth : str or quantity, optional
        Largest axial depth, a length (default: the tool's flute length).
    where : str, optional
        Where it was defined, for messages.
    """

    name: str = attrs.field(converter=_name)
    workpiece: str | None = None
    workpiece_table: str | None = attrs.field(default=None, converter=lambda v: None if v is None else os.fspath(v))
    kt: str | None = attrs.field(default=None, converter=_optional_quantity("kt", "[pressure]"))
    kn: str | None = attrs.field(default=None, converter=_optional_quantity("kn", "[pressure]"))
    kr: float | None = None
    radial_depth: str | None = attrs.field(default=None, converter=_optional_quantity("radial_depth", "[length]"))
    immersion: float | None = None
    milling: str = "up"
    feed_per_tooth: str | None = attrs.field(default=None, converter=_optional_quantity("feed_per_tooth", "[length]"))
    max_depth: str | None = attrs.field(default=None, converter=_optional_quantity("max_depth", "[length]"))
    where: str = attrs.field(default="", eq=False)
    table_text: str | None = attrs.field(init=False, default=None, repr=False, eq=False)

    def __attrs_post_init__(self) -> None:
        if self.milling not in ("up", "down"):
            raise InvalidValueError(f"milling: got {self.milling!r}; expected 'up' or 'down'")
        if (self.workpiece is None) == (self.kt is None):
            raise InvalidValueError("workpiece: give workpiece (a name of the cutting-coefficient table) or kt, "
                                    "one of them")
        if self.workpiece is None and self.kn is None and self.kr is None:
            raise InvalidValueError("kn: missing; with kt give kn (a pressure) or kr (the ratio Kn/Kt)")
        if self.kn is not None and self.kr is not None:
            raise InvalidValueError("kr: give kn (a pressure) or kr (a ratio), not both")
        if (self.radial_depth is None) == (self.immersion is None):
            raise InvalidValueError("radial_depth: give radial_depth (a length) or immersion (a_e/D), one of them")
        if self.immersion is not None and (isinstance(self.immersion, bool) or not isinstance(
                self.immersion, (int, float)) or not 0 < self.immersion <= 1):
            raise InvalidValueError(f"immersion: got {self.immersion!r}; expected a number in (0, 1]")
        if self.kr is not None and (isinstance(self.kr, bool) or not isinstance(self.kr, (int, float))
                                    or not self.kr >= 0):
            raise InvalidValueError(f"kr: got {self.kr!r}; expected the ratio Kn/Kt, a number >= 0")
        if self.workpiece_table is not None and self.workpiece is None:
            raise InvalidValueError("workpiece_table: goes with workpiece")
        if self.workpiece is not None:
            from ..stability import workpiece

            workpiece(self.workpiece, self.workpiece_table)  # an unknown name is an error here, not per row
            if self.workpiece_table is not None:
                from ..io import read_text

                object.__setattr__(self, "table_text", read_text(self.workpiece_table, "workpiece table"))

    def spec(self) -> dict:
        """Plain data for a worker.

        Returns
        -------
        dict
            The fields (values as strings with units), the user table's text.
        """
        out = {key: getattr(self, key) for key in _CUT_KEYS}
        out["workpiece_table"] = self.table_text
        return out


def _model(value: Any) -> str:
    if value not in ("gp", "mlp"):
        raise InvalidValueError(f"model: got {value!r}; expected 'gp' or 'mlp'")
    return value


@attrs.frozen
class SurrogateSpec:
    """The surrogate that predicts the holder-tool joint of combinations without an explicit joint.

    Parameters
    ----------
    table : str, path or JointTable
        The joint table (CSV, or TOML when the name ends in ``.toml``).
    model : {"gp", "mlp"}, default "gp"
        Gaussian process or an ensemble of small networks.
    targets : sequence of str, optional
        The parameters to predict (default: every parameter of the table).
    features : mapping, optional
        For each feature of the table, where a combination's value comes
        from: one of :data:`FEATURE_SOURCES` (``{"tool_diameter":
        "tool.diameter", "gauge_length": "tool.overhang"}``); features not
        mapped are taken from each combination's ``features``.
    """

    table: Any = attrs.field(eq=False)
    model: str = attrs.field(default="gp", converter=_model)
    targets: tuple | None = attrs.field(default=None, converter=lambda v: _names(v, "targets"))
    features: dict = attrs.field(factory=dict, converter=lambda v: dict(v or {}))
    joint_table: Any = attrs.field(init=False, repr=False, eq=False)

    def __attrs_post_init__(self) -> None:
        from ..surrogate import JointTable

        table = self.table
        if not isinstance(table, JointTable):
            from pathlib import Path

            from .._files import file_name

            path = file_name(table, "joint table")
            table = JointTable.from_toml(path) if Path(path).suffix.lower() == ".toml" else JointTable.from_csv(path)
        table.check_not_empty(3, "a surrogate")
        object.__setattr__(self, "joint_table", table)
        for feature, source in self.features.items():
            if feature not in table.features:
                raise InvalidValueError(f"features.{feature}: not a feature of the joint table "
                                        f"({', '.join(table.features)})")
            if source not in FEATURE_SOURCES:
                raise InvalidValueError(f"features.{feature}: got {source!r}; expected one of "
                                        f"{', '.join(FEATURE_SOURCES)}")
        for target in self.targets or ():
            if target not in table.parameters:
                raise InvalidValueError(f"targets: {target!r} is not a parameter of the joint table "
                                        f"({', '.join(table.parameters)})")
