"""Fast logs averaged down before identification: every method at the full rate and averaged,
over noise seeds.

Logs (6 experiments each, 2 kHz): the paper platform's sines (Coulomb 30 N m, 20 s, the reference
sensor noise: what ``stewartid simulate --platform paper --coulomb 30 --sample-rate 2000 --noise
--seed N`` writes, simulated into ``--cache`` when missing), and the example electric platform's
"sines" and "alldof" logs of ``electric_study.py`` (noise-free logs from its ``--cache`` folder,
measured per seed as ``simulate --noise --seed`` does: whole encoder counts, 0.5 % current
noise; ``--engine mujoco``: MuJoCo's, e.g. of 5 s).

For each log and seed, Method B (``wavelet``), least squares (``ls``), Method A (``fourier``) and
the physical model (``physical``, Mt and Bt at neutral from its parameters) are fitted to the
records as logged and averaged over k samples (:func:`stewartid.identification.averaging
.averaging_factor`; ``--samples`` forces k). Per method, over the paper's 20 entries: the
largest shift of the averaged fit in the full-rate fit's standard errors, the ratio of the
standard errors (averaged / full), the entries within 3 standard errors of the truth (the
platform's nominal Mt, Bt) at each rate, and the CPU time of each fit.

Usage::

    python benchmarks/averaging_study.py --paper-seeds 4 --cache DIR [--samples K]
        [--electric DIR/ours-sines-20s,DIR/ours-alldof-20s --electric-seeds 4] [--out rows.jsonl]
    python benchmarks/averaging_study.py --summary rows.jsonl [...]
"""

from __future__ import annotations

import argparse
import json
import sys
import time
import warnings
from pathlib import Path

import numpy as np

from stewartid.datasets.dataset import read_datasets, write_dataset
from stewartid.errors import StewartidError
from stewartid.identification.averaging import averaging_factor
from stewartid.identification.registry import create_identifier
from stewartid.identification.sampling import samples_per_period
from stewartid.model.linearization import nominal_matrices
from stewartid.physical.estimator import PhysicalIdentifier
from stewartid.platform import load_platform
from stewartid.reference.published import PAPER_ENTRIES
from stewartid.simulation.experiments import simulate_experiments
from stewartid.simulation.sensors import reference_noise

sys.path.insert(0, str(Path(__file__).resolve().parent))
from electric_study import electric_platform, measured  # noqa: E402

METHODS = ("wavelet", "ls", "fourier", "physical")


def paper_logs(cache: Path, seed: int) -> list:
    """The paper platform's 2 kHz log of ``seed`` (simulated into ``cache`` when missing)."""
    platform = load_platform("paper").replace(friction__coulomb=30.0, sensors__sample_rate=2000.0)
    folder = cache / f"paper-2k-seed{seed}"
    paths = [folder / f"exp{k + 1}.parquet" for k in range(6)]
    if not all(p.exists() for p in paths):
        folder.mkdir(parents=True, exist_ok=True)
        result = simulate_experiments(platform, coulomb=30.0, duration_s=20.0, seed=seed,
                                      noise=reference_noise(platform), jobs=1)
        for path, data in zip(paths, result.datasets, strict=True):
            write_dataset(data, path)
    return platform, read_datasets(paths, platform)


def entries(result) -> tuple[np.ndarray, np.ndarray]:
    """The paper's 20 entries and their standard errors."""
    value = np.array([(result.M if m == "M" else result.B)[i, j] for m, i, j in PAPER_ENTRIES])
    se = np.array([(result.std_errors_M if m == "M" else result.std_errors_B)[i, j]
                   for m, i, j in PAPER_ENTRIES])
    return value, se


def fit(method: str, data: list, platform):
    """The result (or the first line of the refusal) and CPU seconds of one method."""
    start = time.process_time()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        try:
            estimator = (PhysicalIdentifier() if method == "physical"
                         else create_identifier(method)).fit(data, platform)
        except StewartidError as error:
            return str(error).splitlines()[0], time.process_time() - start
    return estimator.result_, time.process_time() - start


def rows_of(case: str, seed: int, platform, data: list, samples: int | None) -> list[dict]:
    """One row per method: full rate against averaged (over ``samples``, default the rule's)."""
    k = samples or averaging_factor(data)
    margin = samples_per_period(data)
    averaged = [d.averaged(k) for d in data]
    M0, B0 = nominal_matrices(platform)
    truth = np.array([(M0 if m == "M" else B0)[i, j] for m, i, j in PAPER_ENTRIES])
    rows = []
    for method in METHODS:
        full, full_cpu = fit(method, data, platform)
        fast, fast_cpu = fit(method, averaged, platform)
        if isinstance(full, str) or isinstance(fast, str):
            rows.append({"case": case, "seed": seed, "method": method, "samples": k,
                         "refused": full if isinstance(full, str) else fast})
            print(f"{case} seed {seed} {method}: refused: {rows[-1]['refused'][:80]}")
            continue
        (value, se), (other, other_se) = entries(full), entries(fast)
        rows.append({"case": case, "seed": seed, "method": method, "samples": k,
                     "samples_per_period": margin,
                     "shift": (np.abs(other - value) / se).tolist(),
                     "se_ratio": (other_se / se).tolist(),
                     "within_full": (np.abs(value - truth) <= 3 * se).tolist(),
                     "within_averaged": (np.abs(other - truth) <= 3 * other_se).tolist(),
                     "cpu_full": full_cpu, "cpu_averaged": fast_cpu})
        row = rows[-1]
        print(f"{case} seed {seed} {method}: k {k}, shift {max(row['shift']):.3f} SE, SE ratio "
              f"median {np.median(row['se_ratio']):.3f} max {max(row['se_ratio']):.3f}, within 3 "
              f"SE {sum(row['within_full'])} -> {sum(row['within_averaged'])}, CPU "
              f"{full_cpu:.2f} -> {fast_cpu:.2f} s", flush=True)
    return rows


def summary(rows: list[dict]) -> list[str]:
    """Markdown table: per log and method over its seeds."""
    lines = ["| log | method | seeds | samples per period | k | largest shift (full-rate SE) | "
             "SE ratio: median (range) | within 3 SE: full → averaged | CPU: full → averaged "
             "(s) |",
             "|---|---|---|---|---|---|---|---|---|"]
    for case in dict.fromkeys(r["case"] for r in rows):
        for method in METHODS:
            mine = [r for r in rows if r["case"] == case and r["method"] == method
                    and "refused" not in r]
            if not mine:
                continue
            ratio = np.concatenate([r["se_ratio"] for r in mine])
            full = sum(sum(r["within_full"]) for r in mine)
            fast = sum(sum(r["within_averaged"]) for r in mine)
            total = sum(len(r["within_full"]) for r in mine)
            ks = sorted({r["samples"] for r in mine})
            lines.append(
                f"| {case} | {method} | {len(mine)} | "
                f"{min(r['samples_per_period'] for r in mine):.0f} | {','.join(map(str, ks))} | "
                f"{max(max(r['shift']) for r in mine):.3f} | {np.median(ratio):.3f} "
                f"({ratio.min():.3f}–{ratio.max():.3f}) | {full}/{total} → {fast}/{total} | "
                f"{np.mean([r['cpu_full'] for r in mine]):.2f} → "
                f"{np.mean([r['cpu_averaged'] for r in mine]):.2f} |")
    return lines


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--paper-seeds", type=int, default=4)
    parser.add_argument("--cache", type=Path, default=Path("averaging_study_logs"))
    parser.add_argument("--electric", default="",
                        help="comma-separated folders of electric_study.py's noise-free logs")
    parser.add_argument("--electric-seeds", type=int, default=4)
    parser.add_argument("--samples", type=int, help="average this many samples (default: the "
                                                     "rule's)")
    parser.add_argument("--electric-samples", type=int,
                        help="average the electric logs over this many samples (default: "
                             "--samples)")
    parser.add_argument("--out", type=Path, help="JSON lines of every row")
    parser.add_argument("--summary", type=Path, nargs="*",
                        help="print the table of earlier --out files and stop")
    args = parser.parse_args()
    if args.summary:
        rows = [json.loads(line) for path in args.summary
                for line in path.read_text().splitlines()]
        print("\n".join(summary(rows)))
        return
    def cases():  # one log in memory at a time
        for seed in range(args.paper_seeds):
            yield ("paper 2 kHz", seed, *paper_logs(args.cache, seed))
        electric = electric_platform()
        for folder in filter(None, args.electric.split(",")):
            clean = read_datasets(sorted(Path(folder).glob("exp[0-9].parquet")), electric)
            for seed in range(args.electric_seeds):
                yield (f"electric {Path(folder).name}", seed, electric,
                       measured(electric, clean, seed))

    rows = []
    for case, seed, platform, data in cases():
        samples = (args.electric_samples or args.samples) if case.startswith("electric") \
            else args.samples
        new = rows_of(case, seed, platform, data, samples)
        rows += new
        if args.out:
            with args.out.open("a") as handle:
                handle.writelines(json.dumps(r) + "\n" for r in new)
    print("\n".join(summary(rows)))


if __name__ == "__main__":
    main()
