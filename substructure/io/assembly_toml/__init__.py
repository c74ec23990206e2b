"""Assembly files (TOML): read and write assemblies in the format of docs/file-formats.md.

:func:`load_assembly` and :func:`loads_assembly` read a file or a string into
an :class:`~substructure.assembly.Assembly`; :func:`save_assembly` and
:func:`dumps_assembly` write one back, quantities with every digit
(:func:`~substructure.units.format_quantity`), so that
``loads_assembly(dumps_assembly(a)) == a``.  Every problem of a file raises
:class:`~substructure.errors.FileFormatError` whose message starts with the
file name (and the line, where it can be found) and names the key path, e.g.
``components[2].segments[1].od``, what was given and what was expected.

Component types are looked up in :data:`substructure.components.COMPONENT_TYPES`,
so registered user types work: a class with a classmethod
``from_toml(table, materials, key)`` and a method ``to_toml()`` reads and
writes its own table; any other :class:`~substructure.components.Beam`
subclass uses the generic ``name``/``type``/``material``/``segments`` table,
plus one key per further field of its class (quantities written with their
unit).  Writing checks that the text reads back to an equal assembly and
refuses, naming the component and the fields, what would not: a file never
silently loses a value.

The package holds the reading (``reader``: key paths and line numbers in
errors), the writing (``writer``: the text, the round-trip check and the
atomic save, imported on first use) and the keys both share (``_schema``);
every name is imported from here.
"""

from __future__ import annotations

from typing import Any

from ._schema import MACHINE_SIZE_M, MAX_TAPER_STEPS, SIZE_OUTLIER, SIZE_OUTLIER_FLOOR_M, SIZE_RANGE_M  # noqa: F401 (the limits of reading, named in errors)
from .reader import default_assembly, load_assembly, loads_assembly

__all__ = ["load_assembly", "loads_assembly", "save_assembly", "dumps_assembly", "default_assembly"]

_WRITER = ("dumps_assembly", "save_assembly")


def __getattr__(name: str) -> Any:
    # the writer (and tomli_w) is imported when an assembly is written, not by the commands
    # that only read one (PEP 562)
    if name in _WRITER:
        from . import writer

        value = getattr(writer, name)
        globals()[name] = value
        return value
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(__all__))
