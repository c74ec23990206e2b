"""Measurement files (TOML): read a measurement set in the format of docs/file-formats.md.

A measurement file says which measured FRFs exist, where they were taken and
on what configuration::

    name = "bench test, 12 mm tool, 60 mm overhang"

    [[frf]]
    response = "tool.tip"            # point[:dof], dof y by default
    excitation = "tool.tip"
    file = "tool_tip__tool_tip.csv"  # CSV, or a UFF file with `record = N` (0-based)
    quantity = "receptance"          # receptance (default) | mobility | accelerance
    sensors = ["accelerometer"]      # optional: sensors on the structure in this test
    removed = ["tool"]               # optional: components taken off for this test
    averages = 10                    # optional: taps averaged into the FRF (substructure tap writes it)

:func:`load_measurements` and :func:`loads_measurements` (and :meth:`MeasurementSet.from_file`;
the reading itself is in ``substructure.measurements.files``) return a
:class:`~substructure.measurements.MeasurementSet`.  Data file paths are
relative to the measurement file.  Files ending in ``.csv`` are CSV
(``frequency_hz,real,imag``); ``.uff`` and ``.unv`` are universal files,
read with :func:`~substructure.io.frf_files.read_uff` (which takes the
quantity and the units from the record).  Mobilities and accelerances are
converted to receptances on reading; their 0 Hz line, which has no
receptance, is dropped with a warning.

Every problem raises :class:`~substructure.errors.FileFormatError` whose
message starts with the measurement file (and the line, where it can be
found), names the key path (``frf[2].file``) and, for problems of the data,
the data file: unknown keys, missing or mistyped values, unknown quantities,
missing or unreadable data files, NaN or non-increasing frequencies in them,
dead channels (an FRF that is 0 at every line), values beyond any measured
structure (a receptance above 1 m/N, ``RECEPTANCE_LIMIT``; a mobility or an
accelerance divided by ``2 pi f`` once or twice first), and data files on
different frequency grids (never reconciled silently).  A CSV data file
with a fourth column ``coherence`` (written by ``substructure tap``) gives
the measurement its coherence, cropped with the FRF when a 0 Hz line is
dropped.  Records of other programs, whose points are node numbers, are
compared with the tables: a driving point read from a record of two nodes,
or a node read as two points (one point from two nodes) in one file and
configuration, is warned of (a ``SubstructureWarning`` naming the table and
the record; a record index counted from 1, most often).
"""

from __future__ import annotations

import os

from ..measurements import MeasurementSet
from ..measurements.files import read_measurements, reads_measurements

__all__ = ["load_measurements", "loads_measurements"]


def loads_measurements(text: str, base_dir: str | os.PathLike = ".", source: str = "<string>") -> MeasurementSet:
    """Read a measurement set from TOML text.

    Parameters
    ----------
    text : str
        The TOML document (docs/file-formats.md, "Measurement set").
    base_dir : str or path-like
        Directory that relative data file paths start from.
    source : str
        Name of the text in error messages, e.g. the file name.

    Returns
    -------
    MeasurementSet
        Measurements in the order of the ``[[frf]]`` tables, receptances.
        ``Measurement.quantity`` is the quantity the file gave (for a
        UFF record without ``quantity``: the one the record states, by
        default receptance).

    Raises
    ------
    FileFormatError
        Naming ``source``, the key path and the data file; see the module
        documentation for the checks.
    """
    return reads_measurements(MeasurementSet, text, base_dir, source)


def load_measurements(path: str | os.PathLike) -> MeasurementSet:
    """Read a measurement file; data file paths are relative to it (see :func:`loads_measurements`).

    Parameters
    ----------
    path : str or os.PathLike
        The measurement set file (TOML).

    Returns
    -------
    MeasurementSet
        The measurements, their FRFs read; errors name the file and the key.
    """
    return read_measurements(MeasurementSet, path)
