"""Time to identify six experiments of 20 s at 1 kHz with every registered method.

Data: the linear model itself (helper of the test suite) on the paper's platform, one sine
per DOF at 0.5 Hz. BLAS on one thread, as the command line runs it; wall and CPU time of
one fit after a warm-up, with the machine's load average. Run:
``python benchmarks/bench_identification.py``.
"""

from __future__ import annotations

import os
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))

from threadpoolctl import threadpool_limits  # noqa: E402

from linear_model_data import make_experiment, random_matrices  # noqa: E402
from stewartid.identification.registry import registered_methods  # noqa: E402
from stewartid.platform import load_platform  # noqa: E402


def main() -> None:
    with threadpool_limits(limits=1, user_api="blas"):
        run()


def run() -> None:
    platform = load_platform("paper")
    M, B = random_matrices(np.random.default_rng(0))
    data = [make_experiment(platform, M, B, k, frequency_hz=0.5, periods=10,
                            sample_rate=1000.0) for k in range(6)]
    print(f"{len(data)} experiments x {data[0].duration + 1e-3:.0f} s at "
          f"{data[0].sample_rate:.0f} Hz; load average {os.getloadavg()[0]:.1f}")
    for spec in registered_methods():
        spec.create().fit(data[:6], platform)  # warm-up: numba caches, imports
        start, cpu = time.perf_counter(), time.process_time()
        est = spec.create().fit(data, platform)
        elapsed, cpu = time.perf_counter() - start, time.process_time() - cpu
        error = np.max(np.abs(est.M_ - M)) / np.max(np.abs(M))
        print(f"{spec.name:13s} {elapsed:6.2f} s wall {cpu:6.2f} s CPU   "
              f"max |dM| / max|M| = {error:.1e}")
    print(f"load average after: {os.getloadavg()[0]:.1f}")


if __name__ == "__main__":
    main()
