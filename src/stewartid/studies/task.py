"""One study task on a worker: a simulation of the six experiments identified by every method, as
result rows. Picklable; writes nothing."""

from __future__ import annotations

import math
import time
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from stewartid.errors import StewartidError
from stewartid.identification.registry import estimates_only
from stewartid.platform import Platform
from stewartid.reference.published import PAPER_ENTRIES, entry_label, relative_error_percent
from stewartid.simulation import simulate_experiments
from stewartid.simulation.sensors import reference_noise
from stewartid.studies.grid import StudyTask
from stewartid.studies.results import ENTRY_COLUMNS


def _worker_address() -> str | None:
    try:
        from distributed import get_worker

        return str(get_worker().address)
    except (ImportError, ValueError):
        return None


def error_columns(M: np.ndarray, B: np.ndarray, nominal_M: np.ndarray, nominal_B: np.ndarray
                  ) -> dict[str, Any]:
    """A row's error columns: ε (%) of the paper's 20 entries and their maxima.

    ``M, B`` identified, ``nominal_M, nominal_B`` true, shape (6, 6), SI units."""
    matrices = {"M": (M, nominal_M), "B": (B, nominal_B)}
    errors = {key: relative_error_percent(matrices[key[0]][0][key[1], key[2]],
                                          matrices[key[0]][1][key[1], key[2]])
              for key in PAPER_ENTRIES}
    finite = {key: value for key, value in errors.items() if math.isfinite(value)}
    worst = max(finite, key=finite.__getitem__) if finite else None
    row: dict[str, Any] = {
        "max_error_percent": math.nan if worst is None else finite[worst],
        "max_error_entry": None if worst is None else entry_label(worst),
    }
    for matrix in ("M", "B"):
        values = [value for key, value in finite.items() if key[0] == matrix]
        row[f"max_error_{matrix}_percent"] = max(values) if values else math.nan
    row.update(zip(ENTRY_COLUMNS, errors.values(), strict=True))
    return row


def _failed(message: str) -> dict[str, Any]:
    return {"max_error_percent": math.nan, "max_error_entry": None,
            "max_error_M_percent": math.nan, "max_error_B_percent": math.nan,
            **dict.fromkeys(ENTRY_COLUMNS, math.nan), "run_time_s": math.nan,
            "failure": message}


def run_task(task: StudyTask, platform: Platform, methods: Sequence[str],
             method_settings: Mapping[str, Mapping[str, Any]] | None = None,
             actuator: str | None = None) -> list[dict[str, Any]]:
    """Simulate the six experiments at ``task``'s point and identify them with each method.

    A :class:`~stewartid.errors.StewartidError` is a result (NaN errors, message in ``failure``);
    any other exception propagates.

    Parameters
    ----------
    task : StudyTask
    platform : Platform
        The task's friction is applied to it.
    methods : sequence of str
    method_settings : mapping, optional
        ``{method: {setting: value}}``.
    actuator : {"hydraulic", "ideal"}, optional
        Overrides ``[hydraulics] mode``.

    Returns
    -------
    list of dict
        One row per method (:func:`stewartid.studies.results.columns`).
    """
    point = task.parameters
    common = {"task": task.key, **point, "seed": int(task.seed), "worker": _worker_address()}
    cpu_start = time.thread_time()
    start = time.perf_counter()
    try:
        run = simulate_experiments(
            platform, coulomb=point["coulomb"], viscous=point["viscous"],
            frequency_hz=point["frequency"], duration_s=point["duration"],
            noise=reference_noise(platform, point["noise_scale"]), seed=int(task.seed),
            actuator=actuator)
    except StewartidError as exc:
        elapsed = time.perf_counter() - start
        return [{**common, "method": method, **_failed(f"simulation: {exc}"),
                 "simulation_time_s": elapsed,
                 "task_cpu_time_s": time.thread_time() - cpu_start} for method in methods]
    simulation_time = time.perf_counter() - start
    nominal_M = np.asarray(run.meta["nominal"]["M"], dtype=float)
    nominal_B = np.asarray(run.meta["nominal"]["B"], dtype=float)
    plant = platform.replace(friction__coulomb=point["coulomb"],
                             friction__gimbal_viscous=point["viscous"])
    rows = []
    for method in methods:
        settings = dict((method_settings or {}).get(method, {}))
        start = time.perf_counter()
        try:
            estimator = estimates_only(method, **settings).fit(run.datasets, plant)
        except StewartidError as exc:
            row = _failed(f"{method}: {exc}")
        else:
            row = {**error_columns(np.asarray(estimator.M_), np.asarray(estimator.B_),
                                   nominal_M, nominal_B), "failure": None}
        row["run_time_s"] = time.perf_counter() - start
        rows.append({**common, "method": method, **row, "simulation_time_s": simulation_time})
    # one-thread CPU time does not grow when other processes compete for the cores
    cpu_time = time.thread_time() - cpu_start
    return [{**row, "task_cpu_time_s": cpu_time} for row in rows]


__all__ = ["error_columns", "run_task"]
