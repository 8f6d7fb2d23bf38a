"""Studies: Monte Carlo runs and parameter sweeps of simulation and identification.

A study file (:mod:`~stewartid.studies.spec`) names the fixed settings and a grid; every
(grid point, seed) becomes a task (:mod:`~stewartid.studies.grid`) that simulates the six
experiments and identifies them with every method (:mod:`~stewartid.studies.task`). The
tasks run on dask.distributed (:mod:`~stewartid.studies.runner`), their rows are stored as a
partitioned Parquet data set (:mod:`~stewartid.studies.results`), and a report with figures
sums them up (:mod:`~stewartid.studies.report`). ``stewartid study FILE --out DIR`` runs it
all; dask comes with the ``[dask]`` extra.
"""

from stewartid.studies.grid import StudyTask, expand_grid
from stewartid.studies.results import read_results
from stewartid.studies.runner import StudyRun, run_study
from stewartid.studies.spec import StudySpec, load_study, parse_study

__all__ = ["StudyRun", "StudySpec", "StudyTask", "expand_grid", "load_study", "parse_study",
           "read_results", "run_study"]
