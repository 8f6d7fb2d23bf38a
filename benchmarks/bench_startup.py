"""Start-up and run time of the command line, two source trees side by side in one run.

Each command runs in a fresh process with ``PYTHONPATH`` set to one tree's ``src`` folder,
the two trees interleaved so that the machine's load affects both alike; each figure is the
best of ``--repeats`` runs, wall time and CPU time (user + system) of the process. CPU time is
the figure to compare on a shared machine.

Run, for example against the commit before a change::

    git worktree add /tmp/before COMMIT
    python benchmarks/bench_startup.py --before /tmp/before/src [--repeats 7]
"""

from __future__ import annotations

import argparse
import os
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

EXAMPLE = Path(__file__).resolve().parents[1] / "tests" / "data" / "example_c10"


def commands(out: Path) -> dict[str, list[str]]:
    """The timed command lines (arguments of ``python -m stewartid``)."""
    files = [str(EXAMPLE / f"exp{k}.csv") for k in range(1, 7)]
    platform = str(EXAMPLE / "platform.toml")
    timed = {"--help": ["--help"]}
    for method in ("wavelet", "fourier", "ls"):
        timed[f"identify --method {method}"] = [
            "identify", "--method", method, "--platform", platform, "--out",
            str(out / f"{method}.json"), "--force", *files]
    return timed


def run(source: str, arguments: list[str]) -> tuple[float, float]:
    """Wall and CPU time (s) of ``python -m stewartid ARGUMENTS`` with ``source`` first."""
    # __main__ may be missing in an older tree: start the application by its entry point
    code = "from stewartid.cli import main; main()"
    environment = dict(os.environ, PYTHONPATH=source)
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    start = time.perf_counter()
    subprocess.run([sys.executable, "-c", code, *arguments], env=environment, check=True,
                   stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    wall = time.perf_counter() - start
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return wall, (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--before", required=True, help="src folder of the tree to compare with")
    parser.add_argument("--after", default=str(Path(__file__).resolve().parents[1] / "src"))
    parser.add_argument("--repeats", type=int, default=7)
    args = parser.parse_args()
    trees = {"before": args.before, "after": args.after}
    print(f"{os.cpu_count()} cores, load average before: "
          + ", ".join(f"{x:.1f}" for x in os.getloadavg()))
    with tempfile.TemporaryDirectory() as folder:
        timed = commands(Path(folder))
        best = {}
        for _ in range(args.repeats):
            for name, arguments in timed.items():
                for tree, source in trees.items():
                    wall, cpu = run(source, arguments)
                    old = best.get((name, tree), (float("inf"), float("inf")))
                    best[(name, tree)] = (min(old[0], wall), min(old[1], cpu))
    print("| command | before wall (CPU) | after wall (CPU) |")
    print("|---|---|---|")
    for name in timed:
        (bw, bc), (aw, ac) = best[(name, "before")], best[(name, "after")]
        print(f"| `{name}` | {bw:.2f} s ({bc:.2f} s) | {aw:.2f} s ({ac:.2f} s) |")
    print("load average after: " + ", ".join(f"{x:.1f}" for x in os.getloadavg()))


if __name__ == "__main__":
    main()
