"""How often any answer could meet the verdict's bar, given only what the data say.

The verdict study (``verdict_study.py``) counts the logs on which the trusted result's largest
error over the paper's 20 entries is within 1.5x (+0.1 point) of the best method's. Where two
methods of similar precision disagree on the entry that is worst for both, which of them is
right is decided by the noise, and no rule that sees only the data can be right on every log.
This script measures that floor on the study's stored fits (``--out`` files).

For each noisy log, the truth of each of the 16 distinct quantities behind the 20 entries
(Mt and Bt are symmetric) is given its Gaussian posterior under the methods' own error model:
every plausible method that is not a misfit estimates it (its two symmetric members pooled by
inverse variance, :func:`~stewartid.verdict.accuracy.pooled`) with its reported standard
error, the methods' errors correlated as their fold fits show
(:func:`fold_correlation`), a flat prior. Truths drawn from
it give each method's largest error, so the chance that an answer passes the bar on that log
can be computed for any answer: the verdict's trusted result (a consensus rebuilt from its
stored members by this version of the package), each method's, the posterior mean,
and the best answer a search finds (each quantity in turn over a grid spanning the methods'
estimates and the posterior's +-3 SD, three sweeps). That last one is tuned to the bar itself,
with the posterior known: a bound for rules that see the data, not an estimator to use.

The sum of a rule's chances over the logs is its expected count of passes; their product the
chance that it passes every log.

The standard errors are the methods' as reported, with the model floor
(:func:`~stewartid.identification.result.with_model_floor`); ``--own`` takes them without it
where the file stores them (``own_std_M``, ``own_std_B``, as ``verdict_study.py`` and
``delay_default.py`` write them): the floor bounds the linearised model's error rather than
drawing a Gaussian one, and where it sets an entry's standard error (Mt's diagonal and
couplings on long logs) the posterior is wider there than the errors.

Usage::

    python benchmarks/verdict_floor.py FILE.jsonl [FILE.jsonl ...] [--draws 4000] [--seed 0]
        [--own]
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

import numpy as np

from stewartid.identification.result import IdentificationResult
from stewartid.reference.published import PAPER_ENTRIES
from stewartid.verdict.accuracy import entry_estimate, pooled, symmetric_members
from stewartid.verdict.consensus import combine_results

#: The bar of the verdict study: within this factor of the best method's largest error ...
TRUST_FACTOR = 1.5
#: ... plus this many percentage points.
TRUST_MARGIN = 0.1
#: The distinct quantities behind the paper's 20 entries: (matrix, i, j) with i <= j.
QUANTITIES = list(dict.fromkeys((m, min(i, j), max(i, j)) for m, i, j in PAPER_ENTRIES))
#: Which quantity each of the 20 entries is.
ENTRY_QUANTITY = np.array([QUANTITIES.index((m, min(i, j), max(i, j)))
                           for m, i, j in PAPER_ENTRIES])



def fold_correlation(results, folds,
                     entries=PAPER_ENTRIES) -> np.ndarray:
    """Correlation of several methods' errors on the same data, from their fits of the same
    folds.

    A fold's estimate departs from the folds' mean by the noise of the data it was given;
    standardised by the method's standard error, two methods' departures on the same folds
    correlate as their errors do.

    Parameters
    ----------
    results : sequence of IdentificationResult
        The methods' fits of all the data (their standard errors scale the departures).
    folds : sequence of (sequence of IdentificationResult or None)
        Each method's fits of the same folds, in the same order (None: not available).
    entries : sequence of (str, int, int)
        The entries compared.

    Returns
    -------
    ndarray, shape (n, n)
        The correlation matrix (positive semidefinite); 0 off the diagonal for a method
        without two or more folds or whose departures do not vary, and everywhere when the
        methods' numbers of folds differ (they are then not the same folds).
    """
    n = len(results)
    correlation = np.eye(n)
    counts = {len(f) for f in folds if f is not None and len(f) >= 2}
    if len(counts) != 1:
        return correlation
    rows, used = [], []
    for k, (result, fits) in enumerate(zip(results, folds, strict=True)):
        if fits is None or len(fits) not in counts:
            continue
        departures = []
        for matrix, i, j in entries:
            values = np.array([entry_estimate(fit, matrix, i, j)[0] for fit in fits])
            departures.append((values - values.mean()) / entry_estimate(result, matrix, i, j)[1])
        rows.append(np.concatenate(departures))
        used.append(k)
    table = np.array(rows)
    finite = np.all(np.isfinite(table), axis=0) if rows else np.array([], dtype=bool)
    if len(used) < 2 or finite.sum() < 3:
        return correlation
    with np.errstate(divide="ignore", invalid="ignore"):
        found = np.corrcoef(table[:, finite])
    found = np.nan_to_num(found, nan=0.0)
    np.fill_diagonal(found, 1.0)
    correlation[np.ix_(used, used)] = found
    return correlation


def stored_result(method: dict, own: bool = False) -> IdentificationResult:
    """A method's stored fit (or, without standard errors, one of its fold fits) as a result,
    with its standard errors without the model floor in ``diagnostics["own_std_errors"]``
    where the row holds them (``own_std_M``, ``own_std_B``), so that a consensus rebuilt from
    it weighs its members as the verdict did; ``own``: those as its standard errors."""
    M, B = (np.asarray(method[key], dtype=float) for key in ("M", "B"))
    std_M, std_B = ((np.asarray(method[key], dtype=float) if key in method else np.ones((6, 6)))
                    for key in ("std_M", "std_B"))
    diagnostics = {}
    if "own_std_M" in method and "own_std_B" in method:
        diagnostics["own_std_errors"] = {key: np.asarray(method[f"own_std_{key}"], dtype=float)
                                         for key in ("M", "B")}
        if own:
            std_M, std_B = diagnostics["own_std_errors"]["M"], diagnostics["own_std_errors"]["B"]
    return IdentificationResult(M=M, B=B, std_errors_M=std_M, std_errors_B=std_B,
                                condition_number=1.0, residual_rms=np.ones(6), method="stored",
                                diagnostics=diagnostics)


def entries(result: IdentificationResult) -> np.ndarray:
    """The paper's 20 entries of a result, shape (20,)."""
    return np.array([(result.M if m == "M" else result.B)[i, j] for m, i, j in PAPER_ENTRIES])


def answers_of(row: dict) -> dict[str, np.ndarray]:
    """Every fitted method's 20 entries; the consensus rebuilt from its close call's stored
    members by this version of :func:`~stewartid.verdict.consensus.combine_results`
    (the study may have stored an earlier one)."""
    answers = {n: entries(stored_result(m)) for n, m in row["methods"].items()
               if "M" in m and n != "consensus"}
    close = row["verdict"].get("close", [])
    if "consensus" in row["methods"] and len(close) > 1:
        members = [stored_result(row["methods"][n]) for n in close]
        answers["consensus"] = entries(combine_results(members, close))
    return answers


def realised_pass(row: dict, answers: dict[str, np.ndarray]) -> bool:
    """Whether the trusted answer met the bar against the row's truth."""
    truth = np.array([[np.asarray(row["truth"][m])[i, j] for m, i, j in QUANTITIES]])
    worst = {n: float(largest_errors(a, truth)[0]) for n, a in answers.items()}
    return worst[row["trusted"]] <= TRUST_FACTOR * min(worst.values()) + TRUST_MARGIN


def truth_posterior(row: dict, own: bool = False) -> tuple[np.ndarray, np.ndarray]:
    """Posterior mean and SD of each quantity (shape (16,) each), from the plausible methods
    that are not misfits (all fitted methods when none is); ``own``: their standard errors
    without the model floor where the row holds them."""
    fitted = [n for n, m in row["methods"].items() if "M" in m and n != "consensus"]
    evidence = row["verdict"]["evidence"]
    plausible = [n for n in fitted if evidence[n]["plausible"]] or fitted
    names = [n for n in plausible if not evidence[n]["misfit"]] or plausible
    results = [stored_result(row["methods"][n], own) for n in names]
    folds = [[stored_result({"M": a, "B": b}) for a, b in
              zip(row["methods"][n]["folds_M"], row["methods"][n]["folds_B"], strict=True)]
             or None for n in names]
    links = fold_correlation(results, folds)
    mean, sd = np.zeros(len(QUANTITIES)), np.zeros(len(QUANTITIES))
    for q, (matrix, i, j) in enumerate(QUANTITIES):
        values, variances = np.array([pooled(symmetric_members(r, matrix, i, j))
                                      for r in results]).T
        stds = np.sqrt(variances)
        inverse = np.linalg.pinv(links * np.outer(stds, stds), hermitian=True)
        precision = inverse.sum()
        mean[q], sd[q] = inverse.sum(axis=0) @ values / precision, precision ** -0.5
    return mean, sd


def largest_errors(answers: np.ndarray, truths: np.ndarray) -> np.ndarray:
    """Largest relative error (%) over the 20 entries of answers (..., 20) for each draw of the
    truths (draws, 16): shape (..., draws)."""
    truth = truths[:, ENTRY_QUANTITY]
    return 100 * np.max(np.abs(answers[..., None, :] - truth) / np.abs(truth), axis=-1)


def log_floor(row: dict, draws: int, rng: np.random.Generator, own: bool = False
              ) -> dict[str, float]:
    """Chance of passing the bar on one log: the trusted result's, each method's, the
    posterior mean's and the best found answer's (key ``"best"``); ``own`` as
    :func:`truth_posterior`."""
    mean, sd = truth_posterior(row, own)
    truths = mean + sd * rng.standard_normal((draws, len(QUANTITIES)))
    answers = answers_of(row)
    bar = TRUST_FACTOR * np.min(largest_errors(np.stack(list(answers.values())), truths),
                                axis=0) + TRUST_MARGIN
    answers["posterior mean"] = mean[ENTRY_QUANTITY]
    chances = {n: float(np.mean(largest_errors(a, truths) <= bar)) for n, a in answers.items()}
    chances["trusted"] = chances[row["trusted"]]
    best_name = max(answers, key=chances.get)
    best, chance = answers[best_name].copy(), chances[best_name]
    for _ in range(3):
        for q in range(len(QUANTITIES)):
            where = ENTRY_QUANTITY == q
            found = [a[where][0] for a in answers.values() if np.isfinite(a[where][0])]
            grid = np.linspace(min(*found, mean[q] - 3 * sd[q]),
                               max(*found, mean[q] + 3 * sd[q]), 61)
            trials = np.repeat(best[None], grid.size, axis=0)
            trials[:, where] = grid[:, None]
            passed = np.mean(largest_errors(trials, truths) <= bar, axis=1)
            if passed.max() > chance:
                chance, best = float(passed.max()), trials[int(passed.argmax())]
    chances["best"] = chance
    return chances


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("files", type=Path, nargs="+", help="verdict_study.py --out files")
    parser.add_argument("--draws", type=int, default=4000)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--own", action="store_true",
                        help="the posterior from the methods' standard errors without the model "
                             "floor (files that store them: own_std_M, own_std_B)")
    args = parser.parse_args()
    rng = np.random.default_rng(args.seed)
    print("| log set | noisy logs | trusted within 1.5x (observed) | expected: trusted | "
          "posterior mean | best answer found | chance of every log: trusted | "
          "best answer found |")
    print("|---|---|---|---|---|---|---|---|")
    totals: dict[str, list[float]] = {}
    for path in args.files:
        rows = [json.loads(t) for t in path.read_text().splitlines() if t.strip()]
        rows = [r for r in rows if r["seed"] is not None]
        found = [log_floor(r, args.draws, rng, args.own) for r in rows]
        observed = sum(realised_pass(r, answers_of(r)) for r in rows)
        columns = {k: np.array([f[k] for f in found]) for k in ("trusted", "posterior mean",
                                                                 "best")}
        for key, value in (("observed", [float(observed)]), *columns.items()):
            totals.setdefault(key, []).extend(value)
        print(f"| {path.stem} | {len(rows)} | {observed} | {columns['trusted'].sum():.1f} | "
              f"{columns['posterior mean'].sum():.1f} | {columns['best'].sum():.1f} | "
              f"{np.prod(columns['trusted']):.2g} | {np.prod(columns['best']):.2g} |")
    print(f"| all | {len(totals['trusted'])} | {sum(totals['observed']):.0f} | "
          f"{sum(totals['trusted']):.1f} | {sum(totals['posterior mean']):.1f} | "
          f"{sum(totals['best']):.1f} | {np.prod(totals['trusted']):.2g} | "
          f"{np.prod(totals['best']):.2g} |")


if __name__ == "__main__":
    main()
