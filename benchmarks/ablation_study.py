"""Ablation study: which parts of the verdict and of the estimation change results beyond the
noise, on logs with a known truth?

For each log and seed (the logs of ``verdict_study.py``: our plant's kinds of
:mod:`noise_study`, the paper's sines at two Coulomb levels, clean and with the reference
sensor noise per seed, and optionally the independent example data set), every compared
method is fitted and validated ONCE exactly as :func:`verdict_study.evaluate` does, and the
same runs are judged again with one part of the verdict removed each time:

- ``default``: :func:`stewartid.comparison.judge` as it is;
- ``no_close_call``: ``VerdictPolicy(close_factor=1.0)`` (no consensus of close methods; a
  close call then needs exactly equal predicted errors);
- ``no_conditioning``: each method's expected error from its own standard errors alone
  (``error_posterior`` given no other method; the method's own symmetric partner still
  enters);
- ``no_misfit_gate``: ``VerdictPolicy(misfit_factor=inf)`` (no method ranked last for a large
  held-out misfit);
- ``no_pair_pooling``: the consensus without pooling each member's symmetric pairs
  (``pooled_pairs`` returns its inputs).

Per variant it records the trusted method, its largest error over the paper's 20 entries (%),
whether that is within 1.5x (+0.1 point) of the best compared method's (``ok``; the
consensus is not counted as a method there, so the bar is the same for every variant;
``ok_study`` counts a consensus the variant built, as ``verdict_study.py`` does), and the share
of the trusted result's 20 entries within 3 of its standard errors.

Then two parts of the estimation, refitted on the full logs (no folds) for Method B and least
squares only, against their default fits of the same logs:

- ``wavelet_rate_choice``: Method B taking the single soft-sign rate of least residual
  instead of averaging its fits over the rates with Akaike weights (the weights replaced by a
  one-hot weight on the least cost, in both places Method B averages);
- ``ls_one_shape``: least squares with the algebraic Coulomb sign shape only
  (``coulomb_shape="algebraic"``) instead of the average over two shapes; ``ls_erf`` the
  other shape alone.

Each entry's error and error / standard error are stored. One JSON line per log and seed is
appended to ``--out``; logs already there are skipped (a killed run resumes). ``--summary
FILE`` prints the Markdown tables.

Usage::

    python benchmarks/ablation_study.py [--kinds paper,tenx,three,alldof] [--coulomb 5,30]
        [--seeds 4] [--first-seed 0] [--example] [--engine ours|mujoco]
        [--clean /tmp/ablation/clean] [--out /tmp/ablation/rows.jsonl]
    python benchmarks/ablation_study.py --summary /tmp/ablation/rows.jsonl
"""

from __future__ import annotations

import argparse
import contextlib
import dataclasses
import json
import sys
import time
from collections import defaultdict
from pathlib import Path
from unittest import mock

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import verdict_study  # noqa: E402  (a sibling script)

import stewartid.identification.wavelet.rate_selection as rate_selection  # noqa: E402
import stewartid.verdict.rule as rule  # noqa: E402
from stewartid.comparison import judge, run_method  # noqa: E402
from stewartid.errors import StewartidError  # noqa: E402
from stewartid.identification import registry  # noqa: E402
from stewartid.identification.sign_window import widened_by_sign_window  # noqa: E402
from stewartid.reference.published import PAPER_ENTRIES, relative_error_percent  # noqa: E402
from stewartid.verdict.policy import VerdictPolicy  # noqa: E402

TRUST_FACTOR, TRUST_MARGIN = verdict_study.TRUST_FACTOR, verdict_study.TRUST_MARGIN

VARIANTS = ("default", "no_close_call", "no_conditioning",
            "no_misfit_gate", "no_pair_pooling")
#: Refitted variants: (method, variant name, settings, patched rate choice).
REFITS = (("wavelet", "wavelet_rate_choice", {}, True),
          ("ls", "ls_one_shape", {"coulomb_shape": "algebraic"}, False),
          ("ls", "ls_erf", {"coulomb_shape": "erf"}, False))


# -- the parts removed ----------------------------------------------------------------------

_error_posterior = rule.error_posterior


def _own_errors_only(result, others, *args, **kwargs):
    """error_posterior given no other method: the error from the result's own standard
    errors (and its own symmetric partner)."""
    return _error_posterior(result, [], *args, **kwargs)


def _not_pooled(value, std_error):
    """pooled_pairs leaving a member's pairs as they are."""
    return np.array(value, dtype=float), np.array(std_error, dtype=float)


def _least_residual_rate(solutions, rates, half=None):
    """averaged_over_rates with a one-hot weight on the rate of least residual cost: the fit
    at that rate, its own standard errors (widened by the signs' half-window refit, as
    averaged_over_rates widens them)."""
    costs = np.array([rate_selection.residual_cost(s) for s in solutions])
    best = int(np.argmin(costs))
    weights = {f"{rate:g}": float(k == best) for k, rate in enumerate(rates)}
    chosen = dataclasses.replace(solutions[best], rate_weights=weights)
    if half is not None:
        chosen = widened_by_sign_window(chosen, solutions[rate_selection.HALF_WINDOW_RATE],
                                        half, "coulomb")
    return chosen, float(rates[best])


def variant_setup(name: str) -> tuple[VerdictPolicy | None, list]:
    """The policy and the patches of a verdict variant."""
    if name == "no_close_call":
        return VerdictPolicy(close_factor=1.0), []
    if name == "no_misfit_gate":
        return VerdictPolicy(misfit_factor=float("inf")), []
    if name == "no_conditioning":
        return None, [mock.patch("stewartid.verdict.rule.error_posterior", _own_errors_only)]
    if name == "no_pair_pooling":
        return None, [mock.patch("stewartid.verdict.consensus.pooled_pairs", _not_pooled)]
    return None, []


def rate_choice_patches() -> list:
    """Method B's two callers of averaged_over_rates given the least-residual rate."""
    return [mock.patch("stewartid.identification.wavelet.rate_selection.averaged_over_rates",
                       _least_residual_rate),
            mock.patch("stewartid.identification.wavelet.windows.averaged_over_rates",
                       _least_residual_rate)]


# -- scoring ----------------------------------------------------------------------------------

def entry_scores(result, M, B) -> dict:
    """A result's relative errors (%), |error| / standard error and signed errors over the
    paper's 20 entries."""
    errors, ratios = [], []
    for matrix, i, j in PAPER_ENTRIES:
        estimate = (result.M if matrix == "M" else result.B)[i, j]
        truth = (M if matrix == "M" else B)[i, j]
        std = (result.std_errors_M if matrix == "M" else result.std_errors_B)[i, j]
        errors.append(float(relative_error_percent(estimate, truth)))
        ratios.append(float(abs(estimate - truth) / std) if std > 0 else float("inf"))
    return {"worst_percent": max(errors), "errors": errors, "ratios": ratios,
            "in3se": float(np.mean(np.array(ratios) <= 3)), "max_se": max(ratios)}


def verdict_record(runs, verdict, M, B, best: float, seconds: float) -> dict:
    """What one variant's verdict trusted and how accurate that is."""
    by_name = {run.name: run for run in runs}
    scores = entry_scores(by_name[verdict.trusted].result, M, B)
    fitted = [entry_scores(run.result, M, B)["worst_percent"] for run in runs
              if run.result is not None]
    return {"trusted": verdict.trusted, "close": list(verdict.close),
            "worst_percent": scores["worst_percent"], "in3se": scores["in3se"],
            "max_se": scores["max_se"],
            "ok": bool(scores["worst_percent"] <= TRUST_FACTOR * best + TRUST_MARGIN),
            "ok_study": bool(scores["worst_percent"] <= TRUST_FACTOR * min(fitted) + TRUST_MARGIN),
            "seconds": seconds}


def refit(name: str, settings: dict, data, platform, M, B, patched: bool) -> dict:
    """One full fit of a method with a variant's settings (and patches)."""
    start = time.perf_counter()
    with contextlib.ExitStack() as stack:
        for patch in (rate_choice_patches() if patched else []):
            stack.enter_context(patch)
        try:
            result = registry.create_identifier(name, **settings).fit(list(data), platform).result_
        except StewartidError as exc:
            return {"refused": str(exc).splitlines()[0]}
    return {**entry_scores(result, M, B), **weights_of(result),
            "seconds": time.perf_counter() - start}


def weights_of(result) -> dict:
    """Method B's rate weights and least squares' shape weights, where the fit has them."""
    d = result.diagnostics
    return {key: d[key] for key in ("soft_sign_weights", "coulomb_shape_weights", "soft_sign_rate")
            if d.get(key) is not None}


def evaluate(label, platform, data, M, B, seed, engine: str, refits: bool) -> dict:
    """Every compared method fitted once as verdict_study.evaluate does, judged per variant;
    Method B and least squares refitted without their averaging."""
    names = [spec.name for spec in registry.registered_methods()
             if spec.preset_of is None and spec.compared]
    segments = {}
    start = time.perf_counter()
    runs = [run_method(name, {}, data, platform, 3, False, segments) for name in names]
    row = {"log": label, "seed": seed, "engine": engine,
           "fit_seconds": time.perf_counter() - start, "methods": {}, "variants": {},
           "refits": {}}
    for run in runs:
        row["methods"][run.name] = ({"refused": run.error.splitlines()[0]} if run.result is None
                                    else {**entry_scores(run.result, M, B), "seconds": run.seconds})
    best = min(m["worst_percent"] for m in row["methods"].values() if "worst_percent" in m)
    row["best_percent"] = best
    for variant in VARIANTS:
        policy, patches = variant_setup(variant)
        start = time.perf_counter()
        with contextlib.ExitStack() as stack:
            for patch in patches:
                stack.enter_context(patch)
            judged, verdict = (judge(runs) if policy is None else judge(runs, policy=policy))
        row["variants"][variant] = verdict_record(judged, verdict, M, B, best,
                                                  time.perf_counter() - start)
    if refits:
        by_name = {run.name: run for run in runs}
        for name in ("wavelet", "ls"):
            run = by_name.get(name)
            row["refits"][f"{name}_default"] = (
                {"refused": "not fitted"} if run is None or run.result is None
                else {**entry_scores(run.estimator.result_, M, B),
                      **weights_of(run.estimator.result_)})
        for name, variant, settings, patched in REFITS:
            row["refits"][variant] = refit(name, settings, data, platform, M, B, patched)
    return row


def line(row: dict) -> str:
    """One terminal line of a log and seed."""
    seed = "clean" if row["seed"] is None else str(row["seed"])
    text = f"{row['log']:30s} {seed:5s} best {row['best_percent']:.2f} % |"
    for variant, found in row["variants"].items():
        text += (f" {variant}: {found['trusted']} {found['worst_percent']:.2f}"
                 f"{'' if found['ok'] else ' OFF'};")
    for variant, found in row["refits"].items():
        if "worst_percent" in found:
            text += f" {variant} {found['worst_percent']:.2f} % {found['max_se']:.1f} SE;"
    return text


# -- summary ----------------------------------------------------------------------------------

def _fmt(values, digits=3) -> str:
    return "-" if not values else f"{np.mean(values):.{digits}g}"


def paired_change(deltas) -> str:
    """Mean paired change +- its standard error (of the mean over logs)."""
    deltas = np.asarray(deltas, dtype=float)
    if deltas.size == 0:
        return "-"
    se = deltas.std(ddof=1) / np.sqrt(deltas.size) if deltas.size > 1 else float("nan")
    return f"{deltas.mean():+.3f} +- {se:.3f}"


def verdict_table(rows: list[dict]) -> list[str]:
    """Per variant: logs within 1.5x, trusted largest errors, changes against default."""
    lines = ["| variant | within 1.5x: noisy | clean | study-style noisy / clean | "
             "trusted largest error noisy: mean / max (%) | clean: mean / max (%) | "
             "trusted in 3 SE, noisy (%) | trusted changed vs default: noisy / clean | "
             "within 1.5x gained / lost vs default | change of trusted largest error vs default, "
             "noisy (pt, mean +- SE) |",
             "|---|---|---|---|---|---|---|---|---|---|"]
    noisy = [r for r in rows if r["seed"] is not None]
    clean = [r for r in rows if r["seed"] is None]
    for variant in VARIANTS:
        def got(group, key, variant=variant):
            return [r["variants"][variant][key] for r in group]

        def changed(group, variant=variant):
            return sum(r["variants"][variant]["trusted"] != r["variants"]["default"]["trusted"]
                       for r in group)
        gained = sum(r["variants"][variant]["ok"] and not r["variants"]["default"]["ok"] for r in rows)
        lost = sum(r["variants"]["default"]["ok"] and not r["variants"][variant]["ok"] for r in rows)
        deltas = [r["variants"][variant]["worst_percent"] - r["variants"]["default"]["worst_percent"]
                  for r in noisy]
        lines.append(
            f"| {variant} | {sum(got(noisy, 'ok'))}/{len(noisy)} | {sum(got(clean, 'ok'))}/{len(clean)} | "
            f"{sum(got(noisy, 'ok_study'))}/{len(noisy)} / {sum(got(clean, 'ok_study'))}/{len(clean)} | "
            f"{_fmt(got(noisy, 'worst_percent'))} / {max(got(noisy, 'worst_percent'), default=np.nan):.3g} | "
            f"{_fmt(got(clean, 'worst_percent'))} / {max(got(clean, 'worst_percent'), default=np.nan):.3g} | "
            f"{100 * np.mean(got(noisy, 'in3se')) if noisy else np.nan:.1f} | "
            f"{changed(noisy)} / {changed(clean)} | {gained} / {lost} | {paired_change(deltas)} |")
    return lines


def changes_table(rows: list[dict]) -> list[str]:
    """The logs on which some variant trusts another result than the default, with every
    compared method's largest error."""
    names = list(dict.fromkeys(n for r in rows for n in r["methods"]))
    lines = ["| log | seed | " + " | ".join(f"{n} (%)" for n in names)
             + " | default: trusted (%) | variants trusting another result: trusted (%) |",
             "|---|---|" + "---|" * len(names) + "---|---|"]
    for r in rows:
        default = r["variants"]["default"]
        others = [f"{v}: {f['trusted']} {f['worst_percent']:.3g}{'' if f['ok'] else ' (off)'}"
                  for v, f in r["variants"].items()
                  if v != "default" and f["trusted"] != default["trusted"]]
        if not others:
            continue
        cells = [f"{r['methods'][n]['worst_percent']:.3g}" if "worst_percent" in r["methods"].get(n, {})
                 else "refused" for n in names]
        lines.append(f"| {r['log']} | {'clean' if r['seed'] is None else r['seed']} | "
                     + " | ".join(cells)
                     + f" | {default['trusted']} {default['worst_percent']:.3g}"
                     f"{'' if default['ok'] else ' (off)'} | {'; '.join(others)} |")
    return lines


def refit_table(rows: list[dict]) -> list[str]:
    """Calibration and accuracy of Method B and least squares, default and without their
    averaging, noisy and clean logs separately."""
    lines = ["| fit | logs | within 3 SE (%) | largest error/SE | rms error/SE | "
             "largest error: median / max (%) | fits changed vs default | "
             "largest error vs default: smaller / larger | change of largest error (pt, mean +- SE) |",
             "|---|---|---|---|---|---|---|---|---|"]
    pairs = [("wavelet_default", "wavelet_default"), ("wavelet_rate_choice", "wavelet_default"),
             ("ls_default", "ls_default"), ("ls_one_shape", "ls_default"), ("ls_erf", "ls_default")]
    for subset, group in (("noisy", [r for r in rows if r["seed"] is not None]),
                          ("clean", [r for r in rows if r["seed"] is None])):
        for fit, reference in pairs:
            found = [(r["refits"][fit], r["refits"][reference]) for r in group
                     if "worst_percent" in r["refits"].get(fit, {})
                     and "worst_percent" in r["refits"].get(reference, {})]
            if not found:
                continue
            ratios = np.concatenate([f["ratios"] for f, _ in found])
            worst = [f["worst_percent"] for f, _ in found]
            deltas = [f["worst_percent"] - d["worst_percent"] for f, d in found]
            moved = sum(not np.allclose(f["errors"], d["errors"], rtol=0, atol=1e-9) for f, d in found)
            smaller = sum(x < -1e-9 for x in deltas)
            larger = sum(x > 1e-9 for x in deltas)
            same = fit == reference
            lines.append(
                f"| {fit} | {subset} {len(found)} | {100 * np.mean(ratios <= 3):.1f} | {ratios.max():.3g} | "
                f"{np.sqrt(np.mean(ratios ** 2)):.3g} | {np.median(worst):.3g} / {max(worst):.3g} | "
                f"{'-' if same else moved} | {'-' if same else f'{smaller} / {larger}'} | "
                f"{'-' if same else paired_change(deltas)} |")
    return lines


def refit_detail(rows: list[dict]) -> list[str]:
    """Per log (all seeds): the largest error and largest error/SE of each fit."""
    fits = ("wavelet_default", "wavelet_rate_choice", "ls_default", "ls_one_shape", "ls_erf")
    lines = ["| log | " + " | ".join(f"{f}: median / max largest error (%), max SE" for f in fits) + " |",
             "|---|" + "---|" * len(fits)]
    by_log = defaultdict(list)
    for r in rows:
        if r["seed"] is not None:
            by_log[r["log"]].append(r)
    for log, group in by_log.items():
        cells = []
        for fit in fits:
            found = [r["refits"][fit] for r in group if "worst_percent" in r["refits"].get(fit, {})]
            cells.append("-" if not found else
                         f"{np.median([f['worst_percent'] for f in found]):.3g} / "
                         f"{max(f['worst_percent'] for f in found):.3g}, "
                         f"{max(f['max_se'] for f in found):.3g}")
        lines.append(f"| {log} | " + " | ".join(cells) + " |")
    return lines


def summary(rows: list[dict]) -> list[str]:
    """The Markdown tables, per engine."""
    out = []
    for engine in dict.fromkeys(r.get("engine", "ours") for r in rows):
        group = [r for r in rows if r.get("engine", "ours") == engine]
        logs = len({r["log"] for r in group})
        out += [f"### engine {engine}: {len(group)} log runs ({logs} logs)", "",
                "Verdict variants (same fits, judged again):", "", *verdict_table(group), "",
                "Log runs where a variant trusts another result than the default:", "",
                *changes_table(group), ""]
        if any(r["refits"] for r in group):
            out += ["Estimation variants (full refits):", "", *refit_table(group), "",
                    "Per log, noisy seeds:", "", *refit_detail(group), ""]
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--platform", default="paper", help="paper or a platform TOML file")
    parser.add_argument("--kinds", default="paper,tenx,three,alldof")
    parser.add_argument("--coulomb", default="5,30", help="N m, for the paper's sines")
    parser.add_argument("--seeds", type=int, default=4)
    parser.add_argument("--first-seed", type=int, default=0)
    parser.add_argument("--no-clean", action="store_true", help="skip the clean logs")
    parser.add_argument("--example", action="store_true",
                        help="also the independent simulator's example data set")
    parser.add_argument("--only-example", action="store_true",
                        help="the independent example alone")
    parser.add_argument("--engine", default="ours", choices=["ours", "mujoco"])
    parser.add_argument("--clean", type=Path, default=Path("/tmp/ablation/clean"),
                        help="folder of the clean logs (simulated there when missing)")
    parser.add_argument("--out", type=Path, default=Path("/tmp/ablation/rows.jsonl"),
                        help="append JSON lines here; logs already there are skipped")
    parser.add_argument("--no-refits", action="store_true",
                        help="skip the refits of Method B and least squares")
    parser.add_argument("--summary", type=Path, default=None,
                        help="print the Markdown tables of a file written by --out, and stop")
    args = parser.parse_args()
    if args.summary is not None:
        rows = [json.loads(text) for text in args.summary.read_text().splitlines() if text]
        print("\n".join(summary(rows)))
        return
    args.out.parent.mkdir(parents=True, exist_ok=True)
    done = set()
    if args.out.exists():
        done = {(r["log"], r["seed"]) for r in
                (json.loads(text) for text in args.out.read_text().splitlines() if text)}
    kinds = [] if args.only_example else args.kinds.split(",")
    sets = verdict_study.log_sets(args.platform, kinds, [float(c) for c in args.coulomb.split(",")],
                                  args.clean, args.example or args.only_example, args.engine)
    seeds = [*([] if args.no_clean else [None]),
             *range(args.first_seed, args.first_seed + args.seeds)]
    total = len(sets) * len(seeds)
    count, wall = 0, time.perf_counter()
    for label, platform, clean, M, B, noisy in sets:
        for seed in seeds:
            count += 1
            if (label, seed) in done:
                continue
            start = time.perf_counter()
            row = evaluate(label, platform, clean if seed is None else noisy(seed), M, B, seed,
                           args.engine, not args.no_refits)
            row["seconds"] = time.perf_counter() - start
            with args.out.open("a") as handle:
                handle.write(json.dumps(row) + "\n")
            print(f"[{count}/{total}, {row['seconds']:.0f} s, {time.perf_counter() - wall:.0f} s "
                  f"so far] {line(row)}", flush=True)


if __name__ == "__main__":
    main()
