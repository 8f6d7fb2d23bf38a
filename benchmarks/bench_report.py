"""Time to write the identification report (``identify --report``) for six experiments of
20 s at 1 kHz.

Data: the paper's six experiments on the simulated hydraulic plant (Coulomb 10 N m, reference
sensor noise), simulated once before timing. The report runs the default method (Method B),
its 3-fold validation, the consistency check and every figure, export and file; the time is
wall clock from the data sets in memory to the last file. ``--method all`` times the three
methods compared, ``--consistent`` adds the consistent fit.
Run: ``python benchmarks/bench_report.py [--method all] [--consistent]``.
"""

from __future__ import annotations

import argparse
import tempfile
import time
from pathlib import Path

from stewartid import compare_methods, write_report
from stewartid.platform import load_platform
from stewartid.simulation import simulate_experiments
from stewartid.simulation.sensors import reference_noise


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--method", default="wavelet")
    parser.add_argument("--consistent", action="store_true")
    parser.add_argument("--duration", type=float, default=20.0, help="s per experiment")
    options = parser.parse_args()
    platform = load_platform("paper")
    run = simulate_experiments(platform, coulomb=10.0, duration_s=options.duration,
                               noise=reference_noise(platform), seed=1)
    data = run.datasets
    print(f"{len(data)} experiments x {data[0].duration:.0f} s at {data[0].sample_rate:.0f} Hz")
    with tempfile.TemporaryDirectory() as folder:
        # warm-up on a short copy: numba caches and imports, as a second command would have
        short = [d.__class__(t=d.t[:4000], pose=d.pose[:4000], lengths=d.lengths[:4000],
                             forces=d.forces[:4000], name=d.name) for d in data]
        comparison = compare_methods(short, platform, methods="wavelet", folds=2)
        write_report(comparison, Path(folder) / "warm")
        start, cpu = time.perf_counter(), time.process_time()
        comparison = compare_methods(data, platform, methods=options.method,
                                     consistent=options.consistent)
        report = write_report(comparison, Path(folder) / "report")
        wall, cpu = time.perf_counter() - start, time.process_time() - cpu
    print(f"report ({options.method}{', consistent' if options.consistent else ''}): "
          f"{wall:.1f} s wall, {cpu:.1f} s CPU; trusted {report.trusted}")
    for method in report.runs:
        print(f"  {method.name:8s} fit + validation {method.seconds:5.1f} s")


if __name__ == "__main__":
    main()
