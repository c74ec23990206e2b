"""Reading and writing measured FRFs: CSV files and universal files (type 58).

CSV (conventions.md): one FRF per file, header ``frequency_hz,real,imag``,
one line per frequency, receptance in m/N unless the measurement description
says otherwise.  Values are written with every digit (``repr``), so that
reading a written file gives back the same floats.

UFF: type-58 records ("function at nodal DOF"), read and written with
``pyuff`` in ASCII form, one record per entry of the FRF, function type 4
(frequency response function).  The DOF labels, the quantity and the exact
grid are kept in the five ID lines of each record (``response=LABEL``,
``excitation=LABEL``, ``quantity=NAME``, ``grid start=.. step=.. n=..``), so
that they come back; node numbers and direction codes (``y`` -> 2,
``theta`` -> 6, rotation about z) are filled in for other programs.

Precision of UFF files: pyuff writes the ordinates with 12 significant digits
(``E20.11``), so values come back within 5e-12 relative per real and
imaginary part.  It writes abscissae with 6 significant digits (``E13.5``);
the exact grid is therefore recovered from the ID line for uniform grids,
non-uniform grids are written only when every frequency has at most 6
significant digits, and any other grid is refused with an error that says
what to do.

The code is in ``substructure.frf.files``, one format per module: ``csv_files`` (:func:`read_csv`,
:func:`read_csv_with_coherence`, :func:`read_csv_window`, :func:`write_csv`; ``exports`` for other
programs' CSV exports),
``uff_writer`` (:func:`write_uff`), ``uff_reader`` (:func:`read_uff`,
:func:`read_uff_coherence`), ``mat_reader`` (:func:`read_mat`, :func:`read_mat_coherence`: the signal
structures of Simcenter Testlab's MATLAB exports) and ``uff_units`` (what a
type-58 record holds: its labels, quantity, units and abscissa), with ``_common`` for the checks
and codes they share.  It sits in the ``frf`` layer so that ``FRF.to_csv``, ``FRF.from_uff`` and
the other methods read and write without importing ``io``; every name is imported from here
(``substructure.io.frf_files.uff_units`` keeps its old place as well).
"""

from __future__ import annotations

from ...frf.files.csv_files import (  # noqa: F401 (CSV_HEADER: its old place)
    CSV_HEADER,
    read_csv,
    read_csv_window,
    read_csv_with_coherence,
    write_csv,
)
from ...frf.files.mat_reader import read_mat, read_mat_coherence
from ...frf.files.uff_reader import read_uff, read_uff_coherence
from ...frf.files.uff_writer import write_uff

__all__ = ["write_csv", "read_csv", "read_csv_with_coherence", "read_csv_window", "write_uff", "read_uff",
           "read_uff_coherence", "read_mat", "read_mat_coherence"]
