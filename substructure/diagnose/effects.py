"""Effects: physical effects a model may be missing, as named, registered classes.

Each effect is a class with named, unit-carrying, bounded parameters, a
``where`` (the point, joint or component it acts on), a way to apply itself
to an assembly (returning a new assembly, so the fix is a normal model that
files can hold) and a short explanation of its signature.  Effects are
registered by name with :func:`register_effect`, so that users add their own
without touching the core::

    @register_effect
    class HeavyHolderNut(Effect):
        name = "holder-nut"
        parameters = (Parameter("mass", "kg", 0.005, 0.5, 0.05),)
        explanation = "a clamping nut adds mass at the holder face: the holder mode drops"

        @classmethod
        def places(cls, assembly, measured_points):
            return ["holder.tip"]

        def apply(self, assembly):
            return assembly.attach(Sensor("nut", self.where, f"{self.values['mass']} kg"))

The diagnosis (:mod:`substructure.diagnose.diagnosis`) fits every registered
effect at every place it proposes, next to every parameter of the model and
the elements of :mod:`substructure.updating.elements`.  An effect may also
give ``apply_si(structure)``, the same change on the SI form of the model
(:mod:`substructure.updating.structure`), so that fits need not rebuild
objects; the built-in effects do.  :class:`EffectChange` makes an effect at a
place a :class:`~substructure.updating.parameters.Change` of the updating
core.  :func:`registry` snapshots the registry for one diagnosis, and
:func:`registered` registers effects for a ``with`` block only.  The built-in
effects are in :mod:`substructure.diagnose.catalogue`.
"""

from __future__ import annotations

import contextlib
from typing import ClassVar, Mapping, Sequence

import attrs
import numpy as np

from ..assembly import Assembly
from ..errors import InvalidValueError
from ..units import ureg
from ..updating.elements import HitPosition, PointPosition
from ..updating.parameters import Change, ParamSpec

__all__ = ["Parameter", "Effect", "EFFECTS", "register_effect", "get_effect", "EffectChange", "registry",
           "registered", "written_back", "tested_at"]

EFFECTS: dict[str, type] = {}
"""Registered effects by name."""


def register_effect(cls):
    """Class decorator: make an :class:`Effect` subclass available by its ``name``.

    The decorated class is a subclass of :class:`Effect` with a class attribute ``name``.

    Returns
    -------
    type
        The class, registered.

    Raises
    ------
    InvalidValueError
        Without a ``name``, or with the name of another registered effect.
    """
    if not isinstance(getattr(cls, "name", None), str):
        raise InvalidValueError(f"effect {cls.__name__}: needs a class attribute `name`")
    if cls.name in EFFECTS and EFFECTS[cls.name].__qualname__ != cls.__qualname__:
        raise InvalidValueError(
            f"effect {cls.name!r} is already registered ({EFFECTS[cls.name].__qualname__}); choose another name"
        )
    EFFECTS[cls.name] = cls
    return cls


def get_effect(name: str) -> type:
    """The effect class registered under ``name``.

    Parameters
    ----------
    name : str
        The effect's name.

    Returns
    -------
    type
        The class.

    Raises
    ------
    InvalidValueError
        For an unknown name (the message lists the known ones).
    """
    if name not in EFFECTS:
        raise InvalidValueError(f"effect: unknown effect {name!r}; known: {', '.join(EFFECTS)}")
    return EFFECTS[name]


def registry() -> dict[str, type]:
    """A snapshot of the registered effects (a diagnosis works on its own copy).

    Returns
    -------
    dict of str to type
        Effect classes by name.
    """
    return dict(EFFECTS)


@contextlib.contextmanager
def registered(*classes):
    """Register effect classes for the ``with`` block only; the registry is restored after.

    Parameters
    ----------
    *classes : type
        :class:`Effect` subclasses.

    Yields
    ------
    dict
        The registry inside the block.
    """
    saved = dict(EFFECTS)
    try:
        for cls in classes:
            register_effect(cls)
        yield EFFECTS
    finally:
        EFFECTS.clear()
        EFFECTS.update(saved)


@attrs.frozen
class Parameter:
    """A bounded parameter of an effect, in SI ``unit``; fitted on a log scale when ``log``.

    Parameters
    ----------
    name : str
        The parameter's name (``mass``, ``k_yf``).
    unit : str
        Its SI unit (``kg``, ``N/m``).
    lower : float
        Lower bound, in ``unit``.
    upper : float
        Upper bound, in ``unit``.
    start : float
        Starting value of the fit, in ``unit``.
    log : bool
        Fit the logarithm (for positive values spanning decades).
    """

    name: str
    unit: str
    lower: float
    upper: float
    start: float
    log: bool = True

    def quantity(self, value: float):
        """The value as a quantity of this parameter's unit.

        Parameters
        ----------
        value : float
            The value (SI).

        Returns
        -------
        pint.Quantity
            With its unit.
        """
        return ureg.Quantity(value, self.unit)


class Effect:
    """A physical effect at a place, with parameter values (SI).

    Subclasses set ``name``, ``parameters``, ``explanation`` and implement
    ``places(assembly, measured_points)`` (where the effect may act) and
    ``apply(assembly)``; ``starting_values(assembly, where, shift)`` may refine
    the starting point from the relative shift of the main mode
    (measured / model - 1).

    Parameters
    ----------
    where : str
        Where the effect acts: a point (``"tool.tip"``) or a joint name.
    **values : float
        Parameter values in their SI units (``mass=0.002``); missing ones take the start.
    """

    name: ClassVar[str] = ""
    parameters: ClassVar[tuple[Parameter, ...]] = ()
    explanation: ClassVar[str] = ""

    def __init__(self, where: str, **values: float):
        self.where = where
        unknown = set(values) - {p.name for p in self.parameters}
        if unknown:
            raise InvalidValueError(
                f"effect {self.name!r}: unknown parameters {sorted(unknown)}; expected "
                f"{', '.join(p.name for p in self.parameters)}"
            )
        self.values = {p.name: float(values.get(p.name, p.start)) for p in self.parameters}
        for p in self.parameters:
            v = self.values[p.name]
            if not (p.lower <= v <= p.upper):
                raise InvalidValueError(
                    f"effect {self.name!r}: {p.name} = {v:g} {p.unit} is outside [{p.lower:g}, {p.upper:g}]"
                )

    def __repr__(self) -> str:
        vals = ", ".join(f"{k}={v:.4g}" for k, v in self.values.items())
        return f"{type(self).__name__}(where={self.where!r}, {vals})"

    @classmethod
    def places(cls, assembly: Assembly, measured_points: Sequence[str]) -> list[str]:
        """Where it may act.

        Parameters
        ----------
        assembly : Assembly
            The model.
        measured_points : sequence of str
            The measured DOF labels.

        Returns
        -------
        list of str
            Places (points, joint or component names).
        """
        return []

    @classmethod
    def starting_values(cls, assembly: Assembly, where: str, shift: float) -> dict[str, float]:
        """Starting values at a place.

        Parameters
        ----------
        assembly : Assembly
            The model.
        where : str
            The place.
        shift : float
            Relative shift of the main mode, ``f_model / f_measured - 1``.

        Returns
        -------
        dict of str to float
            A value per parameter (SI).
        """
        return {p.name: p.start for p in cls.parameters}

    @classmethod
    def scan_starts(cls, assembly: Assembly, where: str) -> list[dict[str, float]]:
        """More starting points of the screening scan at a place (optional; default none).

        The scan tries the first parameter over its range with the others at
        their starting values; an effect whose parameters act together (a
        flutes' length and depth) gives combinations here.

        Parameters
        ----------
        assembly : Assembly
            The model.
        where : str
            The place.

        Returns
        -------
        list of dict of str to float
            Values (SI) of some parameters each; the others stay at their start.
        """
        return []

    @classmethod
    def bounds(cls, assembly: Assembly, where: str) -> dict[str, tuple[float, float]]:
        """Bounds of each parameter at this place.

        Parameters
        ----------
        assembly : Assembly
            The model.
        where : str
            The place.

        Returns
        -------
        dict of str to (float, float)
            ``(lower, upper)`` per parameter, within the class's.
        """
        return {p.name: (p.lower, p.upper) for p in cls.parameters}

    def apply(self, assembly: Assembly) -> Assembly:
        """The assembly with the effect applied (a new assembly in normal form).

        Parameters
        ----------
        assembly : Assembly
            The model (or one test configuration of it).

        Returns
        -------
        Assembly
            The changed model.
        """
        raise NotImplementedError

    def apply_si(self, structure):
        """The same change on the SI form of the model (optional; fits use it when given).

        Parameters
        ----------
        structure : Structure
            The SI form of one test configuration.

        Returns
        -------
        Structure
            The changed structure.
        """
        raise NotImplementedError

    def parameters_json(self) -> dict:
        """``{name: {"value", "unit"}}`` of this instance (SI).

        Returns
        -------
        dict
            One entry per parameter.
        """
        return {p.name: {"value": self.values[p.name], "unit": p.unit} for p in self.parameters}


class EffectChange(Change):
    """An effect of the catalogue at one place, as a change of the updating core.

    Parameters
    ----------
    cls : type
        The :class:`Effect` subclass.
    where : str
        The place.
    assembly : Assembly
        The model (for the place's bounds and starting values).
    shift : float
        Relative shift of the main mode, for the starting values.
    """

    def __init__(self, cls: type, where: str, assembly: Assembly, shift: float = 0.0):
        self.cls = cls
        self.effect = cls.name
        self.explanation = cls.explanation
        self.where = where
        self.test_only = bool(getattr(cls, "test_only", False))
        bounds = cls.bounds(assembly, where)
        start = cls.starting_values(assembly, where, shift)
        specs = []
        for p in cls.parameters:
            lo, hi = max(bounds[p.name][0], p.lower), min(bounds[p.name][1], p.upper)
            if not lo <= hi:
                raise InvalidValueError(f"effect {cls.name!r} at {where}: {p.name} has no room ({lo:g} > {hi:g})")
            specs.append(ParamSpec(p.name, p.unit, lo, hi, float(np.clip(start.get(p.name, p.start), lo, hi)),
                                   p.log and lo > 0))
        self.specs = tuple(specs)
        self.trials = _scan_starts(cls, where, assembly, {spec.name: (spec.lower, spec.upper) for spec in specs})

    def instance(self, values, where: str | None = None) -> Effect:
        """The effect at this change's place (or at ``where``) with these values (SI)."""
        return self.cls(where or self.where, **{k: float(v) for k, v in values.items()})

    def apply(self, assembly, values):
        """The assembly with the effect applied (:meth:`Change.apply`)."""
        return self.instance(values).apply(assembly)

    def apply_si(self, structure, values):
        """The SI structure with the effect applied (the effect's ``apply_si``, :meth:`Change.apply_si`)."""
        return self.instance(values).apply_si(structure)


def _scan_starts(cls: type, where: str, assembly: Assembly, limits: dict) -> tuple[dict, ...]:
    """``cls.scan_starts`` checked: mappings of its parameters' names to finite numbers, clipped to the bounds."""
    out = []
    for k, trial in enumerate(cls.scan_starts(assembly, where)):
        if not isinstance(trial, Mapping) or not trial:
            raise InvalidValueError(f"effect {cls.name!r} at {where}: scan_starts[{k}]: got {trial!r}; expected a "
                                    f"dict of parameter values such as {{{next(iter(limits))!r}: 1.0}}")
        unknown = sorted(set(trial) - set(limits))
        if unknown:
            raise InvalidValueError(f"effect {cls.name!r} at {where}: scan_starts[{k}]: unknown parameters "
                                    f"{unknown}; expected some of {', '.join(limits)}")
        values = {}
        for name, value in trial.items():
            try:
                value = float(value)
            except (TypeError, ValueError, OverflowError):
                value = float("nan")
            if not np.isfinite(value):
                raise InvalidValueError(f"effect {cls.name!r} at {where}: scan_starts[{k}][{name!r}]: got "
                                        f"{trial[name]!r}; expected a finite number (SI)")
            values[name] = float(np.clip(value, *limits[name]))
        out.append(values)
    return tuple(out)


def effect_change(cls: type, where: str, assembly: Assembly, shift: float = 0.0) -> Change:
    """An :class:`EffectChange` (arguments as there), or one fitted through ``apply`` when the effect has no SI
    form."""
    change = EffectChange(cls, where, assembly, shift)
    if getattr(cls, "apply_si", None) is None or cls.apply_si is Effect.apply_si:
        change.__class__ = _AssemblyOnlyEffect
    return change


class _AssemblyOnlyEffect(EffectChange):
    """An effect without an SI form: fits apply it to the assembly (slower)."""

    apply_si = Change.apply_si


def written_back(assembly, current: list):
    """The assembly with the kept changes applied; a test-only effect at a point whose position was fitted (a
    sensor on a tip tested below its edge) is written where the test was taken (``tool.tip-2 mm``), so that the
    point named as measured finds it there.

    Parameters
    ----------
    assembly : Assembly
        The model as given.
    current : list of (Change, dict)
        The kept changes with their values.

    Returns
    -------
    Assembly
        The model with the changes.
    """
    moved = tested_at(current)
    for c, v in current:
        if isinstance(c, EffectChange) and c.test_only and c.where in moved:
            assembly = c.instance(v, moved[c.where]).apply(assembly)
        else:
            assembly = c.apply(assembly, v)
    return assembly


def tested_at(current, hits: bool = False) -> dict[str, str]:
    """Where kept point positions say the test was taken: ``{"tool.tip": "tool.tip-2 mm"}``; with ``hits``, where
    kept hit positions say the hammer hit, apart from the sensor: ``{"tool.tip": "tool.tip-1 mm"}``.

    Parameters
    ----------
    current : iterable of (Change, dict)
        Kept changes with their values.
    hits : bool
        The hammer's places (``hit-position``) instead of the points' (``point-position``).

    Returns
    -------
    dict of str to str
        The point as the measurements name it, and its place on the model.
    """
    return {c.where: c.place(v) for c, v in current
            if isinstance(c, PointPosition) and isinstance(c, HitPosition) == hits}
