"""Verdict study: does `identify --method all --report` trust the right method, and are every
method's standard errors honest, on logs with a known truth?

Logs: our plant (``--platform paper|FILE``, 6 x 20 s at 1 kHz) for each log kind of
:mod:`noise_study` (the paper's sines at several Coulomb levels, ten-times amplitude, three
sines per DOF, all DOFs at once), clean and with the reference sensor noise per seed; and the
independent simulator's example data set (``example``, truth in ``truth.json``), with the
noise of :func:`noise_study.add_noise`. For each log every registered method is fitted and
validated exactly as the report does (:func:`stewartid.reports.identification.report.run_method`)
and judged as it is (:func:`stewartid.reports.identification.report.judge`: the verdict, and
where it names a close call the consensus of the close methods, trusted).

Per log and seed it prints: the trusted method, whether its largest error over the paper's 20
entries is within 1.5x (+0.1 point) of the best method's, and per method the largest error,
the share of entries within 3 reported standard errors, the largest error in standard errors,
and the worst held-out VAF. ``--out FILE`` appends one JSON line per log and seed (with
every method's whole Mt, Bt, standard errors and fold fits, and the truth, so that a verdict
rule can be judged again on the same fits); ``--summary FILE`` prints the Markdown tables of
``docs/benchmarks.md`` from such a file.

With ``--engine mujoco`` the plant's logs come from the MuJoCo model of the same platform
(:func:`stewartid.mujoco.closed_loop.simulate_mujoco`) instead of our plant.

Usage::

    python benchmarks/verdict_study.py [--platform paper|FILE] [--kinds paper,tenx,three,alldof]
        [--coulomb 0,5,30] [--seeds 4] [--first-seed 0] [--example] [--engine ours|mujoco] [--clean DIR]
        [--out FILE]
    python benchmarks/verdict_study.py --summary FILE
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from collections import defaultdict
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import noise_study  # noqa: E402  (a sibling script)

from stewartid.comparison import judge, run_method  # noqa: E402
from stewartid.identification import registry  # noqa: E402
from stewartid.identification.result import own_std_errors  # noqa: E402
from stewartid.model.linearization import nominal_matrices  # noqa: E402
from stewartid.platform import load_platform  # noqa: E402
from stewartid.reference.published import PAPER_ENTRIES, relative_error_percent  # noqa: E402
from stewartid.simulation import degrade  # noqa: E402
from stewartid.simulation.sensors import reference_noise  # noqa: E402

#: The trusted method's largest error may exceed the best method's by this factor ...
TRUST_FACTOR = 1.5
#: ... plus this many percentage points.
TRUST_MARGIN = 0.1


def log_sets(platform_name: str, kinds, coulombs, clean_folder: Path, example: bool,
             engine: str = "ours"):
    """(label, platform, clean datasets, truth M, truth B, noise function) per log; the
    plant's logs simulated by ``engine`` ("ours" or "mujoco")."""
    out = []
    tag = "paper" if platform_name == "paper" else Path(platform_name).stem
    if engine != "ours":
        tag += f"-{engine}"
    for kind in kinds:
        for coulomb in (coulombs if kind == "paper" else (noise_study.KIND_COULOMB,)):
            platform = load_platform(platform_name).replace(friction__coulomb=float(coulomb))
            folder = clean_folder / f"{tag}_{kind}_c{coulomb:g}"
            clean = noise_study.kind_logs(kind, platform, folder, engine)
            M, B = nominal_matrices(platform)

            def noisy(seed, platform=platform, clean=clean):
                return [degrade(d, platform, reference_noise(platform),
                                np.random.default_rng(seed + 101 * k))
                        for k, d in enumerate(clean)]
            out.append((f"{tag} {kind} {coulomb:g} N m", platform, clean, M, B, noisy))
    if example:
        platform, clean, M, B = noise_study.load_example()

        def noisy(seed, platform=platform, clean=clean):
            return noise_study.add_noise(platform, clean, 20e-6, 0.005, seed)
        out.append(("independent example 10 N m", platform, clean, M, B, noisy))
    return out


def evaluate(label, platform, data, M, B, seed) -> dict:
    """Every registered method fitted and validated as the report does, and the verdict."""
    names = [spec.name for spec in registry.registered_methods()
             if spec.preset_of is None and spec.compared]
    segments = {}  # prepared once, shared by the methods as in the report
    runs, verdict = judge([run_method(name, {}, data, platform, 3, False, segments)
                           for name in names])
    return log_row(label, seed, runs, verdict, M, B)


def log_row(label, seed, runs, verdict, M, B) -> dict:
    """The stored row of one log: every run's fit (its Mt, Bt, standard errors, fold fits and
    errors over the paper's 20 entries against the truth ``M``, ``B``), the verdict, and
    whether the trusted result is within the bar of the best. ``runs`` and ``verdict`` as
    :func:`stewartid.comparison.judge` returns them (or a
    :class:`~stewartid.comparison.Comparison`'s ``runs`` and ``verdict``)."""
    row = {"log": label, "seed": seed, "trusted": verdict.trusted,
           "truth": {"M": np.asarray(M).tolist(), "B": np.asarray(B).tolist()},
           "verdict": verdict.to_dict(), "methods": {}}
    for run in runs:
        if run.result is None:
            row["methods"][run.name] = {"refused": run.error.splitlines()[0]}
            continue
        errors, ratios, signed, stds = [], [], [], []
        for matrix, i, j in PAPER_ENTRIES:
            estimate = (run.result.M if matrix == "M" else run.result.B)[i, j]
            truth = (M if matrix == "M" else B)[i, j]
            std = (run.result.std_errors_M if matrix == "M" else run.result.std_errors_B)[i, j]
            errors.append(relative_error_percent(estimate, truth))
            ratios.append(abs(estimate - truth) / std if std > 0 else np.inf)
            signed.append(float(estimate - truth))
            stds.append(float(std))
        row["methods"][run.name] = {
            "worst_percent": float(max(errors)), "errors": [float(e) for e in errors],
            "ratios": [float(r) for r in ratios],
            "signed_errors": signed, "std_errors": stds,
            # the whole matrices, so that a rule can be replayed on the stored rows
            "M": run.result.M.tolist(), "B": run.result.B.tolist(),
            "std_M": run.result.std_errors_M.tolist(), "std_B": run.result.std_errors_B.tolist(),
            # without the model floor: what a consensus weighs its members by
            "own_std_M": own_std_errors(run.result)[0].tolist(),
            "own_std_B": own_std_errors(run.result)[1].tolist(),
            "folds_M": [] if run.cross_validation is None else
            [fit.M.tolist() for fit in run.cross_validation.fold_results],
            "folds_B": [] if run.cross_validation is None else
            [fit.B.tolist() for fit in run.cross_validation.fold_results],
            "worst_vaf_percent": float(np.nanmin(run.validation.vaf_percent)),
            "sampling": {k: v for k, v in run.result.diagnostics.get("sampling", {}).items()
                         if k in ("limited", "std_ratio", "shift")},
            "seconds": run.seconds}
    fitted = [m for m in row["methods"].values() if "worst_percent" in m]
    best = min(m["worst_percent"] for m in fitted)
    row["trusted_ok"] = bool(row["methods"][verdict.trusted]["worst_percent"]
                             <= TRUST_FACTOR * best + TRUST_MARGIN)
    return row


def line(row: dict) -> str:
    """One terminal line of a log and seed."""
    text = (f"{'ok ' if row['trusted_ok'] else 'OFF'} {row['log']:28s} "
            f"{'clean' if row['seed'] is None else row['seed']!s:5s} "
            f"trusted {row['trusted']:8s}")
    for name, m in row["methods"].items():
        text += (f" | {name}: refused" if "refused" in m else
                 f" | {name}: {m['worst_percent']:.2f} %, "
                 f"{100 * np.mean(np.array(m['ratios']) <= 3):.0f} % in 3 SE, "
                 f"max {max(m['ratios']):.1f} SE, VAF {m['worst_vaf_percent']:.2f}")
    return text


def summary(rows: list[dict]) -> list[str]:
    """Markdown: per log the verdict's record, and per log and method the calibration."""
    by_log = defaultdict(list)
    for row in rows:
        by_log[row["log"]].append(row)
    # the consensus is built only where the verdict names a close call
    names = list(dict.fromkeys(name for row in rows for name in row["methods"]))
    lines = ["| log | trusted (clean; noisy seeds) | trusted within 1.5x of the best | "
             + " | ".join(f"{name}: largest error clean / median noisy (%), in 3 SE (%), "
                          "largest (SE)" for name in names) + " |",
             "|---|---|---|" + "---|" * len(names)]
    for log, group in by_log.items():
        clean = [r for r in group if r["seed"] is None]
        noisy = [r for r in group if r["seed"] is not None]
        trusted = (f"{clean[0]['trusted'] if clean else '-'}; "
                   + ", ".join(r["trusted"] for r in noisy))
        ok = f"{sum(r['trusted_ok'] for r in group)}/{len(group)}"
        cells = []
        for name in names:
            fitted = [r["methods"][name] for r in group
                      if "worst_percent" in r["methods"].get(name, {})]
            if not fitted:
                cells.append("refused" if any(name in r["methods"] for r in group) else "-")
                continue
            ratios = np.concatenate([m["ratios"] for m in fitted])
            clean_worst = next((r["methods"][name]["worst_percent"] for r in clean
                                if "worst_percent" in r["methods"].get(name, {})), float("nan"))
            noisy_worst = np.median([r["methods"][name]["worst_percent"] for r in noisy
                                     if "worst_percent" in r["methods"].get(name, {})]
                                    or [np.nan])
            cells.append(f"{clean_worst:.3g} / {noisy_worst:.3g}, "
                         f"{100 * np.mean(ratios <= 3):.0f}, {ratios.max():.3g}")
        lines.append(f"| {log} | {trusted} | {ok} | " + " | ".join(cells) + " |")
    return lines


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--platform", default="paper", help="paper or a platform TOML file")
    parser.add_argument("--kinds", default="paper,tenx,three,alldof")
    parser.add_argument("--coulomb", default="0,5,30", help="N m, for the paper's sines")
    parser.add_argument("--seeds", type=int, default=4)
    parser.add_argument("--first-seed", type=int, default=0,
                        help="noise seeds first-seed .. first-seed + seeds - 1 (fresh draws)")
    parser.add_argument("--example", action="store_true",
                        help="also the independent simulator's example data set")
    parser.add_argument("--engine", default="ours", choices=["ours", "mujoco"],
                        help="simulate the plant's logs on our hydraulic plant or on the MuJoCo "
                             "model (ideal actuators, the mujoco extra)")
    parser.add_argument("--clean", type=Path, default=Path("noise_study_logs"),
                        help="folder of the clean logs (simulated there when missing)")
    parser.add_argument("--out", type=Path, default=None, help="append JSON lines here")
    parser.add_argument("--summary", type=Path, default=None,
                        help="print the Markdown tables of a file written by --out, and stop")
    args = parser.parse_args()
    if args.summary is not None:
        rows = [json.loads(text) for text in args.summary.read_text().splitlines() if text]
        print("\n".join(summary(rows)))
        return
    rows = []
    for label, platform, clean, M, B, noisy in log_sets(
            args.platform, args.kinds.split(","), [float(c) for c in args.coulomb.split(",")],
            args.clean, args.example, args.engine):
        for seed in [None, *range(args.first_seed, args.first_seed + args.seeds)]:
            start = time.perf_counter()
            row = evaluate(label, platform, clean if seed is None else noisy(seed), M, B, seed)
            rows.append(row)
            print(line(row), f"[{time.perf_counter() - start:.0f} s]", flush=True)
            if args.out is not None:
                with args.out.open("a") as handle:
                    handle.write(json.dumps(row) + "\n")
    print("\n".join(summary(rows)))


if __name__ == "__main__":
    main()
