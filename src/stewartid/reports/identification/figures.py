"""The identification report's figures in report order: what is drawn, with which data and caption."""

from __future__ import annotations

from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from stewartid.comparison import MethodFit, PhysicalSection
from stewartid.datasets.dataset import Dataset
from stewartid.identification.preparation import prepare
from stewartid.identification.wavelet.intervals import joint_rates
from stewartid.parallel import inheriting_workers, longest_first, run_in_order
from stewartid.platform import Platform
from stewartid.reports.drawing import ExperimentTrace, plot_excitation, plot_joint_rates
from stewartid.reports.identification import method_figures as plots
from stewartid.reports.identification.text import used_intervals
from stewartid.signals.differentiation import differentiate


class FigureDrawer:
    """Collects the figures of one folder in report order, then draws them (:meth:`draw`).

    Attributes
    ----------
    folder : Path
    entries : dict of str to (str, str)
        Figure key -> (relative PNG path, caption), in report order.
    files : list of Path
        Every file written.
    """

    def __init__(self, folder: Path):
        self.folder = folder
        self.entries: dict[str, tuple[str, str]] = {}
        self.files: list[Path] = []
        self._pending: list[tuple[str, Callable[..., list[Path]], tuple]] = []

    def add(self, key: str, caption: str, function: Callable[..., list[Path]],
            *args: Any) -> None:
        """Have ``function(*args)`` drawn as ``figures/<key>.png`` and ``.svg``."""
        self.entries[key] = (f"figures/{key}.png", caption)
        self._pending.append((key, function, args))

    def draw(self, jobs: int | None = 1) -> list[Path]:
        """Draw every figure added, in ``jobs`` worker processes (None: every core); returns
        the files written."""
        pending, self._pending = self._pending, []
        workers = inheriting_workers(jobs, len(pending))
        if workers > 1:
            _load_matplotlib()
        # the longest first, so that the workers finish together; the files in report order
        order = longest_first(range(len(pending)), DRAWN_FIRST, key=lambda k: pending[k][0])
        written = dict(zip(order, run_in_order(_draw, order, workers,
                                               shared=(self.folder, pending)), strict=True))
        for k in range(len(pending)):
            self.files += written[k]
        return self.files


#: The figures that take longest to draw (many panels and lines), in that order.
DRAWN_FIRST = ("excitation", "residuals", "workspace", "spectrum", "validation", "joint_rates")


def _load_matplotlib() -> None:
    """Import matplotlib's figure and both file backends here, once, for the forked workers to
    inherit: each would otherwise import them itself (about 0.35 s of CPU)."""
    import matplotlib.backends.backend_agg  # noqa: F401
    import matplotlib.backends.backend_svg  # noqa: F401
    import matplotlib.figure  # noqa: F401


def _draw(work: tuple[Path, list], k: int) -> list[Path]:
    """Figure ``k`` of a :class:`FigureDrawer`'s pending list, drawn into its folder."""
    folder, pending = work
    key, function, args = pending[k]
    return function(*args, directory=folder, stem=key)


def data_figures(drawer: FigureDrawer, datasets: Sequence[Dataset], platform: Platform,
                 rows: Sequence[dict[str, Any]]) -> None:
    """The data's figures: excitation and spectrum."""
    neutral = np.asarray(platform.neutral_pose, dtype=float)
    traces = [ExperimentTrace(name=d.name, excited=row["excited"], t=d.t, pose=d.pose,
                              neutral=neutral) for d, row in zip(datasets, rows, strict=True)]
    drawer.add("excitation", "Measured motion of the most excited coordinate of each "
               "experiment (displacement from the neutral pose).", plot_excitation, traces)
    drawer.add("spectrum", "Amplitude spectrum of the motion of every coordinate; dashed: the "
               "dominant excitation frequency.", plots.plot_spectra,
               [d.name for d in datasets], [d.pose for d in datasets],
               [d.sample_rate for d in datasets], [row["frequency_hz"] for row in rows])


def _joint_rate_trace(dataset: Dataset, platform: Platform, row: dict[str, Any],
                      intervals: np.ndarray | None) -> ExperimentTrace:
    """The joint rates of one experiment, ready to plot; its joint-axis Jacobians, shape
    (N, 6, 5, 6), are not kept."""
    first = prepare([dataset], platform)[0]
    _, q_dot, _ = differentiate(first.q, first.sample_rate, 0.2 / row["frequency_hz"])
    return ExperimentTrace(
        name=dataset.name, excited=row["excited"], t=first.t, pose=first.q,
        neutral=np.asarray(platform.neutral_pose, dtype=float),
        joint_rates=joint_rates(platform, first.q, q_dot, first.joint_jacobians,
                                first.leg_jacobian),
        intervals=intervals)


def result_figures(drawer: FigureDrawer, runs: Sequence[MethodFit],
                   datasets: Sequence[Dataset], platform: Platform,
                   nominal: tuple[np.ndarray, np.ndarray], trusted: str,
                   rows: Sequence[dict[str, Any]]) -> None:
    """The identification's figures: intervals, matrices, residuals, validation, methods, friction."""
    ok = [run for run in runs if run.result is not None]
    best = next(run for run in ok if run.name == trusted)
    frequencies = [row["frequency_hz"] for row in rows]
    owner, intervals, points = used_intervals(runs, trusted, datasets)
    trace = _joint_rate_trace(datasets[0], platform, rows[0],
                              intervals[0] if intervals else None)
    drawer.add("joint_rates", f"Joint rates of {datasets[0].name}; shaded: the "
               f"constant-direction intervals {owner} used." if intervals else
               f"Joint rates of {datasets[0].name} (no method here uses constant-direction "
               "intervals).", plot_joint_rates, trace)
    if intervals:
        drawer.add("intervals", "Constant-direction intervals used in every experiment"
                   + (", with the (a, b) points (bar: scale a)."
                      if any(p is not None for p in points)
                      else "; the test functions span each whole interval."),
                   plots.plot_intervals, [d.name for d in datasets],
                   [(float(d.t[0]), float(d.t[-1])) for d in datasets], intervals, points)
    colours = {run.display_name: run.color for run in ok}
    estimates = {run.display_name: (run.result.M, run.result.B, run.result.std_errors_M,
                                    run.result.std_errors_B) for run in ok}
    drawer.add("matrices", "Identified over nominal for every entry with a non-zero nominal "
               "value, ±2 standard errors.", plots.plot_matrices, estimates, colours, *nominal)
    drawer.add("residuals", f"Residuals of {best.display_name} fitted on all data, over time "
               "and their spectrum.", plots.plot_residuals, best.in_sample, frequencies)
    shown = {run.display_name: run.validation for run in ok}
    if best.validation_unconstrained is not None:
        shown = {f"{best.display_name}, consistent": best.validation,
                 f"{best.display_name}, unconstrained": best.validation_unconstrained}
        colours = {**colours, f"{best.display_name}, consistent": best.color,
                   f"{best.display_name}, unconstrained": "#555555"}
    drawer.add("validation", "Held-out measured and predicted generalized force.",
               plots.plot_validation, shown, colours)
    if len(ok) > 1:
        drawer.add("methods", "Held-out unexplained force per DOF and method.",
                   plots.plot_unexplained,
                   {run.display_name: run.validation.vaf_percent for run in ok}, colours)
    friction = {run.display_name: run.coulomb for run in ok
                if np.all(np.isfinite(run.coulomb[0]))}
    if friction:
        drawer.add("friction", "Coulomb levels per joint type, ±2 standard errors; dashed: "
                   "the platform description's level.", plots.plot_friction, friction,
                   colours, float(platform.friction.coulomb))


def physical_figures(drawer: FigureDrawer, section: PhysicalSection | None) -> None:
    """The physical model's Mt and Bt across the measured poses (none without its section)."""
    if section is None or section.workspace is None:
        return
    drawer.add("workspace", "Mt and Bt of the physical model across the poses the data cover: "
               "each coordinate swept from its smallest to its largest measured value, the "
               "others at their mean; the diagonal entries and the largest couplings as their "
               "change from the identified value at the mean pose, in % of the diagonal's "
               "scale (sqrt(m_ii m_jj) for a coupling); band: ±2 standard errors (delta method); "
               "dashed: the platform description.", plots.plot_workspace, section.workspace)


__all__ = ["FigureDrawer", "data_figures", "physical_figures", "result_figures"]
