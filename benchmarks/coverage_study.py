"""Do the standard errors cover the error? Every method, every log kind, clean and noisy.

For a platform (``paper``, ``benchmarks/heavy_platform.toml``, ``benchmarks/small_platform.toml``
or any TOML) and a simulator (our plant, or MuJoCo with ``--engine mujoco``), the noise-free
logs of each kind of :mod:`noise_study` (the paper's sines, ten times their amplitude, three
sines per DOF, all DOFs at once; 6 x 20 s) are simulated once into ``--clean``, then every
method is fitted to them and to ``--seeds`` copies with the reference sensor noise. The truth
is the platform's nominal (Mt, Bt) at the neutral pose; the scored entries are the paper's 20.
The Coulomb level is the platform file's, or :data:`noise_study.KIND_COULOMB` where it has none.

Per platform, simulator, kind and method the table gives, on the clean logs and over the noisy
seeds, the share of (entry, seed) within 3 reported standard errors and the largest
|error| / SE (the acceptance target: at least 95 % within 3, none beyond 4.5), or the first
line of the message with which the method refused the data. The consensus is combined from
its members' fits (:func:`stewartid.verdict.consensus.combine_results`, as its estimator does).

Usage::

    python benchmarks/coverage_study.py [--platform paper|FILE] [--engine ours|mujoco]
        [--kinds paper,tenx,three,alldof] [--seeds 4] [--methods wavelet,fourier,ls,consensus]
        --clean DIR [--out FILE.jsonl]
    python benchmarks/coverage_study.py --summary FILE.jsonl...
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import noise_study  # noqa: E402  (a sibling script)

from stewartid.identification.registry import create_identifier  # noqa: E402
from stewartid.model.linearization import nominal_matrices  # noqa: E402
from stewartid.platform import load_platform  # noqa: E402
from stewartid.reference.published import PAPER_ENTRIES  # noqa: E402
from stewartid.simulation import degrade  # noqa: E402
from stewartid.simulation.sensors import reference_noise  # noqa: E402
from stewartid.verdict.consensus import DEFAULT_MEMBERS, combine_results  # noqa: E402

#: Methods scored by default: the compared ones and the consensus of its default members.
METHODS = ("wavelet", "fourier", "ls", "consensus")
#: The acceptance target: this share within 3 standard errors, none beyond LARGEST.
WITHIN, LARGEST = 0.95, 4.5


def study_platform(name: str):
    """The platform ``name`` with its own Coulomb level, or the kinds' where it has none."""
    platform = load_platform(name)
    if platform.friction.coulomb == 0:
        platform = platform.replace(friction__coulomb=noise_study.KIND_COULOMB)
    return platform


def entry_scores(result, M: np.ndarray, B: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Relative errors (%) and signed error / SE over the 20 paper entries."""
    found = {"M": (result.M, result.std_errors_M, M), "B": (result.B, result.std_errors_B, B)}
    errors, scores = [], []
    for matrix, i, j in PAPER_ENTRIES:
        value, std, truth = (a[i, j] for a in found[matrix])
        errors.append(100 * (value - truth) / abs(truth))
        scores.append((value - truth) / std if std > 0 else np.inf)
    return np.array(errors), np.array(scores)


def fit_all(methods, data, platform) -> dict:
    """Each method's result on ``data``, or the first line of its refusal."""
    results = {}
    members = [m for m in DEFAULT_MEMBERS if "consensus" in methods]
    for method in dict.fromkeys([*members, *(m for m in methods if m != "consensus")]):
        try:
            results[method] = create_identifier(method).fit(data, platform).result_
        except Exception as error:  # noqa: BLE001 - a refusal is a result of the study
            results[method] = str(error).splitlines()[0]
    if "consensus" in methods:
        fitted = [results[m] for m in members]
        results["consensus"] = (next(r for r in fitted if isinstance(r, str))
                                if any(isinstance(r, str) for r in fitted)
                                else combine_results(fitted, members))
    return {m: results[m] for m in methods}


def run(platform_name: str, engine: str, kinds, seeds, methods, clean_dir: Path, out: Path):
    """Fit every method to the clean and noisy logs of each kind; one JSON line per fit."""
    platform = study_platform(platform_name)
    M, B = nominal_matrices(platform)
    tag = "paper" if platform_name == "paper" else Path(platform_name).stem
    for kind in kinds:
        folder = clean_dir / f"{engine}_{tag}_{kind}_c{platform.friction.coulomb:g}"
        clean = noise_study.kind_logs(kind, platform, folder, engine)
        for seed in [None, *seeds]:
            data = clean if seed is None else [
                degrade(d, platform, reference_noise(platform),
                        np.random.default_rng(seed + 101 * k)) for k, d in enumerate(clean)]
            start = time.perf_counter()
            for method, result in fit_all(methods, data, platform).items():
                row = {"platform": tag, "engine": engine, "kind": kind, "method": method,
                       "seed": seed}
                if isinstance(result, str):
                    row["refused"] = result
                else:
                    errors, scores = entry_scores(result, M, B)
                    row.update(errors=errors.tolist(), scores=scores.tolist())
                with out.open("a") as stream:
                    stream.write(json.dumps(row) + "\n")
            print(f"{tag} {engine} {kind} seed {seed}: {time.perf_counter() - start:.0f} s",
                  flush=True)


def summary(rows) -> list[str]:
    """Markdown table: per platform, engine, kind and method, clean and noisy coverage."""
    lines = ["| platform | engine | log | method | clean: within 3 SE | clean: largest err/SE "
             "| noisy: within 3 SE (%) | noisy: largest err/SE | seeds |",
             "|---|---|---|---|---|---|---|---|---|"]
    keys = dict.fromkeys((r["platform"], r["engine"], r["kind"], r["method"]) for r in rows)
    for key in keys:
        group = [r for r in rows if (r["platform"], r["engine"], r["kind"], r["method"]) == key]
        cells = []
        for noisy in (False, True):
            part = [r for r in group if (r["seed"] is not None) == noisy]
            fitted = [np.abs(r["scores"]) for r in part if "refused" not in r]
            if not fitted:
                refused = next((r["refused"] for r in part if "refused" in r), None)
                cells += ["refused" if refused else "-", "-"]
                continue
            scores = np.concatenate(fitted)
            share = np.mean(scores <= 3)
            mark = "" if share >= WITHIN and scores.max() <= LARGEST else " **x**"
            cells += [f"{100 * share:.0f} %" if noisy else f"{np.sum(scores <= 3)}/{scores.size}",
                      f"{scores.max():.2g}{mark}"]
        seeds = sum(r["seed"] is not None for r in group)
        lines.append(f"| {' | '.join(key)} | {' | '.join(cells)} | {seeds} |")
    return lines


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--platform", default="paper", help="paper or a platform TOML file")
    parser.add_argument("--engine", default="ours", choices=("ours", "mujoco"))
    parser.add_argument("--kinds", default=",".join(noise_study.KINDS))
    parser.add_argument("--seeds", type=int, default=4)
    parser.add_argument("--methods", default=",".join(METHODS),
                        help="comma-separated registered methods (consensus: of wavelet, ls)")
    parser.add_argument("--clean", type=Path, default=Path("noise_study_logs"),
                        help="folder of the clean logs (simulated there when missing)")
    parser.add_argument("--out", type=Path, default=Path("coverage_study.jsonl"),
                        help="fits are appended here, one JSON line each")
    parser.add_argument("--summary", type=Path, nargs="*",
                        help="only print the table of these result files")
    args = parser.parse_args()
    if args.summary is None:
        run(args.platform, args.engine, args.kinds.split(","), tuple(range(args.seeds)),
            args.methods.split(","), args.clean, args.out)
    files = args.summary or [args.out]
    rows = [json.loads(line) for path in files for line in path.read_text().splitlines()]
    print("\n".join(summary(rows)))


if __name__ == "__main__":
    main()
