"""Tool holders: :class:`Holder` and the catalogue of standard holders (approximate geometry, easy to override).

The class and the catalogue are one module, so that :meth:`Holder.from_catalog` and
:meth:`HolderDesign.holder` need no import of each other; ``substructure.holders`` is the
catalogue's public name.


A catalogue holder is an *interface* (the shank that goes into the spindle:
BT40, CAT40, HSK-A63) combined with a *clamping system* (ER collet chucks with
their nut, shrink-fit, hydraulic), named ``"<interface> <clamp>"``, e.g.
``"BT40 ER32"`` or ``"HSK-A63 shrink-fit"``.  The numbers live in
``substructure/data/holders.toml`` with their sources; they are APPROXIMATE
(public standards for the interfaces, rounded typical catalogue values for
the bodies and noses), and every holder built from them says so in its
``description``.  Any number can be overridden by name.

The holder runs from the *gauge line* (steep tapers: where the taper has its
gauge diameter; HSK: the flange contact face), where it meets the spindle
face, to its nose: ``holder.base`` is the spindle-holder joint, as in the
thesis, whose spindle model includes the part of the holder inside the
spindle.  ``shank_taper=True`` adds the taper shank before the gauge line as
a tapered segment (:mod:`substructure.tapers`); the gauge line is then at
``HolderDesign.gauge_line`` from the base.  The tool shank fills the
bore over the clamped length as an :class:`~substructure.beams.Insert`
(thesis section 2.1: the part of the tool inside the holder is coupled to it
rigidly).  See docs/holders.md.

Examples
--------
>>> from substructure import Holder
>>> holder = Holder.from_catalog("HSK-A63 shrink-fit", bore="16 mm", gauge_length="80 mm")
>>> holder.length
<Quantity(80.0, 'millimeter')>
>>> "APPROXIMATE" in holder.description
True
"""

from __future__ import annotations

import functools
import importlib.resources
import math
from typing import Any

import attrs
import pint

from .._toml import loads_toml
from ..beams import Segment
from ..errors import InvalidValueError
from ..sections import Insert, _material
from ..units import Q_, check_number_text, quantity, show_value
from .beam import Beam
from .protocol import register_component

__all__ = ["Holder", "HolderDesign", "catalog_names", "catalog_parameters", "design"]


@register_component("holder")
@attrs.frozen
class Holder(Beam):
    """A tool holder: base at the taper end, tip at its face.

    Parameters
    ----------
    name : str
        Name used in point names (``"holder"`` gives ``"holder.tip"``).
    segments : sequence of Segment
        Base to tip.
    description : str, optional
        What the component is and where its numbers come from (keyword only).

    Notes
    -----
    The part of the tool inside the holder is usually modelled as an
    :class:`~substructure.beams.Insert` of the holder's bore segment
    (thesis section 2.1).  Standard holders (BT40, CAT40, HSK-A63 with ER
    collet chucks, shrink-fit or hydraulic noses) come from
    :meth:`from_catalog`.
    """

    @classmethod
    def from_catalog(cls, entry: str, *, name: str = "holder", **parameters) -> "Holder":
        """A standard holder of approximate geometry from the catalogue, with overrides.

        Parameters
        ----------
        entry : str
            ``"<interface> <clamp>"``, e.g. ``"HSK-A63 shrink-fit"``, ``"BT40 ER32"``,
            ``"CAT40 hydraulic"`` (:func:`substructure.holders.catalog_names`).
        name : str
            Component name.
        **parameters
            ``bore`` (the tool shank diameter, required), ``gauge_length``,
            ``clamp_length``, ``material``, ``tool_material``, ``shank_taper``
            and any geometric value of the catalogue by name, e.g.
            ``nose_diameter="27 mm"`` (:func:`substructure.holders.design`).

        Returns
        -------
        Holder
            From the gauge line (its base, the spindle-holder joint) to the
            nose, the tool shank as an insert over the clamped length; its
            ``description`` says it is approximate and cites the sources.

        Examples
        --------
        >>> h = Holder.from_catalog("BT40 ER32", bore="12 mm", gauge_length="70 mm", nut_diameter="48 mm")
        >>> round(h.mass(), 2)
        1.11
        """
        return design(entry, **parameters).holder(name, cls)


_LENGTH_KEYS = {
    "interface": ("gauge_diameter", "taper_length", "taper_bore", "gap_length", "gap_diameter",
                  "flange_diameter", "flange_length"),
    "collet": ("body_diameter", "nut_diameter", "nut_length", "collet_length", "max_bore"),
    "shrink-fit": ("body_diameter", "nose_diameter"),
    "hydraulic": ("body_diameter", "nose_diameter", "nose_length"),
}
_COMMON = ("bore", "gauge_length", "clamp_length", "material", "tool_material", "shank_taper", "taper_ratio")


@functools.cache
def _data() -> dict:
    resource = importlib.resources.files("substructure") / "data" / "holders.toml"
    return loads_toml(resource.read_text(encoding="utf-8"), "holders.toml").data


def catalog_names() -> tuple[str, ...]:
    """Names of the catalogue holders, ``"<interface> <clamp>"``.

    Returns
    -------
    tuple of str
        Every combination of the interfaces and clamping systems of the data file.
    """
    data = _data()
    return tuple(f"{i} {c}" for i in data["interfaces"] for c in data["clamps"])


def _entry(name: str) -> tuple[str, str]:
    if not isinstance(name, str):
        raise InvalidValueError(f"catalog: got {name!r}; expected a holder name such as 'BT40 ER32'")
    data = _data()
    wanted = " ".join(name.split()).lower()
    for interface in data["interfaces"]:
        for clamp in data["clamps"]:
            if f"{interface} {clamp}".lower() == wanted:
                return interface, clamp
    raise InvalidValueError(
        f"catalog: unknown holder {name!r}; known: {', '.join(catalog_names())} "
        "(an interface BT40, CAT40 or HSK-A63, then a clamping system)"
    )


def catalog_parameters(name: str) -> tuple[str, ...]:
    """The parameters a catalogue holder takes (all can be given as overrides).

    Parameters
    ----------
    name : str
        A catalogue name, e.g. ``"BT40 shrink-fit"``.

    Returns
    -------
    tuple of str
        ``bore``, ``gauge_length``, ``clamp_length``, ``material``,
        ``tool_material``, ``shank_taper``, ``taper_ratio`` and the
        geometric values of its interface and clamping system.
    """
    _, clamp = _entry(name)
    kind = _data()["clamps"][clamp]["kind"]
    extra = ("nose_angle",) if kind == "shrink-fit" else ()
    return _COMMON + _LENGTH_KEYS["interface"] + _LENGTH_KEYS[kind] + extra


@attrs.frozen
class HolderDesign:
    """A catalogue holder resolved: its parameters, segments and description.

    Parameters
    ----------
    entry : str
        Catalogue name, e.g. ``"HSK-A63 shrink-fit"``.
    parameters : dict
        Every parameter used, catalogue values and overrides alike
        (quantities, materials, ``shank_taper``).
    overrides : tuple of str
        Names of the parameters given by the user.
    segments : tuple of Segment
        Base (the taper's small end with ``shank_taper``, else the gauge
        line) to tip (the holder nose).
    gauge_line : pint.Quantity
        Distance of the gauge line (the spindle-holder joint) from the base:
        0, or the taper length with ``shank_taper``.
    description : str
        What it is, that it is approximate, and where the numbers come from.
    """

    entry: str
    parameters: dict
    overrides: tuple[str, ...]
    segments: tuple[Segment, ...]
    gauge_line: pint.Quantity
    description: str

    def holder(self, name: str = "holder", cls: type | None = None):
        """The holder component.

        Parameters
        ----------
        name : str
            Component name (points ``NAME.base``, ``NAME.tip``).
        cls : type, optional
            Component class, :class:`~substructure.components.Holder` by default.

        Returns
        -------
        Holder
            With these segments and this description.
        """
        return (Holder if cls is None else cls)(name, self.segments, description=self.description)


def _table_value(table: dict, key: pint.Quantity, what: str, field: str) -> pint.Quantity:
    """Value of a ``{"6 mm" = "21 mm", ...}`` table for a length ``key`` (matched to 1e-6 mm)."""
    sizes = {k: v for k, v in table.items() if k != "source"}
    for k, v in sizes.items():
        if abs(Q_(k).m_as("mm") - key.m_as("mm")) < 1e-6:
            return Q_(v)
    known = ", ".join(sizes)
    raise InvalidValueError(
        f"{field}: got {key:~P}; the catalogue has {what} for {known}: give {what.split(' ')[0]} yourself "
        f"(e.g. {what.split(' ')[0]}='30 mm') for other sizes"
    )


_MAY_BE_ZERO = ("gap_length", "taper_bore")
"""Catalogue lengths that may be 0 (no gap between gauge line and flange, a solid taper); the others are > 0."""


def _catalog_length(value: Any, key: str) -> pint.Quantity:
    """A length of the catalogue's data or its override, checked under its own name (not a segment's ``od``)."""
    q = quantity(value, key, "[length]")
    if q.magnitude < 0 or (q.magnitude == 0 and key not in _MAY_BE_ZERO):
        expected = "a length >= 0" if key in _MAY_BE_ZERO else "a positive length"
        raise InvalidValueError(f"{key}: got {show_value(value)}; expected {expected}")
    return q


def _angle(value: Any) -> pint.Quantity:
    """An angle with its unit (``"4.5 deg"``); a bare number is refused."""
    if isinstance(value, str):  # "4,5 deg" is 45 deg to pint: refused, as every value's text
        check_number_text(value, "nose_angle", "an angle with its unit, e.g. '4.5 deg'", InvalidValueError)
    try:
        q = value if isinstance(value, pint.Quantity) else Q_(value) if isinstance(value, str) else None
    except pint.PintError:
        q = None
    if q is None or not q.check("[]") or not any(u in str(q.units) for u in ("degree", "radian")):
        raise InvalidValueError(f"nose_angle: got {value!r}; expected an angle with its unit, e.g. '4.5 deg'")
    return q


def design(entry: str, **parameters: Any) -> HolderDesign:
    """Resolve a catalogue holder with overrides into its segments.

    Parameters
    ----------
    entry : str
        Catalogue name ``"<interface> <clamp>"`` (:func:`catalog_names`),
        e.g. ``"BT40 ER32"`` or ``"HSK-A63 shrink-fit"``; case and spacing
        are free.
    **parameters
        ``bore`` (the tool shank diameter; required), ``gauge_length``
        (gauge line to nose; default per clamping system), ``clamp_length``
        (tool shank length inside the holder; default the DIN 6535 shank
        length, at most the collet length), ``material`` (holder, default
        steel), ``tool_material`` (the shank's, default carbide; ``None``
        for an empty bore), ``shank_taper`` (include the taper shank, default
        False), and any value of the data file by name (lengths with units,
        ``nose_angle`` an angle, ``taper_ratio`` a number): see
        :func:`catalog_parameters`.

    Returns
    -------
    HolderDesign
        The parameters used (lengths with units), the segments and the description.

    Raises
    ------
    InvalidValueError
        Unknown holder or parameter, a bore the clamping system cannot take,
        lengths that do not fit (e.g. a gauge length shorter than the flange).
    """
    interface, clamp = _entry(entry)
    data = _data()
    face, chuck = data["interfaces"][interface], data["clamps"][clamp]
    kind = chuck["kind"]
    allowed = catalog_parameters(entry)
    unknown = [k for k in parameters if k not in allowed]
    if unknown:
        raise InvalidValueError(
            f"{unknown[0]}: not a parameter of catalogue holder {interface} {clamp}; allowed: {', '.join(allowed)}"
        )
    if "bore" not in parameters:
        raise InvalidValueError(f"bore: missing; give the tool shank diameter, e.g. bore='16 mm' ({interface} {clamp})")
    p: dict[str, Any] = {}
    for key in _LENGTH_KEYS["interface"]:
        p[key] = _catalog_length(parameters.get(key, face[key]), key)
    for key in _LENGTH_KEYS[kind]:
        if key in parameters:
            p[key] = _catalog_length(parameters[key], key)
        elif key in chuck:
            p[key] = Q_(chuck[key])
    ratio = p["taper_ratio"] = parameters.get("taper_ratio", face["taper_ratio"])
    if isinstance(ratio, bool) or not isinstance(ratio, (int, float)) or not 0 < ratio < 2:
        raise InvalidValueError(f"taper_ratio: got {ratio!r}; expected the change of diameter per length, e.g. 7/24")
    bore = p["bore"] = quantity(parameters["bore"], "bore", "[length]")
    if bore.magnitude <= 0:
        raise InvalidValueError(f"bore: got {parameters['bore']!r}; expected a positive diameter")
    p["gauge_length"] = quantity(parameters.get("gauge_length", chuck["gauge_length"]), "gauge_length", "[length]")
    p["material"] = _material(parameters.get("material", "steel"))
    tool = parameters.get("tool_material", "carbide")
    p["tool_material"] = None if tool is None or tool == "none" else _material(tool)
    p["shank_taper"] = parameters.get("shank_taper", False)
    if not isinstance(p["shank_taper"], bool):
        raise InvalidValueError(f"shank_taper: got {p['shank_taper']!r}; expected true or false")
    if kind == "collet" and bore > p["max_bore"]:
        raise InvalidValueError(f"bore: got {bore:~P}; an {clamp} collet clamps at most {p['max_bore']:~P}")
    if kind in ("shrink-fit", "hydraulic") and "nose_diameter" not in p:
        p["nose_diameter"] = _table_value(chuck["nose_diameters"], bore, "nose_diameter values", "bore")
    if kind == "shrink-fit":
        angle = _angle(parameters.get("nose_angle", chuck["nose_angle"]))
        p["nose_angle"] = angle.to("deg")
        if not 0 < p["nose_angle"].m_as("deg") < 45:
            raise InvalidValueError(f"nose_angle: got {angle:~P}; expected a half-angle between 0 and 45 deg")
    if "clamp_length" in parameters:
        p["clamp_length"] = quantity(parameters["clamp_length"], "clamp_length", "[length]")
    elif kind == "collet":  # the collet's length, or the shank's when it is shorter (DIN 6535 sizes)
        try:
            p["clamp_length"] = min(p["collet_length"], _table_value(data["shank_lengths"], bore, "", "bore"))
        except InvalidValueError:
            p["clamp_length"] = p["collet_length"]
    else:
        p["clamp_length"] = _table_value(data["shank_lengths"], bore, "clamp_length (shank length)", "bore")
    segments, gauge_line = _segments(kind, p)
    given = tuple(parameters)
    return HolderDesign(f"{interface} {clamp}", p, given, segments, gauge_line, _describe(face, chuck, p, given))


def _profile(kind: str, p: dict, front: float) -> list[tuple[float, float, float]]:
    """``(length, od, od_tip)`` in mm of the part in front of the flange, base to tip."""
    body = p["body_diameter"].m_as("mm")
    if kind == "collet":
        nut, nut_len = p["nut_diameter"].m_as("mm"), p["nut_length"].m_as("mm")
        if nut_len >= front:
            raise InvalidValueError(
                f"gauge_length: got {p['gauge_length']:~P}; too short for the flange and the "
                f"{p['nut_length']:~P} nut"
            )
        return [(front - nut_len, body, body), (nut_len, nut, nut)]
    nose = p["nose_diameter"].m_as("mm")
    if kind == "hydraulic":
        nose_len = (p["nose_length"].m_as("mm") if "nose_length" in p
                    else min(front, p["clamp_length"].m_as("mm") + 10.0))
        p["nose_length"] = Q_(nose_len, "mm")
        if nose_len > front:
            raise InvalidValueError(
                f"nose_length: got {p['nose_length']:~P}; longer than the holder in front of its flange")
        return ([(front - nose_len, body, body)] if nose_len < front else []) + [(nose_len, nose, nose)]
    slope = 2.0 * math.tan(p["nose_angle"].m_as("rad"))   # diameter change per length of the cone
    cone = max(0.0, (body - nose) / slope)
    if cone == 0.0:
        return [(front, nose, nose)]
    if cone >= front:
        return [(front, nose + slope * front, nose)]
    return [(front - cone, body, body), (cone, body, nose)]


def _segments(kind: str, p: dict) -> tuple[tuple[Segment, ...], pint.Quantity]:
    def mm(q: pint.Quantity) -> float:
        return q.m_as("mm")

    gauge_length = mm(p["gauge_length"])
    front = gauge_length - mm(p["gap_length"]) - mm(p["flange_length"])
    if front <= 0:
        raise InvalidValueError(
            f"gauge_length: got {p['gauge_length']:~P}; expected more than the gap and flange, "
            f"{p['gap_length'] + p['flange_length']:~P}"
        )
    pieces = []  # (length, od, od_tip) in mm from the gauge line to the nose
    if mm(p["gap_length"]) > 0:
        pieces.append((mm(p["gap_length"]), mm(p["gap_diameter"]), mm(p["gap_diameter"])))
    pieces.append((mm(p["flange_length"]), mm(p["flange_diameter"]), mm(p["flange_diameter"])))
    # diameters to 0.1 um: far below any tolerance, and readable in saved assembly files
    pieces += [(length, round(od, 4), round(od_tip, 4)) for length, od, od_tip in _profile(kind, p, front)]
    clamp, bore = mm(p["clamp_length"]), mm(p["bore"])
    if not 0 < clamp <= gauge_length:
        raise InvalidValueError(
            f"clamp_length: got {p['clamp_length']:~P}; expected a length in (0, gauge_length = {p['gauge_length']:~P}]"
        )
    start = gauge_length - clamp        # where the tool shank begins
    insert = None if p["tool_material"] is None else Insert(p["bore"], p["tool_material"])
    segments, x = [], 0.0
    for length, od, od_tip in pieces:
        cut = start - x
        parts = [(length, od, od_tip, False)]
        if 0 < cut < length:  # the shank starts inside this piece
            od_cut = od + (od_tip - od) * cut / length
            parts = [(cut, od, od_cut, False), (length - cut, od_cut, od_tip, True)]
        elif cut <= 0:
            parts = [(length, od, od_tip, True)]
        for seg_len, a, b, bored in [(q, round(a, 4), round(b, 4), r) for q, a, b, r in parts]:
            if bored and min(a, b) <= bore:
                raise InvalidValueError(
                    f"bore: got {p['bore']:~P}; the holder is only {min(a, b):.4g} mm thick there: "
                    "give a larger nose_diameter or body_diameter, or a shorter clamp_length"
                )
            extra: dict[str, Any] = {"id": p["bore"], "insert": insert} if bored else {}
            tip: dict[str, Any] = {} if a == b else {"od_tip": Q_(b, "mm")}
            segments.append(Segment(Q_(seg_len, "mm"), Q_(a, "mm"), material=p["material"], **extra, **tip))
        x += length
    gauge_line = Q_(0.0, "mm")
    if p["shank_taper"]:
        length = p["taper_length"]
        small = p["gauge_diameter"] - length * p["taper_ratio"]
        if small <= p["taper_bore"]:
            raise InvalidValueError(f"taper_length: got {length:~P}; the taper would close before its end")
        segments.insert(0, Segment(length, small, p["taper_bore"], p["material"], od_tip=p["gauge_diameter"]))
        gauge_line = length.to("mm")
    return tuple(segments), gauge_line


def _describe(face: dict, chuck: dict, p: dict, given: tuple[str, ...]) -> str:
    tool = ("empty bore" if p["tool_material"] is None
            else f"{p['tool_material'].name} shank {p['clamp_length']:~P} deep")
    where = "flange contact face" if p["gap_length"].magnitude == 0 else "gauge line"
    parts = [
        f"{face['title']} + {chuck['title']}: APPROXIMATE catalogue geometry; check it against your "
        f"holder's drawing and override what differs.",
        f"Bore {p['bore']:~P}, gauge length {p['gauge_length']:~P} from the {where}, {tool}.",
    ]
    if p["shank_taper"]:
        parts.append(f"Taper shank included: the gauge line (spindle face) is at holder@{p['taper_length']:~P}.")
    if given:
        parts.append("Given: " + ", ".join(given) + ".")
    parts.append(f"Sources: {face['source']}; {chuck['source']}.")
    return " ".join(parts)
