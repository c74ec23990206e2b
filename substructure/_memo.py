"""Small memos of the evaluation of models (internal): keys by identity, recent arrays up to a size.

:class:`~substructure.updating.evaluator.Evaluator` keeps the coupled
clusters of earlier evaluations in a :class:`Recent` so that a coupling
step whose inputs did not change is not computed again
(:func:`substructure._engine.couple_substructures`); a component taking part
through its own methods is identified in those keys by the object itself
(:class:`Same`).
"""

from __future__ import annotations

from collections import OrderedDict

__all__ = ["Same", "Recent"]


class Same:
    """An object in a key by its identity (held, so that its id is not reused while the key exists)."""

    __slots__ = ("obj",)

    def __init__(self, obj):
        self.obj = obj

    def __hash__(self) -> int:
        return id(self.obj)

    def __eq__(self, other) -> bool:
        return isinstance(other, Same) and other.obj is self.obj


class Recent(OrderedDict):
    """The arrays used last, by key, up to a number of bytes (the oldest dropped first)."""

    def __init__(self, limit: int):
        super().__init__()
        self.limit = limit
        self.bytes = 0

    def get(self, key, default=None):
        value = super().get(key)
        if value is None:
            return default
        self.move_to_end(key)
        return value

    def __setitem__(self, key, value) -> None:
        if key in self:
            self.bytes -= self[key].nbytes
        super().__setitem__(key, value)
        self.move_to_end(key)
        self.bytes += value.nbytes
        while self.bytes > self.limit and len(self) > 1:
            _, old = self.popitem(last=False)
            self.bytes -= old.nbytes
