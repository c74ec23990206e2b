"""Measurement sets: which measured FRFs exist, where they were taken, on what configuration.

A :class:`Measurement` is one measured FRF (a tap test: the response at one
DOF to a force at another) together with the configuration of the structure
during the test: the sensors that were on it and the components that were
taken off.  A :class:`MeasurementSet` gathers the measurements of one test
campaign on one frequency axis, builds the translational receptance matrices
that identification needs (:meth:`MeasurementSet.matrix`, using reciprocity
only when asked to) and checks itself against an assembly
(:meth:`MeasurementSet.validate`).  Both are frozen value objects; files in
the format of docs/file-formats.md ("Measurement set (TOML)") are read by
:mod:`substructure.io.measurements`.

The package holds ``measurement`` (:class:`Measurement`, :func:`dof_label`, the errors),
``measurement_set`` (:class:`MeasurementSet`, :func:`model_of_measurement`) and ``files`` (the
reading of measurement files, into the class it is given); every name is imported from here.
"""

from __future__ import annotations

from .measurement import Measurement, MeasurementSetError, MissingMeasurementError, dof_label
from .measurement_set import MeasurementSet, model_of_measurement

__all__ = ["Measurement", "MeasurementSet", "MeasurementSetError", "MissingMeasurementError", "dof_label",
           "model_of_measurement"]
