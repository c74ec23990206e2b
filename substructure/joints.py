"""Joints, sensors and supports: what connects components and what hangs on points.

* :class:`Joint` connects two points, rigidly or through the complex stiffness
  ``K = [[k_yf, k_ym], [k_tf, k_tm]] + i omega [[c_yf, c_ym], [c_tf, c_tm]]``
  acting on ``[y_a - y_b, theta_a - theta_b]`` (thesis eq. 2.5).
* :class:`Support` is the same matrix between a point and the ground
  (bearings, suspension bands).
* :class:`Sensor` is a rigid body on a point during a test: mass and rotary
  inertia, i.e. the dynamic stiffness ``-omega^2 diag(m, J)`` (thesis eq.
  5.2); a massless sensor stands for a laser vibrometer.
* :class:`Mass` is the same rigid body permanently on the structure (a
  clamping nut, a balancing ring): on in every test and in the cut.

All three give their dynamic stiffness as an array ``(2, 2, n_freq)``, which is
all the coupling engine asks of them: a new joint model is a class with
``name``, ``between``, ``rigid`` and ``dynamic_stiffness(frequency_hz)``.
"""

from __future__ import annotations

import warnings
from typing import Mapping

import attrs
import numpy as np
import pint

from ._blocks import angular_lines, at_decay, checked_block
from .errors import InvalidValueError, NonPassiveJointWarning, NonReciprocalWarning
from .points import check_name, parse_point
from .units import format_quantity, magnitude_in, quantity

__all__ = ["JointMatrix", "Joint", "JointProvenance", "PROVENANCE_KINDS", "Support", "Sensor", "Mass",
           "STIFFNESS_UNITS", "DAMPING_UNITS", "dynamic_stiffness"]

PROVENANCE_KINDS = ("identified", "predicted", "borrowed", "prior")
"""Where a joint's values come from: identified from a test of this assembly; predicted from a joint table
(with the prediction's uncertainty); borrowed from another holder or tool; a prior (a literature or assumed
value for this type of holder, with its source and a wide uncertainty)."""

ENTRIES = ("yf", "ym", "tf", "tm")
#: The SI unit of each stiffness entry: ``yf`` force per displacement, ``ym`` moment per
#: displacement, ``tf`` force per rotation, ``tm`` moment per rotation (thesis eq. 2.5).
STIFFNESS_UNITS = {"yf": "N/m", "ym": "N", "tf": "N/rad", "tm": "N*m/rad"}
#: The SI unit of each damping entry (the stiffness units times s).
DAMPING_UNITS = {"yf": "N*s/m", "ym": "N*s", "tf": "N*s/rad", "tm": "N*m*s/rad"}
_DIMENSIONS = {
    "stiffness": {"yf": "[mass] / [time] ** 2", "ym": "[length] * [mass] / [time] ** 2",
                  "tf": "[length] * [mass] / [time] ** 2", "tm": "[length] ** 2 * [mass] / [time] ** 2"},
    "damping": {"yf": "[mass] / [time]", "ym": "[length] * [mass] / [time]",
                "tf": "[length] * [mass] / [time]", "tm": "[length] ** 2 * [mass] / [time]"},
}


@attrs.frozen
class JointMatrix:
    """A 2x2 joint stiffness or damping matrix with units per entry.

    Build it with :meth:`JointMatrix.from_mapping` from ``{"yf": "4.19e7 N/m", "tm": ...}``
    (missing entries are 0).  ``values`` holds SI floats ``[[yf, ym], [tf, tm]]``.

    Parameters
    ----------
    kind : {"stiffness", "damping"}
        Which matrix: the units are :data:`STIFFNESS_UNITS` or :data:`DAMPING_UNITS`.
    entries : tuple of (str, pint.Quantity)
        The given entries ``(key, quantity)``, keys among ``yf, ym, tf, tm``.
    """

    kind: str
    entries: tuple[tuple[str, pint.Quantity], ...]

    @classmethod
    def from_mapping(cls, mapping, kind: str, field: str) -> "JointMatrix":
        """A matrix from ``{"yf": "4.19e7 N/m", "tm": "8e4 N*m/rad", ...}``, units checked.

        Parameters
        ----------
        mapping : mapping or JointMatrix or None
            Entries ``yf, ym, tf, tm`` as quantities or strings with units (any units of
            the right dimension); None for none.
        kind : {"stiffness", "damping"}
            Which matrix.
        field : str
            Name of the argument, for error messages (``"k"``, ``"c"``).

        Returns
        -------
        JointMatrix
            The matrix.
        """
        if isinstance(mapping, JointMatrix):
            return mapping
        if mapping is None:
            mapping = {}
        if not isinstance(mapping, Mapping):
            raise InvalidValueError(
                f"{field}: got {mapping!r}; expected a table of entries yf, ym, tf, tm with units"
            )
        unknown = sorted(set(mapping) - set(ENTRIES))
        if unknown:
            raise InvalidValueError(
                f"{field}: unknown entries {unknown}; expected some of yf, ym, tf, tm"
            )
        dims = _DIMENSIONS[kind]
        return cls(kind, tuple((key, quantity(mapping[key], f"{field}.{key}", dims[key]))
                               for key in ENTRIES if key in mapping))

    def get(self, key: str) -> float:
        """Entry ``key`` in SI units (0 when not given).

        Parameters
        ----------
        key : {"yf", "ym", "tf", "tm"}
            The entry.

        Returns
        -------
        float
            The value in the entry's SI unit (:data:`STIFFNESS_UNITS` or :data:`DAMPING_UNITS`).
        """
        units = STIFFNESS_UNITS if self.kind == "stiffness" else DAMPING_UNITS
        q = next((q for k, q in self.entries if k == key), None)
        return 0.0 if q is None else magnitude_in(q, units[key])

    @property
    def values(self) -> np.ndarray:
        """``[[yf, ym], [tf, tm]]`` in SI units."""
        return np.array([[self.get("yf"), self.get("ym")], [self.get("tf"), self.get("tm")]])

    def as_dict(self) -> dict[str, str]:
        """Entries as strings that read back to the same quantities.

        Returns
        -------
        dict
            ``{key: "4.19e+07 N/m"}`` for the given entries, in their own units.
        """
        return {k: format_quantity(q) for k, q in self.entries}

    def __bool__(self) -> bool:
        return bool(self.entries)


def _check_matrices(k: np.ndarray, c: np.ndarray, owner: str) -> None:
    """Warn (once per kind of problem) when k or c is not symmetric or not passive."""
    asym, nonpassive = [], []
    for sym_name, m in (("k", k), ("c", c)):
        if np.abs(m).max() == 0:
            continue
        if abs(m[0, 1] - m[1, 0]) > 1e-9 * max(abs(m[0, 1]), abs(m[1, 0])):
            asym.append(f"{sym_name}_ym = {m[0, 1]:.6g} != {sym_name}_tf = {m[1, 0]:.6g}")
        sym = 0.5 * (m + m.T) / np.abs(m).max()  # scaled: the products of entries of 1e200 N/m stay finite
        det = sym[0, 0] * sym[1, 1] - sym[0, 1] ** 2
        if sym[0, 0] < 0 or sym[1, 1] < 0:
            nonpassive.append(f"{sym_name} has a negative diagonal entry")
        elif det < -1e-12 * (abs(sym[0, 0] * sym[1, 1]) + sym[0, 1] ** 2):
            scale = float(np.abs(m).max()) * float(np.abs(m).max())  # Python floats: inf beyond 1e308, no warning
            nonpassive.append(
                f"{sym_name}_ym*{sym_name}_tf = {float(sym[0, 1] ** 2) * scale:.4g} > "
                f"{sym_name}_yf*{sym_name}_tm = {float(sym[0, 0] * sym[1, 1]) * scale:.4g}"
            )
    if asym:
        warnings.warn(
            f"{owner}: the joint matrix is not symmetric ({'; '.join(asym)}): the coupled "
            "receptances will not be reciprocal",
            NonReciprocalWarning,
            stacklevel=4,
        )
    if nonpassive:
        warnings.warn(
            f"{owner}: not positive semi-definite (non-passive): {'; '.join(nonpassive)}; accepted, "
            "but such a joint can generate energy at some frequencies",
            NonPassiveJointWarning,
            stacklevel=4,
        )


def _point(value) -> str:
    return str(parse_point(value, allow_dof=False))


def _between(value) -> tuple[str, str]:
    if isinstance(value, (str, bytes)) or not isinstance(value, (tuple, list)) or len(value) != 2:
        raise InvalidValueError(f"between: got {value!r}; expected two point names (a tuple or a list)")
    a, b = (_point(v) for v in value)
    if a == b:
        raise InvalidValueError(f"between: got the same point twice ({a})")
    return a, b


def _uncertainty(value) -> float | None:
    if value is None:
        return None
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not 1.0 <= float(value) < 1e3:
        raise InvalidValueError(f"uncertainty: got {value!r}; expected a factor >= 1 (the values may be this "
                                "factor lower or higher, e.g. 3), or none")
    return float(value)


def _kind(value) -> str:
    if value not in PROVENANCE_KINDS:
        raise InvalidValueError(f"provenance: got {value!r}; expected one of {', '.join(PROVENANCE_KINDS)}")
    return value


@attrs.frozen
class JointProvenance:
    """Where the values of a joint come from, and how far they may be off.

    Parameters
    ----------
    kind : {"identified", "predicted", "borrowed", "prior"}
        See :data:`PROVENANCE_KINDS`.
    source : str
        The test, the table, the holder they were borrowed from, or the
        literature the prior follows.
    uncertainty : float, optional
        A factor ``f >= 1``: the stiffness and damping may be between ``1/f``
        and ``f`` times the values (None: not stated).
    """

    kind: str = attrs.field(converter=_kind)
    source: str = attrs.field(default="", converter=str)
    uncertainty: float | None = attrs.field(default=None, converter=_uncertainty)

    def describe(self) -> str:
        """One line: the kind, the uncertainty and the source.

        Returns
        -------
        str
            E.g. ``"prior (x/ 3): ..."``.
        """
        spread = f" (within a factor {self.uncertainty:g})" if self.uncertainty is not None else ""
        return f"{self.kind}{spread}" + (f": {self.source}" if self.source else "")

    def to_json(self) -> dict:
        """``kind``, ``source``, ``uncertainty`` (None when not stated).

        Returns
        -------
        dict
            The three fields.
        """
        return {"kind": self.kind, "source": self.source, "uncertainty": self.uncertainty}


def _provenance(value) -> JointProvenance | None:
    if value is None or isinstance(value, JointProvenance):
        return value
    if isinstance(value, str):
        return JointProvenance(value)
    if isinstance(value, Mapping):
        return JointProvenance(**value)
    raise InvalidValueError(f"provenance: got {value!r}; expected a JointProvenance, a kind or a mapping")


@attrs.frozen
class Joint:
    """A connection between two points: rigid, or elastic with stiffness and damping.

    Parameters
    ----------
    name : str
        The joint's name (``"holder-tool"``).
    between : (str, str)
        The two points, e.g. ``("holder.tip", "tool.base")``.
    k, c : mapping, optional
        Stiffness and damping entries ``yf, ym, tf, tm`` with units
        (conventions.md, Joints); missing entries are 0.
    rigid : bool
        Equal displacement and rotation of the two points (no ``k``/``c``).
    provenance : JointProvenance, optional
        Where ``k`` and ``c`` come from (a kind, a mapping or the object);
        None when not stated.  It changes no number: equal joints with
        other provenances are equal.

    Warns
    -----
    NonReciprocalWarning
        When ``ym != tf``.
    NonPassiveJointWarning
        When ``k`` or ``c`` is not positive semi-definite (as the thesis's
        Tables 2.1 and 2.2 are not: ``k_ym^2 > k_yf k_tm``); still accepted.
    """

    name: str = attrs.field(converter=check_name)
    between: tuple[str, str] = attrs.field(converter=_between)
    k: JointMatrix = attrs.field(default=None, converter=lambda v: JointMatrix.from_mapping(v, "stiffness", "k"))
    c: JointMatrix = attrs.field(default=None, converter=lambda v: JointMatrix.from_mapping(v, "damping", "c"))
    rigid: bool = attrs.field(default=False)
    provenance: JointProvenance | None = attrs.field(default=None, kw_only=True, eq=False, converter=_provenance)

    def __attrs_post_init__(self) -> None:
        if not isinstance(self.rigid, bool):
            raise InvalidValueError(f"rigid: got {self.rigid!r}; expected true or false")
        if self.rigid and (self.k or self.c):
            raise InvalidValueError(f"joint {self.name!r}: a rigid joint takes no k or c")
        if not self.rigid:
            if not self.k:
                raise InvalidValueError(
                    f"joint {self.name!r}: an elastic joint needs stiffness entries k "
                    "(or rigid = true)"
                )
            _check_matrices(self.k.values, self.c.values, f"joint {self.name!r}")

    @classmethod
    def rigid_between(cls, name: str, a: str, b: str) -> "Joint":
        """A rigid joint.

        Parameters
        ----------
        name : str
            The joint's name.
        a : str
            The first point.
        b : str
            The second point.

        Returns
        -------
        Joint
            A joint with equal displacement and slope at both points.
        """
        return cls(name, (a, b), rigid=True)

    def dynamic_stiffness(self, frequency_hz: np.ndarray, decay: float = 0.0) -> np.ndarray:
        """``K + i omega C`` (thesis eq. 2.5) as an array ``(2, 2, n_freq)``; rigid joints have none.

        Parameters
        ----------
        frequency_hz : array_like
            Frequencies in Hz.
        decay : float, optional
            ``1/tau`` [1/s]: at the complex frequency ``omega - i decay`` (a tap
            test seen through an exponential window); default 0.

        Returns
        -------
        ndarray
            Complex, shape ``(2, 2, n_freq)``, entries in N/m, N, N/rad and N m/rad.
        """
        if self.rigid:
            raise InvalidValueError(f"joint {self.name!r} is rigid: it has no finite stiffness")
        omega = angular_lines(frequency_hz, decay)
        return self.k.values[:, :, None] + 1j * omega * self.c.values[:, :, None]

    def with_parameters(self, k=None, c=None) -> "Joint":
        """A copy with some entries of ``k`` and ``c`` replaced (others kept).

        Parameters
        ----------
        k : mapping, optional
            Stiffness entries to replace, with units (``{"yf": "1.2e7 N/m"}``).
        c : mapping, optional
            Damping entries to replace, with units (``{"yf": "15 N*s/m"}``).

        Returns
        -------
        Joint
            The new, elastic joint.
        """
        return attrs.evolve(self, k={**self.k.as_dict(), **(k or {})}, c={**self.c.as_dict(), **(c or {})}, rigid=False)


@attrs.frozen
class Support:
    """Springs and dampers from a point to the ground (bearings, suspension bands).

    Parameters
    ----------
    at : str
        The point, e.g. ``"spindle@310 mm"``.
    k, c : mapping
        Entries ``yf, ym, tf, tm`` with units, as for :class:`Joint`.
    name : str, optional
        Defaults to ``"support-N"`` in an assembly.
    """

    at: str = attrs.field(converter=_point)
    k: JointMatrix = attrs.field(default=None, converter=lambda v: JointMatrix.from_mapping(v, "stiffness", "k"))
    c: JointMatrix = attrs.field(default=None, converter=lambda v: JointMatrix.from_mapping(v, "damping", "c"))
    name: str | None = attrs.field(default=None)

    def __attrs_post_init__(self) -> None:
        if self.name is not None:
            check_name(self.name)
        if not self.k and not self.c:
            raise InvalidValueError(f"support at {self.at}: needs stiffness k or damping c entries")
        _check_matrices(self.k.values, self.c.values, f"support at {self.at}")

    def dynamic_stiffness(self, frequency_hz: np.ndarray, decay: float = 0.0) -> np.ndarray:
        """``K + i omega C`` of the support, as for a joint.

        Parameters
        ----------
        frequency_hz : array_like
            Frequencies in Hz.
        decay : float, optional
            ``1/tau`` [1/s]: at the complex frequency ``omega - i decay`` (a tap
            test seen through an exponential window); default 0.

        Returns
        -------
        ndarray
            Complex, shape ``(2, 2, n_freq)``, entries in N/m, N, N/rad and N m/rad.
        """
        omega = angular_lines(frequency_hz, decay)
        return self.k.values[:, :, None] + 1j * omega * self.c.values[:, :, None]


def _not_negative(value, field: str, dimension: str, what: str) -> pint.Quantity:
    q = quantity(value, field, dimension)
    if q.magnitude < 0:
        raise InvalidValueError(f"{field}: got {value!r}; expected {what} >= 0")
    return q


@attrs.frozen
class _Body:
    """A rigid body at a point (the fields and the dynamic stiffness that :class:`Sensor` and :class:`Mass` share)."""

    name: str = attrs.field(converter=check_name)
    at: str = attrs.field(converter=_point)
    mass: pint.Quantity = attrs.field(converter=lambda v: _not_negative(v, "mass", "[mass]", "a mass"))
    inertia: pint.Quantity = attrs.field(default="0 kg*m^2", converter=lambda v: _not_negative(
        v, "inertia", "[mass] * [length] ** 2", "a rotary inertia"))

    @property
    def mass_kg(self) -> float:
        """The mass in kg (a float)."""
        return magnitude_in(self.mass, "kg")

    @property
    def inertia_si(self) -> float:
        """The rotary inertia in kg m^2 (a float)."""
        return magnitude_in(self.inertia, "kg*m^2")

    def dynamic_stiffness(self, frequency_hz: np.ndarray, decay: float = 0.0) -> np.ndarray:
        """``-omega^2 diag(m, J)`` (thesis eq. 5.2, with the rotary inertia J).

        Parameters
        ----------
        frequency_hz : array_like
            Frequencies in Hz.
        decay : float, optional
            ``1/tau`` [1/s]: at the complex frequency ``omega - i decay`` (a tap
            test seen through an exponential window); default 0.

        Returns
        -------
        ndarray
            Complex, shape ``(2, 2, n_freq)``: N/m on y, N m/rad on theta.
        """
        w2 = angular_lines(frequency_hz, decay) ** 2
        out = np.zeros((2, 2, w2.size), dtype=complex)
        out[0, 0] = -w2 * self.mass_kg
        out[1, 1] = -w2 * self.inertia_si
        return out


@attrs.frozen
class Sensor(_Body):
    """A body on the structure during a test: an accelerometer, a magnet, a laser target.

    Parameters
    ----------
    name : str
        Name of the sensor (measurement records list it by this name).
    at : str
        The point, e.g. ``"tool.tip"``.
    mass : quantity or str
        ``"0 g"`` for a non-contact sensor (laser vibrometer).
    inertia : quantity or str, default "0 kg*m^2"
        Rotary inertia about the bending axis.
    always_on : bool, default False
        On the structure in every test, whether a measurement record lists
        it or not (a body the records do not mention, e.g. one found by a
        diagnosis).  Still a sensor: ``Assembly.without_sensors()`` takes it
        off for predictions of the machine in the cut.
    """

    always_on: bool = attrs.field(default=False)

    def __attrs_post_init__(self) -> None:
        if not isinstance(self.always_on, bool):
            raise InvalidValueError(f"always_on: got {self.always_on!r}; expected true or false")

    @classmethod
    def laser(cls, name: str, at: str) -> "Sensor":
        """A non-contact sensor: no mass.

        Parameters
        ----------
        name : str
            The sensor's name.
        at : str
            The point it measures.

        Returns
        -------
        Sensor
            A sensor of 0 g.
        """
        return cls(name, at, "0 g")


@attrs.frozen
class Mass(_Body):
    """A rigid body permanently on the structure: a clamping nut, a balancing ring.

    Unlike a :class:`Sensor`, which is on the structure only in the tests
    that list it, a mass is part of the machine: it acts in every test and in
    every prediction.  Its dynamic stiffness is ``-omega^2 diag(m, J)``.

    Parameters
    ----------
    name : str
        Name of the body.
    at : str
        The point, e.g. ``"holder@50 mm"``.
    mass : quantity or str
        Its mass, e.g. ``"120 g"``.
    inertia : quantity or str, default "0 kg*m^2"
        Rotary inertia about the bending axis.
    """


def dynamic_stiffness(link, frequency_hz, decay: float = 0.0) -> np.ndarray:
    """``link.dynamic_stiffness(frequency_hz)``, checked when the joint model is one of one's own.

    Every computation takes a joint's (support's, body's) dynamic stiffness
    through here: a joint model defined outside the package that raises,
    gives another shape than ``(2, 2, n)`` or values that are not finite is
    refused naming the joint and its type.

    Parameters
    ----------
    link : Joint, Support, Sensor, Mass or a joint model of one's own
        What connects or hangs on points.
    frequency_hz : ndarray
        Frequencies [Hz].
    decay : float, optional
        ``1/tau`` [1/s]: at the complex frequency ``omega - i decay`` (a tap
        test seen through an exponential window), from a
        ``dynamic_stiffness`` that takes ``decay``; default 0.

    Returns
    -------
    ndarray
        Complex, shape ``(2, 2, n)``.

    Raises
    ------
    InvalidValueError
        When a joint model of one's own breaks the protocol, or ``decay`` is
        not 0 and its ``dynamic_stiffness`` does not take it.
    """
    return checked_block(link, "joint", "dynamic_stiffness", at_decay(link, "dynamic_stiffness", frequency_hz, decay),
                         2, frequency_hz)
