"""Wall and CPU time of the command line, each command in a fresh process, as a user runs it.

``stewartid simulate`` of the paper's six experiments of 20 s at 1 kHz (CSV and Parquet),
``stewartid identify`` on them with every registered method, and with ``--reproduce``
``stewartid reproduce --quick`` and the full ``stewartid reproduce``. Each figure is the best
of ``--repeats`` runs; CPU time is that of the command and its worker processes. The machine
is described with its load average before and after, since a shared machine's load changes
wall times far more than CPU times.

Run: ``python benchmarks/bench_cli.py [--repeats 3] [--reproduce]``.
"""

from __future__ import annotations

import argparse
import os
import resource
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from stewartid.identification.registry import registered_methods

COMMAND = [sys.executable, "-c", "from stewartid.cli import main; main()"]


def timed(arguments: list[str], repeats: int, out: Path | None = None) -> tuple[float, float]:
    """Best wall and CPU time (s) of ``stewartid ARGUMENTS`` in fresh processes; ``out`` is
    removed before each run."""
    best_wall, best_cpu = float("inf"), float("inf")
    for _ in range(repeats):
        if out is not None:
            shutil.rmtree(out, ignore_errors=True)
        before = resource.getrusage(resource.RUSAGE_CHILDREN)
        start = time.perf_counter()
        subprocess.run(COMMAND + arguments, check=True, stdout=subprocess.DEVNULL,
                       stderr=subprocess.DEVNULL)
        wall = time.perf_counter() - start
        after = resource.getrusage(resource.RUSAGE_CHILDREN)
        cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
        best_wall, best_cpu = min(best_wall, wall), min(best_cpu, cpu)
    return best_wall, best_cpu


def load() -> str:
    return ", ".join(f"{x:.1f}" for x in os.getloadavg())


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--reproduce", action="store_true",
                        help="also time reproduce --quick and the full reproduce")
    args = parser.parse_args()
    print(f"{os.cpu_count()} cores, load average before: {load()}")
    rows = []
    with tempfile.TemporaryDirectory() as folder:
        data = Path(folder) / "csv"
        for kind in ("csv", "parquet"):
            out = Path(folder) / kind
            rows.append((f"simulate 6 x 20 s --format {kind}", *timed(
                ["simulate", "--platform", "paper", "--coulomb", "5", "--duration", "20",
                 "--format", kind, "--out", str(out)], args.repeats, out)))
        files = sorted(str(p) for p in data.glob("exp*.csv"))
        for spec in registered_methods():
            rows.append((f"identify --method {spec.name} (6 x 20 s CSV)", *timed(
                ["identify", "--method", spec.name, "--platform", "paper", *files],
                args.repeats)))
        if args.reproduce:
            out = Path(folder) / "reproduce"
            rows.append(("reproduce --quick", *timed(
                ["reproduce", "--quick", "--out", str(out)], 1, out)))
            rows.append(("reproduce", *timed(["reproduce", "--out", str(out)], 1, out)))
    width = max(len(r[0]) for r in rows)
    print(f"{'command':{width}s} {'wall s':>7s} {'CPU s':>7s}")
    for name, wall, cpu in rows:
        print(f"{name:{width}s} {wall:7.2f} {cpu:7.2f}")
    print(f"load average after: {load()}")


if __name__ == "__main__":
    main()
