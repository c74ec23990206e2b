"""Timoshenko cross-sections: bending and shear stiffness, mass and rotary inertia per length.

The section physics of the exact beam model (docs/beams.md): :class:`Section`
holds the four SI numbers a uniform segment needs (``EI``, ``kappa G A``,
``rho A``, ``rho I``), :func:`shear_coefficient` gives Cowper's (1966) shear
coefficient of a hollow circular section,
``kappa = 6(1+nu)(1+m^2)^2 / ((7+6nu)(1+m^2)^2 + (20+12nu)m^2)``, ``m = id/od``
(0.886 for a solid steel section), and :class:`Insert` and :class:`Flutes`
describe what fills a bore and what a fluted length is.  A composite section
(a bore filled by an ``Insert``) sums ``EI``, ``kappa G A``, ``rho A`` and
``rho I`` over its layers, each with its own ``kappa``.  A fluted length is a
solid section of the equivalent diameter ``diameter_ratio * od`` for both
stiffness and mass.  :class:`~substructure.beams.Segment` builds its section
from these; the names are also importable from :mod:`substructure.beams`.
"""

from __future__ import annotations

import math

import attrs
import numpy as np
import pint

from .errors import InvalidValueError
from .materials import Material, get_material
from .units import dimensionless, magnitude_in, quantity, ureg

__all__ = ["Section", "Insert", "Flutes", "shear_coefficient"]


SIZE_RANGE_M = (1e-6, 1e3)
"""Lengths and diameters of sections and segments [m]: 1 um to 1 km, the range the beam model is made
for (outside it a wrong unit is far more likely than a real part, and the closed forms overflow)."""


def _length(field: str, *, allow_zero: bool = False):
    def convert(value) -> pint.Quantity:
        q = quantity(value, field, "[length]")
        if not np.isfinite(q.magnitude) or q.magnitude < 0 or (q.magnitude == 0 and not allow_zero):
            expected = "a length >= 0" if allow_zero else "a positive length"
            raise InvalidValueError(f"{field}: got {value!r}; expected {expected}")
        if q.magnitude != 0:
            metres = magnitude_in(q, "m")
            if not SIZE_RANGE_M[0] <= metres <= SIZE_RANGE_M[1]:
                raise InvalidValueError(f"{field}: got {value!r}; expected a length from 1 um to 1 km "
                                        "(the range of the beam model): check the unit")
        return q

    return convert


_METRE = ureg.Unit("m")


def _metres(value, field: str) -> pint.Quantity:
    """A float in metres as a quantity (no text parsed); bare numbers only."""
    if isinstance(value, bool) or not isinstance(value, (int, float, np.floating, np.integer)):
        raise InvalidValueError(f"{field}: got {value!r}; expected a number of metres")
    return ureg.Quantity(float(value), _METRE)


def _material(value: Material | str) -> Material:
    if isinstance(value, Material):
        return value
    if isinstance(value, str):
        return get_material(value)
    raise InvalidValueError(
        f"material: got {value!r}; expected a Material or a catalogue name (steel, carbide, aluminium)"
    )


def shear_coefficient(nu: float, ratio: float = 0.0) -> float:
    """Cowper's (1966) shear coefficient of a hollow circular section.

    Parameters
    ----------
    nu : float
        Poisson ratio.
    ratio : float
        Inner to outer diameter, ``m = id / od`` (0 for a solid section).

    Returns
    -------
    float
        The shear coefficient kappa (dimensionless).
    """
    m2 = ratio * ratio
    a = (1.0 + m2) ** 2
    return 6.0 * (1.0 + nu) * a / ((7.0 + 6.0 * nu) * a + (20.0 + 12.0 * nu) * m2)


@attrs.frozen
class Section:
    """Section properties of a segment in SI units (complex with loss factor).

    Parameters
    ----------
    EI : complex
        Bending stiffness [N m^2].
    kGA : complex
        Shear stiffness ``kappa G A`` [N].
    rhoA : float
        Mass per length [kg/m].
    rhoI : float
        Rotary inertia per length [kg m].
    """

    # each an ndarray over configurations in the stacked sections of the batched kernels (_chains)
    EI: complex | np.ndarray
    kGA: complex | np.ndarray
    rhoA: float | np.ndarray
    rhoI: float | np.ndarray

    def __add__(self, other: "Section") -> "Section":
        return Section(self.EI + other.EI, self.kGA + other.kGA, self.rhoA + other.rhoA, self.rhoI + other.rhoI)

    @classmethod
    def ring(cls, od: float, id: float, material: Material) -> "Section":
        """A circular ring of one material (``id = 0`` for a solid circle), SI inputs.

        Parameters
        ----------
        od : float
            Outer diameter in m.
        id : float
            Inner diameter in m (0 for a solid circle).
        material : Material
            The material.

        Returns
        -------
        Section
            The section properties, SI.
        """
        area = math.pi / 4.0 * (od**2 - id**2)
        inertia = math.pi / 64.0 * (od**4 - id**4)
        kappa = shear_coefficient(material.nu, id / od)
        return cls(
            EI=material.E_si * inertia,
            kGA=kappa * material.G_si * area,
            rhoA=material.rho_si * area,
            rhoI=material.rho_si * inertia,
        )


@attrs.frozen
class Insert:
    """A concentric body filling a segment's bore, e.g. the tool shank in a holder.

    Parameters
    ----------
    od : quantity or str
        Outer diameter of the insert; at most the bore (``id``) of its segment.
    material : Material or str
        The insert's material (a catalogue name such as ``"carbide"``).
    id : quantity or str, default "0 mm"
        Inner diameter of the insert (0 for a solid shank).
    """

    od: pint.Quantity = attrs.field(converter=_length("insert.od"))  # type: ignore[misc]  # attrs plugin: converter factory
    material: Material = attrs.field(converter=_material)
    id: pint.Quantity = attrs.field(default="0 mm", converter=_length("insert.id", allow_zero=True))  # type: ignore[misc]  # attrs plugin: converter factory
    _si: tuple = attrs.field(init=False, eq=False, repr=False)

    def __attrs_post_init__(self) -> None:
        od, id_ = magnitude_in(self.od, "m"), magnitude_in(self.id, "m")
        if id_ >= od:
            raise InvalidValueError(
                f"insert.id: got {self.id:~P} with insert.od {self.od:~P}; expected id < od"
            )
        object.__setattr__(self, "_si", (od, id_))

    @property
    def od_m(self) -> float:
        """Outer diameter in metres."""
        return self._si[0]

    @property
    def id_m(self) -> float:
        """Inner diameter in metres."""
        return self._si[1]


def _ratio(value) -> float:
    r = dimensionless(value, "flutes.diameter_ratio")
    if not 0.0 < r <= 1.0:
        raise InvalidValueError(f"flutes.diameter_ratio: got {value!r}; expected a ratio in (0, 1]")
    return r


@attrs.frozen
class Flutes:
    """Fluted length of a tool, modelled by an equivalent solid diameter.

    The fluted section is a circle of diameter ``diameter_ratio * od`` for
    both its stiffness and its mass (0.8 is a common value for two- to
    four-flute end mills).

    Parameters
    ----------
    diameter_ratio : float
        Equivalent diameter over the outer diameter, in (0, 1] (dimensionless).
    """

    diameter_ratio: float = attrs.field(converter=_ratio)
