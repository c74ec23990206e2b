"""Inverse identification of a joint's stiffness and damping from FRFs, for any joint.

Two methods, meant to be used together:

* :func:`closed_form` is thesis eq. 2.3 generalised to any joint of any
  assembly that the joint splits in two (:func:`joint_sides`): exact on
  exact data, very sensitive to noise, with the condition numbers of its
  inversions reported;
* :class:`JointIdentifier` fits constant ``k`` and ``c`` by least squares to
  the measured FRFs over the band where the joint is observable, with
  standard deviations: the robust method the thesis asks for as future work.

:func:`identify_joint` runs both on an assembly and a measurement set, with
finite-difference rotations and sensor masses handled as the set says.
"""

from .band_fit import JointIdentifier, auto_band, model_of_measurement
from .closed_form import COND_WARN, PARAMETERS, ClosedFormResult, closed_form, joint_sides
from .workflow import IdentificationReport, identify_joint

__all__ = [
    "ClosedFormResult", "closed_form", "joint_sides", "JointIdentifier", "auto_band",
    "model_of_measurement", "PARAMETERS", "COND_WARN", "IdentificationReport", "identify_joint",
]
