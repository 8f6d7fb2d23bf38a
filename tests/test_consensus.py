"""The consensus of a close call: the inverse-variance mean against hand values and a Monte
Carlo of correlated members, the verdict that trusts it, and the report that builds it."""

from __future__ import annotations

import json

import numpy as np
import pytest

from stewartid.verdict.close_call import CONSENSUS, consensus_members, trust_consensus
from stewartid.verdict.consensus import combine_estimates, combine_results, pooled_pairs
from stewartid.verdict.rule import choose_trusted
from test_verdict import _result, _validation


def test_the_mean_of_agreeing_members_weights_each_by_its_inverse_variance():
    values = np.array([[10.0, 10.0], [11.0, 14.0]])
    std = np.array([[1.0, 1.0], [2.0, 2.0]])
    value, se, used = combine_estimates(values, std, agreement=1.0)
    # entry 0: |11 - 10| = 1 <= hypot(1, 2): weights 1 and 1/4 of 1.25
    assert value[0] == pytest.approx((10 + 11 / 4) / 1.25, rel=1e-12)
    assert se[0] == pytest.approx((1 + 2 / 4) / 1.25, rel=1e-12)
    # entry 1: |14 - 10| = 4 > hypot(1, 2) = 2.24: the reference alone
    assert value[1] == 10.0 and se[1] == 1.0
    assert used.tolist() == [[True, True], [True, False]]


def test_a_reference_without_a_usable_standard_error_stands_alone():
    values = np.array([[3.0, 5.0], [3.1, np.nan]])
    std = np.array([[0.0, 1.0], [1.0, 1.0]])
    value, se, used = combine_estimates(values, std)
    assert value.tolist() == [3.0, 5.0] and se.tolist() == [0.0, 1.0]
    assert used.tolist() == [[True, True], [False, False]]


@pytest.mark.parametrize("correlation", [1.0, 0.5, 0.0])
def test_the_standard_error_bounds_the_spread_of_correlated_members(correlation):
    """Two unbiased members with standard errors 1 and 1.5 whose errors correlate: over
    40 000 draws the spread of the consensus (every entry combined: agreement wide open) is
    the reported standard error for fully correlated members and below it otherwise (the
    spread's sampling error is 0.35 %)."""
    rng = np.random.default_rng(3)
    s = np.array([1.0, 1.5])
    cov = np.array([[s[0] ** 2, correlation * s[0] * s[1]],
                    [correlation * s[0] * s[1], s[1] ** 2]])
    draws = rng.multivariate_normal([0.0, 0.0], cov, size=40_000).T
    value, se, _ = combine_estimates(draws, np.broadcast_to(s[:, None], draws.shape),
                                     agreement=1e9)
    spread = value.std()
    independent = 1 / np.sqrt(np.sum(1 / s ** 2))
    assert se[0] == pytest.approx(np.sum(s / s ** 2) / np.sum(1 / s ** 2), rel=1e-12)
    if correlation == 1.0:
        assert spread == pytest.approx(se[0], rel=0.02)
    else:
        assert independent * 0.98 <= spread <= se[0]


def test_a_pair_pooled_is_unbiased_and_its_standard_error_covers_it():
    """Two unbiased estimates of one symmetric pair, standard errors 1 and 2, independent:
    over 40 000 draws the pooled estimate's spread is the inverse-variance one (0.894, its
    sampling error 0.35 %), below the reported standard error for fully correlated ones
    (1.2) scaled by the Birge ratio where the two scatter apart; the diagonal, a pair given
    one estimate and a pair without a standard error are unchanged."""
    rng = np.random.default_rng(5)
    n = 40_000
    value = np.zeros((n, 3, 3))
    value[:, 0, 2] = 1.0 * rng.standard_normal(n)
    value[:, 2, 0] = 2.0 * rng.standard_normal(n)
    value[:, 0, 1] = value[:, 1, 0] = rng.standard_normal(n)
    value[:, 1, 1] = 7.0
    std = np.ones((3, 3))
    std[2, 0] = 2.0
    std[1, 2] = np.nan
    value[:, 1, 2], value[:, 2, 1] = 3.0, 4.0
    pooled = [pooled_pairs(v, std) for v in value]
    estimate = np.array([p[0][0, 2] for p in pooled])
    reported = np.array([p[1][0, 2] for p in pooled])
    assert abs(estimate.mean()) < 4 * 0.894 / np.sqrt(n)
    assert estimate.std() == pytest.approx(1 / np.sqrt(1 + 1 / 4), rel=0.02)
    assert reported.min() == pytest.approx(1.2, rel=1e-12)
    assert np.mean(np.abs(estimate) <= 3 * reported) > 0.999
    assert all(p[0][0, 2] == p[0][2, 0] and p[1][0, 2] == p[1][2, 0] for p in pooled)
    first, first_std = pooled[0]
    assert first[1, 1] == 7.0 and first[0, 1] == value[0, 0, 1] and first_std[0, 1] == 1.0
    assert (first[1, 2], first[2, 1], first_std[2, 1]) == (3.0, 4.0, 1.0)


def test_a_pair_whose_members_disagree_carries_the_disagreement_into_its_error():
    """One member of the pair biased by 10 standard errors of the difference (a model error its
    standard errors do not cover): the pooled estimate carries a share of it; without the
    Birge ratio its standard error would cover it in under half the draws, with it in all."""
    rng = np.random.default_rng(6)
    n = 4000
    std = np.array([[1.0, 1.0], [2.0, 1.0]])
    bias = 10 * np.hypot(1.0, 2.0)
    errors, reported = [], []
    for a, b in zip(rng.standard_normal(n), 2.0 * rng.standard_normal(n) + bias, strict=True):
        value, error = pooled_pairs(np.array([[5.0, a], [b, 5.0]]), std)
        errors.append(value[0, 1])
        reported.append(error[0, 1])
    errors, reported = np.abs(errors), np.array(reported)
    assert np.mean(errors <= 3 * 1.2) < 0.5
    assert np.mean(errors <= 3 * reported) == 1.0


def test_a_close_call_trusts_the_consensus_and_says_why():
    assessed = {"a": (_result(0.010), _validation(0.1)),
                "b": (_result(0.012, shift=0.004), _validation(0.1))}
    verdict = choose_trusted(assessed)
    assert consensus_members(verdict) == ("a", "b")
    combined = combine_results([assessed["a"][0], assessed["b"][0]], ["a", "b"])
    trusted = trust_consensus(verdict, combined, _validation(0.1),
                              {name: pair[0] for name, pair in assessed.items()})
    assert trusted.trusted == CONSENSUS and trusted.ranking == (CONSENSUS, "a", "b")
    assert trusted.reasons[0].startswith("consensus: a, b are a close call")
    assert trusted.to_dict()["trusted"] == CONSENSUS
    # b's Mt sits 0.4 % above a's, within a standard error of their difference (1.6 %)
    assert np.all(combined.M > assessed["a"][0].M - 1e-9)
    assert np.all(combined.M < assessed["b"][0].M + 1e-9)
    # 3 % apart at 1 and 3 % standard errors: b takes nine tenths of the difference
    clear = choose_trusted({"a": (_result(0.010), _validation(0.1)),
                            "b": (_result(0.030, shift=0.03), _validation(0.1))})
    assert consensus_members(clear) == ()


@pytest.mark.slow
def test_the_report_builds_and_trusts_the_consensus_of_a_close_call(tmp_path, paper):
    """A noisy 4 s log with 30 N m of Coulomb friction where Method B and least squares
    predict largest errors within 1.25x of each other."""
    from stewartid import compare_methods, write_report
    from stewartid.simulation import simulate_experiments
    from stewartid.simulation.sensors import reference_noise

    run = simulate_experiments(paper, coulomb=30.0, duration_s=4.0, noise=reference_noise(paper),
                               seed=3)
    comparison = compare_methods(run.datasets, paper, methods=("wavelet", "ls"), folds=2)
    report = write_report(comparison, tmp_path)
    assert report.trusted == CONSENSUS and report.verdict.close == ("wavelet", "ls")
    document = json.loads((tmp_path / "result.json").read_text())
    assert document["method"] == CONSENSUS and document["verdict"]["trusted"] == CONSENSUS
    for name in ("wavelet", "ls", CONSENSUS):
        for suffix in ("M", "B", "std_errors_M", "std_errors_B"):
            assert (tmp_path / f"{name}_{suffix}.csv").is_file()
    runs = {r.name: r for r in report.runs}
    # every entry between its members' estimates of it, Mt(i,j) or Mt(j,i) (an inverse-variance
    # mean of agreeing ones, each member's pair pooled first), and Mt, Bt symmetric
    found = [m for name in ("wavelet", "ls") for m in (runs[name].result.M, runs[name].result.M.T)]
    low, high = np.min(found, axis=0), np.max(found, axis=0)
    margin = 1e-12 * np.abs(high).max()
    assert np.all((runs[CONSENSUS].result.M >= low - margin)
                  & (runs[CONSENSUS].result.M <= high + margin))
    for matrix in (runs[CONSENSUS].result.M, runs[CONSENSUS].result.B):
        assert np.allclose(matrix, matrix.T, rtol=0, atol=1e-12 * np.abs(matrix).max())
    assert not np.allclose(runs["ls"].result.M, runs["ls"].result.M.T)
    # its held-out prediction is scored like the members' (fold consensus on the same segments)
    assert runs[CONSENSUS].validation.vaf_percent.min() > 99.0
    assert "**Trust the consensus of" in (tmp_path / "report.md").read_text()


def test_no_consensus_of_members_validated_on_differently_prepared_segments():
    """Members whose held-out forces differ (one subtracted gravity, the other not) cannot be
    validated as one model: no consensus is built, and the verdict stays with one method."""
    from stewartid.comparison import MethodFit, consensus_run, same_segments
    from stewartid.validation.heldout import CrossValidation, Segment

    rng = np.random.default_rng(2)

    def segment(force):
        n = len(force)
        return Segment("exp1[0-2 s]", 0, 0, np.arange(n) / 100.0, force,
                       rng.normal(size=(n, 6)), rng.normal(size=(n, 6)),
                       rng.normal(size=(n, 3, 6)))

    force = rng.normal(size=(40, 6))
    with_gravity, without = [segment(force)], [segment(force + 9.81)]
    assert same_segments(with_gravity, [segment(force.copy())])
    assert not same_segments(with_gravity, without)
    members = [MethodFit(name, name, "k", result=_result(0.01), unconstrained=_result(0.01),
                            cross_validation=CrossValidation(2, [_result(0.01)] * 2, segments))
               for name, segments in (("a", with_gravity), ("b", without))]
    assert consensus_run(members, consistent=False) is None
