"""The checks and conversions of an assembly's fields: sequences of joints, components, bodies.

:class:`~substructure.assembly.Assembly` uses them as attrs converters; each
refuses an item that is not what the field holds, naming the field and the
position.
"""

from __future__ import annotations

from ..errors import InvalidValueError


def _tuple(kind: type | None = None, field: str = ""):
    def convert(value) -> tuple:
        if value is None:
            return ()
        try:
            if isinstance(value, (str, bytes)):
                raise TypeError
            items = tuple(value)
        except TypeError:
            raise InvalidValueError(
                f"{field or 'value'}: got a {type(value).__name__}; expected a sequence of them (a tuple or a "
                f"list: {field or 'items'}=(item,) for one)") from None
        if kind is not None:
            for i, item in enumerate(items):
                if not isinstance(item, kind):
                    where = f"{field}[{i}]: got {item!r}" if field else f"got {item!r} at position {i}"
                    raise InvalidValueError(f"{where}; expected a {kind.__name__}")
        return items

    return convert


def _joint_check(items) -> tuple:
    items = _tuple(field="joints")(items)
    for i, j in enumerate(items):
        missing = [a for a in ("name", "between", "rigid", "dynamic_stiffness") if not hasattr(j, a)]
        if missing:
            raise InvalidValueError(
                f"joints[{i}]: {j!r} is not a joint (it has no {', '.join(missing)}); expected a Joint "
                "or an object with name, between, rigid and dynamic_stiffness(frequency_hz)"
            )
    return items


def _component_check(items) -> tuple:
    items = _tuple(field="components")(items)
    for c in items:
        for attr in ("name", "component_names", "node_key", "receptance_matrix"):
            if not hasattr(c, attr):
                raise InvalidValueError(
                    f"components: {c!r} is not a component (it has no {attr!r}); see "
                    "substructure.components for the protocol"
                )
        names = c.component_names
        if isinstance(names, (str, bytes)) or not all(isinstance(n, str) for n in _items(names)):
            raise InvalidValueError(
                f"components: {getattr(c, 'name', c)!r}: component_names is {names!r}; expected a set of the names "
                f"of the pieces it holds, e.g. {{{getattr(c, 'name', 'holder')!r}}} (a text is not a set of names)"
            )
    return items


def _items(value) -> tuple:
    """The items of a collection, or (None,) when it is none (then refused as not a name)."""
    try:
        return tuple(value)
    except TypeError:
        return (None,)
