"""The one process-pool policy: "fork" where available, one BLAS thread per task (bitwise results
for any worker count), every core by default, results in task order, progress per finished task.
"""

from __future__ import annotations

import ctypes
import multiprocessing
import os
import warnings
from collections.abc import Callable, Iterator, Sequence
from concurrent.futures import Executor, Future, ProcessPoolExecutor, as_completed
from contextlib import ExitStack, contextmanager
from functools import partial
from typing import Any

import numpy as np
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
    """Worker initializer: one BLAS/OpenMP thread here, freed memory kept for the next task
    (:func:`keep_freed_memory`), then ``initializer(*initargs)``."""
    threadpool_limits(limits=1)
    keep_freed_memory()
    if initializer is not None:
        initializer(*initargs)


#: glibc's mallopt parameters: the trim threshold, the top pad and the mmap threshold.
_M_TRIM_THRESHOLD, _M_TOP_PAD, _M_MMAP_THRESHOLD = -1, -2, -3


def keep_freed_memory() -> bool:
    """Have glibc's allocator keep this process's freed memory for its next allocations, on
    ordinary pages: a worker's tasks allocate and free records' worth of arrays, and memory
    given back to the system costs a page fault per page when taken again. Only for worker
    processes, which end with their pool; returns False where the C library is not glibc.
    """
    # numpy asks for huge pages for large arrays; arrays written once or twice and then freed
    # gain little from them, and a huge page's first touch zeroes and backs all 2 MiB at once
    # (docs/benchmarks.md, "Memory in the workers")
    multiarray = getattr(getattr(np, "_core", None), "multiarray", None)
    if multiarray is None:  # numpy 1.26
        multiarray = np.core.multiarray
    if hasattr(multiarray, "_set_madvise_hugepage"):
        multiarray._set_madvise_hugepage(False)
    try:
        mallopt = ctypes.CDLL(None).mallopt
    except (OSError, AttributeError):
        return False
    # every array from the heap (no mmap threshold below 1 GiB), and what is freed at its top
    # kept there (trim threshold, top pad)
    return all(mallopt(param, value) == 1 for param, value in (
        (_M_MMAP_THRESHOLD, 1 << 30), (_M_TRIM_THRESHOLD, 1 << 30), (_M_TOP_PAD, 1 << 26)))


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


#: What a :class:`WorkerPool`'s tasks are handed in every worker (set once per process).
_SHARED: list[Any] = []


def _share(value: Any) -> None:
    _SHARED[:] = [value]


def _captured(call: Callable[[], Any]) -> tuple[Any, list[tuple[Warning, type[Warning]]]]:
    """``call()`` in a worker, with the warnings it raised, for the caller's process to raise
    again (a worker's own would reach neither the caller's filters nor its records)."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        result = call()
    return result, [(w.message, w.category) for w in caught]


def _call_with_shared(function: Callable[[Any, Any], Any], task: Any) -> Any:
    return _captured(lambda: function(_SHARED[0], task))


class WorkerPool:
    """Worker processes kept for several rounds of tasks of one computation, started once:
    :func:`worker_count` of them, started by :func:`process_pool` with ``shared`` (large data
    every task of :meth:`map_shared` reads) handed to each once. One worker runs the tasks in
    this process. Results come in task order; warnings a task raises are raised again here.

    Use as a context manager.
    """

    def __init__(self, workers: int | None, tasks: int, shared: Any = None):
        self.count = worker_count(workers, tasks)
        self.shared = shared
        self._stack = ExitStack()
        self._pool: Executor | None = None

    def __enter__(self) -> WorkerPool:
        if self.count > 1:
            self._pool = self._stack.enter_context(process_pool(self.count, _share,
                                                                (self.shared,)))
        else:
            self._stack.enter_context(threadpool_limits(limits=1))
        return self

    def __exit__(self, *exc: Any) -> None:
        self._stack.close()

    def map_shared(self, function: Callable[[Any, Any], Any], tasks: Sequence[Any],
                   progress: TaskProgress | None = None) -> list[Any]:
        """``[function(shared, task) for task in tasks]``, ``function`` module-level."""
        if self._pool is None:
            return self._in_order([partial(function, self.shared, task) for task in tasks],
                                  progress)
        return self._gathered([self._pool.submit(_call_with_shared, function, task)
                               for task in tasks], progress)

    def call_all(self, calls: Sequence[Callable[[], Any]]) -> list[Any]:
        """``[call() for call in calls]``, each call picklable (a :func:`functools.partial` of
        a module-level function)."""
        if self._pool is None:
            return self._in_order(calls, None)
        return self.gather(self.submit_all(calls))

    def submit_all(self, calls: Sequence[Callable[[], Any]]) -> list[Future]:
        """Start ``calls`` (as :meth:`call_all`) and return at once, with their futures for
        :meth:`gather`: this process can work meanwhile. One worker: each runs now, here."""
        if self._pool is None:
            return [InlineExecutor().submit(call) for call in calls]
        return [self._pool.submit(_captured, call) for call in calls]

    def gather(self, futures: Sequence[Future]) -> list[Any]:
        """The results of :meth:`submit_all`'s ``futures``, in their order; the first failure
        is raised."""
        if self._pool is None:
            return [future.result() for future in futures]
        return self._gathered(list(futures), None)

    @staticmethod
    def _in_order(calls: Sequence[Callable[[], Any]], progress: TaskProgress | None
                  ) -> list[Any]:
        results = []
        for index, call in enumerate(calls):
            results.append(call())
            if progress is not None:
                progress(index + 1, len(calls), index)
        return results

    @staticmethod
    def _gathered(futures: list[Future], progress: TaskProgress | None) -> list[Any]:
        order = {future: k for k, future in enumerate(futures)}
        results: list[Any] = [None] * len(futures)
        raised: list[list] = [[] for _ in futures]
        for done, future in enumerate(as_completed(futures), start=1):
            index = order[future]
            results[index], raised[index] = future.result()
            if progress is not None:
                progress(done, len(futures), index)
        for caught in raised:  # in task order, as one process would have raised them
            for message, category in caught:
                warnings.warn(message, category, stacklevel=3)
        return results


def longest_first(tasks: Sequence[Any], first: Sequence[Any],
                  key: Callable[[Any], Any] = lambda task: task) -> list[Any]:
    """``tasks`` with those whose ``key`` is in ``first`` (the longest, longest first) ahead, in
    that order, then the others as they came: workers given the long tasks early finish
    together."""
    return sorted(tasks, key=lambda task: (first.index(key(task)) if key(task) in first
                                           else len(first)))


def run_in_order(function: Callable[..., Any], tasks: Sequence[Any], workers: int | None = None,
                 progress: TaskProgress | None = None, shared: Any = None) -> list[Any]:
    """``[function(task) for task in tasks]`` on :func:`worker_count` processes, in task order.

    ``function`` is module-level, called as ``function(shared, task)`` when ``shared`` (large data sent
    once per worker) is given; ``progress(done, total, index)`` as tasks finish; the first failure is raised.
    """
    tasks = list(tasks)
    with WorkerPool(workers, len(tasks), shared) as pool:
        if shared is None:
            return pool.map_shared(_unshared, [(function, task) for task in tasks], progress)
        return pool.map_shared(function, tasks, progress)


def _unshared(_: Any, task: tuple[Callable[[Any], Any], Any]) -> Any:
    function, argument = task
    return function(argument)


__all__ = ["START_METHOD", "WORKERS_INHERIT", "WORKER_THREADS", "InlineExecutor", "TaskProgress",
           "WorkerPool", "inheriting_workers", "keep_freed_memory", "limit_worker_threads",
           "longest_first", "one_blas_thread", "process_pool", "run_in_order", "worker_count"]
