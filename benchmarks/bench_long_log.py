"""Long logs: time and peak memory of Method B on 1, 10 and 60 minutes at 1 kHz.

The logs are the paper's six experiments on our plant (Coulomb 5 N m, reference sensor
noise, 0.5 Hz), simulated for 20 s each and then extended to the wanted length by repeating
their last eight excitation periods (16 s, whole periods, so the signals stay continuous):
six experiments of 10 s, 100 s and 600 s, i.e. 1, 10 and 60 minutes of log in all. Each
length runs in a fresh process, which reports the wall and CPU time of
``WaveletIdentifier().fit`` (after a warm-up fit on a short log in the same process; every
core, as a user runs it), its CPU time with its worker processes', and the peak resident memory
(``ru_maxrss``) of the largest process, the fitting one or a worker, with the memory the data
themselves take.

``--stages`` adds, for one length, the peak resident memory inside each stage of the default
Method B and what each stage keeps, to show where the memory goes.

Run: ``python benchmarks/bench_long_log.py [--minutes 1 10 60] [--stages 10]``.
"""

from __future__ import annotations

import argparse
import functools
import json
import os
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

SAMPLE_RATE = 1000.0
PERIOD_SAMPLES = 2000  # 0.5 Hz at 1 kHz
TILE_PERIODS = 8


def simulate_base(path: Path) -> None:
    """Six 20 s experiments on the plant, saved as arrays in ``path`` (.npz)."""
    from stewartid.platform import load_platform
    from stewartid.simulation import simulate_experiments
    from stewartid.simulation.sensors import reference_noise

    paper = load_platform("paper").replace(friction__coulomb=5.0)
    run = simulate_experiments(paper, duration_s=20.0, noise=reference_noise(paper),
                               jobs=os.cpu_count() or 1)
    np.savez(path, **{f"{field}{k}": getattr(d, field) for k, d in enumerate(run.datasets)
                      for field in ("pose", "lengths", "forces")})


def long_datasets(base: Path, seconds_each: float) -> list:
    """Six experiments of ``seconds_each`` s: the base records' last whole periods, repeated."""
    from stewartid.datasets.dataset import Dataset

    arrays = np.load(base)
    n = int(round(seconds_each * SAMPLE_RATE)) + 1
    tile = TILE_PERIODS * PERIOD_SAMPLES
    out = []
    for k in range(6):
        signals = {}
        for field in ("pose", "lengths", "forces"):
            record = arrays[f"{field}{k}"]
            block = record[len(record) - 1 - tile:len(record) - 1]
            signals[field] = np.resize(block, (n, 6)) if n > tile else block[:n]
        out.append(Dataset(t=np.arange(n) / SAMPLE_RATE, name=f"exp{k + 1}", **signals))
    return out


def resident_mib() -> float:
    """Current resident memory of this process (MiB)."""
    with open("/proc/self/statm", encoding="ascii") as f:
        return int(f.read().split()[1]) * os.sysconf("SC_PAGE_SIZE") / 2 ** 20


def measure(base: Path, minutes: float) -> dict:
    """Time and memory of one Method B fit on ``minutes`` of log (this process)."""
    from stewartid.identification.wavelet.estimator import WaveletIdentifier
    from stewartid.platform import load_platform

    paper = load_platform("paper")
    WaveletIdentifier().fit(long_datasets(base, 10.0), paper)  # warm-up: caches, imports
    datasets = long_datasets(base, minutes * 60.0 / 6)
    data_mib = sum(d.t.nbytes + 3 * d.pose.nbytes for d in datasets) / 2 ** 20
    before = resident_mib()
    start, start_cpu = time.perf_counter(), _cpu_with_workers()
    estimator = WaveletIdentifier().fit(datasets, paper)
    wall, cpu = time.perf_counter() - start, _cpu_with_workers() - start_cpu
    # the workers have ended with the fit: the children's figure is the largest of them
    peak = max(resource.getrusage(who).ru_maxrss
               for who in (resource.RUSAGE_SELF, resource.RUSAGE_CHILDREN)) / 1024
    return {"minutes": minutes, "samples": sum(len(d) for d in datasets), "wall_s": wall,
            "cpu_s": cpu, "peak_rss_mib": peak, "rss_before_fit_mib": before,
            "data_mib": data_mib, "M_33": float(estimator.M_[2, 2])}


def _cpu_with_workers() -> float:
    """CPU time (s) of this process and of its ended worker processes."""
    times = os.times()
    return times.user + times.system + times.children_user + times.children_system


def stages(base: Path, minutes: float) -> list[tuple[str, float, float]]:
    """Peak resident memory inside each stage of the default Method B and what it keeps.

    The fit in this one process (``jobs=1``), so that every stage runs where it is measured.
    Resident memory sampled every millisecond by a thread (tracemalloc would miss the arrays
    that compiled kernels allocate). Returns (stage, peak above the stage's entry, kept
    after it), MiB; a stage called several times reports its largest peak and the sum kept.
    """
    import threading

    from stewartid.identification.wavelet import estimator as wavelet
    from stewartid.platform import load_platform

    rows: dict[str, list[float]] = {}
    active: dict[str, float] = {}  # running stage -> highest resident memory seen in it
    running = threading.Event()

    def sample() -> None:
        while not running.is_set():
            now = resident_mib()
            for name in list(active):
                active[name] = max(active.get(name, now), now)
            time.sleep(1e-3)

    def traced(name, function):
        @functools.wraps(function)
        def wrapper(*args, **kwargs):
            entry = active[name] = resident_mib()
            result = function(*args, **kwargs)
            exit_ = resident_mib()
            high = max(active.pop(name), exit_)
            previous = rows.get(name, [0.0, 0.0])
            rows[name] = [max(previous[0], high - entry), previous[1] + exit_ - entry]
            return result
        return wrapper

    for name in ("one_sine", "prepare_experiment", "estimate_noise", "detect_intervals",
                 "patterns_with_half_window", "model_equations", "solve_models"):
        setattr(wavelet, name, traced(name, getattr(wavelet, name)))
    estimator = wavelet.WaveletIdentifier(jobs=1)
    estimator.fit(long_datasets(base, 10.0), load_platform("paper"))  # warm-up
    rows.clear()
    datasets = long_datasets(base, minutes * 60.0 / 6)
    thread = threading.Thread(target=sample, daemon=True)
    thread.start()
    start = resident_mib()
    fit = traced("fit (all stages)", estimator.fit)
    fit(datasets, load_platform("paper"))
    running.set()
    thread.join()
    rows["fit (all stages)"][1] = resident_mib() - start
    return [(name, high, kept) for name, (high, kept) in rows.items()]


def machine() -> str:
    """CPU model, core count and load average."""
    model = "unknown CPU"
    with open("/proc/cpuinfo", encoding="utf-8") as f:
        for line in f:
            if line.startswith("model name"):
                model = line.split(":", 1)[1].strip()
                break
    load = ", ".join(f"{x:.1f}" for x in os.getloadavg())
    return f"{model}, {os.cpu_count()} cores, load average {load}"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--minutes", type=float, nargs="+", default=[1.0, 10.0, 60.0])
    parser.add_argument("--stages", type=float, default=None,
                        help="also break the memory down by stage for this many minutes")
    parser.add_argument("--child", nargs=2, metavar=("BASE", "MINUTES"),
                        help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.child:
        print(json.dumps(measure(Path(args.child[0]), float(args.child[1]))))
        return
    print(machine())
    with tempfile.TemporaryDirectory() as folder:
        base = Path(folder) / "base.npz"
        simulate_base(base)
        print(f"{'minutes':>7s} {'samples':>9s} {'wall s':>7s} {'cpu s':>7s} "
              f"{'s/min':>6s} {'peak RSS MiB':>12s} {'before fit':>10s} {'data MiB':>8s}")
        for minutes in args.minutes:
            done = subprocess.run([sys.executable, __file__, "--child", str(base), str(minutes)],
                                  capture_output=True, text=True, check=True)
            r = json.loads(done.stdout.strip().splitlines()[-1])
            print(f"{r['minutes']:7.0f} {r['samples']:9d} {r['wall_s']:7.2f} {r['cpu_s']:7.2f} "
                  f"{r['cpu_s'] / r['minutes']:6.2f} {r['peak_rss_mib']:12.0f} "
                  f"{r['rss_before_fit_mib']:10.0f} {r['data_mib']:8.0f}", flush=True)
        if args.stages:
            print(f"\nresident memory by stage, {args.stages:g} min (MiB): peak above entry, "
                  "kept")
            for name, peak, kept in stages(base, args.stages):
                print(f"  {name:20s} {peak:9.0f} {kept:9.0f}")
    print(machine())


if __name__ == "__main__":
    main()
