"""The keys of an assembly file, shared by the reader and the writer.

The allowed keys of every table (top level, frequency, materials,
components, segments, inserts, flutes, joints, supports, sensors, masses and
the joint matrices), and the fields of a component class that its table
holds: the generic ``name``/``segments``/``description`` plus one key per
further init field of an attrs class.
"""

from __future__ import annotations

import attrs

from ...beams import MAX_TAPER_STEPS  # noqa: F401 (the limits of the beam model, named in the reader's errors)
from ...materials import E_RANGE, LOSS_FACTOR_MAX, RHO_RANGE
from ...sections import SIZE_RANGE_M  # noqa: F401

_TOP_KEYS = ("name", "frequency", "materials", "components", "joints", "supports", "sensors", "masses")
_FREQUENCY_KEYS = ("start", "stop", "step")
_MATERIAL_KEYS = ("E", "nu", "rho", "loss_factor")
_COMPONENT_KEYS = ("name", "type", "material", "segments", "description")
_CATALOG_KEYS = ("name", "type", "catalog")  # and the catalogue holder's parameters

_SEGMENT_KEYS = ("length", "od", "id", "material", "insert", "flutes", "od_tip", "id_tip", "taper_steps")
_INSERT_KEYS = ("od", "material", "id")
_FLUTES_KEYS = ("diameter_ratio",)
_JOINT_KEYS = ("name", "between", "k", "c", "rigid", "prior", "provenance", "source", "uncertainty")
_SUPPORT_KEYS = ("name", "at", "k", "c")
_SENSOR_KEYS = ("name", "at", "mass", "inertia", "always_on")
_MASS_KEYS = ("name", "at", "mass", "inertia")
_MATRIX_KEYS = ("yf", "ym", "tf", "tm")
_STANDARD_FIELDS = ("name", "segments", "description")

SIZE_OUTLIER = 20.0
"""A segment's diameter or length this many times the median of the file's, and over ``SIZE_OUTLIER_FLOOR_M`` of its
kind, is refused as a unit typo (``od = "12 m"`` for 12 mm): the largest parts of a spindle, holder or tool are a
few times the median, and a spindle is under a metre across."""

SIZE_OUTLIER_FLOOR_M = {"diameter": 1.0, "length": 5.0}
"""The size [m] below which a segment is never refused as an outlier (micro tools beside a spindle are a hundredth of
its diameter; many short steps of a taper make the median length small)."""

MACHINE_SIZE_M = {"diameter": 2.0, "length": 10.0}
"""Beyond these [m] (a diameter, a component's length) a file is warned of as written in m for mm, every size
alike (no size stands out of the others): no spindle, holder or tool is 2 m across or 10 m long, while
the beam model computes far larger structures right."""

# The values the beam and coupling models compute right (beyond them, results turn to NaN, overflow or noise):
# a value outside is a wrong unit or a typo.  key -> (SI unit, lowest, highest, the range in words)
PLAUSIBLE = {  # a material's as Material checks them, said at the file's key and line
    "E": ("Pa", *E_RANGE, "from 1 kPa to 10 TPa"),
    "rho": ("kg/m^3", *RHO_RANGE, "from 0.1 to 1e5 kg/m^3"),
    "loss_factor": ("", 0.0, LOSS_FACTOR_MAX, f"at most {LOSS_FACTOR_MAX:g}"),
    "mass": ("kg", 0.0, 1e6, "at most 1e6 kg"),
    "inertia": ("kg*m^2", 0.0, 1e6, "at most 1e6 kg*m^2"),
}
MAX_JOINT_ENTRY = 1e100
"""The largest magnitude of a joint's or support's k or c entry in SI units: beyond it the coupling's products
of entries overflow (a joint without flexibility is ``rigid = true``)."""


def _init_fields(cls) -> tuple[str, ...]:
    return tuple(f.name for f in attrs.fields(cls) if f.init) if attrs.has(cls) else _STANDARD_FIELDS


def _extra_fields(cls) -> tuple[str, ...]:
    """The init fields of a Beam subclass beyond ``name`` and ``segments``: one key each in its table."""
    return tuple(f for f in _init_fields(cls) if f not in _STANDARD_FIELDS)

