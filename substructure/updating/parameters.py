"""Every number of an assembly by its path in the assembly file, and changes that fit them.

A model parameter is named by where it sits in the assembly file:

=============================================  ==========================================
path                                           value (SI)
=============================================  ==========================================
``components.C.segments.I.length|od|id``       a segment's length or diameter [m]
``components.C.segments.I.od_tip|id_tip``      a segment's diameters at its tip end [m] (a uniform one set so tapers)
``components.C.segments.I.insert.od|id``       the insert's diameters [m]
``components.C.segments.I.flutes.diameter_ratio``  the flutes' equivalent diameter ratio
``components.C.segments.I.end``                where segment ``I`` ends and ``I+1`` begins, from the
                                               component's base [m] (linked: both lengths change,
                                               the component's length is kept)
``materials.M.E|rho|nu|loss_factor``           a material, in every part made of it
``joints.J.k.yf|ym|tf|tm``, ``joints.J.c.E``   a joint entry (``ym`` and ``tf`` are one number: either sets both)
``supports.I.k.E``, ``supports.I.c.E``         a support entry (``I``: index in the file)
``supports.I.at``                              a support's position along its component [m]
``sensors.S.mass|inertia``                     a sensor [kg, kg m^2]
``masses.S.mass|inertia|at``                   a permanent body
=============================================  ==========================================

and a few *linked* parameters that move several numbers as one thing a user
thinks of: ``components.C.overhang`` (a tool's length out of the holder [m]:
the first segment at the shank end changes, the fluted length stays),
``components.C.bore`` (a bore through the whole part [m], its shank held in
another part too: a coolant bore, a hollow shank),
``components.C.segments.I.end`` (the step between two different segments
moves, the component's length kept: a bore or an insert deeper, a longer
fluted length on a tool of the same length),
``components.C.E|rho|loss_factor`` (that component's own material only, as
a factor: "this component is stiffer"; materials are shared between
components, so ``materials.M.E`` is another candidate),
``joints.J.k`` and ``joints.J.c`` (every entry of a joint's stiffness or
damping, as a factor) and ``components.C.supports.k`` (the stiffness of
every support on a component, as a factor: a bearing preload).

:func:`model_parameters` lists them with physical bounds per kind,
:func:`get_parameter` and :func:`set_parameters` read and change them on an
:class:`~substructure.assembly.Assembly` (the result saves normally), and
:class:`ParameterChange` applies one to the SI form of a structure
(:mod:`substructure.updating.structure`) for fits.  :class:`Change` is the
protocol every fitted change follows (a parameter correction, an added
element, an effect of the diagnosis catalogue).

Every key of a path must name something of the assembly, case-sensitively:
an unknown key, a negative or too large index, a matrix other than ``k``
and ``c`` or an entry other than ``yf``, ``ym``, ``tf``, ``tm`` is refused
with the keys that exist there (``substructure.updating.paths.check_path``).
"""

from __future__ import annotations

from typing import Mapping

import attrs
import numpy as np

from ..components import Holder, Spindle, Tool, own_parameters
from ..errors import InvalidValueError
from ..joints import DAMPING_UNITS, STIFFNESS_UNITS, Joint
from ..materials import Material
from .changes import Change, ParamSpec
from .structure import assembly_checked
from .paths import (
    _on_beam,
    _overhang_segment,
    _plain,
    _segmented,
    _unknown,
    apply_path_si,
    bore_segments,
    check_path,
    set_parameters,
)

__all__ = ["ParamSpec", "Change", "ModelParameter", "ParameterChange", "ParameterSet", "model_parameters",
           "material_changes", "parameter_change", "get_parameter", "set_parameters",
           "apply_path_si", "LENGTH_FACTOR", "ENGINEERING_E", "ENGINEERING_RHO", "ENGINEERING_NU", "POSITION_FRACTION",
           "STEP_KEEP"]


@attrs.frozen
class ModelParameter:
    """A number of an assembly that a fit may correct.

    Parameters
    ----------
    path : str
        Where it sits in the assembly file (see the module docstring).
    unit : str
        SI unit (``dimensionless`` for the factors of linked parameters).
    nominal : float
        Its value in the assembly.
    lower, upper : float
        Physical bounds.
    log : bool
        Fitted on a log scale.
    description : str
        What it is, in words.
    linked : bool
        Several numbers moved as one (an overhang, a component's material, a
        joint's whole stiffness, a set of supports).
    known : bool
        A number known to a few per cent, whose change more likely stands in
        for something the model lacks (a holder's steel: its density 12 %
        higher is a nut on it); the diagnosis reports an element that fits
        as well before it (the diagnosis's order of preference, docs/diagnose.md).
    """

    path: str
    unit: str
    nominal: float
    lower: float
    upper: float
    log: bool
    description: str
    linked: bool = False
    known: bool = False

    def spec(self) -> ParamSpec:
        """The fitted parameter ``value``, starting at the nominal value.

        Returns
        -------
        ParamSpec
            Bounds, scale and the nominal value.
        """
        start = float(np.clip(self.nominal, self.lower, self.upper))
        return ParamSpec("value", self.unit, self.lower, self.upper, start, self.log, self.nominal)


def _log(path, unit, nominal, lo, hi, text) -> ModelParameter:
    return ModelParameter(path, unit, float(nominal), float(lo), float(hi), True, text)


def _lin(path, unit, nominal, lo, hi, text) -> ModelParameter:
    return ModelParameter(path, unit, float(nominal), float(lo), float(hi), False, text)


def _linked(path, unit, nominal, lo, hi, text) -> ModelParameter:
    return ModelParameter(path, unit, float(nominal), float(lo), float(hi), True, text, True)


_C_DEFAULT = {"yf": (1e-2, 1e5), "tm": (1e-4, 1e3)}


LENGTH_FACTOR = 1.5
"""Lengths and diameters of the model are corrected within this factor of their nominal values (a drawing
is not off by half a part, a tool is not clamped at half its length)."""
ENGINEERING_E = (40e9, 700e9)
"""Range of Young's modulus of the engineering materials a machine-tool part is made of [Pa]: from
magnesium and aluminium alloys to cemented carbide."""
ENGINEERING_RHO = (1500.0, 19300.0)
"""Range of density of those materials [kg/m^3]: from magnesium alloys to heavy tungsten alloys."""
ENGINEERING_NU = (0.15, 0.40)
"""Range of Poisson's ratio of those materials (ceramics and carbides about 0.2, metals about 0.3)."""


POSITION_FRACTION = 0.25
"""A support or body the model places is where the drawing says within this fraction of its component's length
(a bearing's effective centre, a nut's seat: centimetres, not across the part)."""


STEP_KEEP = 0.2
"""A step between two segments (``components.C.segments.I.end``) moves within its two segments, each keeping at
least this fraction of its length (a bore or an insert deeper or shallower, not gone)."""


def _same_section(a, b) -> bool:
    """Two neighbouring segments of the same section (moving the step between them changes nothing)."""
    if a.is_tapered or b.is_tapered:
        return False
    return (a.od == b.od and a.id == b.id and a.material == b.material and a.insert == b.insert
            and a.flutes == b.flutes)


def _position_bounds(x: float, length: float) -> tuple[float, float]:
    half = POSITION_FRACTION * length
    return float(max(0.0, x - half)), float(min(length, x + half))


def _within(nominal: float, factor_lo: float, factor_hi: float, allowed: tuple[float, float]) -> tuple[float, float]:
    """Bounds ``factor_lo..factor_hi`` times nominal, cut to ``allowed`` but always holding the nominal value."""
    lo = min(max(factor_lo * nominal, allowed[0]), nominal)
    hi = max(min(factor_hi * nominal, allowed[1]), nominal)
    return float(lo), float(hi)


def _matrix_parameters(prefix: str, owner, what: str) -> list[ModelParameter]:
    out = []
    k, c = owner.k.values, owner.c.values
    for kind, m, units in (("k", k, STIFFNESS_UNITS), ("c", c, DAMPING_UNITS)):
        for entry, (i, j) in (("yf", (0, 0)), ("tm", (1, 1))):
            v = m[i, j]
            if v > 0:
                out.append(_log(f"{prefix}.{kind}.{entry}", units[entry], v, 1e-3 * v, 1e3 * v,
                                f"{what} {kind}_{entry}"))
            elif kind == "c" and k[i, j] > 0:
                lo, hi = _C_DEFAULT[entry]
                out.append(ModelParameter(f"{prefix}.c.{entry}", units[entry], 0.0, lo, hi, True,
                                          f"{what} c_{entry}"))
        limit = 0.999 * np.sqrt(max(m[0, 0] * m[1, 1], 0.0))
        if limit > 0:
            out.append(_lin(f"{prefix}.{kind}.ym", units["ym"], m[0, 1], -limit, limit,
                            f"{what} {kind}_ym = {kind}_tf (cross-coupling)"))
    return out


def model_parameters(assembly) -> list[ModelParameter]:
    """Every number of ``assembly`` a fit may correct, with physical bounds.

    Bounds per kind: lengths and outer diameters within
    ``LENGTH_FACTOR`` (1.5) times nominal either way (diameters above
    the bore); bores and inserts within the section; flutes' ratio 0.5 to 1;
    ``E`` and ``rho`` 0.25 to 4 times, within the range of engineering
    materials (``ENGINEERING_E``, ``ENGINEERING_RHO``); ``nu`` 0 to
    0.49; loss factors 1e-5 to 0.2; joint and support entries 1e-3 to 1e3
    times (cross terms within passivity, ``k_ym^2 < k_yf k_tm``); positions
    of supports and bodies within ``POSITION_FRACTION`` (0.25) of their
    component's length of where the model has them; sensor and body masses
    0.1 to 10 times; linked
    factors 0.25 to 4 (a component's own ``E`` and ``rho`` within the
    engineering range too, and not for a spindle, whose shaft is steel; a
    tool's overhang within 1.5 times; a step between segments within
    them, each keeping ``STEP_KEEP`` (a fifth) of its length).

    Parameters
    ----------
    assembly : Assembly
        The model.

    Returns
    -------
    list of ModelParameter
        Components first, then materials, joints, supports, sensors, masses.
    """
    assembly_checked(assembly)
    out: list[ModelParameter] = []
    materials: dict[str, Material] = {}
    for comp in assembly.components:
        base = f"components.{comp.name}"
        out += [ModelParameter(f"{base}.{p.name}", p.unit, p.nominal, p.lower, p.upper, p.log, p.text)
                for p in own_parameters(comp)]
        if not _segmented(comp):
            continue
        si = _plain(comp)  # materials are shared by name among the plain beams
        for i, seg in enumerate(comp.segments):
            p = f"{base}.segments.{i}"
            L, od, id_ = seg.length_m, seg.od.m_as("m"), seg.id.m_as("m")
            fluted = seg.flutes.diameter_ratio if seg.flutes else 1.0
            out.append(_log(f"{p}.length", "m", L, L / LENGTH_FACTOR, LENGTH_FACTOR * L,
                            f"length of segment {i} of {comp.name}"))
            low = max(od / LENGTH_FACTOR, 1.02 * id_ / fluted)
            out.append(_log(f"{p}.od", "m", od, low, LENGTH_FACTOR * od,
                            f"outer diameter of segment {i} of {comp.name}"))
            if seg.is_tapered:
                od1, id1 = seg._od_tip.m_as("m"), seg._id_tip.m_as("m")
                low = max(od1 / LENGTH_FACTOR, 1.02 * id1 / fluted)
                out.append(_log(f"{p}.od_tip", "m", od1, low, LENGTH_FACTOR * od1,
                                f"outer diameter at the tip end of tapered segment {i} of {comp.name}"))
                if id1 > 0:
                    out.append(_lin(f"{p}.id_tip", "m", id1, 0.0, 0.9 * od1, f"bore at the tip end of tapered segment "
                                                                            f"{i} of {comp.name}"))
            if seg.insert is None:
                narrow = min(od, seg._od_tip.m_as("m")) if seg.is_tapered else od
                out.append(_lin(f"{p}.id", "m", id_, 0.0, 0.9 * narrow * fluted, f"bore of segment {i} of {comp.name}"))
            else:
                iod = seg.insert.od.m_as("m")
                out.append(_log(f"{p}.insert.od", "m", iod, max(0.5 * iod, 1.02 * seg.insert.id.m_as("m")), id_,
                                f"insert diameter in segment {i} of {comp.name}"))
                if si:
                    materials.setdefault(seg.insert.material.name, seg.insert.material)
            if seg.flutes is not None:
                low = max(0.5, 1.02 * id_ / od)
                out.append(_lin(f"{p}.flutes.diameter_ratio", "dimensionless", seg.flutes.diameter_ratio, low, 1.0,
                                f"flutes' diameter ratio of segment {i} of {comp.name}"))
            if si:
                materials.setdefault(seg.material.name, seg.material)
        ends = np.cumsum([seg.length_m for seg in comp.segments])
        for i in range(len(comp.segments) - 1):
            a, b = comp.segments[i], comp.segments[i + 1]
            if _same_section(a, b):
                continue
            start, stop = ends[i] - a.length_m, ends[i + 1]
            out.append(ModelParameter(f"{base}.segments.{i}.end", "m", float(ends[i]),
                                      float(start + STEP_KEEP * a.length_m), float(stop - STEP_KEEP * b.length_m),
                                      False, f"step from segment {i} to {i + 1} of {comp.name}, from its base "
                                             f"({comp.name}'s length kept)", True))
        if isinstance(comp, Tool) and _overhang_segment(comp) is not None:
            total = comp.length_m
            fixed = total - comp.segments[_overhang_segment(comp)].length_m
            out.append(_linked(f"{base}.overhang", "m", total,
                               max(total / LENGTH_FACTOR, fixed + 0.1 * (total - fixed)),
                               LENGTH_FACTOR * total, f"overhang of {comp.name} (its fluted length kept)"))
        free = bore_segments(comp)
        if free is not None:  # a bore through the whole part (a coolant bore, a hollow shank or holder)
            narrow = min(comp.segments[i].od.m_as("m") * (comp.segments[i].flutes.diameter_ratio
                                                          if comp.segments[i].flutes else 1.0) for i in free)
            out.append(ModelParameter(f"{base}.bore", "m", comp.segments[free[0]].id.m_as("m"), 0.0, 0.9 * narrow,
                                      False, f"bore through {comp.name} (every segment without an insert)", True))
        own = comp.segments[0].material
        # a spindle shaft is steel, whose E and rho are known to a few per cent: its stiffness and mass are
        # questions of geometry, bearings and joints, not of its own material (materials.steel.E stays)
        props = (("loss_factor", "material damping"),) if isinstance(comp, Spindle) else (
            ("E", "stiffness (E)"), ("rho", "density"), ("loss_factor", "material damping"))
        for prop, text in props:
            if prop == "loss_factor":
                lo, hi = 0.05, 20.0
            else:
                value = own.E.m_as("Pa") if prop == "E" else own.rho_si
                engineering = ENGINEERING_E if prop == "E" else ENGINEERING_RHO
                lo, hi = (x / value for x in _within(value, 0.25, 4.0, engineering))
            factor = _linked(f"{base}.{prop}", "dimensionless", 1.0, lo, hi, f"{text} of {comp.name} only, as a factor")
            # a holder is steel: its E and rho are known to a few per cent (its material as a whole may differ)
            out.append(attrs.evolve(factor, known=True) if isinstance(comp, Holder) and prop != "loss_factor"
                       else factor)
    for name, m in materials.items():
        p = f"materials.{name}"
        E, rho = m.E.m_as("Pa"), m.rho_si
        out.append(_log(f"{p}.E", "Pa", E, *_within(E, 0.25, 4.0, ENGINEERING_E), f"Young's modulus of {name}"))
        out.append(_log(f"{p}.rho", "kg/m^3", rho, *_within(rho, 0.25, 4.0, ENGINEERING_RHO), f"density of {name}"))
        out.append(_lin(f"{p}.nu", "dimensionless", m.nu, 0.0, 0.49, f"Poisson ratio of {name}"))
        out.append(ModelParameter(f"{p}.loss_factor", "dimensionless", m.loss_factor, 1e-5, 0.2, True,
                                  f"loss factor of {name}"))
    for j in assembly.joints:
        if getattr(j, "rigid", False):
            continue
        p = f"joints.{j.name}"
        out += [ModelParameter(f"{p}.{q.name}", q.unit, q.nominal, q.lower, q.upper, q.log, q.text)
                for q in own_parameters(j)]
        if not isinstance(j, Joint):
            continue
        out += _matrix_parameters(p, j, f"joint {j.name}")
        out.append(_linked(f"{p}.k", "dimensionless", 1.0, 1e-3, 1e3, f"stiffness of joint {j.name}, as a factor"))
        if j.c:
            out.append(_linked(f"{p}.c", "dimensionless", 1.0, 1e-3, 1e3, f"damping of joint {j.name}, as a factor"))
    per_component: dict[str, list] = {}
    for i, s in enumerate(assembly.supports):
        p = f"supports.{i}"
        out += _matrix_parameters(p, s, f"support {s.name or i} at {s.at}")
        comp, x, length = _on_beam(assembly, s.at)
        if comp is not None:
            out.append(_lin(f"{p}.at", "m", x, *_position_bounds(x, length),
                            f"position of support {s.name or i} along {comp}"))
            if s.k:
                per_component.setdefault(comp, []).append((x, i))
    for comp, found in per_component.items():
        if len(found) >= 2:
            out.append(_linked(f"components.{comp}.supports.k", "dimensionless", 1.0, 1e-2, 1e2,
                               f"stiffness of every support on {comp}, as a factor"))
        order = [i for _, i in sorted(found)]
        if len(order) >= 3:
            for a, b in zip(order[:-1], order[1:]):  # neighbours: a bearing pair
                out.append(_linked(f"supports.{a}+{b}.k", "dimensionless", 1.0, 1e-2, 1e2,
                                   f"stiffness of the neighbouring supports {a} and {b} on {comp}, as a factor"))
    for kind, items in (("sensors", assembly.sensors), ("masses", assembly.masses)):
        for s in items:
            p = f"{kind}.{s.name}"
            if s.mass_kg > 0:
                out.append(_log(f"{p}.mass", "kg", s.mass_kg, 0.1 * s.mass_kg, 10 * s.mass_kg, f"mass of {s.name}"))
            if s.inertia_si > 0:
                out.append(_log(f"{p}.inertia", "kg*m^2", s.inertia_si, 0.1 * s.inertia_si, 10 * s.inertia_si,
                                f"rotary inertia of {s.name}"))
            if kind == "masses":
                comp, x, length = _on_beam(assembly, s.at)
                if comp is not None:
                    out.append(_lin(f"{p}.at", "m", x, *_position_bounds(x, length),
                                    f"position of {s.name} along {comp}"))
    return out


def material_changes(assembly, known=None) -> list["ParameterSet"]:
    """Per tool and holder, "this part is made of another material": its ``E``, ``rho`` and ``nu`` fitted together.

    The change is named ``components.C.material`` (effect
    ``model-parameter``) with the parameters ``E`` [Pa], ``rho`` [kg/m^3]
    and ``nu`` of the component's own material (every segment of it;
    inserts keep theirs), bounded by the range of engineering materials
    (``ENGINEERING_E``, ``ENGINEERING_RHO``,
    ``ENGINEERING_NU``), starting at the model's values; its extra
    starting points (``trials``) are the materials the library and the
    assembly know, so that a fit reaches the right one from where it is (a
    carbide tool that is HSS: steel's constants).

    Parameters
    ----------
    assembly : Assembly
        The model.
    known : mapping of str to Material, optional
        Materials to start from (default the library's catalogue and the assembly's own).

    Returns
    -------
    list of ParameterSet
        One change per plain tool and holder component (a tool's material
        is a choice among carbide grades, HSS and steels, a holder's among
        steels and heavy metals; a spindle shaft is steel).
    """
    from ..materials import CATALOG

    known = dict(known) if known is not None else {**CATALOG, **{m.name: m for m in assembly.materials}}
    from ..components import Holder

    out = []
    for comp in assembly.components:
        if not _plain(comp) or not isinstance(comp, (Tool, Holder)):
            continue  # a tool's or a holder's material is a choice; a spindle shaft is steel
        own = comp.segments[0].material
        E, rho = own.E.m_as("Pa"), own.rho_si
        e_lo, e_hi = _within(E, 0.0, np.inf, ENGINEERING_E)
        r_lo, r_hi = _within(rho, 0.0, np.inf, ENGINEERING_RHO)
        base = f"components.{comp.name}.material"
        nu = float(own.nu)
        n_lo, n_hi = _within(nu, 0.0, np.inf, ENGINEERING_NU)
        change = ParameterSet("model-parameter", base, {"E": f"{base}.E", "rho": f"{base}.rho", "nu": f"{base}.nu"},
                              (ParamSpec("E", "Pa", e_lo, e_hi, E, True, E),
                               ParamSpec("rho", "kg/m^3", r_lo, r_hi, rho, True, rho),
                               ParamSpec("nu", "dimensionless", n_lo, n_hi, nu, False, nu)))
        change.explanation = (f"{comp.name} is made of another material than the model says: E, rho and nu move "
                              "together (a stiffer or lighter material raises the modes where it bends)")
        change.linked = True
        change.trials = tuple({"E": float(np.clip(m.E.m_as("Pa"), e_lo, e_hi)),
                               "rho": float(np.clip(m.rho_si, r_lo, r_hi)), "nu": float(np.clip(m.nu, n_lo, n_hi))}
                              for m in known.values() if (m.E.m_as("Pa"), m.rho_si) != (E, rho))
        out.append(change)
    return out


# ---------------------------------------------------------------------------
# Reading values on an assembly


def get_parameter(assembly, path: str) -> float:
    """The value of a parameter of ``assembly`` (SI; linked factors are 1).

    Parameters
    ----------
    assembly : Assembly
        The model.
    path : str
        A path of :func:`model_parameters` (e.g. ``"components.tool.segments.0.length"``).

    Returns
    -------
    float
        The value in SI units.

    Raises
    ------
    UnknownPointError
        When the path names nothing in the assembly.
    """
    assembly_checked(assembly)
    for p in model_parameters(assembly):
        if p.path == path:
            return p.nominal
    check_path(assembly, path)  # a key that names nothing: refused with the keys that exist
    raise _unknown(path, "not a parameter of this assembly (see model_parameters)")


# ---------------------------------------------------------------------------
# The same on the SI form


class ParameterSet(Change):
    """Several model parameters fitted together, each under a short name (e.g. a joint's entries).

    Parameters
    ----------
    effect : str
        A name for reports.
    where : str
        What it acts on.
    paths : mapping of str to str
        Short name -> parameter path (see :func:`model_parameters`).
    specs : sequence of ParamSpec
        One per short name, with bounds and start.
    """

    def __init__(self, effect: str, where: str, paths: Mapping[str, str], specs):
        self.effect = effect
        self.where = where
        self.paths = dict(paths)
        self.specs = tuple(specs)
        unknown = [s.name for s in self.specs if s.name not in self.paths]
        if unknown:
            raise InvalidValueError(f"parameters {unknown} have no path")

    def apply(self, assembly, values):
        return set_parameters(assembly, {self.paths[k]: v for k, v in values.items()})

    def apply_si(self, structure, values):
        for k, v in values.items():
            structure = apply_path_si(structure, self.paths[k], float(v))
        return structure


class ParameterChange(ParameterSet):
    """A correction of one model parameter (effect ``model-parameter``, ``where`` its path).

    Parameters
    ----------
    parameter : ModelParameter
        The parameter, with its bounds.
    """

    effect = "model-parameter"
    explanation = "a number of the model is off: the fit corrects it"

    def __init__(self, parameter: ModelParameter):
        if not isinstance(parameter, ModelParameter):
            raise InvalidValueError(f"parameter: got {parameter!r}; expected a ModelParameter (from "
                                    "model_parameters(assembly))")
        super().__init__("model-parameter", parameter.path, {"value": parameter.path}, (parameter.spec(),))
        self.parameter = parameter


def parameter_change(parameter: ModelParameter) -> ParameterChange:
    """The change that corrects a model parameter (on the SI form, as every parameter is).

    Parameters
    ----------
    parameter : ModelParameter
        The parameter.

    Returns
    -------
    ParameterChange
        A :class:`ParameterChange`.
    """
    return ParameterChange(parameter)
