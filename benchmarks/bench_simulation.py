"""Speed of the plant simulator: simulated seconds per wall-clock second.

Full hydraulic closed loop (valves, chambers, PID, friction), 1 kHz output, RK4 at the
default 0.5 ms step, on one core; then the paper's set on two worker processes and the time
to write it as CSV and as Parquet. Run: ``python benchmarks/bench_simulation.py``.
"""

from __future__ import annotations

import os
import tempfile
import time
from pathlib import Path

os.environ.setdefault("NUMBA_NUM_THREADS", "1")

from stewartid.platform import load_platform  # noqa: E402
from stewartid.simulation import (  # noqa: E402
    paper_experiments,
    simulate_experiment,
    simulate_experiments,
    write_experiments,
)


def main() -> None:
    paper = load_platform("paper").replace(friction__coulomb=5.0)
    excitation = paper_experiments(paper)[3]
    simulate_experiment(paper, excitation, 0.5)  # compile / load the numba cache
    for mode in ("hydraulic", "ideal"):
        plant = paper.replace(hydraulics__mode=mode)
        start = time.perf_counter()
        simulate_experiment(plant, excitation, 20.0)
        wall = time.perf_counter() - start
        print(f"{mode:9s} one 20 s experiment: {wall:.2f} s wall, {20.0 / wall:.1f}x real time")
    start = time.perf_counter()
    run = simulate_experiments(paper, duration_s=20.0)
    wall = time.perf_counter() - start
    print(f"paper set 6 x 20 s (hydraulic, with FK and sensors): {wall:.2f} s wall, "
          f"{120.0 / wall:.1f}x real time")
    start = time.perf_counter()
    simulate_experiments(paper, duration_s=20.0, jobs=2)
    print(f"paper set 6 x 20 s on 2 worker processes: {time.perf_counter() - start:.2f} s wall")
    with tempfile.TemporaryDirectory() as folder:
        for kind in ("csv", "parquet"):
            start = time.perf_counter()
            write_experiments(run, Path(folder) / kind, format=kind)
            print(f"writing the set as {kind}: {time.perf_counter() - start:.2f} s wall")


if __name__ == "__main__":
    main()
