"""Speed of the plant simulator: simulated seconds per wall-clock second.

Full hydraulic closed loop (valves, chambers, PID, friction), 1 kHz output, RK4 at the
default 0.5 ms step, on one core. Run: ``python benchmarks/bench_simulation.py``.
"""

from __future__ import annotations

import os
import time

os.environ.setdefault("NUMBA_NUM_THREADS", "1")

from stewartid.platform import load_platform  # noqa: E402
from stewartid.simulation import paper_experiments, simulate_experiment, simulate_experiments  # noqa: E402,E501


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
    simulate_experiments(paper, duration_s=20.0)
    wall = time.perf_counter() - start
    print(f"paper set 6 x 20 s (hydraulic, with FK and sensors): {wall:.2f} s wall, "
          f"{120.0 / wall:.1f}x real time")


if __name__ == "__main__":
    main()
