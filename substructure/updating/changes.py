"""What a fit changes or adds in a model: the protocol of the model-updating core.

A :class:`Change` is anything a fit may correct or add: a model parameter
(:mod:`substructure.updating.parameters`), an element at a fitted place
(:mod:`substructure.updating.elements`), an effect of the diagnosis
catalogue.  It names its fitted parameters (:class:`ParamSpec`: unit,
physical bounds, start, log or linear scale) and applies itself both to the
SI form of a model (for fits) and to an assembly (for the result, a normal
model that saves as usual).
"""

from __future__ import annotations

from typing import ClassVar, Mapping

import attrs

__all__ = ["ParamSpec", "Change"]


@attrs.frozen
class ParamSpec:
    """One fitted parameter of a change.

    Parameters
    ----------
    name : str
        Its name in reports (``value``, ``mass``, ``k_yf``, ...).
    unit : str
        SI unit of the value.
    lower, upper : float
        Physical bounds.
    start : float
        Starting value.
    log : bool
        Fitted as a logarithm (positive values spanning decades).
    nominal : float or None
        The model's value before the change (for parameter corrections).
    """

    name: str
    unit: str
    lower: float
    upper: float
    start: float
    log: bool = True
    nominal: float | None = None


class Change:
    """Something a fit may change or add in a model: the protocol of the updating core.

    Subclasses set ``effect`` (a name), ``where``, ``specs`` (the fitted
    parameters), ``explanation`` and implement :meth:`apply_si` (on the SI
    form, for fits) and :meth:`apply` (on the assembly, for the result).
    Either may raise :class:`~substructure.errors.UnknownPointError` when the
    change has no place in a configuration (e.g. a component taken off); it
    is then skipped there.  A subclass's :meth:`apply_si`, :meth:`apply` and
    :meth:`place` without a docstring of their own are documented by the
    protocol's (the class's docstring says what its change does).
    """

    effect: ClassVar[str] = ""
    explanation: ClassVar[str] = ""
    where: str = ""
    specs: tuple = ()
    test_only: ClassVar[bool] = False

    def __init_subclass__(cls, **kwargs) -> None:
        super().__init_subclass__(**kwargs)
        for name in ("apply_si", "apply", "place"):
            method = vars(cls).get(name)
            if method is not None and not method.__doc__:
                method.__doc__ = getattr(Change, name).__doc__

    @property
    def key(self) -> tuple[str, str]:
        """``(effect, where)``: what identifies the change."""
        return (self.effect, self.where)

    def place(self, values: Mapping[str, float]) -> str:
        """Where the change acts with these values (default ``where``; elements give their point).

        Parameters
        ----------
        values : mapping of str to float
                The change's values by parameter name (SI).

        Returns
        -------
        str
            A place for reports, e.g. ``holder@55 mm``.
        """
        return self.where

    def apply_si(self, structure, values: Mapping[str, float]):
        """The structure with the change applied.

        Parameters
        ----------
        structure : Structure
            The SI form of one test configuration.
        values : mapping of str to float
                The change's values by parameter name (SI).

        Returns
        -------
        Structure
            The changed structure.
        """
        raise NotImplementedError

    def apply(self, assembly, values: Mapping[str, float]):
        """The assembly with the change applied.

        Parameters
        ----------
        assembly : Assembly
            The model (or one configuration of it).
        values : mapping of str to float
                The change's values by parameter name (SI).

        Returns
        -------
        Assembly
            A new assembly, in the file's usual forms.
        """
        raise NotImplementedError

    def __repr__(self) -> str:
        return f"{type(self).__name__}({self.effect!r} at {self.where!r})"
