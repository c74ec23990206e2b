"""Predicting joint parameters for tools never tested (thesis chapter 4).

A :class:`JointTable` of identified joints and their features, surrogates
that learn parameters from features with an honest uncertainty
(:class:`MLPSurrogate`, :class:`GPSurrogate`), their cross-validation
(:func:`cross_validate`), and the tool point FRF band of a predicted joint
(:func:`predict_frf_band`).  Needs scikit-learn.
"""

from .models import ExtrapolationWarning, GPSurrogate, JointSurrogate, MLPSurrogate, Prediction, make_surrogate
from .table import PARAMETER_UNITS, JointTable, thesis_table_4_2
from .band import FRFBand, predict_frf_band
from .validation import CrossValidation, cross_validate

__all__ = ["JointTable", "PARAMETER_UNITS", "thesis_table_4_2", "JointSurrogate", "MLPSurrogate", "GPSurrogate",
           "Prediction", "ExtrapolationWarning", "make_surrogate", "CrossValidation", "cross_validate",
           "FRFBand", "predict_frf_band"]
