"""Peaks of sampled curves: :func:`local_maxima`, the rules of ``scipy.signal.find_peaks``.

Used by :meth:`FRF.peaks <substructure.frf.FRF.peaks>` and by the modal fit
for starting values; written with whole-array numpy operations so that a
plain peak search does not load ``scipy.signal``.
"""

from __future__ import annotations

import numpy as np

from ..errors import InvalidValueError

__all__ = ["local_maxima"]


def local_maxima(values: np.ndarray) -> np.ndarray:
    """Indices of the local maxima of a 1-D real array, ascending.

    Parameters
    ----------
    values : ndarray
        Real values, 1-D (e.g. ``|H|`` over the frequency lines).

    Returns
    -------
    ndarray of int
        A run of equal values (one value or more) that is higher than the
        values just before and just after it gives one index, the middle of
        the run (the left one of two middles); runs at either end of the
        array give none.  The same peaks as ``scipy.signal.find_peaks``
        without conditions, found with whole-array numpy operations.
    """
    x = np.asarray(values)
    if x.ndim != 1:
        raise InvalidValueError(f"values: got shape {x.shape}; expected a 1-D array")
    if x.size < 3:
        return np.zeros(0, dtype=np.intp)
    change = np.flatnonzero(x[1:] != x[:-1])  # a new run starts after each of these
    starts = np.concatenate(([0], change + 1))
    ends = np.concatenate((change, [x.size - 1]))
    level = x[starts]
    higher = np.zeros(level.size, dtype=bool)
    higher[1:] = level[1:] > level[:-1]  # rises into the run
    higher[:-1] &= level[1:] < level[:-1]  # and falls after it
    higher[-1] = False
    return (starts[higher] + ends[higher]) // 2
