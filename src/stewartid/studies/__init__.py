"""Studies: Monte Carlo runs and parameter sweeps of simulation and identification on
dask.distributed (``stewartid study FILE --out DIR``, the ``[dask]`` extra)."""

from stewartid.studies.grid import StudyTask, expand_grid
from stewartid.studies.results import read_results
from stewartid.studies.runner import StudyRun, run_study
from stewartid.studies.spec import StudySpec, load_study, parse_study

__all__ = ["StudyRun", "StudySpec", "StudyTask", "expand_grid", "load_study", "parse_study",
           "read_results", "run_study"]
