"""A reproduction's noisy case: every method at the highest Coulomb level with the reference sensor
noise (the paper shows noise-free simulations only); a table, a figure and a summary line."""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence

from stewartid.reference.published import PAPER_ENTRIES, entry_label
from stewartid.reports.methods import method_name
from stewartid.reports.tables import ResultTable
from stewartid.reproduction.comparison import ComparisonResults, MethodRun
from stewartid.reproduction.document import run_record
from stewartid.reproduction.tables import comparison_table

#: Multiple of the reference sensor noise in the noisy case.
NOISE_SCALE = 1.0
#: File stem of the noisy case's table and figure.
STEM = "noisy"


def within_three_std(results: ComparisonResults, run: MethodRun) -> int:
    """Number of the 20 paper entries whose error is at most 3 reported standard errors."""
    count = 0
    for key in PAPER_ENTRIES:
        error = abs(run.value(key) - results.nominal(key))
        count += bool(error <= 3.0 * run.std_error(key))
    return count


def noisy_summary(results: ComparisonResults) -> str:
    """One line: per method, the largest ε over the 20 entries and the entries within 3 SE."""
    level = max(results.coulomb_levels)
    parts = []
    for method in results.methods:
        run = results.run(method, level)
        if run is None:
            continue
        key, eps = results.worst(run)
        parts.append(f"{method_name(method)} {eps:.3g} % ({entry_label(key)}), "
                     f"{within_three_std(results, run)}/20 within 3 SE")
    return (f"With the reference sensor noise at Coulomb {level:g} N·m (20 µm leg lengths, "
            f"0.5 % of the static leg force): largest ε " + "; ".join(parts) + ".")


def noisy_table(results: ComparisonResults) -> ResultTable:
    """The comparison of every method at the noisy level, with the standard errors' check."""
    level = max(results.coulomb_levels)
    table = comparison_table(results, level)
    notes = (noisy_summary(results),
             "The paper's columns (where shown) are its noise-free values.")
    return dataclasses.replace(
        table, name=f"comparison_coulomb{level:g}_{STEM}",
        title=f"All methods, Coulomb friction {level:g} N·m, reference sensor noise",
        notes=notes)


def noisy_results(runs: Sequence[MethodRun], clean: ComparisonResults) -> ComparisonResults:
    """The noisy runs with the clean run's nominal values, published tables and settings."""
    return ComparisonResults(tuple(runs), clean.nominal_M, clean.nominal_B, clean.published,
                             dict(clean.settings))


def noisy_document(results: ComparisonResults) -> dict:
    """JSON-ready noisy case (``results.json`` key ``noise_case``), each run with ``within_3_std``."""
    level = max(results.coulomb_levels)
    runs = [{**run_record(results, run), "within_3_std": within_three_std(results, run)}
            for run in (results.run(m, level) for m in results.methods) if run is not None]
    return {"coulomb": level, "noise_scale": NOISE_SCALE,
            "noise": "reference: 20 um leg lengths (pose by forward kinematics), 0.5 % of "
                     "the static leg force",
            "runs": runs, "summary": noisy_summary(results)}


__all__ = ["NOISE_SCALE", "STEM", "noisy_document", "noisy_results", "noisy_summary",
           "noisy_table", "within_three_std"]
