"""Regenerate the paper's Section 5 comparison: simulate, identify, tabulate, plot, report.

The paper (Zhang 2020) compares two identification methods on a simulated hydraulic Stewart
platform: Method A (Fourier, Tian et al.) with viscous friction only (Table 3), Methods A and
B with 5 N·m of Coulomb friction per joint axis (Tables 4, 5) and Method B with 30 N·m
(Table 6). :func:`run_reproduce` runs every method at every Coulomb level (0, 5, 30 N·m) on
this package's plant simulator, adds the time-domain least-squares baseline and the
position-only wavelet variant, and writes into one folder:

- ``results.json``: every identified matrix, standard error and ε, the nominal matrices, the
  settings, the seed, the package version and the run time;
- ``tables/``: the paper's Tables 3-6 with the published values beside ours, a comparison of
  all methods per Coulomb level and a summary, as Markdown and CSV;
- ``figures/``: PNG and SVG figures;
- ``report.md`` and ``report.html``.

Simulations and identifications run in parallel worker processes
(:class:`concurrent.futures.ProcessPoolExecutor`); every file is written atomically.

References
----------
Zhang, C. "A Parameter Identification Method for Stewart Manipulator Based on Wavelet
Transform." Mathematics 8(2), 257 (2020). doi:10.3390/math8020257
"""

from __future__ import annotations

import importlib
import math
import os
import time
from collections.abc import Callable, Iterator, Sequence
from concurrent.futures import Executor, Future, ProcessPoolExecutor
from contextlib import contextmanager
from dataclasses import dataclass, field
from datetime import UTC, datetime
from pathlib import Path
from typing import Any

import numpy as np

from stewartid.errors import ConfigError, DataError
from stewartid.platform import Platform, load_platform
from stewartid.published import PAPER_ENTRIES, entry_label, load_published
from stewartid.reporting.files import write_json_atomic
from stewartid.reporting.results import ComparisonResults, MethodRun

#: Coulomb friction levels of the paper's experiments (N·m per joint axis).
COULOMB_LEVELS = (0.0, 5.0, 30.0)
#: Excitation frequency of the paper's experiments (Hz).
FREQUENCY_HZ = 0.5
#: Record length per experiment (s): full run and ``--quick``. The full run holds 7 periods
#: at 0.5 Hz after the 2 s fade-in; the quick one 2, enough for every method to run.
FULL_DURATION_S = 20.0
QUICK_DURATION_S = 6.0

#: Identification methods: key -> (module, class, keyword arguments).
METHODS: dict[str, tuple[str, str, dict[str, Any]]] = {
    "fourier": ("stewartid.identification.fourier", "FourierIdentifier", {}),
    # Method B as this package runs it by default: compact polynomial wavelets spanning each
    # constant-direction interval, derivatives moved onto the wavelet (MODEL.md, numerics)
    "wavelet": ("stewartid.identification.wavelet", "WaveletIdentifier", {}),
    # Method B with the paper's own equations: Mexican hat, W psi q_ddot and a W psi1 q_ddot
    "wavelet_paper": ("stewartid.identification.wavelet", "WaveletIdentifier",
                      {"variant": "paper", "wavelet": "mexican_hat"}),
    "least_squares": ("stewartid.identification.least_squares", "LeastSquaresIdentifier", {}),
}

#: Coulomb level (index into the levels run, from the top) whose experiment is plotted.
TRACE_EXPERIMENT = 0


@dataclass(frozen=True)
class ReproduceSettings:
    """What a reproduction runs.

    Attributes
    ----------
    quick : bool
        Shortened records (``QUICK_DURATION_S``) for tests and CI.
    duration_s : float
        Record length per experiment (s).
    frequency_hz : float
        Sine excitation frequency (Hz).
    coulomb_levels : tuple of float
        Coulomb friction per joint axis (N·m), one simulated plant each.
    methods : tuple of str
        Keys of :data:`METHODS`.
    seed : int
        Seed of the simulator's noise; the same seed at every level, so that the levels
        differ only by their friction.
    jobs : int
        Worker processes (1: everything in this process).
    platform : str
        ``"paper"`` or a platform TOML file.
    """

    quick: bool = False
    duration_s: float = FULL_DURATION_S
    frequency_hz: float = FREQUENCY_HZ
    coulomb_levels: tuple[float, ...] = COULOMB_LEVELS
    methods: tuple[str, ...] = tuple(METHODS)
    seed: int = 0
    jobs: int = 1
    platform: str = "paper"

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready settings."""
        return {"quick": self.quick, "duration_s": self.duration_s,
                "frequency_hz": self.frequency_hz,
                "coulomb_levels": list(self.coulomb_levels), "methods": list(self.methods),
                "seed": self.seed, "jobs": self.jobs, "platform": self.platform,
                "experiments": 6}


def make_settings(quick: bool = False, jobs: int | None = None, seed: int = 0,
                  duration_s: float | None = None,
                  coulomb_levels: Sequence[float] = COULOMB_LEVELS,
                  methods: Sequence[str] | None = None, platform: str = "paper",
                  frequency_hz: float = FREQUENCY_HZ) -> ReproduceSettings:
    """Validated :class:`ReproduceSettings`; ``jobs=None`` uses every core."""
    jobs = (os.cpu_count() or 1) if jobs is None else jobs
    if isinstance(jobs, bool) or not isinstance(jobs, int) or jobs < 1:
        raise ConfigError(f"jobs must be a positive integer (worker processes); got {jobs!r}.")
    duration = (QUICK_DURATION_S if quick else FULL_DURATION_S) if duration_s is None \
        else float(duration_s)
    if not (math.isfinite(duration) and duration > 0):
        raise ConfigError(f"duration_s must be a positive number of seconds; got {duration_s!r}.")
    levels = tuple(float(c) for c in coulomb_levels)
    if not levels or any(not (math.isfinite(c) and c >= 0) for c in levels):
        raise ConfigError(f"coulomb_levels must be non-negative numbers (N·m); got "
                          f"{list(coulomb_levels)!r}.")
    methods = tuple(METHODS) if methods is None else tuple(methods)
    unknown = [m for m in methods if m not in METHODS]
    if unknown or not methods:
        raise ConfigError(f"unknown method(s) {unknown!r}; expected some of {list(METHODS)}.")
    if isinstance(seed, bool) or not isinstance(seed, int | np.integer) or seed < 0:
        raise ConfigError(f"seed must be a non-negative integer; got {seed!r}.")
    return ReproduceSettings(quick=bool(quick), duration_s=duration,
                             frequency_hz=float(frequency_hz), coulomb_levels=levels,
                             methods=methods, seed=int(seed), jobs=int(jobs),
                             platform=str(platform))


@dataclass(frozen=True)
class ReproduceOutput:
    """What :func:`run_reproduce` produced.

    Attributes
    ----------
    results : ComparisonResults
    directory : Path
    files : list of Path
        Every file written.
    runtime_s : float
        Wall time (s).
    """

    results: ComparisonResults
    directory: Path
    files: list[Path] = field(default_factory=list)
    runtime_s: float = 0.0


# ---------------------------------------------------------------------------- workers
# Module-level functions: they run in worker processes and must be picklable.

def simulate_one(platform: Platform, experiment: int, frequency_hz: float, duration_s: float,
                 seed: int, keep_record: bool = False) -> tuple[Any, Any, list[float]]:
    """Simulate experiment ``experiment`` (0-5) of the paper's six on ``platform``.

    The noise stream of experiment k is the k-th child of ``SeedSequence(seed)``, as in
    :func:`stewartid.simulation.simulate_experiments`, so a run split into one task per
    experiment gives the same data as one call simulating all six.

    Returns
    -------
    dataset : Dataset
        Measured signals.
    record : ExperimentRecord or None
        True signals, only when ``keep_record`` (they are large).
    tracking_error : list of float
        RMS leg-length tracking error per leg (m).
    """
    from stewartid.simulation import SensorNoise, paper_experiments, simulate_experiment

    excitation = paper_experiments(platform, frequency_hz)[experiment]
    stream = np.random.SeedSequence(int(seed)).spawn(6)[experiment]
    dataset, record = simulate_experiment(platform, excitation, duration_s,
                                          SensorNoise.from_sensors(platform.sensors),
                                          np.random.default_rng(stream))
    return dataset, record if keep_record else None, record.tracking_error().tolist()


def identify(method: str, coulomb: float, datasets: Sequence[Any], platform: Platform
             ) -> MethodRun:
    """Fit one identifier (a key of :data:`METHODS`) to the experiments of one level."""
    module, name, options = METHODS[method]
    identifier_class = getattr(importlib.import_module(module), name)
    start = time.perf_counter()
    identifier = identifier_class(**options).fit(list(datasets), platform)
    seconds = time.perf_counter() - start
    result = identifier.result_
    diagnostics = {"condition_number": float(result.condition_number),
                   "residual_rms": np.asarray(result.residual_rms, dtype=float).tolist(),
                   "settings": _jsonable(result.settings),
                   "details": _jsonable(result.diagnostics)}
    return MethodRun(method=method, coulomb=float(coulomb), M=np.array(result.M, dtype=float),
                     B=np.array(result.B, dtype=float),
                     M_std=np.array(result.std_errors_M, dtype=float),
                     B_std=np.array(result.std_errors_B, dtype=float),
                     seconds=seconds, diagnostics=diagnostics)


def _jsonable(value: Any) -> Any:
    """Numbers, lists and dicts only; non-finite floats become None."""
    if isinstance(value, np.ndarray):
        return _jsonable(value.tolist())
    if isinstance(value, dict):
        return {str(k): _jsonable(v) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return [_jsonable(v) for v in value]
    if isinstance(value, np.generic):
        return _jsonable(value.item())
    if isinstance(value, float):
        return value if math.isfinite(value) else None
    if isinstance(value, str | int | bool) or value is None:
        return value
    return str(value)


# ---------------------------------------------------------------------------- traces

def experiment_trace(platform: Platform, dataset: Any, excited: int, frequency_hz: float,
                     reference: np.ndarray | None = None, record: Any = None):
    """Everything the signal figures need from one simulated experiment.

    The force components are the model's terms along the motion: with the simulator's true
    record, at its true pose, velocity and acceleration; without it, at the measured pose
    differentiated by Savitzky-Golay filtering (as an identifier would). The actuators'
    generalized force is always the measured one, so the figure shows how far the model's
    terms explain it.

    Parameters
    ----------
    platform : Platform
        The simulated plant (its Coulomb level sets the Coulomb component).
    dataset : Dataset
        Measured signals.
    excited : int
        Excited coordinate (0-5).
    frequency_hz : float
        Excitation frequency (Hz), sets the differentiation window.
    reference : ndarray, shape (N, 6), optional
        Commanded pose (m, rad).
    record : ExperimentRecord, optional
        True signals of the simulator (``q``, ``q_dot``, ``q_ddot``).

    Returns
    -------
    ExperimentTrace
    """
    from stewartid.dynamics import ModelTerms, friction_forces
    from stewartid.identification.intervals import (
        constant_direction_intervals,
        joint_rates,
    )
    from stewartid.identification.signals import default_window, differentiate
    from stewartid.reporting.figures import ExperimentTrace

    t = np.asarray(dataset.t, dtype=float)
    pose = np.asarray(dataset.pose, dtype=float)
    if record is not None:
        q, q_dot, q_ddot = (np.asarray(record.q), np.asarray(record.q_dot),
                            np.asarray(record.q_ddot))
    else:
        q = pose
        _, q_dot, q_ddot = differentiate(pose, dataset.sample_rate,
                                         default_window(frequency_hz))
    terms = ModelTerms(platform, q, q_dot)
    measured = terms if record is None else ModelTerms(platform, pose)
    rates = joint_rates(platform, q, q_dot, terms.joint_jacobians, terms.leg_jacobian)
    intervals = constant_direction_intervals(t, rates, ignore_below=0.01)
    viscous = friction_forces(platform.replace(friction__coulomb=0.0), q, q_dot)
    friction = friction_forces(platform, q, q_dot)
    gravity_0 = ModelTerms(platform, platform.neutral_pose).gravity[0]
    actuators = np.einsum("nji,nj->ni", measured.leg_jacobian, np.asarray(dataset.forces))
    forces = {
        "inertial": np.einsum("nij,nj->ni", terms.mass_matrix, q_ddot) + terms.velocity_product,
        "viscous": viscous,
        "coulomb": friction - viscous,
        "gravity": terms.gravity - gravity_0,
        "actuators": actuators - gravity_0,
    }
    return ExperimentTrace(name=str(dataset.name), excited=int(excited), t=t, pose=pose,
                           neutral=np.asarray(platform.neutral_pose, dtype=float),
                           reference=reference, joint_rates=rates, intervals=intervals,
                           forces=forces)


def reference_poses(platform: Platform, frequency_hz: float, times: Sequence[np.ndarray]
                    ) -> list[np.ndarray | None]:
    """Commanded poses of the paper's six experiments at the given sample times."""
    try:
        from stewartid.simulation.excitation import paper_experiments
    except ImportError:
        return [None] * len(times)
    excitations = paper_experiments(platform, frequency_hz=frequency_hz)
    return [excitation.evaluate(np.asarray(t))[0] for excitation, t in
            zip(excitations, times, strict=False)]


# ---------------------------------------------------------------------------- results.json

def results_document(results: ComparisonResults, runtime_s: float,
                     files: Sequence[str] = ()) -> dict[str, Any]:
    """Everything of a run as a JSON-ready dict (see the module docstring)."""
    from stewartid import __version__
    from stewartid.reporting.report import summary_lines

    runs = []
    for run in results.runs:
        eps = results.eps_all(run)
        worst = max(eps, key=eps.__getitem__)
        published = {}
        for key in PAPER_ENTRIES:
            entry = results.published_entry(run.method, run.coulomb, key)
            if entry is not None:
                published[entry_label(key)] = {"value": entry.value, "eps": entry.eps}
        runs.append({
            "method": run.method, "coulomb": run.coulomb,
            "M": run.M.tolist(), "B": run.B.tolist(),
            "std_errors_M": None if run.M_std is None else _jsonable(run.M_std),
            "std_errors_B": None if run.B_std is None else _jsonable(run.B_std),
            "eps": {entry_label(k): v for k, v in eps.items()},
            "max_eps": eps[worst], "max_eps_entry": entry_label(worst),
            "eps_all_entries": {
                "M": (np.abs(run.M - results.nominal_M)
                      / np.where(results.nominal_M == 0, np.nan, np.abs(results.nominal_M))
                      * 100.0),
                "B": (np.abs(run.B - results.nominal_B)
                      / np.where(results.nominal_B == 0, np.nan, np.abs(results.nominal_B))
                      * 100.0)},
            "published": published or None,
            "seconds": run.seconds,
            "diagnostics": run.diagnostics,
        })
    return _jsonable({
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


def load_results(path: str | Path) -> ComparisonResults:
    """Rebuild the :class:`ComparisonResults` of a run from its ``results.json``."""
    import json

    path = Path(path)
    try:
        document = json.loads(path.read_text(encoding="utf-8"))
        runs = tuple(MethodRun(
            method=str(item["method"]), coulomb=float(item["coulomb"]),
            M=np.asarray(item["M"], dtype=float), B=np.asarray(item["B"], dtype=float),
            M_std=None if item.get("std_errors_M") is None
            else np.asarray(item["std_errors_M"], dtype=float),
            B_std=None if item.get("std_errors_B") is None
            else np.asarray(item["std_errors_B"], dtype=float),
            seconds=float(item.get("seconds", 0.0)),
            diagnostics=dict(item.get("diagnostics", {}))) for item in document["runs"])
        nominal_M = np.asarray(document["nominal"]["M"], dtype=float)
        nominal_B = np.asarray(document["nominal"]["B"], dtype=float)
    except (KeyError, TypeError, ValueError) as exc:
        raise DataError(f"{path}: not a results.json written by 'stewartid reproduce' "
                        f"({type(exc).__name__}: {exc}).") from None
    return ComparisonResults(runs, nominal_M, nominal_B, load_published(),
                             dict(document.get("settings", {})))


# ---------------------------------------------------------------------------- orchestration

class _InlineExecutor(Executor):
    """Runs submitted calls at once in this process (``jobs=1``)."""

    def submit(self, fn: Callable[..., Any], /, *args: Any, **kwargs: Any) -> Future:
        future: Future = Future()
        try:
            future.set_result(fn(*args, **kwargs))
        except BaseException as exc:  # handed to the caller through the future
            future.set_exception(exc)
        return future


#: Thread counts of the numerical libraries inside worker processes: one each, since the
#: parallelism is across processes (two-thread BLAS in two workers on two cores doubles the
#: identification time).
_WORKER_THREADS = {name: "1" for name in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS",
                                          "MKL_NUM_THREADS", "NUMBA_NUM_THREADS")}


def _ready() -> bool:
    return True


@contextmanager
def _executor(jobs: int) -> Iterator[Executor]:
    """A pool of ``jobs`` fresh worker processes ("spawn": they read the thread limits from
    the environment at start), or in-process execution for ``jobs=1``."""
    if jobs <= 1:
        yield _InlineExecutor()
        return
    import multiprocessing

    saved = {name: os.environ.get(name) for name in _WORKER_THREADS}
    os.environ.update(_WORKER_THREADS)
    try:
        pool = ProcessPoolExecutor(max_workers=jobs,
                                   mp_context=multiprocessing.get_context("spawn"))
        pool.submit(_ready).result()  # starts every worker while the limits are set
    finally:
        for name, value in saved.items():
            if value is None:
                os.environ.pop(name, None)
            else:
                os.environ[name] = value
    with pool:
        yield pool


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
    """A rich progress display of the stages, or a silent stand-in."""
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


def check_output_folder(directory: Path, force: bool) -> None:
    """Refuse a non-empty output folder unless ``force``; existing files are then overwritten
    one by one (nothing else in the folder is deleted)."""
    if directory.exists() and not directory.is_dir():
        raise FileExistsError(f"output path {directory} exists and is not a folder; choose "
                              "another --out")
    if directory.is_dir() and any(directory.iterdir()) and not force:
        raise FileExistsError(f"output folder {directory} is not empty; pass --force to "
                              "overwrite its results or choose another --out")


def _collect(futures: Sequence[Future], progress: Any, task: Any) -> list[Any]:
    """Results of ``futures`` in submission order, advancing ``task`` as each completes;
    the first failure is raised at once."""
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

    Stages: simulate the six experiments at every Coulomb level (one task per experiment),
    identify with every method at every level (one task each), draw the figures (one task
    each; the signal figures while the identifications run), then write the tables,
    ``results.json`` and the report.

    Parameters
    ----------
    out : str or Path
        Output folder; created if missing, refused if not empty unless ``force``.
    quick : bool
        Shortened records (for tests and CI).
    jobs : int, optional
        Worker processes; every core by default.
    force : bool
        Overwrite the results of an earlier run in ``out``.
    seed : int
        Seed of the simulated sensor noise.
    progress : bool
        Show a progress bar of the stages on the terminal.
    settings : ReproduceSettings, optional
        Full control over what runs (then ``quick``, ``jobs`` and ``seed`` are ignored).

    Returns
    -------
    ReproduceOutput
    """
    from stewartid import __version__
    from stewartid.linearization import nominal_matrices
    from stewartid.reporting.report import write_report
    from stewartid.reporting.tables import build_tables, write_tables

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
    with _progress(progress) as bar, _executor(settings.jobs) as pool:
        task = bar.add_task("simulating experiments", total=6 * len(levels))
        keys = [(level, k) for level in levels for k in range(6)]
        futures = [pool.submit(simulate_one, plants[level], k, settings.frequency_hz,
                               settings.duration_s, settings.seed,
                               keep_record=(level == trace_level and k == TRACE_EXPERIMENT))
                   for level, k in keys]
        outputs = dict(zip(keys, _collect(futures, bar, task), strict=True))
        datasets = {level: [outputs[(level, k)][0] for k in range(6)] for level in levels}

        jobs_list = [(method, level) for level in levels for method in settings.methods]
        identify_task = bar.add_task("identifying Mt, Bt", total=len(jobs_list))
        identifications = [pool.submit(identify, method, level, datasets[level], plants[level])
                           for method, level in jobs_list]
        figure_task = bar.add_task("drawing figures", total=6 + len(levels))
        figures = _FigureQueue(pool, directory / "figures", bar, figure_task)
        traces = _signal_figures(figures, plants[trace_level], datasets[trace_level],
                                 outputs[(trace_level, TRACE_EXPERIMENT)][1], trace_level,
                                 settings.frequency_hz)
        runs = tuple(_collect(identifications, bar, identify_task))
        recorded = settings.to_dict()
        recorded["version"] = __version__
        recorded["tracking_error_rms_m"] = {
            f"{level:g}": [outputs[(level, k)][2] for k in range(6)] for level in levels}
        results = ComparisonResults(runs, nominal_M, nominal_B, load_published(), recorded)
        _comparison_figures(figures, results, trace_level, traces)
        bar.update(figure_task, total=len(figures.submitted))
        entries, files = figures.finish()
    tables = build_tables(results)
    files += write_tables(tables, directory / "tables")
    recorded["runtime_s"] = time.perf_counter() - start
    files += list(write_report(results, tables, entries, directory))
    names = [str(p.relative_to(directory)) for p in files] + ["results.json"]
    files.append(write_json_atomic(directory / "results.json",
                                   results_document(results, recorded["runtime_s"], names)))
    return ReproduceOutput(results=results, directory=directory, files=files,
                           runtime_s=time.perf_counter() - start)


class _FigureQueue:
    """Figures submitted to the pool, with their report captions, in report order."""

    def __init__(self, pool: Executor, folder: Path, bar: Any, task: Any):
        self.pool, self.folder, self.bar, self.task = pool, folder, bar, task
        self.submitted: list[tuple[Future, Any]] = []

    def submit(self, function: Callable[..., Any], stem: str, caption: str, *args: Any,
               **kwargs: Any) -> None:
        from stewartid.reporting.report import FigureEntry

        future = self.pool.submit(function, *args, directory=self.folder, stem=stem, **kwargs)
        future.add_done_callback(lambda _: self.bar.advance(self.task))
        self.submitted.append((future, FigureEntry(f"figures/{stem}.png", caption)))

    def finish(self) -> tuple[list[Any], list[Path]]:
        files: list[Path] = []
        for future, _ in self.submitted:
            files += future.result()
        return [entry for _, entry in self.submitted], files


def _signal_figures(figures: _FigureQueue, plant: Platform, datasets: Sequence[Any],
                    record: Any, level: float, frequency_hz: float) -> list[Any]:
    """Submit the excitation, joint-velocity and force-budget figures; return the traces."""
    from stewartid.reporting import figures as plots
    from stewartid.reporting.figures import ExperimentTrace

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
    figures.submit(plots.plot_excitation, "excitation",
                   f"Excitation at Coulomb {level:g} N·m: each experiment drives one "
                   f"coordinate with a {frequency_hz:g} Hz sine; commanded, measured and "
                   "tracking error.", traces)
    figures.submit(plots.plot_joint_rates, "joint_velocities",
                   f"Joint velocities of {trace.name} at Coulomb {level:g} N·m; shaded: the "
                   "constant-direction intervals in which no joint reverses.", trace)
    figures.submit(plots.plot_force_budget, "force_budget",
                   f"Force budget of {trace.name} at Coulomb {level:g} N·m: the model's "
                   "inertial, viscous, Coulomb and gravity terms along the simulated motion, "
                   "and the measured actuators' generalized force.", trace)
    return traces


def _comparison_figures(figures: _FigureQueue, results: ComparisonResults, level: float,
                        traces: Sequence[Any]) -> None:
    """Submit the scalogram and the figures that compare methods."""
    from stewartid.reporting import figures as plots

    trace = traces[TRACE_EXPERIMENT]
    scalogram = _scalogram_arguments(results, level, trace)
    if scalogram is not None:
        figures.submit(plots.plot_scalogram, "scalogram",
                       f"Scalogram of the excited equation of {trace.name} at Coulomb "
                       f"{level:g} N·m, with the (a, b) points Method B used.", **scalogram)
    figures.submit(plots.plot_errors, "errors",
                   "ε per entry at each Coulomb level: every method, and the paper's "
                   "published ε (hatched) where it reports one.", results)
    for value in results.coulomb_levels:
        figures.submit(plots.plot_identified_vs_nominal,
                       f"identified_vs_nominal_coulomb{value:g}",
                       f"Identified / nominal per entry at Coulomb {value:g} N·m.", results,
                       value)


def _scalogram_arguments(results: ComparisonResults, level: float, trace: Any
                         ) -> dict[str, Any] | None:
    """Signal, (a, b) points and wavelet of Method B on the traced experiment, if it ran."""
    from stewartid.reporting.figures import COORDINATES

    run = results.run("wavelet", level) or results.run("wavelet_paper", level)
    if run is None:
        return None
    details = run.diagnostics.get("details", {})
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


__all__ = [
    "COULOMB_LEVELS",
    "FREQUENCY_HZ",
    "FULL_DURATION_S",
    "METHODS",
    "QUICK_DURATION_S",
    "ReproduceOutput",
    "ReproduceSettings",
    "experiment_trace",
    "identify",
    "load_results",
    "make_settings",
    "reference_poses",
    "results_document",
    "run_reproduce",
    "simulate_one",
]
