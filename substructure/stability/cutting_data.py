"""Cutting data in the shop's terms: cutting speed, feed per tooth, feed rate, checked against a range.

A recommendation in rpm and mm says nothing of whether the tool survives
it: 11,600 rpm with a 12 mm carbide end mill in 1045 steel is a cutting
speed of 437 m/min, well above what carbide takes in steel.  This module
turns a spindle speed and a cut into the numbers a machinist checks
(cutting speed ``v_c = pi D n`` in m/min and SFM, feed per tooth, feed rate
``v_f = f_z z n``) and checks them against the range of the project's table
(``substructure/data/cutting_data.toml``, per work material and tool
material: carbide or HSS) or a user's table in the same format.  Outside
the range :func:`check_cutting` returns the reasons and the commands warn
(:class:`CuttingDataWarning`); nothing is clipped: the stability result
stands, and the machinist decides.

The table's ranges are assumed ranges of the published orders of magnitude
(each row names what it follows), not measurements; see
``docs/machinist.md``.
"""

from __future__ import annotations

import importlib.resources
from typing import Any

import attrs
import numpy as np
import pint

from .._toml import TomlDocument, loads_toml, read_toml
from ..errors import InvalidValueError, SubstructureWarning
from ..units import quantity

__all__ = ["CuttingData", "CuttingDataWarning", "cutting_data", "load_cutting_data", "cutting_conditions",
           "check_cutting", "TOOL_MATERIALS", "M_PER_MIN_TO_SFM"]

TOOL_MATERIALS = ("carbide", "hss")
"""Tool materials of the table: solid cemented carbide and high-speed steel."""

M_PER_MIN_TO_SFM = 1.0 / 0.3048
"""Surface feet per minute in one metre per minute (1 ft = 0.3048 m)."""

_KEYS = ("workpiece", "tool_material", "cutting_speed", "feed_per_tooth", "default_feed_per_tooth", "source")


class CuttingDataWarning(SubstructureWarning):
    """A recommended cutting speed or feed per tooth outside the table's range for the work and tool material."""


def _pair(field: str, dimension: str):
    def convert(value: Any) -> tuple:
        if isinstance(value, str) or len(value) != 2:
            raise InvalidValueError(f"{field}: got {value!r}; expected [LOW, HIGH] with units, e.g. "
                                    "[\"80 m/min\", \"250 m/min\"]")
        lo, hi = (quantity(v, field, dimension) for v in value)
        if not 0 < lo.m_as(_SI[dimension]) < hi.m_as(_SI[dimension]):
            raise InvalidValueError(f"{field}: got {value!r}; expected 0 < LOW < HIGH")
        return lo, hi

    return convert


_SI = {"[length] / [time]": "m/min", "[length]": "mm"}


def _tool_material(value: Any) -> str:
    key = str(value).strip().lower().replace("-", "").replace(" ", "")
    key = {"hssco": "hss", "highspeedsteel": "hss", "cementedcarbide": "carbide", "solidcarbide": "carbide"}.get(key,
                                                                                                                key)
    if key not in TOOL_MATERIALS:
        raise InvalidValueError(f"tool_material: got {value!r}; expected one of {', '.join(TOOL_MATERIALS)}")
    return key


@attrs.frozen
class CuttingData:
    """The usual range of cutting speed and feed per tooth of one work material with one tool material.

    Parameters
    ----------
    workpiece : str
        The work material's name in the coefficient table (``"steel-1045"``).
    tool_material : {"carbide", "hss"}
        Solid carbide or high-speed steel.
    cutting_speed : (quantity, quantity)
        Lowest and highest cutting speed (surface speed), e.g. ``("80 m/min", "250 m/min")``.
    feed_per_tooth : (quantity, quantity)
        Lowest and highest feed per tooth [length].
    default_feed_per_tooth : quantity
        The feed per tooth used when none is given [length].
    source : str
        What the range follows, and whether it is measured, copied or assumed.
    """

    workpiece: str
    tool_material: str = attrs.field(converter=_tool_material)
    cutting_speed: tuple = attrs.field(converter=_pair("cutting_speed", "[length] / [time]"))
    feed_per_tooth: tuple = attrs.field(converter=_pair("feed_per_tooth", "[length]"))
    default_feed_per_tooth: pint.Quantity = attrs.field(
        converter=lambda v: quantity(v, "default_feed_per_tooth", "[length]"))
    source: str = ""

    def __attrs_post_init__(self) -> None:
        if not self.source.strip():
            raise InvalidValueError(f"cutting data of {self.workpiece!r}: source is missing; every row names it")
        lo, hi = (q.m_as("mm") for q in self.feed_per_tooth)
        if not lo <= self.default_feed_per_tooth.m_as("mm") <= hi:
            raise InvalidValueError(f"default_feed_per_tooth: {self.default_feed_per_tooth:~P} is outside the "
                                    f"row's feed_per_tooth range")

    @property
    def speed_range_m_per_min(self) -> tuple[float, float]:
        """``(low, high)`` cutting speed in m/min."""
        return tuple(float(q.m_as("m/min")) for q in self.cutting_speed)

    @property
    def feed_range_m(self) -> tuple[float, float]:
        """``(low, high)`` feed per tooth in m."""
        return tuple(float(q.m_as("m")) for q in self.feed_per_tooth)

    def to_json(self) -> dict:
        """The row in numbers.

        Returns
        -------
        dict
            ``workpiece``, ``tool_material``, ``cutting_speed_m_per_min`` and ``feed_per_tooth_m``
            (``[low, high]``), ``default_feed_per_tooth_m``, ``source``.
        """
        return {"workpiece": self.workpiece, "tool_material": self.tool_material,
                "cutting_speed_m_per_min": list(self.speed_range_m_per_min),
                "feed_per_tooth_m": list(self.feed_range_m),
                "default_feed_per_tooth_m": float(self.default_feed_per_tooth.m_as("m")), "source": self.source}


def _parse(doc: TomlDocument) -> tuple[CuttingData, ...]:
    out = []
    for i, row in enumerate(doc.tables("cutting", _KEYS, _KEYS)):
        try:
            out.append(CuttingData(**row))
        except (InvalidValueError, TypeError, ValueError) as exc:
            raise doc.wrap(["cutting", i], str(exc)) from None
    return tuple(out)


def load_cutting_data(path: Any = None) -> tuple[CuttingData, ...]:
    """Read a table of cutting data (TOML, ``[[cutting]]`` tables); the project's without a path.

    Parameters
    ----------
    path : str or path-like, optional
        A user's table; default the project's ``substructure/data/cutting_data.toml``.

    Returns
    -------
    tuple of CuttingData
        Its rows, in file order.

    Raises
    ------
    FileFormatError
        Naming the file, the row and the key.
    """
    if path is None:
        resource = importlib.resources.files("substructure") / "data" / "cutting_data.toml"
        return _parse(loads_toml(resource.read_text(encoding="utf-8"), "cutting_data.toml"))
    return _parse(read_toml(path, "cutting-data table"))


def cutting_data(workpiece: Any, tool_material: str = "carbide", table: Any = None) -> CuttingData | None:
    """The row for a work material and a tool material, or None when no table has one.

    Parameters
    ----------
    workpiece : Workpiece or str
        The work material (its ``name`` is looked up; a string goes through
        :func:`~substructure.stability.workpiece` first, so aliases work).
    tool_material : {"carbide", "hss"}, default "carbide"
        The tool's material.
    table : path, optional
        A user table searched first.

    Returns
    -------
    CuttingData or None
        The first row for both.
    """
    from .workpieces import workpiece as lookup

    if not isinstance(workpiece, str) and not hasattr(workpiece, "name"):
        raise InvalidValueError(f"workpiece: got {workpiece!r}; expected a workpiece's name or a Workpiece")
    name = (lookup(workpiece) if isinstance(workpiece, str) else workpiece).name
    tool = _tool_material(tool_material)
    rows = (list(load_cutting_data(table)) if table is not None else []) + list(load_cutting_data())
    return next((r for r in rows if r.workpiece == name and r.tool_material == tool), None)


def cutting_conditions(cut: Any, speed_rpm: Any, data: CuttingData | None = None) -> dict:
    """The shop's numbers of a milling cut at spindle speeds, and whether they lie in the table's range.

    Parameters
    ----------
    cut : MillingCut
        Its diameter, teeth and (optional) feed per tooth.
    speed_rpm : float or array_like
        Spindle speeds [rpm].
    data : CuttingData, optional
        The range to check against.

    Returns
    -------
    dict
        ``cutting_speed_m_per_min`` (``pi D n``), ``cutting_speed_sfm``,
        ``feed_per_tooth_m`` (None without one), ``feed_rate_m_per_min``
        (``f_z z n``, None without a feed), and with ``data``:
        ``speed_in_range``, ``feed_in_range`` (None without a feed) and the
        row (``range``).  Floats for a scalar speed, arrays otherwise.
    """
    n = np.asarray(speed_rpm, dtype=float)
    d = float(cut.diameter.m_as("m"))
    vc = np.pi * d * n
    fz = None if cut.feed_per_tooth is None else float(cut.feed_per_tooth.m_as("m"))
    scalar = n.ndim == 0

    def out(v):
        return float(v) if scalar else v

    result = {"cutting_speed_m_per_min": out(vc), "cutting_speed_sfm": out(vc * M_PER_MIN_TO_SFM),
              "feed_per_tooth_m": fz, "feed_rate_m_per_min": None if fz is None else out(fz * cut.teeth * n)}
    if data is not None:
        lo, hi = data.speed_range_m_per_min
        inside = (vc >= lo * (1 - 1e-12)) & (vc <= hi * (1 + 1e-12))
        result["speed_in_range"] = bool(inside) if scalar else inside
        flo, fhi = data.feed_range_m
        result["feed_in_range"] = None if fz is None else bool(flo * (1 - 1e-12) <= fz <= fhi * (1 + 1e-12))
        result["range"] = data.to_json()
    return result


def check_cutting(cut: Any, speed_rpm: float, data: CuttingData | None) -> list[str]:
    """Why the cut at a spindle speed lies outside the table's range (empty when inside, or without a row).

    Parameters
    ----------
    cut : MillingCut
        The cut (diameter, teeth, feed per tooth).
    speed_rpm : float
        The spindle speed [rpm].
    data : CuttingData or None
        The range.

    Returns
    -------
    list of str
        One sentence per quantity outside its range, with the values, the
        range and its source.
    """
    if data is None:
        return []
    c = cutting_conditions(cut, float(speed_rpm), data)
    lo, hi = data.speed_range_m_per_min
    where = f"for {data.workpiece} with a {data.tool_material} tool ({data.source.split(';')[0]})"
    reasons = []
    vc = c["cutting_speed_m_per_min"]
    if not c["speed_in_range"]:
        side = "above" if vc > hi else "below"
        reasons.append(f"cutting speed {vc:.0f} m/min ({vc * M_PER_MIN_TO_SFM:.0f} SFM) at {speed_rpm:.0f} rpm with "
                       f"D = {cut.diameter.to('mm'):~.4g} is {side} the usual {lo:.0f} to {hi:.0f} m/min {where}")
    if c["feed_in_range"] is False:
        flo, fhi = data.feed_range_m
        fz = c["feed_per_tooth_m"]
        side = "above" if fz > fhi else "below"
        reasons.append(f"feed per tooth {fz * 1e3:.3g} mm is {side} the usual {flo * 1e3:.3g} to {fhi * 1e3:.3g} mm "
                       f"{where}")
    return reasons
