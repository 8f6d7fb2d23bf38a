"""Regenerate the paper's Section 5 comparison (Zhang 2020): simulate, identify, tabulate, plot
and report into one folder, simulations and fits in worker processes."""

from __future__ import annotations

import time
from collections.abc import Iterator, Sequence
from concurrent.futures import Future
from contextlib import contextmanager
from pathlib import Path
from typing import Any

from stewartid.files import check_output_folder, to_jsonable, write_json_atomic
from stewartid.parallel import process_pool
from stewartid.platform import Platform, load_platform
from stewartid.reference.published import load_published
from stewartid.reports.tables import write_tables
from stewartid.reproduction.comparison import ComparisonResults, MethodRun
from stewartid.reproduction.document import results_document
from stewartid.reproduction.noisy import (
    NOISE_SCALE,
    STEM,
    noisy_document,
    noisy_results,
    noisy_summary,
    noisy_table,
)
from stewartid.reproduction.plots import (
    FigureQueue,
    submit_comparison_figures,
    submit_signal_figures,
)
from stewartid.reproduction.settings import (
    TRACE_EXPERIMENT,
    ReproduceOutput,
    ReproduceSettings,
    make_settings,
)

# ---------------------------------------------------------------------------- workers
# Module-level functions: they run in worker processes and must be picklable.

def simulate_one(platform: Platform, experiment: int, frequency_hz: float, duration_s: float,
                 seed: int, keep_record: bool = False, noise_scale: float = 0.0
                 ) -> tuple[Any, Any, list[float]]:
    """Simulate experiment ``experiment`` (0-5) of the paper's six on ``platform``.

    Same noise generator as :func:`~stewartid.simulation.simulate_experiments` (one task per
    experiment gives the same data); ``noise_scale`` > 0 measures with that multiple of
    :func:`~stewartid.simulation.sensors.reference_noise` instead of the platform's sensors.
    Returns the dataset, the true signals (only with ``keep_record``, else None) and the RMS
    leg-length tracking error per leg (m)."""
    from stewartid.simulation import SensorNoise, paper_experiments, simulate_experiment
    from stewartid.simulation.experiments import noise_generator
    from stewartid.simulation.sensors import reference_noise

    excitations = paper_experiments(platform, frequency_hz)
    sensors = reference_noise(platform, noise_scale) if noise_scale > 0 else \
        SensorNoise.from_sensors(platform.sensors)
    dataset, record = simulate_experiment(platform, excitations[experiment], duration_s,
                                          sensors,
                                          noise_generator(seed, experiment, len(excitations)))
    return dataset, record if keep_record else None, record.tracking_error().tolist()


def identify(method: str, coulomb: float, datasets: Sequence[Any], platform: Platform
             ) -> MethodRun:
    """Fit one registered method or preset to the experiments of one level."""
    from stewartid.identification.registry import create_identifier

    start = time.perf_counter()
    identifier = create_identifier(method).fit(list(datasets), platform)
    seconds = time.perf_counter() - start
    return MethodRun(method=method, coulomb=float(coulomb), result=identifier.result_,
                     seconds=seconds)


# ---------------------------------------------------------------------------- orchestration

class _Silent:
    """Stand-in for a rich progress display when progress is off."""

    def add_task(self, *args: Any, **kwargs: Any) -> int:
        return 0

    def advance(self, *args: Any, **kwargs: Any) -> None:
        pass

    def update(self, *args: Any, **kwargs: Any) -> None:
        pass


@contextmanager
def _progress(enabled: bool) -> Iterator[Any]:
    if not enabled:
        yield _Silent()
        return
    from rich.progress import (
        BarColumn,
        MofNCompleteColumn,
        Progress,
        TextColumn,
        TimeElapsedColumn,
    )

    columns = (TextColumn("{task.description:<24}"), BarColumn(), MofNCompleteColumn(),
               TimeElapsedColumn())
    with Progress(*columns, transient=False) as progress:
        yield progress


def _collect(futures: Sequence[Future], progress: Any, task: Any) -> list[Any]:
    """Results of ``futures`` in submission order, advancing ``task``; raises the first failure."""
    from concurrent.futures import as_completed

    for future in as_completed(futures):
        future.result()
        progress.advance(task)
    return [future.result() for future in futures]


def run_reproduce(out: str | Path = "results/reproduce", quick: bool = False,
                  jobs: int | None = None, force: bool = False, seed: int = 0,
                  progress: bool = False, settings: ReproduceSettings | None = None
                  ) -> ReproduceOutput:
    """Run the paper's comparison and write results, tables, figures and the report.

    Parameters
    ----------
    out : str or Path
        Output folder; created if missing, refused if not empty unless ``force``.
    quick : bool
        Shortened records (tests, CI).
    jobs : int, optional
        Worker processes; every core by default.
    force : bool
        Overwrite an earlier run's results in ``out``.
    seed : int
        Simulated sensor noise seed.
    progress : bool
        Terminal progress bar of the stages.
    settings : ReproduceSettings, optional
        Full control (``quick``, ``jobs`` and ``seed`` then ignored).
    """
    from stewartid import __version__
    from stewartid.model.linearization import nominal_matrices
    from stewartid.reproduction.figures import plot_identified_vs_nominal
    from stewartid.reproduction.report import write_report
    from stewartid.reproduction.tables import build_tables

    start = time.perf_counter()
    settings = settings or make_settings(quick=quick, jobs=jobs, seed=seed)
    directory = Path(out)
    check_output_folder(directory, force)
    platform = load_platform(settings.platform)
    levels = settings.coulomb_levels
    plants = {level: platform.replace(friction__coulomb=level) for level in levels}
    nominal_M, nominal_B = nominal_matrices(platform)
    # the signal figures show the highest Coulomb level, where friction shows most
    trace_level = max(levels)
    with _progress(progress) as bar, process_pool(settings.jobs) as pool:
        task = bar.add_task("simulating experiments", total=6 * len(levels))
        keys = [(level, k) for level in levels for k in range(6)]
        futures = [pool.submit(simulate_one, plants[level], k, settings.frequency_hz,
                               settings.duration_s, settings.seed,
                               keep_record=(level == trace_level and k == TRACE_EXPERIMENT))
                   for level, k in keys]
        # the noisy case: the highest level once more, with the reference sensor noise
        noisy_futures = [pool.submit(simulate_one, plants[trace_level], k,
                                     settings.frequency_hz, settings.duration_s,
                                     settings.seed, noise_scale=NOISE_SCALE)
                         for k in range(6)] if settings.noise_case else []
        bar.update(task, total=len(futures) + len(noisy_futures))
        outputs = dict(zip(keys, _collect(futures, bar, task), strict=True))
        datasets = {level: [outputs[(level, k)][0] for k in range(6)] for level in levels}
        noisy_datasets = [output[0] for output in _collect(noisy_futures, bar, task)]

        jobs_list = [(method, level) for level in levels for method in settings.methods]
        identify_task = bar.add_task("identifying Mt, Bt", total=len(jobs_list))
        identifications = [pool.submit(identify, method, level, datasets[level], plants[level])
                           for method, level in jobs_list]
        noisy_identifications = [pool.submit(identify, method, trace_level, noisy_datasets,
                                             plants[trace_level])
                                 for method in settings.methods] if noisy_datasets else []
        bar.update(identify_task, total=len(identifications) + len(noisy_identifications))
        figure_task = bar.add_task("drawing figures", total=6 + len(levels))
        figures = FigureQueue(pool, directory / "figures", bar, figure_task)
        traces = submit_signal_figures(figures, plants[trace_level], datasets[trace_level],
                                 outputs[(trace_level, TRACE_EXPERIMENT)][1], trace_level,
                                 settings.frequency_hz)
        runs = tuple(_collect(identifications, bar, identify_task))
        noisy_runs = _collect(noisy_identifications, bar, identify_task)
        recorded = settings.to_dict()
        recorded["version"] = __version__
        recorded["tracking_error_rms_m"] = {
            f"{level:g}": [outputs[(level, k)][2] for k in range(6)] for level in levels}
        results = ComparisonResults(runs, nominal_M, nominal_B, load_published(), recorded)
        noisy = noisy_results(noisy_runs, results) if noisy_runs else None
        if noisy is not None:
            recorded["noise_case_summary"] = noisy_summary(noisy)
            figures.submit(plot_identified_vs_nominal, f"identified_vs_nominal_{STEM}",
                           f"Identified / nominal per entry at Coulomb {trace_level:g} N·m "
                           "with the reference sensor noise.", noisy, trace_level)
        submit_comparison_figures(figures, results, trace_level, traces)
        bar.update(figure_task, total=len(figures.submitted))
        entries, files = figures.finish()
    tables = build_tables(results) + ([noisy_table(noisy)] if noisy is not None else [])
    files += write_tables(tables, directory / "tables")
    recorded["runtime_s"] = time.perf_counter() - start
    files += list(write_report(results, tables, entries, directory))
    names = [str(p.relative_to(directory)) for p in files] + ["results.json"]
    document = results_document(results, recorded["runtime_s"], names)
    if noisy is not None:
        document["noise_case"] = to_jsonable(noisy_document(noisy))
    files.append(write_json_atomic(directory / "results.json", document))
    return ReproduceOutput(results=results, directory=directory, files=files,
                           runtime_s=time.perf_counter() - start)


__all__ = ["identify", "run_reproduce", "simulate_one"]
