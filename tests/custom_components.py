"""Two component types of a user's own (test helper), as docs/extending.md writes them.

``NutChuck``: a collet chuck (a :class:`Holder` subclass) whose clamping nut is
a rigid body at its tip, its own numbers ``nut_mass`` and ``nut_inertia``; its
receptances are the beam's with the nut added by structural modification.
It is not a plain beam, so every workflow must go through its
``receptance_matrix``.

``LumpedChuck``: not a beam at all, a chuck as a two-node lumped model (a
shank mass and a nose mass on a spring, each with a rotary inertia), with
points ``base`` and ``tip``; its receptances are the inverse of its dynamic
stiffness matrix, which has no rigid-body constraint (free-free, like every
component).  It names its parameters itself through ``parameters()``.
"""

from __future__ import annotations

import attrs
import numpy as np
import pint

from substructure import Holder
from substructure.components import ComponentParameter
from substructure.errors import InvalidValueError, UnknownPointError
from substructure.points import parse_point
from substructure.units import quantity


def _non_negative(field, dimension):
    def convert(value):
        q = quantity(value, field, dimension)
        if not q.magnitude >= 0:
            raise InvalidValueError(f"{field}: got {value!r}; expected a value >= 0")
        return q
    return convert


@attrs.frozen
class NutChuck(Holder):
    """A collet chuck whose clamping nut is a rigid body at its tip."""

    nut_mass: pint.Quantity = attrs.field(default="150 g", kw_only=True, converter=_non_negative("nut_mass", "[mass]"))
    nut_inertia: pint.Quantity = attrs.field(default="0 kg*m^2", kw_only=True,
                                             converter=_non_negative("nut_inertia", "[mass] * [length] ** 2"))

    def receptance_matrix(self, refs, frequency_hz):
        f = np.asarray(frequency_hz, dtype=float)
        tip = [i for i, r in enumerate(refs) if self.position(r) >= self.length_m * (1 - 1e-12)]
        points = list(refs) if tip else [*refs, parse_point(f"{self.name}.tip", allow_dof=False)]
        h = super().receptance_matrix(points, f)                         # the plain beam, (2q, 2q, n)
        w2 = (2 * np.pi * f) ** 2
        z = (-w2 * self.nut_mass.m_as("kg"), -w2 * self.nut_inertia.m_as("kg*m^2"))  # -omega^2 diag(m, J)
        t = 2 * (tip[0] if tip else len(refs))
        # a body at the tip, by structural modification: H - H[:, t] Z (I + H[t, t] Z)^-1 H[t, :],
        # the 2x2 inverse written out, every line at once
        a = [[1 + h[t, t] * z[0], h[t, t + 1] * z[1]], [h[t + 1, t] * z[0], 1 + h[t + 1, t + 1] * z[1]]]
        det = a[0][0] * a[1][1] - a[0][1] * a[1][0]
        inv = [[a[1][1] / det, -a[0][1] / det], [-a[1][0] / det, a[0][0] / det]]
        p = 2 * len(refs)
        out = h[:p, :p].copy()
        for i in range(2):
            for j in range(2):
                g = z[i] * inv[i][j]
                out -= h[:p, t + i][:, None] * g * h[t + j, :p][None, :]
        return out


@attrs.frozen
class LumpedChuck:
    """A chuck as two lumped bodies on a beam-like spring (shank at ``base``, nose at ``tip``)."""

    name: str
    shank_mass: float = attrs.field(default=1.2, kw_only=True)      # kg
    nose_mass: float = attrs.field(default=0.4, kw_only=True)       # kg
    shank_inertia: float = attrs.field(default=6e-4, kw_only=True)  # kg m^2
    nose_inertia: float = attrs.field(default=1.5e-4, kw_only=True)  # kg m^2
    k_y: float = attrs.field(default=2.0e8, kw_only=True)           # N/m, shear of the spring
    k_theta: float = attrs.field(default=2.0e5, kw_only=True)       # N m/rad, bending of the spring
    length: float = attrs.field(default=0.06, kw_only=True)         # m, between the two nodes
    loss_factor: float = attrs.field(default=0.01, kw_only=True)
    kind = "test-lumped-chuck"

    def __attrs_post_init__(self):
        for field in attrs.fields(type(self))[1:]:
            value = getattr(self, field.name)
            if not (isinstance(value, (int, float)) and np.isfinite(value) and value > 0):
                raise InvalidValueError(f"{field.name}: got {value!r}; expected a positive number")

    @property
    def component_names(self):
        return (self.name,)

    def node_key(self, ref):
        if ref.component != self.name or ref.where not in ("base", "tip"):
            raise UnknownPointError(f"point {ref}: {self.name!r} has points base and tip")
        return ref.where

    def parameters(self):
        return tuple(ComponentParameter(n, u, getattr(self, n), 0.1 * getattr(self, n), 10 * getattr(self, n),
                                        True, f"{n.replace('_', ' ')} of {self.name}")
                     for n, u in (("nose_mass", "kg"), ("k_y", "N/m"), ("k_theta", "N*m/rad")))

    @classmethod
    def from_toml(cls, table, materials, key):
        fields = {f.name for f in attrs.fields(cls)} - {"name"}
        unknown = set(table) - fields - {"name", "type"}
        if unknown:
            raise InvalidValueError(f"{key}: unknown keys {sorted(unknown)}")
        return cls(table["name"], **{k: float(v) for k, v in table.items() if k in fields})

    def to_toml(self):
        return {f.name: getattr(self, f.name) for f in attrs.fields(type(self))[1:]}

    def stiffness(self):
        """The 4x4 stiffness of the spring between the nodes (a beam element's, with k_y and k_theta)."""
        L, ky, kt = self.length, self.k_y, self.k_theta
        # shear spring k_y between the displacements; bending k_theta between the slopes; the lever of L
        a = np.array([[1.0, L / 2, -1.0, L / 2]])
        b = np.array([[0.0, 1.0, 0.0, -1.0]])
        return ky * a.T @ a + kt * b.T @ b

    def receptance_matrix(self, refs, frequency_hz):
        f = np.asarray(frequency_hz, dtype=float)
        w2 = (2 * np.pi * f) ** 2
        m = np.diag([self.shank_mass, self.shank_inertia, self.nose_mass, self.nose_inertia])
        z = (self.stiffness() * (1 + 1j * self.loss_factor))[:, :, None] - m[:, :, None] * w2
        h = np.moveaxis(np.linalg.inv(np.moveaxis(z, -1, 0)), 0, -1)
        idx = [i for r in refs for i in ((0, 1) if self.node_key(r) == "base" else (2, 3))]
        return h[np.ix_(idx, idx)]
