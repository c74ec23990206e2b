"""Model against measurement: where the model fails, which physical effect it misses, and the fix.

* :mod:`~substructure.diagnose.compare`: the error measure (RMS of the complex
  log ratio), mode pairing, FRAC, error bands and the noise floor estimated
  from the data;
* :mod:`~substructure.diagnose.effects`: the catalogue of physical effects
  (registered by name; users add their own);
* :mod:`~substructure.diagnose.diagnosis`: :func:`diagnose`, on the
  model-updating core (:mod:`substructure.updating`): the candidates of the
  open world (``search``: every model parameter, bodies, springs and section
  changes at fitted positions, the catalogue; screening, full fits), starting
  values from mode shifts (``modes``), the refinement by significance with
  elimination and review (``refine``), and the verdict, the signature and the
  separating measurement (``report``);
* :mod:`~substructure.diagnose.settings`: :class:`DiagnoseSettings`, every
  threshold, grid and budget of a diagnosis, named and overridable;
* :mod:`~substructure.diagnose.words`: every sentence a diagnosis writes.
"""

from .compare import METRIC, Comparison, compare, error, frac, noise_floor, pair_modes
from .diagnosis import Candidate, Diagnosis, Found, Step, diagnose
from .result import Alternatives, Changes, Measures, Verdict
from .settings import DEFAULT_SETTINGS, DiagnoseSettings
from .effects import EFFECTS, Effect, Parameter, get_effect, register_effect, registered, registry

# The built-in effects register themselves on import; importing any module of the package runs this first.
from . import catalogue as _catalogue  # noqa: F401

__all__ = [
    "METRIC", "Comparison", "compare", "error", "frac", "noise_floor", "pair_modes", "Candidate",
    "Diagnosis", "Verdict", "Measures", "Changes", "Alternatives", "DiagnoseSettings", "DEFAULT_SETTINGS", "Found",
    "Step", "diagnose", "EFFECTS", "Effect", "Parameter", "get_effect", "register_effect",
    "registered", "registry",
]
