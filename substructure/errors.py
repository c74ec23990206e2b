"""Exceptions and warning categories of `substructure`.

Every error the library raises for a user's mistake derives from
:class:`SubstructureError` and also from the builtin exception that fits, so
that ``except ValueError`` keeps working for callers that do not know this
package.  Soft problems (a joint that is not passive, an ill-conditioned
inversion) are warnings with a category of their own, so that they can be
filtered precisely.
"""

from __future__ import annotations

__all__ = [
    "SubstructureError",
    "UnitError",
    "InvalidValueError",
    "FrequencyAxisMismatchError",
    "UnknownPointError",
    "AssemblyError",
    "FileFormatError",
    "OutputExistsError",
    "SubstructureWarning",
    "NonPassiveJointWarning",
    "NonReciprocalWarning",
    "IllConditionedWarning",
    "WindowedFRFWarning",
]


class SubstructureError(Exception):
    """Base class of every error raised by `substructure`."""


class UnitError(SubstructureError, TypeError):
    """A value has no unit where one is needed, or the wrong dimension."""


class InvalidValueError(SubstructureError, ValueError):
    """A value has the right type and unit but is not physically valid."""


class FrequencyAxisMismatchError(SubstructureError, ValueError):
    """Two FRFs on different frequency axes were combined without interpolation."""


class UnknownPointError(SubstructureError, KeyError):
    """A point name does not exist on the component or assembly.

    Subclasses ``KeyError`` but prints its message plainly.
    """

    def __str__(self) -> str:  # KeyError quotes its argument; we want prose
        return str(self.args[0]) if self.args else ""


class AssemblyError(SubstructureError, ValueError):
    """An assembly is inconsistent: duplicate names, dangling joints, ..."""


class FileFormatError(SubstructureError, ValueError):
    """A file (TOML, CSV, UFF) cannot be read or does not follow its format."""


class OutputExistsError(SubstructureError, FileExistsError):
    """A file to be written exists and replacing it was not asked for (``overwrite``)."""


class SubstructureWarning(UserWarning):
    """Base class of the warnings of `substructure`."""


class NonPassiveJointWarning(SubstructureWarning):
    """A joint's stiffness or damping matrix is not positive semi-definite."""


class NonReciprocalWarning(SubstructureWarning):
    """A joint's or an FRF's cross terms are not symmetric."""


class IllConditionedWarning(SubstructureWarning):
    """A matrix inversion is so ill-conditioned that its result is unreliable."""


class WindowedFRFWarning(SubstructureWarning):
    """An FRF read as it is was measured through an exponential window: every mode carries the window's damping."""
