"""Speed and memory of the identification path beside an earlier source tree, in one run.

Both trees are byte-compiled first (``compileall``, as installing a wheel does), so that no
command compiles the package's sources where the environment forbids writing bytecode
(``PYTHONDONTWRITEBYTECODE``). Each command runs in a fresh process, the two trees interleaved
(A B A B ...), and its wall
time, CPU time (with its worker processes) and peak resident memory of its largest process are
read from the process itself (``os.wait4``), the peak memory of the whole process tree sampled
as PSS (pages shared by forked workers counted once).
Then each tree fits the methods in one process after a warm-up (the library's cost without
start-up), best CPU time of ``--repeats``, and, where a method takes worker processes
(``jobs``), its best wall time on every core.

The logs: the paper platform's six experiments of 20 s at 1 kHz with the reference sensor
noise and 30 N m of Coulomb friction (Parquet), simulated once by this tree, and the same at
2 kHz. ``--average`` adds ``identify --method all --report`` on the 2 kHz log and gives the
later tree's commands on it ``--average`` (``identify --average``). ``--log LABEL=DIR[@PLATFORM]``
(repeatable) adds ``identify --method wavelet`` on a folder of logs already written (a
three-sine log with late forces, an electric 2 kHz log), with ``--platform PLATFORM`` unless a
``meta.json`` beside them names it.

Usage::

    git worktree add /tmp/before <commit>
    python benchmarks/bench_speed.py --before /tmp/before/src [--repeats 5] [--reproduce]
        [--average] [--log three=DIR --log electric=DIR@src/stewartid/data/electric.toml]
"""

from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path

#: A CLI call of a source tree: its own ``main`` on the module path.
RUN = "import sys; sys.path.insert(0, sys.argv.pop(1)); from stewartid.cli import main; main()"
#: In-process fits after a warm-up: best CPU time of ``repeats`` fits of each method.
FIT = """
import sys, time, warnings
sys.path.insert(0, sys.argv[1])
warnings.simplefilter("ignore")
from pathlib import Path
from stewartid.platform import load_platform
from stewartid.identification.registry import create_identifier
try:
    from stewartid.datasets import read_datasets
except ImportError:  # an older layout
    from stewartid.dataset import read_datasets
platform = load_platform("paper")
files = sorted(str(p) for p in Path(sys.argv[2]).glob("exp*.parquet"))
for name in sys.argv[4].split(","):
    create_identifier(name).fit(read_datasets(files, platform), platform)
    # a fresh read for every fit: nothing derived from an earlier fit's records is reused
    best = min(_timed(lambda data: create_identifier(name).fit(data, platform),
                      read_datasets(files, platform)) for _ in range(int(sys.argv[3])))
    # a tree whose method takes worker processes: its wall time on every core too
    wall = float("nan")
    if "jobs" in create_identifier(name).get_params():
        wall = min(_walled(lambda data: create_identifier(name, jobs=None).fit(data, platform),
                           read_datasets(files, platform)) for _ in range(int(sys.argv[3])))
    print(name, best, wall)
"""
TIMER = """
def _timed(call, data):
    start = time.process_time()
    call(data)
    return time.process_time() - start

def _walled(call, data):
    start = time.perf_counter()
    call(data)
    return time.perf_counter() - start
"""


def tree_pss(root: int) -> float:
    """Proportional set size (MiB) of a process and its descendants (Linux ``/proc``): pages
    shared between them, as a forked worker's, counted once."""
    total, stack = 0, [root]
    while stack:
        pid = stack.pop()
        try:
            rollup = Path(f"/proc/{pid}/smaps_rollup").read_text().splitlines()
            for children in Path(f"/proc/{pid}/task").glob("*/children"):
                stack += [int(child) for child in children.read_text().split()]
        except OSError:
            continue
        total += next((int(line.split()[1]) for line in rollup if line.startswith("Pss:")), 0)
    return total / 1024


def measured(command: list[str], env: dict[str, str]) -> tuple[float, float, float, float]:
    """Wall s, CPU s (with its worker processes), peak resident MiB of its largest process and
    peak PSS MiB of its process tree (sampled every 0.1 s); NaN wall if it failed (exit 2: the
    method refused the log)."""
    start = time.perf_counter()
    process = subprocess.Popen(command, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                               env=env)
    peak = [0.0]
    running = threading.Event()
    running.set()

    def sample() -> None:
        while running.is_set():
            peak[0] = max(peak[0], tree_pss(process.pid))
            time.sleep(0.1)

    sampler = threading.Thread(target=sample, daemon=True)
    sampler.start()
    _, status, usage = os.wait4(process.pid, 0)
    running.clear()
    sampler.join()
    wall = time.perf_counter() - start
    wall = wall if status == 0 else float("nan")
    return wall, usage.ru_utime + usage.ru_stime, usage.ru_maxrss / 1024, peak[0]


SIMULATE = """
import os, sys
from stewartid.platform import load_platform
from stewartid.simulation.experiments import simulate_experiments, write_experiments
from stewartid.simulation.sensors import reference_noise

platform = load_platform("paper").replace(sensors__sample_rate=float(sys.argv[2]))
result = simulate_experiments(platform, coulomb=30.0, duration_s=20.0, seed=1,
                              noise=reference_noise(platform), jobs=os.cpu_count() or 1)
write_experiments(result, sys.argv[1], format="parquet")
"""


def simulate(folder: Path, rate: float) -> None:
    """The benchmark's log at ``rate`` Hz, by this tree, in a process of its own: a child's peak
    memory starts from its parent's, which must stay small."""
    subprocess.run([sys.executable, "-c", SIMULATE, str(folder), str(rate)], check=True)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--before", required=True, help="src folder of the earlier tree")
    parser.add_argument("--after", default=str(Path(__file__).resolve().parents[1] / "src"))
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--reproduce", action="store_true", help="also time reproduce")
    parser.add_argument("--average", action="store_true",
                        help="also time --method all on the 2 kHz log, and run the later "
                             "tree's 2 kHz commands with --average")
    parser.add_argument("--log", action="append", default=[], metavar="LABEL=DIR[@PLATFORM]",
                        help="also time identify --method wavelet on these logs")
    args = parser.parse_args()
    env = {**os.environ, "OPENBLAS_NUM_THREADS": "1"}
    trees = {"before": args.before, "after": args.after}
    for src in trees.values():  # an installed package's bytecode, as pip writes it
        subprocess.run([sys.executable, "-m", "compileall", "-q", src], check=True,
                       stdout=subprocess.DEVNULL)
    print(f"{os.cpu_count()} cores; load average before: {os.getloadavg()[0]:.2f}")
    with tempfile.TemporaryDirectory() as scratch:
        scratch = Path(scratch)
        logs = {"1 kHz": scratch / "log1k", "2 kHz": scratch / "log2k"}
        simulate(logs["1 kHz"], 1000.0)
        simulate(logs["2 kHz"], 2000.0)
        commands = {
            "identify --method wavelet": ["identify", str(logs["1 kHz"]), "--method", "wavelet"],
            "identify --method wavelet (2 kHz)": ["identify", str(logs["2 kHz"]), "--method",
                                                  "wavelet"],
            "identify --method all --report": ["identify", str(logs["1 kHz"]), "--method",
                                               "all", "--report", str(scratch / "report")],
        }
        for entry in args.log:
            label, _, where = entry.partition("=")
            folder, _, description = where.partition("@")
            commands[f"identify --method wavelet ({label})"] = [
                "identify", folder, "--method", "wavelet",
                *(["--platform", description] if description else [])]
        if args.average:
            commands["identify --method all --report (2 kHz)"] = [
                "identify", str(logs["2 kHz"]), "--method", "all", "--report",
                str(scratch / "report")]
        if args.reproduce:
            commands["reproduce"] = ["reproduce", "--out", str(scratch / "reproduce"),
                                     "--force"]
        rows = []
        for label, arguments in commands.items():
            runs: dict[str, list[tuple[float, float, float]]] = {tree: [] for tree in trees}
            for _ in range(args.repeats if label != "reproduce" else 1):
                for tree, src in trees.items():
                    for folder in ("report", "reproduce"):
                        subprocess.run(["rm", "-rf", str(scratch / folder)], check=True)
                    extra = (["--average"] if args.average and tree == "after"
                             and "2 kHz" in label else [])
                    runs[tree].append(measured([sys.executable, "-c", RUN, src, *arguments,
                                                *extra], env))
            for tree in trees:
                wall, cpu, memory, pss = (statistics.median(x)
                                          for x in zip(*runs[tree], strict=True))
                rows.append((label, tree, wall, cpu, memory, pss))
        fits = {}
        for tree, src in trees.items():
            output = subprocess.run(
                [sys.executable, "-c", TIMER + FIT, src, str(logs["1 kHz"]), str(args.repeats),
                 "wavelet,ls,fourier"], capture_output=True, text=True, env=env, check=True)
            fits[tree] = {line.split()[0]: line.split()[1:] for line in output.stdout.splitlines()}
    width = max(len(r[0]) for r in rows)
    print(f"{'command':{width}s} {'tree':>6s} {'wall s':>7s} {'CPU s':>7s} {'peak MiB':>9s} "
          f"{'tree PSS':>9s}")
    for label, tree, wall, cpu, memory, pss in rows:
        shown = "failed" if wall != wall else f"{wall:7.2f}"
        print(f"{label:{width}s} {tree:>6s} {shown:>7s} {cpu:7.2f} {memory:9.0f} {pss:9.0f}")
    print("in-process fit, best CPU s (one process): " + "; ".join(
        f"{name}: {float(fits['before'][name][0]):.2f} -> {float(fits['after'][name][0]):.2f}"
        for name in fits["after"]))
    print("in-process fit, best wall s on every core (jobs=None), where the tree has it: "
          + "; ".join(f"{name}: {float(fits[tree][name][1]):.2f} ({tree})"
                      for name in fits["after"] for tree in trees
                      if fits[tree][name][1] != "nan"))
    print(f"load average after: {os.getloadavg()[0]:.2f}")


if __name__ == "__main__":
    main()
