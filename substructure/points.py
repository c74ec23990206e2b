"""Point names: ``NAME.base``, ``NAME.tip``, ``NAME@X``, ``NAME.tip-X``, with ``:y``/``:theta``.

A point name says which component a point belongs to and where on it the
point lies (conventions.md, Geometry).  :func:`parse_point` turns the text
into a :class:`PointRef`; components turn a ``PointRef`` into a position.
"""

from __future__ import annotations

import re

import attrs
import pint

from .errors import InvalidValueError, UnitError, UnknownPointError
from .units import format_quantity, quantity

__all__ = ["PointRef", "parse_point", "check_name", "DOFS"]

#: The two degrees of freedom of a point: the displacement ``y`` (m) and the slope
#: ``theta`` (rad), in this order in every receptance matrix.
DOFS = ("y", "theta")
_NAME = re.compile(r"^[A-Za-z_][A-Za-z0-9_\-]*$")
# NAME.tip-X, spaces allowed around '.' and '-' as around the other parts of a point name
_FROM_TIP = re.compile(r"^(?P<name>[^.]*?)\s*\.\s*tip\s*-(?P<distance>.*)$")


def check_name(value, field: str = "name") -> str:
    """Validate a component, joint or sensor name (letters, digits, ``_``, ``-``).

    Parameters
    ----------
    value : str
        The name.
    field : str
        Name of the argument, for error messages.

    Returns
    -------
    str
        The name, unchanged.
    """
    if not isinstance(value, str) or not _NAME.match(value):
        raise InvalidValueError(
            f"{field}: got {value!r}; expected a name of letters, digits, '_' or '-' "
            "starting with a letter (no '.', '@' or ':', which point names use)"
        )
    return value


@attrs.frozen
class PointRef:
    """A parsed point name.

    Parameters
    ----------
    component : str
        Name of the component the point is on.
    where : str
        ``"base"``, ``"tip"``, ``"at"`` (distance from the base) or
        ``"from_tip"`` (distance back from the tip); a measured component may
        use any other location word (``"NAME.LABEL"``).
    distance : pint.Quantity or None
        The distance for ``"at"`` and ``"from_tip"``.
    dof : str or None
        ``"y"`` or ``"theta"`` when the name carried a suffix.
    """

    component: str
    where: str
    distance: pint.Quantity | None = None
    dof: str | None = None

    @property
    def point(self) -> "PointRef":
        """The same point without its DOF suffix."""
        return attrs.evolve(self, dof=None)

    def __str__(self) -> str:
        if self.where in ("at", "from_tip") and self.distance is not None:  # the two always have a distance
            text = f"{self.component}{'@' if self.where == 'at' else '.tip-'}{format_quantity(self.distance)}"
        else:
            text = f"{self.component}.{self.where}"
        return text if self.dof is None else f"{text}:{self.dof}"


def _distance(text: str, spec: str) -> pint.Quantity:
    body = text.strip()
    for i, c in enumerate(body[1:], start=1):  # "tool.tip-5 mm-3 mm": pint would compute 2 mm
        if c in "+-" and body[:i].rstrip()[-1:] not in ("e", "E", "^", "*", "/", "("):
            raise UnknownPointError(
                f"point {spec!r}: the distance {body!r} holds a sum or a difference; expected one length, "
                "as NAME@X (from the base) or NAME.tip-X (back from the tip)"
            )
    try:
        q = quantity(text.strip(), f"point {spec!r}", "[length]")
    except (UnitError, InvalidValueError) as exc:
        raise UnknownPointError(f"{exc}") from None
    if q.magnitude < 0:
        raise UnknownPointError(f"point {spec!r}: the distance must be >= 0")
    return q


def parse_point(spec, *, allow_dof: bool = True) -> PointRef:
    """Parse a point name such as ``"tool.tip"``, ``"spindle@310 mm"`` or ``"tool.tip-15 mm:theta"``.

    Parameters
    ----------
    spec : str or PointRef
        The point name.
    allow_dof : bool
        Accept a ``:y`` or ``:theta`` suffix.

    Returns
    -------
    PointRef
        The parsed point (distances as quantities).

    Raises
    ------
    UnknownPointError
        When the text is not a point name.
    """
    if isinstance(spec, PointRef):
        ref = spec
    else:
        if not isinstance(spec, str) or not spec.strip():
            raise UnknownPointError(f"point: got {spec!r}; expected a name like 'tool.tip'")
        text = spec.strip()
        dof = None
        if text.count(":") > 1:
            raise UnknownPointError(f"point {spec!r}: more than one ':'; expected one DOF suffix, ':y' or ':theta'")
        if ":" in text:
            text, dof = text.rsplit(":", 1)
            dof = dof.strip()
            if dof not in DOFS:
                raise UnknownPointError(f"point {spec!r}: unknown DOF {dof!r}; expected ':y' or ':theta'")
        if "@" in text:
            name, dist = text.split("@", 1)
            ref = PointRef(name.strip(), "at", _distance(dist, spec), dof)
        elif from_tip := _FROM_TIP.match(text):
            ref = PointRef(from_tip["name"], "from_tip", _distance(from_tip["distance"], spec), dof)
        elif "." in text:
            name, where = text.split(".", 1)
            ref = PointRef(name.strip(), where.strip(), None, dof)
        else:
            raise UnknownPointError(
                f"point {spec!r}: expected NAME.base, NAME.tip, NAME@X or NAME.tip-X (e.g. 'tool.tip')"
            )
        if not _NAME.match(ref.component) or not ref.where:
            raise UnknownPointError(f"point {spec!r}: {ref.component!r} is not a component name")
    if ref.dof is not None and not allow_dof:
        raise UnknownPointError(f"point {spec!r}: a DOF suffix is not allowed here")
    return ref
