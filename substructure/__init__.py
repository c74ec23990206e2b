"""substructure: structural dynamics of machine tools by receptance coupling.

Describe a spindle, holder and tool with real units (in code or in a TOML
file), couple them through joints, and get the tool point frequency response
function (FRF) of the assembly; compare it with tap tests, identify joints,
and compute stability lobes.

The public names most users need are importable from here::

    from substructure import (Assembly, Spindle, Holder, Tool, Segment, Insert,
                              Flutes, Joint, Sensor, Support, FRF, Frequency)
"""

from .assembly import Assembly
from .beams import Flutes, Insert, Segment, shear_coefficient
from .components import (
    COMPONENT_TYPES,
    Beam,
    Holder,
    MeasuredComponent,
    Spindle,
    Tool,
    register_component,
)
from .coupling import add_mass, decouple, modify, remove_mass
from .errors import (
    AssemblyError,
    FileFormatError,
    FrequencyAxisMismatchError,
    IllConditionedWarning,
    InvalidValueError,
    NonPassiveJointWarning,
    NonReciprocalWarning,
    OutputExistsError,
    SubstructureError,
    SubstructureWarning,
    UnitError,
    UnknownPointError,
)
from .frf import FRF, Frequency
from .joints import Joint, Sensor, Support
from .materials import CATALOG, Material, get_material
from .units import Q_, ureg
from .io.assembly_toml import default_assembly, dumps_assembly, load_assembly, loads_assembly, save_assembly
from .sweep import SweepResult, sweep

__version__ = "0.1.0"

__all__ = [
    "Assembly", "Beam", "Spindle", "Holder", "Tool", "MeasuredComponent", "Segment", "Insert",
    "Flutes", "Joint", "Sensor", "Support", "FRF", "Frequency", "Material", "CATALOG",
    "get_material", "COMPONENT_TYPES", "register_component", "shear_coefficient", "add_mass",
    "remove_mass", "modify", "decouple", "ureg", "Q_", "SubstructureError", "UnitError",
    "InvalidValueError", "FrequencyAxisMismatchError", "UnknownPointError", "AssemblyError",
    "FileFormatError", "OutputExistsError", "SubstructureWarning", "NonPassiveJointWarning",
    "NonReciprocalWarning", "IllConditionedWarning", "load_assembly", "loads_assembly", "save_assembly",
    "dumps_assembly", "default_assembly", "sweep", "SweepResult",
]
