"""Study benchmark: the 3 x 3 x 8-seed study of 10 s records on 1 and on 2 dask workers.

Coulomb friction 0, 5 and 30 N m times noise scale 0, 1 and 2 times 8 seeds is 72 tasks
(one simulation of the six experiments each) and 216 rows over Methods B, A and least
squares. Each worker count runs the whole study into a fresh folder on a fresh LocalCluster
(start-up included in the wall time); the last run's report is kept in ``--out``. Prints a
Markdown table with the machine, its load average before and after each run, the tasks' wall
and CPU times summed, and the cores the study obtained (CPU seconds per wall second): on a
machine shared with other jobs, that is what limits the speed-up.

Usage::

    python benchmarks/bench_study.py [--workers 1,2] [--duration 10] [--seeds 8]
                                     [--out results/bench_study]
"""

from __future__ import annotations

import argparse
import os
import platform
import shutil
import tempfile
import time
from pathlib import Path

from stewartid.studies import parse_study, run_study

METHODS = ["wavelet", "fourier", "ls"]


def study_document(duration_s: float, seeds: int) -> dict:
    """The benchmark study as a decoded study file."""
    return {"study": {"platform": "paper", "methods": METHODS, "duration": duration_s,
                      "seeds": seeds, "title": "Benchmark study: Coulomb friction x noise"},
            "grid": {"coulomb": [0.0, 5.0, 30.0], "noise_scale": [0.0, 1.0, 2.0],
                     "frequency": [0.5]}}


def cpu_name() -> str:
    """The processor's model name (Linux), else what the platform module knows."""
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or platform.machine()


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--workers", default="1,2", help="comma-separated worker counts")
    parser.add_argument("--duration", type=float, default=10.0, help="s per experiment")
    parser.add_argument("--seeds", type=int, default=8)
    parser.add_argument("--out", type=Path, default=Path("results/bench_study"),
                        help="folder for the last run's results and report")
    args = parser.parse_args()
    spec = parse_study(study_document(args.duration, args.seeds))
    counts = [int(n) for n in args.workers.split(",")]
    print(f"machine: {cpu_name()}, {os.cpu_count()} logical cores, Python "
          f"{platform.python_version()}")
    print(f"study: {spec.size} tasks, {spec.size * len(spec.methods)} rows, "
          f"{args.duration:g} s records")
    lines = ["| workers | wall time (s) | rows | task wall time, sum (s) | task CPU time, sum (s) "
             "| cores obtained | load before | load after | speed-up |",
             "|---:|---:|---:|---:|---:|---:|---:|---:|---:|"]
    first = None
    for k, count in enumerate(counts):
        last = k == len(counts) - 1
        folder = Path(tempfile.mkdtemp(prefix=f"bench_study_{count}_"))
        load_before = os.getloadavg()[0]
        start = time.perf_counter()
        run = run_study(spec, folder, workers=count, progress=True, report=last)
        wall = time.perf_counter() - start
        load_after = os.getloadavg()[0]
        rows = run.rows
        tasks = rows.groupby("task")
        task_wall = tasks["simulation_time_s"].first().sum() + rows["run_time_s"].sum()
        task_cpu = tasks["task_cpu_time_s"].first().sum()
        first = first or wall
        # CPU seconds per wall second: the cores the study actually got on a shared machine
        lines.append(f"| {count} | {wall:.0f} | {len(rows)} | {task_wall:.0f} | {task_cpu:.0f} "
                     f"| {task_cpu / wall:.2f} | {load_before:.2f} | {load_after:.2f} | "
                     f"{first / wall:.2f}× |")
        print(lines[-1], flush=True)
        if last:
            shutil.rmtree(args.out, ignore_errors=True)
            shutil.copytree(folder, args.out)
        shutil.rmtree(folder, ignore_errors=True)
    print("\n".join(lines))
    print(f"report: {args.out / 'report.md'}")


if __name__ == "__main__":
    main()
