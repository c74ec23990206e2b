"""The numbers a component type of one's own adds: what they are, and the component with one changed.

A built-in beam's numbers are its segments' (lengths, diameters, materials),
which every workflow reads from ``segments``.  A component that adds physics
of its own (a holder with a clamping nut, a lumped model of a chuck) has
numbers no workflow can guess: it names them through the optional member
``parameters()``, a sequence of :class:`ComponentParameter`, and every
workflow reaches them by path, ``components.NAME.FIELD``: the Python API
(:func:`substructure.updating.set_parameters`), identification, the
diagnosis (which fits them like any number of the model) and the model the
diagnosis saves.  A component is changed with ``attrs.evolve`` (the field's
own converter checks the value) unless it has ``with_parameter(name,
value)`` of its own.

Without ``parameters()``, a component that is not a plain beam (see
:func:`~substructure.components.is_plain_beam`) offers the attrs fields its
class adds beyond :class:`~substructure.components.Beam` (or, for another
class, every field but ``name``) that hold a positive number or a positive
scalar quantity: each fitted on a log scale from a tenth to ten times its
value, as the masses of sensors and bodies are.  A field that is zero has no
scale to search on and is left out; name it in ``parameters()`` with bounds
of its own.  A field declared ``int`` is a count (the steps of a taper), not
a value a fit may move, and is left out too.
"""

from __future__ import annotations

import math
from typing import Any

import attrs
import pint

from ..errors import InvalidValueError, UnknownPointError
from .beam import Beam
from .protocol import is_plain_beam

__all__ = ["ComponentParameter", "own_parameters", "with_parameter"]


def _finite(value, field: str) -> float:
    if isinstance(value, (bool, str)):  # float(True) is 1.0 and float("1e3") 1000.0: neither is a value given
        raise InvalidValueError(f"{field}: got {value!r}; expected a number")
    try:
        x = float(value)
    except (TypeError, ValueError, OverflowError):
        raise InvalidValueError(f"{field}: got {value!r}; expected a number") from None
    if not math.isfinite(x):
        raise InvalidValueError(f"{field}: got {value!r}; expected a finite number")
    return x


@attrs.frozen
class ComponentParameter:
    """One number a component adds, as a fit sees it.

    Parameters
    ----------
    name : str
        The key after ``components.NAME`` (an attrs field's name for the
        default :func:`with_parameter`).
    unit : str
        The SI unit of ``nominal``, ``lower`` and ``upper`` (``"kg"``,
        ``"kg*m^2"``, ``"dimensionless"``).
    nominal : float
        The value as the component has it [``unit``].
    lower, upper : float
        The physical bounds a fit stays within [``unit``].
    log : bool
        Searched on a log scale (positive values spanning decades).
    text : str
        What it is, for reports (``"mass of the clamping nut"``).
    """

    name: str = attrs.field()
    unit: str = attrs.field()
    nominal: float = attrs.field(converter=lambda v: _finite(v, "nominal"))
    lower: float = attrs.field(converter=lambda v: _finite(v, "lower"))
    upper: float = attrs.field(converter=lambda v: _finite(v, "upper"))
    log: bool = attrs.field(default=True)
    text: str = attrs.field(default="")

    def __attrs_post_init__(self):
        if not (isinstance(self.name, str) and self.name.isidentifier()):
            raise InvalidValueError(f"name: got {self.name!r}; expected a field name such as 'nut_mass'")
        if not self.lower <= self.nominal <= self.upper:
            raise InvalidValueError(f"parameter {self.name!r}: nominal {self.nominal!r} {self.unit} lies outside "
                                    f"its bounds {self.lower!r} to {self.upper!r}")
        if self.lower >= self.upper or (self.log and self.lower <= 0):
            raise InvalidValueError(f"parameter {self.name!r}: bounds {self.lower!r} to {self.upper!r} {self.unit}; "
                                    "expected lower < upper (and lower > 0 on a log scale)")


def _derived(component: Any) -> tuple[ComponentParameter, ...]:
    from ..joints import Joint

    if is_plain_beam(component) or not attrs.has(type(component)) or type(component) is Joint:
        return ()
    base = ({f.name for f in attrs.fields(Beam)} if isinstance(component, Beam) else
            {f.name for f in attrs.fields(Joint)} if isinstance(component, Joint) else {"name"})
    out = []
    for field in attrs.fields(type(component)):
        if field.name in base or field.name.startswith("_"):
            continue
        value = getattr(component, field.name)
        if isinstance(value, pint.Quantity):
            if not isinstance(value.magnitude, (int, float)) or isinstance(value.magnitude, bool):
                continue
            base_value = value.to_base_units()
            nominal, unit = float(base_value.magnitude), f"{base_value.units:~C}" or "dimensionless"
        elif field.type in (int, "int"):  # a count (the steps of a taper): a fit would set it to 4.37
            continue
        elif isinstance(value, (int, float)) and not isinstance(value, bool):
            nominal, unit = float(value), "dimensionless"
        else:
            continue
        if nominal > 0 and math.isfinite(nominal):
            out.append(ComponentParameter(field.name, unit, nominal, 0.1 * nominal, 10.0 * nominal, True,
                                          f"{field.name.replace('_', ' ')} of {component.name}"))
    return tuple(out)


def own_parameters(component: Any) -> tuple[ComponentParameter, ...]:
    """The numbers a component adds to its segments (see the module docstring).

    Parameters
    ----------
    component : object
        Any component.

    Returns
    -------
    tuple of ComponentParameter
        From the component's ``parameters()`` when it has one, else derived
        from the fields its class adds (none for a plain beam).

    Raises
    ------
    InvalidValueError
        When ``parameters()`` fails or gives something other than
        :class:`ComponentParameter` entries with distinct names.
    """
    hook = getattr(component, "parameters", None)
    if not callable(hook):
        return _derived(component)
    name = getattr(component, "name", "?")
    try:
        found = tuple(hook())
    except Exception as exc:  # a component type of one's own: its error named with it, not a bare traceback
        raise InvalidValueError(f"component {name!r}: its parameters() failed ({type(exc).__name__}: {exc})") from exc
    if not all(isinstance(p, ComponentParameter) for p in found):
        raise InvalidValueError(f"component {name!r}: parameters() must give ComponentParameter entries, got "
                                f"{[type(p).__name__ for p in found]}")
    names = [p.name for p in found]
    if len(set(names)) != len(names):
        raise InvalidValueError(f"component {name!r}: parameters() names a parameter twice: {names}")
    return found


def with_parameter(component: Any, name: str, value: float) -> Any:
    """The component with one of its own numbers set.

    Parameters
    ----------
    component : object
        The component.
    name : str
        The parameter's name (see :func:`own_parameters`).
    value : float
        The new value, in the parameter's unit.

    Returns
    -------
    object
        A new component: the component's ``with_parameter(name, value)``
        when it has one, else ``attrs.evolve`` with the value in the field's
        form (a quantity in the parameter's unit, or a number).

    Raises
    ------
    UnknownPointError
        When the component has no such parameter.
    """
    params = {p.name: p for p in own_parameters(component)}
    if name not in params:
        raise UnknownPointError(f"component {component.name!r} has no parameter {name!r}; its own parameters: "
                                f"{', '.join(params) or 'none'}")
    value = _finite(value, name)
    hook = getattr(component, "with_parameter", None)
    if callable(hook):
        return hook(name, value)
    current = getattr(component, name)
    if isinstance(current, pint.Quantity):
        new = current._REGISTRY.Quantity(float(value), params[name].unit).to(current.units)
        return attrs.evolve(component, **{name: new})
    return attrs.evolve(component, **{name: float(value)})
