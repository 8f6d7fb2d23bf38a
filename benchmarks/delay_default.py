"""The force delay by default: estimated and applied where the motion tells it from damping,
left alone where it is noise. The three-sine and all-DOF logs (6 x 20 s at 1 kHz,
:func:`noise_study.kind_logs`) of a platform (``--platform paper|FILE``; its own Coulomb level,
or :data:`noise_study.KIND_COULOMB` where it has none) on our plant or on MuJoCo
(``--engine mujoco``), the reference sensor noise per seed, the forces logged ``--late``
seconds late or on time. Per log :func:`stewartid.compare_methods` is run with its defaults,
as ``identify --method all --report`` does: the estimated delay, whether it was applied, the
trusted method and its errors against the nominal matrices (largest Mt-diagonal error, largest
error over the paper's 20 entries, entries within 3 reported SE), the best method's largest
error and the trusted one's ratio to it, and Method B's and least squares' errors.
``--out FILE`` appends one JSON line per log in the row format of ``verdict_study.py --out``
(every method's fit, the verdict, the truth; read by ``verdict_floor.py``), with the log's
``kind``, ``late`` (s) and ``delay`` entry.

Usage::

    python benchmarks/delay_default.py [--platform paper|FILE] [--engine ours|mujoco]
        [--kinds three,alldof] [--seeds 4] [--first-seed 0] [--late 0.002] [--duration 20]
        [--clean DIR] [--out FILE]
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import noise_study  # noqa: E402  (a sibling script)
import verdict_study  # noqa: E402  (a sibling script)

import stewartid as sid  # noqa: E402
from stewartid.comparison import compare_methods  # noqa: E402
from stewartid.reference.published import PAPER_ENTRIES, relative_error_percent  # noqa: E402


def study_platform(name: str):
    """The platform ``name`` with its own Coulomb level, or the kinds' where it has none."""
    platform = sid.load_platform(name)
    if platform.friction.coulomb == 0:
        platform = platform.replace(friction__coulomb=noise_study.KIND_COULOMB)
    return platform


def errors(result, M, B) -> tuple[float, float, int]:
    """Largest Mt-diagonal error, largest error (%) and entries within 3 SE of the 20."""
    truth = {"M": M, "B": B}
    found = {"M": result.M, "B": result.B}
    std = {"M": result.std_errors_M, "B": result.std_errors_B}
    rel = [relative_error_percent(found[m][i, j], truth[m][i, j]) for m, i, j in PAPER_ENTRIES]
    within = sum(abs(found[m][i, j] - truth[m][i, j]) <= 3 * std[m][i, j]
                 for m, i, j in PAPER_ENTRIES)
    return max(rel[:6]), max(rel), int(within)


def cell(scores) -> str:
    return "refused" if scores is None else f"{scores[0]:.2f} / {scores[1]:.1f}, {scores[2]}/20"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--platform", default="paper", help="paper or a platform TOML file")
    parser.add_argument("--engine", default="ours", choices=("ours", "mujoco"))
    parser.add_argument("--kinds", default="three,alldof")
    parser.add_argument("--seeds", type=int, default=4)
    parser.add_argument("--first-seed", type=int, default=0)
    parser.add_argument("--late", type=float, default=0.002)
    parser.add_argument("--duration", type=float, default=noise_study.KIND_DURATION,
                        help="record length of each experiment (s)")
    parser.add_argument("--clean", type=Path, default=Path("results/delay_default"),
                        help="folder of the clean logs (simulated there when missing)")
    parser.add_argument("--out", type=Path, default=None,
                        help="append one JSON line per log here (verdict_study.py's rows)")
    options = parser.parse_args()
    noise_study.KIND_DURATION = options.duration
    platform = study_platform(options.platform)
    M, B = sid.nominal_matrices(platform)
    tag = "paper" if options.platform == "paper" else Path(options.platform).stem
    suffix = "" if options.duration == 20.0 else f"_d{options.duration:g}"
    print("| platform | engine | log | late (ms) | seed | delay ± SE (ms) | applied | trusted | "
          "trusted: Mt diag / largest (%), in 3 SE | best's largest (%) | trusted / best | "
          "Method B | least squares |")
    print("|---" * 13 + "|")
    for kind in options.kinds.split(","):
        folder = (options.clean
                  / f"{options.engine}_{tag}_{kind}_c{platform.friction.coulomb:g}{suffix}")
        clean = noise_study.kind_logs(kind, platform, folder, options.engine)
        for late in (options.late, 0.0):
            noise = dataclasses.replace(sid.reference_noise(platform), force_delay=late)
            for seed in range(options.first_seed, options.first_seed + options.seeds):
                data = [sid.degrade(d, platform, noise, np.random.default_rng(seed + 101 * k))
                        for k, d in enumerate(clean)]
                comparison = compare_methods(data, platform)
                scores = {run.name: None if run.result is None else errors(run.result, M, B)
                          for run in comparison.runs}
                trusted = comparison.verdict.trusted
                best = min(s[1] for s in scores.values() if s is not None)
                entry = comparison.delay or {}
                delay = ("not estimated" if entry.get("seconds") is None else
                         f"{entry['seconds'] * 1e3:.3f} ± {entry['std_error'] * 1e3:.3f}")
                print(f"| {tag} | {options.engine} | {kind} | {late * 1e3:g} | {seed} | {delay} "
                      f"| {entry.get('applied', False)} | {trusted} | {cell(scores[trusted])} | "
                      f"{best:.1f} | {scores[trusted][1] / best:.2f} | "
                      f"{cell(scores.get('wavelet'))} | {cell(scores.get('ls'))} |", flush=True)
                if options.out is not None:
                    row = verdict_study.log_row(
                        f"{tag} {options.engine} {kind} late {late * 1e3:g} ms", seed,
                        comparison.runs, comparison.verdict, M, B)
                    row.update(kind=kind, late=late, delay=comparison.delay)
                    with options.out.open("a") as handle:
                        handle.write(json.dumps(row, default=float) + "\n")


if __name__ == "__main__":
    main()
