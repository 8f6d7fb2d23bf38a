"""The worker pool: results in task order whichever worker finishes first, warnings raised again
in the calling process (where filters and records see them), failures passed on."""

from __future__ import annotations

import multiprocessing
import os
import platform
import time
import warnings
from functools import partial

import numpy as np
import pytest

from stewartid.parallel import WORKERS_INHERIT, WorkerPool, run_in_order

#: Two workers on a platform that starts them by fork (the inline pool runs everywhere).
TWO_FORKED = pytest.param(2, marks=pytest.mark.skipif(
    not WORKERS_INHERIT, reason="the test's tasks reach forked workers only"))


def _offset_square(shared: int, task: int) -> int:
    time.sleep(0.02 * (4 - task))   # the first tasks finish last
    return shared + task * task


def _warned(label: str) -> str:
    warnings.warn(f"careful: {label}", UserWarning, stacklevel=1)
    return label


def _refused(label: str) -> str:
    raise ValueError(f"refused {label}")


@pytest.mark.parametrize("workers", [1, TWO_FORKED])
def test_a_pool_keeps_task_order_over_rounds(workers):
    with WorkerPool(workers, 4, shared=100) as pool:
        first = pool.map_shared(_offset_square, range(4))
        second = pool.call_all([partial(_offset_square, 1, k) for k in range(4)])
    assert first == [100, 101, 104, 109]
    assert second == [1, 2, 5, 10]


@pytest.mark.parametrize("workers", [1, TWO_FORKED])
def test_started_tasks_run_while_this_process_works_and_come_back_in_order(workers):
    # tasks started before this process's own work, then a second batch after it: every
    # result in its batch's order, the first failure of a batch raised by its gather
    with WorkerPool(workers, 4) as pool:
        early = pool.submit_all([partial(_offset_square, 10, k) for k in range(4)])
        own = sum(k * k for k in range(1000))
        late = pool.submit_all([partial(_offset_square, 20, k) for k in range(2)])
        assert pool.gather(late) == [20, 21]
        assert pool.gather(early) == [10, 11, 14, 19]
        failing = pool.submit_all([partial(abs, -1), partial(_refused, "b")])
        with pytest.raises(ValueError, match="refused b"):
            pool.gather(failing)
    assert own == 332833500


@pytest.mark.parametrize("workers", [1, TWO_FORKED])
def test_warnings_of_workers_are_raised_here_in_task_order(workers):
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        with WorkerPool(workers, 3) as pool:
            assert pool.call_all([partial(_warned, k) for k in "abc"]) == list("abc")
    assert [str(w.message) for w in caught] == ["careful: a", "careful: b", "careful: c"]
    assert {w.category for w in caught} == {UserWarning}


@pytest.mark.parametrize("workers", [1, TWO_FORKED])
def test_a_failed_task_raises_its_error(workers):
    with pytest.raises(ValueError, match="refused b"), WorkerPool(workers, 3) as pool:
        pool.call_all([partial(abs, -1), partial(_refused, "b"), partial(abs, -3)])
    assert run_in_order(abs, [-1, 2, -3], workers=workers) == [1, 2, 3]


def _resident_after_freeing(megabytes: int) -> tuple[int, int]:
    """This process's resident pages before and after a freshly written array of ``megabytes``
    is freed."""
    def resident() -> int:
        with open("/proc/self/statm") as statm:
            return int(statm.read().split()[1])

    block = np.ones(megabytes * (1 << 20) // 8)
    holding = resident()
    del block
    return holding, resident()


@pytest.mark.skipif(not WORKERS_INHERIT or platform.libc_ver()[0] != "glibc"
                    or not os.path.exists("/proc/self/statm"),
                    reason="glibc's allocator and /proc only")
def test_workers_keep_freed_memory_for_their_next_task():
    # a record's array freed in a worker stays mapped there for the next task (no page faults
    # to take it again); in a process with the allocator's defaults the system takes it back
    pages = (64 << 20) // os.sysconf("SC_PAGE_SIZE")
    with WorkerPool(2, 2) as pool:
        kept = pool.call_all([partial(_resident_after_freeing, 64)] * 2)
    for holding, after in kept:
        assert after > holding - pages // 8
    with multiprocessing.get_context("spawn").Pool(1) as fresh:
        holding, after = fresh.apply(_resident_after_freeing, (64,))
    assert after < holding - pages // 2


#: numpy 2's switch of huge pages for large arrays, where it has one.
_HUGE_PAGES = getattr(getattr(np, "_core", None), "multiarray", None)


def _numpy_huge_pages() -> bool:
    return bool(_HUGE_PAGES._get_madvise_hugepage())


@pytest.mark.skipif(not WORKERS_INHERIT or not hasattr(_HUGE_PAGES, "_get_madvise_hugepage"),
                    reason="forked workers and numpy 2's huge-page switch only")
def test_workers_put_arrays_on_ordinary_pages_and_leave_the_caller_alone():
    before = _numpy_huge_pages()
    with WorkerPool(2, 2) as pool:
        assert pool.call_all([_numpy_huge_pages] * 2) == [False, False]
    assert _numpy_huge_pages() == before


def test_longest_first_puts_the_named_tasks_ahead_in_their_order_and_keeps_the_rest():
    from stewartid.parallel import longest_first

    tasks = ["a", "b", "c", "d", "e"]
    assert longest_first(tasks, ("d", "b")) == ["d", "b", "a", "c", "e"]
    assert longest_first(range(4), ("y", "w"), key=lambda k: "wxyz"[k]) == [2, 0, 1, 3]
    assert longest_first(tasks, ()) == tasks
