"""Cutting-coefficient data: specific cutting forces of work materials, by name.

The project ships a small table (``substructure/data/cutting_coefficients.toml``)
of published coefficients for common work materials, each with its source;
users add their own tables in the same format (:func:`load_workpieces`).
Two force laws are supported:

* **linear** (the mechanistic edge-force model of Altintas, *Manufacturing
  Automation*, ch. 2): per unit axial depth ``F_t = Kt h + Kte`` and
  ``F_r = Kr h + Kre``;
* **kienzle**: ``k_c = kc11 (h / 1 mm)^(-mc)``, the main cutting force per
  chip area.  Stability needs the slope ``dF_t/dh`` at the cut's mean chip
  thickness: ``Kt = (1 - mc) kc11 (h_m / 1 mm)^(-mc)``; the power uses the
  force itself.

A value its source does not give is absent, never estimated: the Kienzle
entries have no radial coefficient, which the user then gives.
"""

from __future__ import annotations

import difflib
import importlib.resources
import os
import re
from typing import Any

import attrs
import pint

from .._toml import TomlDocument, loads_toml, read_toml
from ..errors import InvalidValueError
from ..units import Q_, dimensionless, quantity, show_value

__all__ = ["Workpiece", "workpiece", "workpieces", "load_workpieces", "WORKPIECE_KEYS"]

WORKPIECE_KEYS = ("name", "aliases", "material", "model", "kt", "kr", "kte", "kre", "kc11", "mc", "tool",
                  "source", "note")
_PRESSURE = "[mass] / [length] / [time] ** 2"
_EDGE = "[mass] / [time] ** 2"


def _optional(field: str, dimension: str):
    def convert(value: Any) -> pint.Quantity | None:
        if value is None:
            return None
        q = quantity(value, field, dimension)
        if not q.magnitude >= 0:
            raise InvalidValueError(f"{field}: got {show_value(value)}; expected a value >= 0")
        return q

    return convert


def _mc(value: Any) -> float | None:
    if value is None:
        return None
    mc = dimensionless(value, "mc")
    if not 0.0 <= mc < 1.0:
        raise InvalidValueError(f"mc: got {show_value(value)}; expected the Kienzle exponent in [0, 1)")
    return mc


def _aliases(value: Any, field: str) -> tuple:
    """A list of names; a string is refused (``tuple("mill")`` would be the aliases m, i, l, l)."""
    if isinstance(value, str):
        raise InvalidValueError(f"{field}: got the string {value!r}; expected a list of names, e.g. "
                                f"aliases = [{value!r}]")
    try:
        names = tuple(value)
    except TypeError:
        raise InvalidValueError(f"{field}: got {show_value(value)}; expected a list of names") from None
    bad = [a for a in names if not isinstance(a, str) or not a.strip()]
    if bad:
        raise InvalidValueError(f"{field}: got {show_value(bad[0])} in the list; expected names (strings)")
    return names


def _model(value: Any) -> str:
    if value not in ("linear", "kienzle"):
        raise InvalidValueError(f"model: got {show_value(value)}; expected 'linear' or 'kienzle'")
    return value


@attrs.frozen
class Workpiece:
    """Cutting coefficients of one work material, with their source.

    Parameters
    ----------
    name : str
        The name used to select it (``--workpiece NAME``).
    model : {"linear", "kienzle"}
    kt, kr : quantity, optional
        Linear model: tangential and radial cutting coefficients (pressures).
    kte, kre : quantity, optional
        Linear model: tangential and radial edge forces per length of edge.
    kc11 : quantity, optional
        Kienzle: specific cutting force of a 1 mm x 1 mm chip (a pressure).
    mc : float, optional
        Kienzle exponent.
    aliases : tuple of str
        Other names it answers to (case and spaces ignored).
    material, tool, source, note : str
        What the material is, with which tool it was measured, the published
        source, remarks.
    """

    name: str
    model: str = attrs.field(converter=_model)
    kt: pint.Quantity | None = attrs.field(default=None, converter=_optional("kt", _PRESSURE))
    kr: pint.Quantity | None = attrs.field(default=None, converter=_optional("kr", _PRESSURE))
    kte: pint.Quantity | None = attrs.field(default=None, converter=_optional("kte", _EDGE))
    kre: pint.Quantity | None = attrs.field(default=None, converter=_optional("kre", _EDGE))
    kc11: pint.Quantity | None = attrs.field(default=None, converter=_optional("kc11", _PRESSURE))
    mc: float | None = attrs.field(default=None, converter=_mc)
    aliases: tuple = attrs.field(default=(), converter=lambda v: _aliases(v, "aliases"))
    material: str = ""
    tool: str = ""
    source: str = ""
    note: str = ""

    def __attrs_post_init__(self) -> None:
        if self.model == "linear" and self.kt is None:
            raise InvalidValueError(f"workpiece {self.name!r}: a linear entry needs kt")
        if self.model == "kienzle" and (self.kc11 is None or self.mc is None):
            raise InvalidValueError(f"workpiece {self.name!r}: a kienzle entry needs kc11 and mc")
        if not self.source.strip():
            raise InvalidValueError(f"workpiece {self.name!r}: source is missing; every entry names its source")

    @property
    def short_source(self) -> str:
        """The source up to its first comma, for messages."""
        return " ".join(self.source.split()).split(",")[0]

    def coefficients(self, mean_chip_thickness: Any = None) -> dict:
        """The coefficients of the stability model and the power, as quantities.

        Parameters
        ----------
        mean_chip_thickness : quantity or str, optional
            Needed for a Kienzle entry (the coefficient depends on it).

        Returns
        -------
        dict
            ``kt``, ``kn`` (pressures; ``kn`` None when the entry has none),
            ``kte``, ``kne`` (forces per length).
        """
        zero = Q_(0.0, "N/m")
        if self.model == "linear":
            return {"kt": self.kt, "kn": self.kr, "kte": self.kte or zero, "kne": self.kre or zero}
        if mean_chip_thickness is None:
            raise InvalidValueError(
                f"feed_per_tooth: workpiece {self.name!r} is a Kienzle entry, whose coefficient depends on the "
                "chip thickness; give the feed per tooth (e.g. '0.1 mm')")
        h = quantity(mean_chip_thickness, "mean_chip_thickness", "[length]").m_as("mm")
        if not h > 0:
            raise InvalidValueError(f"mean_chip_thickness: got {show_value(mean_chip_thickness)}; expected > 0")
        kt = (1.0 - self.mc) * self.kc11 * h ** (-self.mc)
        return {"kt": kt.to("MPa"), "kn": None, "kte": zero, "kne": zero}

    def tangential_force_per_depth(self, chip_thickness_m: Any):
        """The tangential force law itself: force per unit depth at chip thicknesses.

        Parameters
        ----------
        chip_thickness_m : array_like
            Chip thicknesses in m.

        Returns
        -------
        ndarray
            N per m of axial depth.
        """
        import numpy as np

        h = np.asarray(chip_thickness_m, dtype=float)
        if self.model == "linear":
            kte = 0.0 if self.kte is None else self.kte.m_as("N/m")
            return self.kt.m_as("Pa") * h + np.where(h > 0, kte, 0.0)
        return self.kc11.m_as("Pa") * h * (np.maximum(h, 0.0) / 1e-3) ** (-self.mc)

    def describe(self) -> str:
        """One line: the name, the values and the source.

        Returns
        -------
        str
            E.g. ``"aluminium-7075 (...): Kt = 767.01 MPa, ...; source: ..."``.
        """
        if self.model == "linear":
            values = f"Kt = {self.kt.to('MPa'):.5g~P}"
            for label, q in (("Kr", self.kr), ("Kte", self.kte), ("Kre", self.kre)):
                if q is not None:
                    values += f", {label} = {q.to('MPa' if label == 'Kr' else 'N/mm'):.4g~P}"
        else:
            values = f"Kienzle kc1.1 = {self.kc11.to('MPa'):.5g~P}, mc = {self.mc:g}"
        return f"{self.name} ({self.material}): {values}; source: {self.short_source}"

    def to_json(self) -> dict:
        """The entry with SI numbers (Pa, N/m) and its texts.

        Returns
        -------
        dict
            ``name``, ``model``, ``material``, ``source`` and the values the
            entry has (``kt_pa``, ``kr_pa``, ``kte_n_per_m``, ``kre_n_per_m``,
            ``kc11_pa``, ``mc``).
        """
        out = {"name": self.name, "model": self.model, "material": self.material,
               "source": " ".join(self.source.split())}
        for key, unit in (("kt", "Pa"), ("kr", "Pa"), ("kte", "N/m"), ("kre", "N/m"), ("kc11", "Pa")):
            q = getattr(self, key)
            if q is not None:
                out[f"{key}_{unit.replace('/', '_per_').lower()}"] = float(q.m_as(unit))
        if self.mc is not None:
            out["mc"] = self.mc
        return out


_SPELLINGS = {"aluminum": "aluminium", "alu": "aluminium", "al": "aluminium", "aisi": "", "sae": "",
              "gray": "grey", "stainless-steel": "stainless", "ss": "stainless"}
"""Common spellings mapped to the table's words (a word mapped to "" is dropped: AISI 1045 is 1045)."""
_TEMPER = re.compile(r"^t\d{1,4}$")  # aluminium tempers: -T6, -T651, -T73
_WORDS = re.compile(r"[\s_\-/]+")
_LETTERS_DIGITS = re.compile(r"^([a-z]+)(\d{3,}[a-z]?)$")  # al6061 -> al 6061, ss304 -> ss 304


def _key(name: str) -> str:
    """The normalised form of a workpiece name: case, spaces, hyphens and underscores, the word order, the
    spellings aluminium/aluminum and a temper suffix (6061-T651 is 6061) do not matter."""
    words = []
    for word in _WORDS.split(str(name).strip().lower()):
        if _TEMPER.match(word):
            continue
        split = _LETTERS_DIGITS.match(word)
        for part in (split.groups() if split else (word,)):
            part = _SPELLINGS.get(part, part)
            if part and not _TEMPER.match(part):
                words.append(part)
    return " ".join(sorted(words))


def _parse(doc: TomlDocument) -> tuple[Workpiece, ...]:
    out: list[Workpiece] = []
    seen: dict[str, str] = {}
    for i, row in enumerate(doc.tables("workpiece", WORKPIECE_KEYS, ("name", "model", "source"))):
        try:
            out.append(Workpiece(**row))
        except (InvalidValueError, TypeError, ValueError) as exc:
            raise doc.wrap(["workpiece", i], str(exc)) from None
        for key, alias in [("name", out[-1].name)] + [("aliases", a) for a in out[-1].aliases]:
            if seen.setdefault(_key(alias), out[-1].name) != out[-1].name:
                raise doc.error(["workpiece", i, key], f"the name {alias!r} is used by {seen[_key(alias)]!r} and "
                                f"{out[-1].name!r}")
    return tuple(out)


def load_workpieces(path: Any) -> tuple[Workpiece, ...]:
    """Read a table of workpieces (TOML, ``[[workpiece]]`` tables, units on every value).

    Parameters
    ----------
    path : str or path-like
        The TOML file.

    Returns
    -------
    tuple of Workpiece
        Its entries, in file order.

    Raises
    ------
    FileFormatError
        Naming the file, the row and the key.
    """
    return _parse(read_toml(path, "workpiece table"))


def workpieces() -> tuple[Workpiece, ...]:
    """The project's table (``substructure/data/cutting_coefficients.toml``).

    Returns
    -------
    tuple of Workpiece
        Every entry of the project's table.
    """
    resource = importlib.resources.files("substructure") / "data" / "cutting_coefficients.toml"
    return _parse(loads_toml(resource.read_text(encoding="utf-8"), "cutting_coefficients.toml"))


def workpiece(name: str, table: Any = None) -> Workpiece:
    """A workpiece by name or alias (case and spaces ignored).

    Parameters
    ----------
    name : str
        E.g. ``"aluminium-7075"``, ``"7075"``, ``"steel-1045"``.
    table : path or sequence of Workpiece, optional
        A user table searched first (then the project's).

    Returns
    -------
    Workpiece
        The first entry answering to the name.
    """
    entries: list[Workpiece] = []
    if table is not None:
        entries += list(load_workpieces(table) if isinstance(table, (str, os.PathLike)) else table)
    entries += list(workpieces())
    if not isinstance(name, str) or not name.strip():
        raise InvalidValueError(f"workpiece: got {show_value(name)}; expected the name of a work material, "
                                "e.g. aluminium-6061 or steel-1045")
    key = _key(name)
    for w in entries:
        if key in {_key(a) for a in (w.name, *w.aliases)}:
            return w
    names = ", ".join(dict.fromkeys(w.name for w in entries))
    raise InvalidValueError(f"workpiece: got {name!r}; {_suggest(key, entries)}known: {names}")


def _suggest(key: str, entries: list) -> str:
    """'did you mean ...; ' for a name that is not in the table: the entries whose names hold every word of it
    (``aluminium`` -> both aluminium alloys: a choice, never a guess), else the close spellings."""
    words = set(key.split())
    holding = [w.name for w in entries if any(words <= set(_key(a).split()) for a in (w.name, *w.aliases))]
    if not holding:
        spelled = {_key(a): w.name for w in entries for a in (w.name, *w.aliases)}
        holding = [spelled[k] for k in difflib.get_close_matches(key, list(spelled), n=6, cutoff=0.6)]
    holding = list(dict.fromkeys(holding))
    if not holding:
        return ""
    return f"did you mean {' or '.join(holding)}? "
