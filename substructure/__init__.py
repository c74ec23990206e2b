"""substructure: structural dynamics of machine tools by receptance coupling.

Describe a spindle, holder and tool with real units (in code or in a TOML
file), couple them through joints, and get the tool point frequency response
function (FRF) of the assembly; compare it with tap tests, identify joints,
and compute stability lobes.

The public names most users need are importable from here::

    from substructure import (Assembly, Spindle, Holder, Tool, Segment, Insert,
                              Flutes, Joint, Sensor, Support, FRF, Frequency)

They are imported on first use (PEP 562), so that ``import substructure``,
and a command that needs only part of the library, stay fast.
"""

from __future__ import annotations

import importlib
import sys
import types
from typing import TYPE_CHECKING, Any

__version__ = "0.1.0"

# public name -> the module that defines it
_EXPORTS = {
    "Assembly": "assembly",
    "Flutes": "beams", "Insert": "beams", "Segment": "beams", "shear_coefficient": "beams",
    "COMPONENT_TYPES": "components", "Beam": "components", "Holder": "components",
    "MeasuredComponent": "components", "Spindle": "components", "Tool": "components",
    "register_component": "components",
    "add_mass": "coupling", "decouple": "coupling", "modify": "coupling", "remove_mass": "coupling",
    "AssemblyError": "errors", "FileFormatError": "errors", "FrequencyAxisMismatchError": "errors",
    "IllConditionedWarning": "errors", "InvalidValueError": "errors", "NonPassiveJointWarning": "errors",
    "NonReciprocalWarning": "errors", "OutputExistsError": "errors", "SubstructureError": "errors",
    "SubstructureWarning": "errors",
    "UnitError": "errors", "UnknownPointError": "errors",
    "FRF": "frf", "Frequency": "frf",
    "Joint": "joints", "Sensor": "joints", "Support": "joints", "Mass": "joints",
    "CATALOG": "materials", "Material": "materials", "get_material": "materials",
    "Q_": "units", "ureg": "units",
    "default_assembly": "io.assembly_toml", "dumps_assembly": "io.assembly_toml",
    "load_assembly": "io.assembly_toml", "loads_assembly": "io.assembly_toml",
    "save_assembly": "io.assembly_toml",
    "SweepResult": "sweep", "sweep": "sweep",
}

__all__ = [
    "Assembly", "Beam", "Spindle", "Holder", "Tool", "MeasuredComponent", "Segment", "Insert",
    "Flutes", "Joint", "Sensor", "Support", "Mass", "FRF", "Frequency", "Material", "CATALOG",
    "get_material", "COMPONENT_TYPES", "register_component", "shear_coefficient", "add_mass",
    "remove_mass", "modify", "decouple", "ureg", "Q_", "SubstructureError", "UnitError",
    "InvalidValueError", "FrequencyAxisMismatchError", "UnknownPointError", "AssemblyError",
    "FileFormatError", "OutputExistsError", "SubstructureWarning", "NonPassiveJointWarning",
    "NonReciprocalWarning", "IllConditionedWarning", "load_assembly", "loads_assembly", "save_assembly",
    "dumps_assembly", "default_assembly", "sweep", "SweepResult",
]


class _PintWithoutDask:
    """Import pint, once, without letting it import Dask.

    pint imports ``dask.base`` (about 0.1 s) whenever Dask is installed, for
    quantities that wrap Dask arrays, which this package never makes; with
    the ``study`` extra installed (``substructure study`` runs on Dask) that
    would slow every command.  This finder, first on ``sys.meta_path`` until
    pint is imported, runs pint's import with ``sys.modules["dask"] = None``,
    which ``importlib.util.find_spec`` reads as "not installed"; afterwards
    Dask imports as usual.  When Dask was imported before pint (a notebook
    with a Dask client), nothing is changed.
    """

    def find_spec(self, fullname, path=None, target=None):
        if fullname != "pint":
            return None
        sys.meta_path[:] = [f for f in sys.meta_path if f is not self]
        spec = importlib.util.find_spec(fullname)
        if spec is None or spec.loader is None or "dask" in sys.modules or not hasattr(spec.loader, "exec_module"):
            return spec
        run = spec.loader.exec_module

        def exec_module(module):
            sys.modules["dask"] = None
            try:
                run(module)
            finally:
                if "dask" in sys.modules and sys.modules["dask"] is None:
                    del sys.modules["dask"]

        spec.loader.exec_module = exec_module
        return spec


if "pint" not in sys.modules:
    import importlib.util

    sys.meta_path.insert(0, _PintWithoutDask())


def __getattr__(name: str) -> Any:
    module = _EXPORTS.get(name)
    if module is None:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    value = getattr(importlib.import_module(f".{module}", __name__), name)
    globals()[name] = value  # next time without this function
    return value


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(__all__))


class _Package(types.ModuleType):
    """The package module: ``substructure.sweep`` stays the function when its module is imported.

    Importing a submodule sets it as an attribute of the package; for the one
    public name that is also a module's name (``sweep``), the package keeps
    the function, as it did when it imported everything at once.
    """

    def __setattr__(self, name: str, value: Any) -> None:
        if isinstance(value, types.ModuleType) and _EXPORTS.get(name) == name:
            value = getattr(value, name)
        super().__setattr__(name, value)


sys.modules[__name__].__class__ = _Package


if TYPE_CHECKING:  # for type checkers and editors: the names as plain imports
    from .assembly import Assembly
    from .beams import Flutes, Insert, Segment, shear_coefficient
    from .components import COMPONENT_TYPES, Beam, Holder, MeasuredComponent, Spindle, Tool, register_component
    from .coupling import add_mass, decouple, modify, remove_mass
    from .errors import (AssemblyError, FileFormatError, FrequencyAxisMismatchError, IllConditionedWarning,
                         InvalidValueError, NonPassiveJointWarning, NonReciprocalWarning, OutputExistsError,
                         SubstructureError, SubstructureWarning, UnitError, UnknownPointError)
    from .frf import FRF, Frequency
    from .io.assembly_toml import default_assembly, dumps_assembly, load_assembly, loads_assembly, save_assembly
    from .joints import Joint, Mass, Sensor, Support
    from .materials import CATALOG, Material, get_material
    from .sweep import SweepResult, sweep
    from .units import Q_, ureg
