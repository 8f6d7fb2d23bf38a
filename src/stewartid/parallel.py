"""The one process-pool policy: "fork" where available, one BLAS thread per task (bitwise results
for any worker count), every core by default, results in task order, progress per finished task.
"""

from __future__ import annotations

import multiprocessing
import os
from collections.abc import Callable, Iterator, Sequence
from concurrent.futures import Executor, Future, ProcessPoolExecutor, as_completed
from contextlib import contextmanager
from typing import Any

from threadpoolctl import threadpool_limits

#: Thread counts of the numerical libraries in worker processes started by another library
#: (environment variables, read by each library when it loads): one each, as
#: :func:`limit_worker_threads` sets in the workers of :func:`process_pool`.
WORKER_THREADS = {name: "1" for name in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS",
                                         "MKL_NUM_THREADS", "NUMBA_NUM_THREADS")}

#: Start method of every worker process (see the module docstring).
START_METHOD = "fork" if "fork" in multiprocessing.get_all_start_methods() else "spawn"

#: True when workers start with this process's loaded modules and compiled kernels.
WORKERS_INHERIT = START_METHOD == "fork"

#: Called as ``progress(done, total, index)`` after each finished task.
TaskProgress = Callable[[int, int, int], Any]


def worker_count(workers: int | None, tasks: int) -> int:
    """Worker processes for ``tasks`` tasks: ``workers`` or every core, at most one per task, at least one."""
    wanted = (os.cpu_count() or 1) if workers is None else int(workers)
    return max(1, min(wanted, tasks))


def inheriting_workers(workers: int | None, tasks: int) -> int:
    """:func:`worker_count` where workers start with this process's modules, data and compiled
    kernels ("fork"); else 1: a started ("spawn") worker would import, load and receive
    everything again, which costs more than the tasks that share a fit."""
    return worker_count(workers, tasks) if WORKERS_INHERIT else 1


def limit_worker_threads(initializer: Callable[..., Any] | None = None,
                         *initargs: Any) -> None:
    """Worker initializer: one BLAS/OpenMP thread here, then ``initializer(*initargs)``."""
    threadpool_limits(limits=1)
    if initializer is not None:
        initializer(*initargs)


def one_blas_thread() -> Any:
    """One BLAS thread for a ``with`` block or a decorated function: the package's many small
    products run faster on one, and every entry point (command line, Python) gives the same
    bits."""
    return threadpool_limits.wrap(limits=1, user_api="blas")


class InlineExecutor(Executor):
    """Runs submitted calls at once in this process (one worker, no pool)."""

    def submit(self, fn: Callable[..., Any], /, *args: Any, **kwargs: Any) -> Future:
        """Call ``fn(*args, **kwargs)`` now and return a Future holding its result or error."""
        future: Future = Future()
        try:
            future.set_result(fn(*args, **kwargs))
        except BaseException as exc:  # handed to the caller through the future
            future.set_exception(exc)
        return future


@contextmanager
def process_pool(workers: int, initializer: Callable[..., Any] | None = None,
                 initargs: tuple = ()) -> Iterator[Executor]:
    """An executor of ``workers`` processes with one BLAS thread each, shut down on exit; for
    ``workers`` <= 1 an :class:`InlineExecutor`. ``initializer(*initargs)`` runs in each worker.
    """
    if workers <= 1:
        with threadpool_limits(limits=1):
            yield InlineExecutor()
        return
    context = multiprocessing.get_context(START_METHOD)
    with ProcessPoolExecutor(max_workers=workers, mp_context=context,
                             initializer=limit_worker_threads,
                             initargs=(initializer, *initargs)) as pool:
        yield pool


#: What :func:`run_in_order` hands to every task of a worker (set once per process).
_SHARED: list[Any] = []


def _share(value: Any) -> None:
    _SHARED[:] = [value]


def _call_with_shared(function: Callable[[Any, Any], Any], task: Any) -> Any:
    return function(_SHARED[0], task)


def run_in_order(function: Callable[..., Any], tasks: Sequence[Any], workers: int | None = None,
                 progress: TaskProgress | None = None, shared: Any = None) -> list[Any]:
    """``[function(task) for task in tasks]`` on :func:`worker_count` processes, in task order.

    ``function`` is module-level, called as ``function(shared, task)`` when ``shared`` (large data sent
    once per worker) is given; ``progress(done, total, index)`` as tasks finish; the first failure is raised.
    """
    tasks = list(tasks)
    count = worker_count(workers, len(tasks))
    results: list[Any] = [None] * len(tasks)
    if count == 1:
        with threadpool_limits(limits=1):
            for index, task in enumerate(tasks):
                results[index] = function(task) if shared is None else function(shared, task)
                if progress is not None:
                    progress(index + 1, len(tasks), index)
        return results
    call: Callable[..., Any] = function
    arguments: list[tuple] = [(task,) for task in tasks]
    initializer, initargs = None, ()
    if shared is not None:
        call, initializer, initargs = _call_with_shared, _share, (shared,)
        arguments = [(function, task) for task in tasks]
    with process_pool(count, initializer, initargs) as pool:
        futures = {pool.submit(call, *args): k for k, args in enumerate(arguments)}
        for done, future in enumerate(as_completed(futures), start=1):
            index = futures[future]
            results[index] = future.result()
            if progress is not None:
                progress(done, len(tasks), index)
    return results


__all__ = ["START_METHOD", "WORKERS_INHERIT", "WORKER_THREADS", "InlineExecutor", "TaskProgress",
           "inheriting_workers", "limit_worker_threads", "one_blas_thread", "process_pool", "run_in_order",
           "worker_count"]
