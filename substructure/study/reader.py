"""Study files: a TOML file (and optionally a CSV file of combinations) read into a :class:`Study`.

The format is docs/file-formats.md, "substructure study".  Every problem
of the structure (TOML syntax, unknown or missing keys, wrong types, units
of the values every combination shares, names that do not exist) raises
:class:`~substructure.errors.FileFormatError` whose message starts with
the file and the line and names the key path (``cuts[1].radial_depth``,
``combinations[3].tool.diameter``; for the CSV file the line and the
column).  The values of one combination's tool, holder and joint are
checked when it is computed: a bad combination fails its rows, with the
file and line in the message, and the study goes on.  The reading itself
is in ``substructure.study._reader``, which :meth:`Study.from_file` uses too.
"""

from __future__ import annotations

from typing import Any

from ._reader import TOP_KEYS, read_combinations_csv, read_study, reads_study
from .study import Study

__all__ = ["load_study", "loads_study", "read_combinations_csv", "TOP_KEYS"]


def loads_study(text: str, source: str = "<string>", base: Any = ".") -> Study:
    """Read a study from TOML text.

    Parameters
    ----------
    text : str
        The study file's text.
    source : str
        Its name in messages.
    base : str or path
        The folder that relative file names are relative to.

    Returns
    -------
    Study
        The study.
    """
    return reads_study(Study, text, source, base)


def load_study(path: Any) -> Study:
    """Read a study file (TOML).

    Parameters
    ----------
    path : str or path
        The study file.

    Returns
    -------
    Study
        The study; relative file names in it are relative to its folder.
    """
    return read_study(Study, path)
