"""Frequency response functions: the value object every other layer exchanges.

A :class:`Frequency` is an immutable, strictly increasing axis in Hz (``omega``
derived); an :class:`FRF` holds complex data ``(n_freq, n_out, n_in)`` on it, with
DOF labels (``"tool.tip:y"``, ``"tool.tip:theta"``) and its quantity (receptance,
mobility, accelerance).  Both are frozen: band selection, interpolation, label
selection and arithmetic return new objects, and FRFs on different axes are never
reconciled silently.  Plots and files are delegated to :mod:`substructure.plot`
and :mod:`substructure.io.frf_files`, imported on use.

The package holds one concept per module: ``axis`` (:class:`Frequency`),
``response`` (:class:`FRF`), ``_fields`` (the checks of an FRF's fields) and
``peaks`` (:func:`local_maxima`) and ``passivity`` (:func:`reversed_share`, the
sign of a driving point); every name is imported from here.
"""

from __future__ import annotations

from ._fields import QUANTITIES
from .axis import MAX_GRID_LINES, Frequency
from .passivity import REVERSED_SHARE, reversed_share
from .peaks import local_maxima
from .response import FRF, frf_checked

__all__ = ["Frequency", "FRF", "frf_checked", "QUANTITIES", "MAX_GRID_LINES", "local_maxima", "reversed_share",
           "REVERSED_SHARE"]
