"""Running a study on dask.distributed: resumable, fault tolerant, with a progress bar. Only the
client writes, each task's rows as it finishes: a lost worker costs one task, an interrupted run
keeps every finished task, workers need no shared file system."""

from __future__ import annotations

import dataclasses
import json
import logging
import os
import time
import uuid
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

from rich.progress import BarColumn, Progress, TextColumn, TimeElapsedColumn

from stewartid.errors import ConfigError, OutputExistsError
from stewartid.files import write_json_atomic
from stewartid.parallel import WORKER_THREADS
from stewartid.studies.grid import StudyTask, expand_grid
from stewartid.studies.lock import study_lock
from stewartid.studies.report import write_study_report
from stewartid.studies.results import RESULTS_NAME, finished_tasks, read_results, write_part
from stewartid.studies.spec import StudySpec
from stewartid.studies.task import run_task

#: The validated study, kept beside its results so that a resumed run can be checked.
SPEC_NAME = "study.json"
#: Tasks that crashed (an exception other than a StewartidError, or workers lost too often).
FAILED_NAME = "failed.json"

#: Called after every finished or failed task as ``progress(done, failed, remaining)``.
ProgressCallback = Callable[[int, int, int], Any]


@dataclasses.dataclass(frozen=True)
class TaskFailure:
    """A task that raised on every attempt.

    Attributes
    ----------
    task, label, message : str
        Task key; its parameters and seed; ``Type: message`` of the exception.
    """

    task: str
    label: str
    message: str


@dataclasses.dataclass(frozen=True)
class StudyRun:
    """What :func:`run_study` did.

    Attributes
    ----------
    directory : Path
    spec : StudySpec
    rows : pandas.DataFrame
        Every row of the study's tasks in the folder after the run.
    computed, skipped : int
        Tasks computed by this run; tasks already stored before it (``resume``).
    failures : tuple of TaskFailure
        Tasks failed in this run; retried by a run with ``resume``.
    files : list of Path
        Report, figure and table files written.
    runtime_s : float
        Wall time (s).
    """

    directory: Path
    spec: StudySpec
    rows: Any
    computed: int
    skipped: int
    failures: tuple[TaskFailure, ...]
    files: list[Path]
    runtime_s: float


def _check_folder(spec: StudySpec, directory: Path, resume: bool) -> None:
    """Refuse a folder holding another study, or any study without ``resume``."""
    if directory.exists() and not directory.is_dir():
        raise OutputExistsError(f"output path {str(directory)!r} exists and is not a folder; "
                                "choose another folder.")
    recorded = directory / SPEC_NAME
    holds_study = recorded.is_file() or (directory / RESULTS_NAME).exists()
    if holds_study and not resume:
        raise OutputExistsError(f"output folder {str(directory)!r} already holds a study; pass "
                                "--resume to compute its missing rows, or choose another folder.")
    if recorded.is_file():
        try:
            document = json.loads(recorded.read_text(encoding="utf-8"))
        except json.JSONDecodeError as exc:
            raise ConfigError(f"{recorded}: not valid JSON ({exc}); remove it to resume "
                              "anyway.") from None
        differs = spec.mismatch(document)
        if differs is not None:
            raise ConfigError(f"{recorded}: the study in this folder was run with other "
                              f"{differs!r} than the study file; only the grid values and the "
                              "seeds may change on --resume. Use another folder.")
    elif holds_study:
        raise ConfigError(f"{directory}: has results but no {SPEC_NAME}; cannot check that "
                          "they belong to this study. Use another folder.")


@contextmanager
def connect(scheduler: str | None = None, workers: int | None = None) -> Iterator[Any]:
    """A :class:`distributed.Client` of ``scheduler``, or of a new LocalCluster closed on exit.

    The LocalCluster has ``workers`` single-threaded processes (one per core by default).

    Raises
    ------
    ConfigError
        dask.distributed missing (the ``[dask]`` extra), ``workers`` < 1, or scheduler unreachable.
    """
    try:
        from distributed import Client, LocalCluster
    except ImportError:
        raise ConfigError("stewartid study runs on dask.distributed, which is not installed; "
                          "install the extra: pip install 'stewartid[dask]'.") from None
    if scheduler is not None:
        try:
            client = Client(scheduler, timeout="20s")
        except (OSError, TimeoutError, ValueError) as exc:
            raise ConfigError(f"cannot connect to the dask scheduler at {scheduler!r} "
                              f"({type(exc).__name__}: {exc}); check the address, e.g. "
                              "tcp://host:8786.") from None
        with client:
            yield client
        return
    count = (os.cpu_count() or 1) if workers is None else workers
    if count < 1:
        raise ConfigError(f"--workers must be >= 1; got {workers!r}.")
    # one BLAS thread per worker; quiet workers: their shutdown heartbeats log spurious errors,
    # and a task's failure reaches the client through its future
    with LocalCluster(n_workers=count, threads_per_worker=1, processes=True,
                      dashboard_address=None, silence_logs=logging.CRITICAL,
                      env=dict(WORKER_THREADS)) as cluster, Client(cluster) as client:
        yield client


@contextmanager
def _progress_display(enabled: bool, total: int) -> Iterator[ProgressCallback | None]:
    """A rich progress bar of the tasks (done, failed, remaining), or nothing."""
    if not enabled:
        yield None
        return
    counts = TextColumn("{task.fields[done]} done, {task.fields[failed]} failed, "
                        "{task.fields[remaining]} remaining")
    with Progress(TextColumn("study"), BarColumn(), counts, TimeElapsedColumn()) as bar:
        task = bar.add_task("study", total=total, done=0, failed=0, remaining=total)

        def update(done: int, failed: int, remaining: int) -> None:
            bar.update(task, completed=done + failed, done=done, failed=failed,
                       remaining=remaining)

        yield update


def _submit_all(client: Any, tasks: list[StudyTask], spec: StudySpec, retries: int
                ) -> dict[Any, StudyTask]:
    platform = spec.load_platform()
    run_id = uuid.uuid4().hex[:8]
    # a key per run: a resumed run on the same cluster never meets the cancelled futures of
    # an interrupted one
    return {client.submit(run_task, task, platform, spec.methods, spec.method_settings,
                          spec.actuator, key=f"stewartid-study-{task.key}-{run_id}",
                          retries=retries): task
            for task in tasks}


def run_study(spec: StudySpec, out: str | Path, *, scheduler: str | None = None,
              workers: int | None = None, resume: bool = False, retries: int = 2,
              client: Any = None, progress: bool | ProgressCallback = False,
              report: bool = True) -> StudyRun:
    """Run every task of ``spec`` not yet stored in ``out``, then write the report.

    Parameters
    ----------
    spec : StudySpec
    out : str or Path
        Output folder (created if missing).
    scheduler : str, optional
        An existing dask scheduler (``tcp://host:8786``); a LocalCluster otherwise.
    workers : int, optional
        LocalCluster processes; one per core by default.
    resume : bool
        Continue the study in ``out``: compute only its missing tasks.
    retries : int
        Extra attempts of a task that raises (a dead worker's task is rerun regardless).
    client : distributed.Client, optional
        Use this client (``scheduler`` and ``workers`` ignored).
    progress : bool or callable
        True: a terminal progress bar; a callable: ``progress(done, failed, remaining)`` per task.
    report : bool
        Write ``report.md``/``report.html`` with figures and tables at the end.

    Raises
    ------
    OutputExistsError
        ``out`` holds a study and not ``resume``.
    ConfigError
        ``resume`` meets other fixed settings, dask is unavailable, or another run holds ``out``.
    """
    start = time.perf_counter()
    directory = Path(out)
    _check_folder(spec, directory, resume)
    with study_lock(directory):
        # again under the lock: another run may have started this folder meanwhile
        _check_folder(spec, directory, resume)
        return _run_locked(spec, directory, start, scheduler, workers, retries, client,
                           progress, report)


def _run_locked(spec: StudySpec, directory: Path, start: float, scheduler: str | None,
                workers: int | None, retries: int, client: Any,
                progress: bool | ProgressCallback, report: bool) -> StudyRun:
    """:func:`run_study`'s work, with the folder's lock held."""
    tasks = expand_grid(spec)
    stored = finished_tasks(directory)
    todo = [task for task in tasks if task.key not in stored]
    skipped = len(tasks) - len(todo)
    failures: list[TaskFailure] = []
    computed = 0
    if todo:
        with (connect(scheduler, workers) if client is None else _given(client)) as active, \
                _progress_display(progress is True, len(tasks)) as display:
            # written once a cluster is reached: a run that cannot start leaves no study
            write_json_atomic(directory / SPEC_NAME, spec.to_dict())
            notify = display or (progress if callable(progress) else None)
            if notify is not None:
                notify(skipped, 0, len(todo))
            from distributed import as_completed

            futures = _submit_all(active, todo, spec, retries)
            try:
                for future in as_completed(list(futures)):
                    task = futures.pop(future)
                    if future.status == "finished":
                        write_part(directory, task.key, future.result())
                        computed += 1
                    else:
                        failures.append(TaskFailure(task.key, task.label, _describe(future)))
                    future.release()
                    if notify is not None:
                        notify(skipped + computed, len(failures), len(futures))
            finally:
                if futures:
                    active.cancel(list(futures))
    else:
        write_json_atomic(directory / SPEC_NAME, spec.to_dict())
    failed_path = directory / FAILED_NAME
    if failures:
        write_json_atomic(failed_path, [dataclasses.asdict(f) for f in failures])
    else:
        failed_path.unlink(missing_ok=True)
    rows = read_results(directory, {task.key for task in tasks})
    files: list[Path] = []
    if report:
        files = write_study_report(rows, spec, directory, total_tasks=len(tasks),
                                   failed_tasks=len(failures))
    return StudyRun(directory, spec, rows, computed, skipped, tuple(failures), files,
                    time.perf_counter() - start)


def _describe(future: Any) -> str:
    """``Type: message`` of a future's exception."""
    if future.status == "cancelled":
        return "CancelledError: the task was cancelled on the cluster"
    error = future.exception()
    return f"{type(error).__name__}: {error}"


@contextmanager
def _given(client: Any) -> Iterator[Any]:
    yield client


__all__ = ["FAILED_NAME", "SPEC_NAME", "StudyRun", "TaskFailure", "connect", "run_study"]
