"""What a study computes and on which grids: :class:`Compute` and :class:`Grid`.

Settings shared by every combination of a study (the tool point, the
stability methods, the recommendation's margin, the band of a predicted
joint, the figures; the frequency lines and spindle speeds), checked when
they are made, so that a wrong setting stops the study before any work.
"""

from __future__ import annotations

import re
from collections.abc import Mapping
from typing import Any

import attrs

from ..errors import InvalidValueError, SubstructureError
from ..units import items_of
from .spec import plain

__all__ = ["Compute", "Grid", "METHODS"]

#: The stability methods: zero order and semi-discretization.
METHODS = ("zoa", "sdm")


def _methods(value: Any) -> tuple[str, ...]:
    value = (value,) if isinstance(value, str) else tuple(items_of(value, "lobes", "methods, zoa and/or sdm"))
    for m in value:
        if not isinstance(m, str) or m not in METHODS:
            raise InvalidValueError(f"lobes: got {m!r}; expected zoa and/or sdm")
    if len(set(value)) != len(value):
        raise InvalidValueError(f"lobes: got {list(value)!r}; a method given twice")
    return value


def _fraction(field: str, lo: float, hi: float):
    def convert(value: Any) -> float:
        if isinstance(value, bool) or not isinstance(value, (int, float)) or not lo <= value < hi:
            raise InvalidValueError(f"{field}: got {value!r}; expected a number in [{lo:g}, {hi:g})")
        return float(value)

    return convert


def _quantiles(value: Any) -> tuple[float, ...]:
    try:
        q = tuple(float(v) for v in value if not isinstance(v, bool))
    except (TypeError, ValueError, OverflowError):
        q = ()
    if len(q) < 2 or len(q) != len(value) or any(not 0 < v < 1 for v in q) or list(q) != sorted(set(q)):
        raise InvalidValueError(f"quantiles: got {value!r}; expected two or more increasing probabilities in (0, 1), "
                                "e.g. [0.025, 0.5, 0.975]")
    return q


def _count(field: str, lo: int, hi: int):
    def convert(value: Any) -> int:
        if isinstance(value, bool) or not isinstance(value, int) or not lo <= value <= hi:
            raise InvalidValueError(f"{field}: got {value!r}; expected a whole number from {lo} to {hi}")
        return value

    return convert


def _flag(field: str):
    def convert(value: Any) -> bool:
        if not isinstance(value, bool):
            raise InvalidValueError(f"{field}: got {value!r}; expected true or false")
        return value

    return convert


@attrs.frozen
class Compute:
    """What a study computes for each combination.

    Parameters
    ----------
    at : str, default "tool.tip"
        The tool point (translational DOF, ``y`` by default).
    lobes : sequence of {"zoa", "sdm"}, default ("zoa",)
        Stability lobes by the zero-order approximation and/or
        semi-discretization (modes fitted to the FRF); empty: the FRF only.
    recommend : bool, default True
        The recommended speed and depth per cut (from semi-discretization
        when it is computed, else from the zero order).
    band : bool, default True
        With a predicted joint: the FRF envelope, the tool mode's band and
        lobes over the prediction's quantiles, so that the recommendation's
        margin holds over the band.
    samples : int, default 32
        Samples of the prediction for the FRF envelope (figures).
    quantiles : sequence of float, default (0.025, 0.5, 0.975)
        Quantiles of the predicted joint (every predicted parameter at the
        same quantile) whose FRFs and lobes make the band.
    margin : float, default 0.2
        Fraction of the stability limit kept in reserve.
    speed_tolerance : float, default 0.03
        The speed window ``n (1 +- x)`` that must stay stable.
    figures : bool, default True
        A figure per combination (the summary figure that ranks them is
        always drawn when the study has an output directory).
    frf_files : bool, default False
        Write each tool point FRF as a CSV file.
    """

    at: str = "tool.tip"
    lobes: tuple = attrs.field(default=("zoa",), converter=_methods)
    recommend: bool = attrs.field(default=True, converter=_flag("recommend"))
    band: bool = attrs.field(default=True, converter=_flag("band"))
    samples: int = attrs.field(default=32, converter=_count("samples", 2, 10_000))
    quantiles: tuple = attrs.field(default=(0.025, 0.5, 0.975), converter=_quantiles)
    margin: float = attrs.field(default=0.2, converter=_fraction("margin", 0.0, 1.0))
    speed_tolerance: float = attrs.field(default=0.03, converter=_fraction("speed_tolerance", 0.0, 0.5))
    figures: bool = attrs.field(default=True, converter=_flag("figures"))
    frf_files: bool = attrs.field(default=False, converter=_flag("frf_files"))

    def __attrs_post_init__(self) -> None:
        from ..points import parse_point

        ref = parse_point(self.at)
        if ref.dof == "theta":
            raise InvalidValueError(f"at: got {self.at!r}; the tool point needs a translational DOF (':y')")
        if self.recommend and not self.lobes:
            raise InvalidValueError("recommend: a recommendation needs lobes (lobes = ['zoa'])")

    @property
    def point(self) -> str:
        """The tool point with its DOF, e.g. ``"tool.tip:y"``."""
        return self.at if ":" in self.at else f"{self.at}:y"

    @property
    def recommend_method(self) -> str | None:
        """The method whose lobes the recommendation uses: ``"sdm"`` when computed, else ``"zoa"``."""
        return None if not self.lobes else ("sdm" if "sdm" in self.lobes else "zoa")


def _range(field: str, kind: str):
    def convert(value: Any) -> tuple | None:
        if value is None:
            return None
        if isinstance(value, Mapping):
            unknown = [k for k in value if k not in ("start", "stop", "step")]
            if unknown:
                raise InvalidValueError(f"{field}.{unknown[0]}: unknown key; expected start, stop, step")
            missing = [k for k in ("start", "stop", "step") if k not in value]
            if missing:
                raise InvalidValueError(f"{field}.{missing[0]}: missing; a grid is start, stop and step")
            value = (value["start"], value["stop"], value["step"])
        if not isinstance(value, (list, tuple)) or len(value) != 3:
            raise InvalidValueError(f"{field}: got {value!r}; expected start, stop and step with units")
        value = tuple(plain(v, field) for v in value)
        try:
            if kind == "frequency":
                from ..frf import Frequency

                Frequency.from_range(*value)
            else:
                from ..stability import spindle_speeds

                spindle_speeds(*value)
        except SubstructureError as exc:  # "step: ..." is speeds.step of the grid
            message = " ".join(str(exc).split())
            sub = re.match(r"(start|stop|step)\b", message)
            raise InvalidValueError(f"{field}.{message}" if sub else f"{field}: {message}") from None
        return value

    return convert


@attrs.frozen
class Grid:
    """The grids of a study: frequency lines and spindle speeds.

    Parameters
    ----------
    frequency : mapping or (start, stop, step), optional
        Frequency lines with units; default each machine's ``[frequency]``.
    speeds : mapping or (start, stop, step), default 2000 to 24000 rpm by 50 rpm
        Spindle speeds in rpm for the lobes.
    sdm_speeds : mapping or (start, stop, step), optional
        Speeds for semi-discretization (each costs a run of its own); default
        ``speeds``.
    """

    frequency: tuple | None = attrs.field(default=None, converter=_range("frequency", "frequency"))
    speeds: tuple = attrs.field(default=("2000 rpm", "24000 rpm", "50 rpm"), converter=_range("speeds", "speeds"))
    sdm_speeds: tuple | None = attrs.field(default=None, converter=_range("sdm_speeds", "speeds"))
