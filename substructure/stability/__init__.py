"""Chatter stability of milling and turning: stability lobe diagrams from any tool point FRF.

A machinist has a tool point FRF (tapped, or predicted by the library) and a
cut; this package gives the stability lobe diagram: for every spindle speed
the largest axial depth of cut free of chatter, the chatter frequency, the
best speeds, and how much the lobes move when the FRF changes.

* :class:`MillingCut`, :class:`TurningCut`: the cut, with units
  (:mod:`~substructure.stability.cutting`).
* :func:`xy_frf`: the tool point receptances in x (feed) and y from FRFs.
* :class:`Mode`, :class:`ModalModel`, :class:`ModalFitter`, :func:`fit_modes`:
  modal parameters, given or fitted.
* :func:`zoa`: zero-order approximation (Altintas & Budak), from FRF data or
  modes; all lobes, the envelope, the absolute limit.
* :func:`sdm`: semi-discretization (Insperger & Stepan), from modes; right at
  low radial immersion where the zero order is not.
* :class:`Lobes`, :func:`lobes_band`: results, several on one plot, and a
  band from an FRF uncertainty band.
* :func:`window_removed`, :func:`mode_without_window`: the damping of an
  exponential window taken out of a tapped FRF (``substructure tap``
  applies one when the response still rings at the end of the taps).
* :func:`flexible_band`, :func:`assembly_structure`: the part of a tool point
  FRF stability may use (no rigid-body or suspension lines).
* :func:`recommend`, :class:`MachineLimits`, :class:`Recommendation`: the
  spindle speed and depth of cut to use, with a stated margin, within the
  machine's speed, power, torque and depth.
* :func:`workpiece`, :class:`Workpiece`: published cutting coefficients of
  common work materials, by name (aliases and the shop's spellings).
* :func:`cutting_data`, :func:`cutting_conditions`, :func:`check_cutting`:
  cutting speed (m/min, SFM), feed per tooth and feed rate, checked against
  the usual range per work and tool material.

Spindle speeds are in rpm (:func:`spindle_speeds`), depths in m, frequencies
in Hz; see ``docs/stability.md``.

Examples
--------
>>> from substructure.stability import MillingCut, ModalModel, Mode, spindle_speeds, zoa
>>> cut = MillingCut(2, "10 mm", "10 mm", kt="6e8 Pa", kn="2e8 Pa", milling="down")
>>> model = ModalModel([Mode("x", "922 Hz", 0.011, f"{0.03993 * (2 * 3.141592653589793 * 922) ** 2} N/m")])
>>> lobes = zoa(model, cut, spindle_speeds("5000 rpm", "25000 rpm", "10 rpm"))
>>> round(lobes.absolute_limit_m * 1e3, 4)
0.2981
"""

from .band import FlexibleBand, assembly_structure, choose_band, flexible_band
from .cutting_data import (CuttingData, CuttingDataWarning, check_cutting, cutting_conditions, cutting_data,
                           load_cutting_data)
from .cutting import MillingCut, TurningCut, as_speed_rpm, spindle_speeds, tooth_passing_hz
from .machine import MachineLimits, SpeedCurve, cut_power, cut_torque, removal_rate
from .modal import MODES_CSV_HEADER, ModalFitter, ModalFitWarning, ModalModel, Mode, fit_modes
from .result import Lobes, LobesBand, StabilityWarning, lobes_band
from .sdm import sdm, spectral_radius
from .structure import XY_LABELS, xy_frf
from .recommend import RECOMMENDATION_KEYS, NoRecommendationError, Recommendation, recommend
from .workpieces import Workpiece, load_workpieces, workpiece, workpieces
from .window import WindowRemoved, mode_without_window, window_removed
from .zoa import zoa

__all__ = [
    "MillingCut", "TurningCut", "spindle_speeds", "as_speed_rpm", "tooth_passing_hz",
    "Mode", "ModalModel", "ModalFitter", "fit_modes", "ModalFitWarning", "MODES_CSV_HEADER",
    "xy_frf", "XY_LABELS", "zoa", "sdm", "spectral_radius",
    "Lobes", "LobesBand", "lobes_band", "StabilityWarning",
    "FlexibleBand", "flexible_band", "choose_band", "assembly_structure",
    "MachineLimits", "SpeedCurve", "cut_power", "cut_torque", "removal_rate",
    "Recommendation", "recommend", "RECOMMENDATION_KEYS", "NoRecommendationError",
    "Workpiece", "workpiece", "workpieces", "load_workpieces",
    "CuttingData", "CuttingDataWarning", "cutting_data", "load_cutting_data", "cutting_conditions", "check_cutting",
    "window_removed", "mode_without_window", "WindowRemoved",
]
