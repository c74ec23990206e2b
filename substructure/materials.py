"""Materials: elastic constants, density and loss factor, with a catalogue.

A :class:`Material` is a frozen value object; the catalogue holds typical
values for the materials of spindles, holders and tools.  Files and users may
define their own (``Material("bronze", E="110 GPa", nu=0.34, rho="8800 kg/m^3")``).

The loss factor ``eta`` makes both moduli complex, ``E(1 + i*eta)`` and
``G(1 + i*eta)`` (conventions.md, time-harmonic convention).
"""

from __future__ import annotations

import attrs
import pint

from .errors import InvalidValueError
from .units import dimensionless, quantity

__all__ = ["Material", "CATALOG", "get_material", "steel", "carbide", "aluminium", "E_RANGE", "RHO_RANGE",
           "LOSS_FACTOR_MAX"]


E_RANGE = (1e3, 1e13)
"""Young's moduli the beam model computes right [Pa] (1 kPa to 10 TPa): beyond them its products overflow or
vanish in floating point."""
RHO_RANGE = (0.1, 1e5)
"""Densities the beam model computes right [kg/m^3]."""
LOSS_FACTOR_MAX = 10.0
"""The largest structural loss factor taken (a material's ``eta``; 0.5 is already a very lossy polymer)."""


def _positive(value, field: str, dimension: str, what: str, si: str = "", within: tuple = (0.0, float("inf")),
              shown: str = "") -> pint.Quantity:
    q = quantity(value, field, dimension)
    if q.magnitude <= 0:
        raise InvalidValueError(f"{field}: got {value!r}; expected a positive {what}")
    if si and not within[0] <= q.m_as(si) <= within[1]:
        raise InvalidValueError(f"{field}: got {value!r}; expected a {what} {shown} (beyond, the beam model's "
                                "numbers overflow or vanish)")
    return q


def _poisson(value) -> float:
    nu = dimensionless(value, "nu")
    if not -1.0 < nu < 0.5:
        raise InvalidValueError(f"nu: got {value!r}; expected a Poisson ratio in (-1, 0.5)")
    return nu


def _loss(value) -> float:
    eta = dimensionless(value, "loss_factor")
    if eta < 0:
        raise InvalidValueError(
            f"loss_factor: got {value!r}; expected a loss factor >= 0 (a negative one adds energy)"
        )
    if not eta <= LOSS_FACTOR_MAX:
        raise InvalidValueError(f"loss_factor: got {value!r}; expected a loss factor of at most {LOSS_FACTOR_MAX:g}")
    return eta


def _name(value) -> str:
    if not isinstance(value, str) or not value.strip():
        raise InvalidValueError(f"name: got {value!r}; expected a non-empty string")
    return value


@attrs.frozen
class Material:
    """An isotropic, linear viscoelastic material.

    Parameters
    ----------
    name : str
        Name used in files and messages.
    E : quantity or str
        Young's modulus, e.g. ``"210 GPa"``; from 1 kPa to 10 TPa (``E_RANGE``).
    nu : float
        Poisson ratio, in (-1, 0.5).
    rho : quantity or str
        Density, e.g. ``"7850 kg/m^3"``; from 0.1 to 1e5 kg/m^3 (``RHO_RANGE``).
    loss_factor : float, default 0
        Structural (hysteretic) loss factor, ``0 <= eta <= 10`` (``LOSS_FACTOR_MAX``).

    Notes
    -----
    Values outside these ranges are refused: the beam model's numbers overflow
    or vanish there, and such a value is a wrong unit or a typo.
    """

    name: str = attrs.field(converter=_name)
    E: pint.Quantity = attrs.field(
        converter=lambda v: _positive(v, "E", "[mass] / [length] / [time] ** 2", "Young's modulus", "Pa", E_RANGE,
                                      "from 1 kPa to 10 TPa"))
    nu: float = attrs.field(converter=_poisson)
    rho: pint.Quantity = attrs.field(converter=lambda v: _positive(v, "rho", "[mass] / [length] ** 3", "density",
                                                                   "kg/m^3", RHO_RANGE, "from 0.1 to 1e5 kg/m^3"))
    loss_factor: float = attrs.field(default=0.0, converter=_loss)
    # SI values, derived once (every section of every beam variant needs them)
    _si: tuple = attrs.field(init=False, eq=False, repr=False)

    def __attrs_post_init__(self) -> None:
        damping = 1.0 + 1j * self.loss_factor
        object.__setattr__(
            self, "_si", (self.E.m_as("Pa") * damping, self.G.m_as("Pa") * damping, self.rho.m_as("kg/m^3"))
        )

    @property
    def G(self) -> pint.Quantity:
        """Shear modulus ``E / (2 (1 + nu))``."""
        return self.E / (2.0 * (1.0 + self.nu))

    @property
    def E_si(self) -> complex:
        """Complex Young's modulus ``E (1 + i eta)`` in Pa."""
        return self._si[0]

    @property
    def G_si(self) -> complex:
        """Complex shear modulus ``G (1 + i eta)`` in Pa."""
        return self._si[1]

    @property
    def rho_si(self) -> float:
        """Density in kg/m^3."""
        return self._si[2]

    @classmethod
    def from_catalog(cls, name: str) -> "Material":
        """The catalogue material called ``name`` (see :data:`CATALOG`).

        Parameters
        ----------
        name : str
            ``"steel"``, ``"carbide"`` or ``"aluminium"``.

        Returns
        -------
        Material
            The material.
        """
        return get_material(name)


steel = Material("steel", E="210 GPa", nu=0.29, rho="7850 kg/m^3", loss_factor=0.002)
"""Tool and spindle steel."""
carbide = Material("carbide", E="580 GPa", nu=0.22, rho="14500 kg/m^3", loss_factor=0.002)
"""Cemented tungsten carbide (end mills)."""
aluminium = Material("aluminium", E="70 GPa", nu=0.33, rho="2700 kg/m^3", loss_factor=0.001)
"""Aluminium alloy."""

CATALOG: dict[str, Material] = {m.name: m for m in (steel, carbide, aluminium)}
"""Built-in materials by name.  Read-only by convention: pass custom ones explicitly."""


def get_material(name: str, extra: dict[str, Material] | None = None) -> Material:
    """Look a material up by name, first in ``extra`` then in the catalogue.

    Parameters
    ----------
    name : str
        The material's name.
    extra : dict of str to Material, optional
        Custom materials, looked up first.

    Returns
    -------
    Material
        The material (E and G in Pa, rho in kg/m^3).

    Raises
    ------
    InvalidValueError
        For an unknown name (the message lists the known ones).
    """
    if not isinstance(name, str):
        raise InvalidValueError(f"material: got {name!r}; expected the name of a material (a text)")
    if extra and name in extra:
        return extra[name]
    if name in CATALOG:
        return CATALOG[name]
    known = sorted(set(CATALOG) | set(extra or {}))
    raise InvalidValueError(f"material: unknown material {name!r}; known: {', '.join(known)}")
