"""Prior joint values per holder type, and where every joint's values come from.

A catalogue holder (:mod:`substructure.holders`) has approximate geometry
and no joint values of its own.  Reusing the joints of another holder (the
thesis's collet chuck) makes a shrink-fit chuck look like that collet chuck
at its joints and can rank holders in an order no source supports.  This
module gives each type of holder a documented **prior**
(``substructure/data/joint_priors.toml``): for the holder-tool joint per
clamping system (ER collet, shrink-fit, hydraulic) and for the
spindle-holder joint per interface (steep taper, HSK), each with its source,
whether it is measured (the middle of the thesis's identified values) or
assumed (a measured row times a factor that follows a qualitative fact of
the literature), and a wide uncertainty factor ``f``: the joint may be
anywhere between ``1/f`` and ``f`` times the values.

:func:`joint_provenances` says for every joint of an assembly where its
values come from (:class:`~substructure.joints.JointProvenance`), flagging
the joints of a catalogue holder whose provenance is not stated;
:func:`with_joint_priors` puts the priors in place; :func:`joint_variants`
gives the assemblies at the ends of every stated uncertainty, from which the
stability band is computed (:func:`substructure.stability.lobes_band`).

Examples
--------
>>> from substructure.joint_priors import prior_joint
>>> j = prior_joint("holder-tool", "shrink-fit", "ht", ("holder.tip", "tool.base"))
>>> j.provenance.kind, j.provenance.uncertainty
('prior', 4.0)
"""

from __future__ import annotations

import functools
import importlib.resources
import itertools
from typing import Any

import attrs
import numpy as np

from ._toml import loads_toml
from .errors import InvalidValueError
from .units import items_of, whole_number
from .joints import DAMPING_UNITS, STIFFNESS_UNITS, Joint, JointProvenance
from .points import parse_point

__all__ = ["ROLES", "holder_type", "joint_role", "prior_joint", "prior_for", "joint_provenances",
           "with_joint_priors", "joint_variants", "priors_table"]

ROLES = ("holder-tool", "spindle-holder")
"""The joints a prior exists for."""

_CATALOGUE_MARK = "APPROXIMATE catalogue geometry"


@functools.cache
def priors_table() -> dict:
    """The prior table: ``{role: {kind: row}}``, each row with ``title``, ``basis``, ``k``, ``c``,
    ``uncertainty``, ``source``.

    Returns
    -------
    dict
        The parsed ``substructure/data/joint_priors.toml``.
    """
    resource = importlib.resources.files("substructure") / "data" / "joint_priors.toml"
    return loads_toml(resource.read_text(encoding="utf-8"), "joint_priors.toml").data


def holder_type(holder: Any) -> dict | None:
    """The interface and clamping system of a catalogue holder, from its description (None for another holder).

    Parameters
    ----------
    holder : Holder
        A holder component; catalogue holders say so in their description
        (also after a save and a load).

    Returns
    -------
    dict or None
        ``{"interface": "steep-taper" | "hsk", "clamp": "collet" | "shrink-fit" | "hydraulic", "name": ...}``.
    """
    text = getattr(holder, "description", None) or ""
    if _CATALOGUE_MARK not in text:
        return None
    head = text.split(":")[0]
    clamp = next((c for c in ("shrink-fit", "hydraulic", "collet") if c in head.lower()), None)
    interface = "hsk" if "HSK" in head else "steep-taper"
    return {"interface": interface, "clamp": clamp, "name": head.strip()}


def _type_of(assembly: Any, point: str) -> str:
    return type(assembly.component(parse_point(point).component)).__name__


def joint_role(assembly: Any, joint: Joint) -> tuple[str, Any] | None:
    """Whether a joint joins a holder to a tool or a spindle to a holder, and the holder.

    Parameters
    ----------
    assembly : Assembly
        The assembly of the joint.
    joint : Joint
        One of its joints.

    Returns
    -------
    (str, Holder) or None
        ``("holder-tool", holder)``, ``("spindle-holder", holder)`` or None.
    """
    types = [_type_of(assembly, p) for p in joint.between]
    holders = [parse_point(p).component for p, t in zip(joint.between, types) if t == "Holder"]
    if not holders:
        return None
    other = [t for t in types if t != "Holder"]
    role = {"Tool": "holder-tool", "Spindle": "spindle-holder"}.get(other[0]) if other else None
    return (role, assembly.component(holders[0])) if role else None


def prior_joint(role: str, kind: str, name: str, between: Any) -> Joint:
    """A joint with the prior values of a holder type, its provenance saying so.

    Parameters
    ----------
    role : {"holder-tool", "spindle-holder"}
        Which joint.
    kind : str
        Holder-tool: the clamping system (``"collet"``, ``"shrink-fit"``,
        ``"hydraulic"``); spindle-holder: the interface (``"steep-taper"``,
        ``"hsk"``).
    name : str
        The joint's name.
    between : (str, str)
        Its two points.

    Returns
    -------
    Joint
        Stiffness and damping of the prior (N/m, N m/rad and their dampings),
        ``provenance`` a :class:`~substructure.joints.JointProvenance` of kind
        ``"prior"`` with the row's source and uncertainty factor.
    """
    table = priors_table()
    if not isinstance(role, str) or role not in table:
        raise InvalidValueError(f"role: got {role!r}; expected one of {', '.join(ROLES)}")
    if not isinstance(kind, str) or kind not in table[role]:
        raise InvalidValueError(f"{role} prior: no row for {kind!r}; known: {', '.join(table[role])}")
    row = table[role][kind]
    source = f"{row['title']} ({row['basis']}): {row['source']}"
    return Joint(name, tuple(between), k=row["k"], c=row["c"],
                 provenance=JointProvenance("prior", source, row["uncertainty"]))


def prior_for(assembly: Any, joint: Joint) -> Joint | None:
    """The prior of a joint of a catalogue holder (None when the joint is not at one).

    Parameters
    ----------
    assembly : Assembly
        The assembly.
    joint : Joint
        One of its joints.

    Returns
    -------
    Joint or None
        :func:`prior_joint` for the joint's role and the holder's type.
    """
    found = joint_role(assembly, joint)
    if found is None:
        return None
    role, holder = found
    kind = holder_type(holder)
    if kind is None or (role == "holder-tool" and kind["clamp"] is None):
        return None
    return prior_joint(role, kind["clamp"] if role == "holder-tool" else kind["interface"], joint.name,
                       joint.between)


def joint_provenances(assembly: Any) -> list[dict]:
    """Where the values of every elastic joint come from, with a warning for a catalogue holder's unstated ones.

    Parameters
    ----------
    assembly : Assembly
        The assembly.

    Returns
    -------
    list of dict
        Per elastic joint: ``name``, ``role`` (or None), ``holder`` (the
        catalogue holder's name, or None), ``kind`` (``identified``,
        ``predicted``, ``borrowed``, ``prior`` or ``"not stated"``),
        ``source``, ``uncertainty``, ``basis`` (``"measured"`` or
        ``"assumed"`` for the shipped prior of the holder's type, from its
        row of the prior table; None otherwise) and ``warning`` (None, or why
        the values cannot be trusted for this holder).
    """
    rows = []
    for joint in assembly.joints:
        if joint.rigid:
            continue
        found = joint_role(assembly, joint)
        kind = holder_type(found[1]) if found else None
        p = joint.provenance
        row = {"name": joint.name, "role": found[0] if found else None, "holder": kind["name"] if kind else None,
               "kind": p.kind if p else "not stated", "source": p.source if p else "",
               "uncertainty": p.uncertainty if p else None, "basis": None, "warning": None}
        if p is not None and p.kind == "prior":
            shipped = prior_for(assembly, joint)  # the shipped prior of this holder type, when it is that one
            if shipped is not None and shipped.provenance.source == p.source:
                role, kind_name = found[0], kind["clamp"] if found[0] == "holder-tool" else kind["interface"]
                row["basis"] = priors_table()[role][kind_name]["basis"]
        if kind is not None and (p is None or p.kind == "borrowed"):
            row["warning"] = (f"the values of joint {joint.name!r} were not identified or predicted for the catalogue "
                              f"holder {kind['name']}" + (": borrowed" if p else ": their provenance is not stated")
                              + "; they may be another holder's. Use its prior (prior = true in the assembly "
                              "file, with a wide uncertainty) or identify the joint from a tap test")
        rows.append(row)
    return rows


def with_joint_priors(assembly: Any, names: Any = None) -> Any:
    """The assembly with joints of catalogue holders replaced by their priors.

    Parameters
    ----------
    assembly : Assembly
        The assembly.
    names : sequence of str, optional
        The joints to replace; default every joint of a catalogue holder
        whose provenance is not stated or ``"borrowed"``.

    Returns
    -------
    Assembly
        A new assembly (joints identified, predicted or already priors kept).
    """
    if names is not None:
        names = [names] if isinstance(names, str) else items_of(names, "names", "joint names")
    out = assembly
    for joint in assembly.joints:
        if joint.rigid or not (joint.name in names if names is not None
                               else joint.provenance is None or joint.provenance.kind == "borrowed"):
            continue
        prior = prior_for(assembly, joint)
        if prior is None:
            if names is not None:
                raise InvalidValueError(f"joint {joint.name!r}: not the holder-tool or spindle-holder joint of a "
                                        "catalogue holder; no prior for it")
            continue
        out = out.with_joint(prior)
    return out


def joint_variants(assembly: Any, levels: int = 3) -> list:
    """Assemblies at the ends (and the middle) of every joint's stated uncertainty, for a stability band.

    Each joint whose provenance states an uncertainty factor ``f`` takes the
    stiffness and damping factors ``f**t`` for ``t`` on ``levels`` points of
    ``[-1, 1]``; the variants are every combination (``levels ** n``, the
    nominal among them for odd ``levels``).

    Parameters
    ----------
    assembly : Assembly
        The assembly.
    levels : int, default 3
        Points per uncertain joint (2 to 5).

    Returns
    -------
    list of Assembly
        The variants; ``[assembly]`` when no joint states an uncertainty.
    """
    whole_number(levels, "levels", 2, "a whole number of levels", 5)  # (2.7 was taken as 2)
    uncertain = [j for j in assembly.joints if not j.rigid and j.provenance is not None
                 and j.provenance.uncertainty is not None and j.provenance.uncertainty > 1.0]
    if not uncertain:
        return [assembly]
    exponents = np.linspace(-1.0, 1.0, int(levels))
    variants = []
    for combo in itertools.product(exponents, repeat=len(uncertain)):
        out = assembly
        for joint, t in zip(uncertain, combo):
            factor = float(joint.provenance.uncertainty ** t)
            scaled, damp = ({key: f"{float(m.get(key)) * factor!r} {unit}" for key, unit in units.items()
                             if m.get(key) != 0.0}
                            for m, units in ((joint.k, STIFFNESS_UNITS), (joint.c, DAMPING_UNITS)))
            out = out.with_joint(attrs.evolve(joint, k=scaled, c=damp))
        variants.append(out)
    return variants
