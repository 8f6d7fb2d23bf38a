"""Studies: Monte Carlo runs and parameter sweeps of simulation and identification.

``stewartid study FILE --out DIR`` runs every (grid point, seed) of a study file on
dask.distributed (the ``[dask]`` extra) and reports the errors of every method.
"""

from stewartid.studies.grid import StudyTask, expand_grid
from stewartid.studies.results import read_results
from stewartid.studies.runner import StudyRun, run_study
from stewartid.studies.spec import StudySpec, load_study, parse_study

__all__ = ["StudyRun", "StudySpec", "StudyTask", "expand_grid", "load_study", "parse_study",
           "read_results", "run_study"]
