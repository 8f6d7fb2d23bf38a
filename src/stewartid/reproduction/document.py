"""A reproduction's ``results.json``: every result of a run as one JSON document, and back."""

from __future__ import annotations

import json
from collections.abc import Sequence
from datetime import UTC, datetime
from pathlib import Path
from typing import Any

import numpy as np

from stewartid.errors import DataError
from stewartid.files import to_jsonable
from stewartid.identification.result import IdentificationResult
from stewartid.reference.published import (
    PAPER_ENTRIES,
    entry_label,
    load_published,
    relative_error_percent,
)
from stewartid.reproduction.comparison import ComparisonResults, MethodRun
from stewartid.reproduction.report import summary_lines

#: Method names of files written before the registry (read as the registry's names).
LEGACY_METHOD_NAMES = {"least_squares": "ls", "wavelet_paper": "wavelet-paper"}


def run_record(results: ComparisonResults, run: MethodRun) -> dict[str, Any]:
    """One identification as a JSON-ready dict: matrices, standard errors, ε per entry and the
    largest, the paper's values where published, time and diagnostics."""
    eps = results.eps_all(run)
    worst = max(eps, key=eps.__getitem__)
    published = {}
    for key in PAPER_ENTRIES:
        entry = results.published_entry(run.method, run.coulomb, key)
        if entry is not None:
            published[entry_label(key)] = {"value": entry.value, "eps": entry.eps}
    return {
        "method": run.method, "coulomb": run.coulomb,
        "M": run.result.M.tolist(), "B": run.result.B.tolist(),
        "std_errors_M": run.result.std_errors_M, "std_errors_B": run.result.std_errors_B,
        "eps": {entry_label(k): v for k, v in eps.items()},
        "max_eps": eps[worst], "max_eps_entry": entry_label(worst),
        "eps_all_entries": {
            "M": relative_error_percent(run.result.M, results.nominal_M),
            "B": relative_error_percent(run.result.B, results.nominal_B)},
        "published": published or None,
        "seconds": run.seconds,
        "diagnostics": run.diagnostics,
    }


def results_document(results: ComparisonResults, runtime_s: float,
                     files: Sequence[str] = ()) -> dict[str, Any]:
    """Everything of a run as a JSON-ready dict: settings, nominal matrices and every run's record."""
    from stewartid import __version__

    runs = [run_record(results, run) for run in results.runs]
    return to_jsonable({
        "package": "stewartid", "version": __version__,
        "created": datetime.now(UTC).isoformat(timespec="seconds"),
        "runtime_s": runtime_s, "seed": results.settings.get("seed"),
        "settings": results.settings,
        "reference": {"citation": results.published.citation, "doi": results.published.doi},
        "nominal": {"M": results.nominal_M, "B": results.nominal_B},
        "eps_definition": "|identified - nominal| / |nominal| * 100 (%), nominal of the "
                          "simulated plant at the neutral pose; eps_all_entries is null where "
                          "the nominal entry is zero",
        "runs": runs,
        "summary": summary_lines(results),
        "files": list(files),
    })


def _method_run(item: dict[str, Any]) -> MethodRun:
    """A :class:`MethodRun` from its :func:`run_record`, as far as it keeps it."""
    method = LEGACY_METHOD_NAMES.get(item["method"], str(item["method"]))
    diagnostics = dict(item.get("diagnostics", {}))
    result = IdentificationResult.from_dict({
        **{key: item.get(key) for key in ("M", "B", "std_errors_M", "std_errors_B")},
        "condition_number": diagnostics.get("condition_number"),
        "residual_rms": diagnostics.get("residual_rms"), "method": method,
        "settings": diagnostics.get("settings", {}),
        "diagnostics": diagnostics.get("details", {})})
    return MethodRun(method=method, coulomb=float(item["coulomb"]), result=result,
                     seconds=float(item.get("seconds", 0.0)))


def load_results(path: str | Path) -> ComparisonResults:
    """Rebuild the :class:`ComparisonResults` of a run from its ``results.json``."""
    path = Path(path)
    try:
        document = json.loads(path.read_text(encoding="utf-8"))
        runs = tuple(_method_run(item) for item in document["runs"])
        nominal_M = np.asarray(document["nominal"]["M"], dtype=float)
        nominal_B = np.asarray(document["nominal"]["B"], dtype=float)
    except (KeyError, TypeError, ValueError) as exc:
        raise DataError(f"{path}: not a results.json written by 'stewartid reproduce' "
                        f"({type(exc).__name__}: {exc}).") from None
    return ComparisonResults(runs, nominal_M, nominal_B, load_published(),
                             dict(document.get("settings", {})))


__all__ = ["LEGACY_METHOD_NAMES", "load_results", "results_document", "run_record"]
