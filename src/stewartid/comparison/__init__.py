"""Every method fitted to the same experiments, validated on held-out data and judged:
:func:`compare_methods` returns a :class:`Comparison`, which the identification report renders
(:func:`stewartid.write_report`)."""

from stewartid.comparison._compare import (
    ALL_METHODS,
    Comparison,
    check_jobs,
    compare_methods,
    method_names,
    plausibility_check,
)
from stewartid.comparison._delay import (
    DELAY_SIGNIFICANCE,
    Alignment,
    align_experiments,
    delay_note,
)
from stewartid.comparison._physical import (
    PhysicalRequest,
    fit_physical,
    largest_couplings,
    workspace,
)
from stewartid.comparison._records import MethodFit, PhysicalSection, Workspace
from stewartid.comparison._runs import (
    consensus_run,
    consistent_result,
    judge,
    run_method,
    same_segments,
)

__all__ = ["ALL_METHODS", "DELAY_SIGNIFICANCE", "Alignment", "Comparison", "MethodFit", "PhysicalRequest",
           "PhysicalSection", "Workspace", "align_experiments", "check_jobs", "compare_methods",
           "consensus_run", "consistent_result", "delay_note", "fit_physical", "judge",
           "largest_couplings", "method_names", "plausibility_check", "run_method",
           "same_segments", "workspace"]
