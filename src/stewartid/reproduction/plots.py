"""A reproduction's figures, drawn on the worker pool in report order with their captions."""

from __future__ import annotations

from collections.abc import Callable, Sequence
from concurrent.futures import Executor, Future
from pathlib import Path
from typing import Any

import numpy as np

from stewartid.platform import COORDINATES, Platform
from stewartid.reports.drawing import ExperimentTrace, plot_excitation, plot_joint_rates
from stewartid.reproduction.comparison import ComparisonResults
from stewartid.reproduction.figures import (
    plot_errors,
    plot_force_budget,
    plot_identified_vs_nominal,
    plot_scalogram,
)
from stewartid.reproduction.report import FigureEntry
from stewartid.reproduction.settings import TRACE_EXPERIMENT
from stewartid.reproduction.traces import experiment_trace, reference_poses


class FigureQueue:
    """Figures submitted to the pool, with their report captions, in report order."""

    def __init__(self, pool: Executor, folder: Path, bar: Any, task: Any):
        self.pool, self.folder, self.bar, self.task = pool, folder, bar, task
        self.submitted: list[tuple[Future, FigureEntry]] = []

    def submit(self, function: Callable[..., Any], stem: str, caption: str, *args: Any,
               **kwargs: Any) -> None:
        """Draw ``function(*args, directory=folder, stem=stem, **kwargs)`` on the pool as ``stem``."""
        future = self.pool.submit(function, *args, directory=self.folder, stem=stem, **kwargs)
        future.add_done_callback(lambda _: self.bar.advance(self.task))
        self.submitted.append((future, FigureEntry(f"figures/{stem}.png", caption)))

    def finish(self) -> tuple[list[FigureEntry], list[Path]]:
        """Wait for every figure; returns their report entries and the files written."""
        files: list[Path] = []
        for future, _ in self.submitted:
            files += future.result()
        return [entry for _, entry in self.submitted], files


def submit_signal_figures(figures: FigureQueue, plant: Platform, datasets: Sequence[Any],
                    record: Any, level: float, frequency_hz: float) -> list[Any]:
    """Submit the excitation, joint-velocity and force-budget figures; return the traces."""
    references = reference_poses(plant, frequency_hz, [d.t for d in datasets])
    traces = []
    for k, dataset in enumerate(datasets):
        if k == TRACE_EXPERIMENT:
            traces.append(experiment_trace(plant, dataset, k, frequency_hz, references[k],
                                           record))
        else:
            traces.append(ExperimentTrace(name=str(dataset.name), excited=k,
                                          t=np.asarray(dataset.t),
                                          pose=np.asarray(dataset.pose),
                                          neutral=np.asarray(plant.neutral_pose),
                                          reference=references[k]))
    trace = traces[TRACE_EXPERIMENT]
    figures.submit(plot_excitation, "excitation",
                   f"Excitation at Coulomb {level:g} N·m: each experiment drives one "
                   f"coordinate with a {frequency_hz:g} Hz sine; commanded, measured and "
                   "tracking error.", traces)
    figures.submit(plot_joint_rates, "joint_velocities",
                   f"Joint velocities of {trace.name} at Coulomb {level:g} N·m; shaded: the "
                   "constant-direction intervals in which no joint reverses.", trace)
    figures.submit(plot_force_budget, "force_budget",
                   f"Force budget of {trace.name} at Coulomb {level:g} N·m: the model's "
                   "inertial, viscous, Coulomb and gravity terms along the simulated motion, "
                   "and the measured actuators' generalized force.", trace)
    return traces


def submit_comparison_figures(figures: FigureQueue, results: ComparisonResults, level: float,
                        traces: Sequence[Any]) -> None:
    """Submit the scalogram and the figures that compare methods."""
    trace = traces[TRACE_EXPERIMENT]
    scalogram = _scalogram_arguments(results, level, trace)
    if scalogram is not None:
        figures.submit(plot_scalogram, "scalogram",
                       f"Scalogram of the excited equation of {trace.name} at Coulomb "
                       f"{level:g} N·m, with the (a, b) points Method B used.", **scalogram)
    figures.submit(plot_errors, "errors",
                   "ε per entry at each Coulomb level: every method, and the paper's "
                   "published ε (hatched) where it reports one.", results)
    for value in results.coulomb_levels:
        figures.submit(plot_identified_vs_nominal,
                       f"identified_vs_nominal_coulomb{value:g}",
                       f"Identified / nominal per entry at Coulomb {value:g} N·m.", results,
                       value)


def _scalogram_arguments(results: ComparisonResults, level: float, trace: Any
                         ) -> dict[str, Any] | None:
    """Signal, (a, b) points and wavelet of Method B on the traced experiment, if it ran."""
    run = results.run("wavelet", level) or results.run("wavelet-paper", level)
    if run is None:
        return None
    details = run.result.diagnostics
    chosen = next((e for e in details.get("experiments") or []
                   if e.get("name") == trace.name), None)
    if chosen is None:
        return None
    points = np.column_stack([np.asarray(chosen.get("scales", []), dtype=float),
                              np.asarray(chosen.get("shifts", []), dtype=float)])
    k = trace.excited
    unit = "N" if k < 3 else "N·m"
    return {"t": trace.t, "signal": trace.forces["actuators"][:, k], "points": points,
            "wavelet": details.get("wavelet", "mexican_hat"),
            "signal_label": f"(Jᵀ f)_{COORDINATES[k]} ({unit})",
            "intervals": np.asarray(chosen.get("intervals", []), dtype=float).reshape(-1, 2)}


__all__ = ["FigureQueue", "submit_comparison_figures", "submit_signal_figures"]
