"""The model-updating core: parameters, fast evaluation, noise, likelihood, fits and model selection.

Identification and diagnosis are thin workflows over this package (neither
imports the other):

* :mod:`~substructure.updating.parameters`: every number of an assembly by
  its path in the assembly file (``components.tool.segments.0.length``,
  ``joints.holder-tool.k.yf``, ``materials.carbide.E``, ...) and the linked
  ones (a tool's overhang, a component's own material, a joint's whole
  stiffness, a bearing pair), with physical bounds; get and set on an
  :class:`~substructure.assembly.Assembly`;
* :mod:`~substructure.updating.changes`: the protocol of what a fit changes
  or adds (:class:`Change`, :class:`ParamSpec`);
* :mod:`~substructure.updating.structure` and
  :mod:`~substructure.updating.paths`: the SI form of an assembly, changed
  without rebuilding objects, and its fast evaluation;
* :mod:`~substructure.updating.elements`: bodies, springs to the ground and
  section changes at fitted positions;
* :mod:`~substructure.updating.noise`: the per-line noise of a measured FRF,
  estimated from the data (:mod:`~substructure.updating.interpolated`: on
  the measured lines of an FRF interpolated between them);
* :mod:`~substructure.updating.likelihood`: ``chi^2`` of whitened complex
  log ratios, each measurement in its configuration;
* :mod:`~substructure.updating.fit`: weighted nonlinear least squares with
  standard deviations and correlations, inflated by the misfit;
* :mod:`~substructure.updating.selection`: the significance test, the test
  of consistency with the noise, the indifference region.
"""

from .changes import Change, ParamSpec
from .elements import AddedMass, GroundSpring, SectionChange
from .fit import Fit, fit
from .interpolated import interpolated_from
from .likelihood import Likelihood, Measured, measured_frfs
from .noise import NoiseModel, estimate_noise, window_correlation
from .parameters import (ModelParameter, ParameterChange, ParameterSet, get_parameter, model_parameters,
                         set_parameters)
from .paths import apply_path_si
from .selection import Consistency, ErrorCheck, Significance, consistency, error_check, indifferent, significance
from .evaluator import Evaluator
from .structure import Structure

__all__ = [
    "Change", "ParamSpec", "AddedMass", "GroundSpring", "SectionChange", "Fit", "fit", "Likelihood", "Measured",
    "measured_frfs", "NoiseModel", "estimate_noise", "window_correlation", "interpolated_from", "ModelParameter",
    "ParameterChange", "ParameterSet",
    "get_parameter", "model_parameters", "set_parameters", "apply_path_si", "Consistency", "ErrorCheck",
    "Significance", "consistency", "error_check", "indifferent", "significance", "Evaluator", "Structure",
]
