"""Whole tool libraries: every holder/tool combination on its machines, for every cut, on Dask.

A shop (or a research group with virtual designs) has hundreds of
holder/tool combinations on several machines.  A :class:`Study` computes,
for each combination on each machine, the tool point FRF (the joint from an
explicit table or predicted by a surrogate, with its uncertainty band), the
tool mode and its band, the stability lobes of every cut (zero order and/or
semi-discretization) and the recommended spindle speed and depth with a
margin that holds over the band.  Each combination is one task on Dask
(a local cluster, an existing scheduler or a notebook's client); each
finished combination is saved as it completes, an interrupted study
resumes where it stopped, a bad combination fails its own rows only, and
the results come back as one table (pandas; Parquet and CSV files) with a
figure per combination and a summary that ranks them.

* :class:`Study` (``Study.from_file``, ``Study.tasks``, ``Study.run``) and
  its parts :class:`Machine`, :class:`Combination`, :class:`Cut`,
  :class:`Compute`, :class:`Grid`, :class:`SurrogateSpec`.
* :data:`COLUMNS`: the table's columns, units and meaning.

Needs the ``study`` extra (dask[distributed], pandas, pyarrow), imported
when a study runs.  See docs/study.md.
"""

from .settings import METHODS, Compute, Grid
from .spec import FEATURE_SOURCES, Combination, Cut, Machine, SurrogateSpec
from .study import Study, task_key, task_seed
from .table import COLUMNS

__all__ = ["Study", "Machine", "Combination", "Cut", "Compute", "Grid", "SurrogateSpec", "COLUMNS",
           "FEATURE_SOURCES", "METHODS", "task_key", "task_seed"]
