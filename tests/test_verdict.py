"""The verdict's rule on constructed evidence: what each step decides, and the expected
largest error against a Monte Carlo of the same Gaussian errors."""

from __future__ import annotations

import numpy as np
import pytest

from stewartid.identification.result import IdentificationResult
from stewartid.reference.published import PAPER_ENTRIES
from stewartid.validation.heldout import Segment, ValidationResult
from stewartid.verdict.accuracy import (
    entry_relative_std,
    error_posterior,
    expected_worst_error,
)
from stewartid.verdict.policy import VerdictPolicy, scored_entries
from stewartid.verdict.rule import choose_trusted


def test_expected_worst_error_against_analytic_and_monte_carlo_values():
    # one entry: E|N(0, s^2)| = s sqrt(2 / pi)
    assert expected_worst_error(np.array([2.0])) == pytest.approx(2 * np.sqrt(2 / np.pi),
                                                                  rel=1e-6)
    s = np.array([3.0, 2.0, 0.5] + [1.0] * 17)
    draws = np.abs(np.random.default_rng(1).normal(size=(200_000, 20)) * s).max(axis=1)
    assert expected_worst_error(s) == pytest.approx(draws.mean(), abs=5 * draws.std() / 447)
    assert expected_worst_error(np.array([1.0, np.inf])) == np.inf


def _result(relative_std: float, *, shift: float = 0.0, definite: bool = True,
            friction_model: str | None = None) -> IdentificationResult:
    M = (np.diag([1e4, 1e4, 1e4, 5e4, 5e4, 5e4]) + 1e3 * (np.eye(6, k=4) + np.eye(6, k=-4))
         + 5e2 * (np.eye(6, k=2) + np.eye(6, k=-2)))
    B = 0.4 * M
    if not definite:
        M = M.copy()
        M[2, 2] = -1e4
    M = M * (1 + shift)
    diagnostics = {} if friction_model is None else {"friction_model": friction_model}
    return IdentificationResult(M=M, B=B, std_errors_M=relative_std * np.abs(M) + 1e-9,
                                std_errors_B=relative_std * np.abs(B) + 1e-9,
                                condition_number=1.0, residual_rms=np.ones(6), method="x",
                                diagnostics=diagnostics)


def _validation(unexplained_percent: float) -> ValidationResult:
    rng = np.random.default_rng(0)
    n = 50
    segment = Segment("s", 0, 0, np.arange(n) / 100.0, rng.normal(size=(n, 6)),
                      rng.normal(size=(n, 6)), rng.normal(size=(n, 6)),
                      rng.normal(size=(n, 3, 6)))
    vaf = np.full(6, 100.0 - unexplained_percent)
    return ValidationResult(vaf, np.full(6, 0.01), 3, [segment.force],
                            [0.9 * segment.force], [segment])


def test_the_smallest_predicted_worst_error_is_trusted_and_ranked_first():
    # b 5 % off at a 5 % standard error: conditioned on a's estimate it takes 25/26 of it
    # (two identical estimates would be equally accurate, whatever their standard errors)
    verdict = choose_trusted({"a": (_result(0.01), _validation(0.1)),
                              "b": (_result(0.05, shift=0.05), _validation(0.1)),
                              "c": None})
    assert verdict.trusted == "a" and verdict.ranking == ("a", "b")
    assert verdict.not_applicable == ("c",)
    document = verdict.to_dict()
    assert document["trusted"] == "a" and document["ranking"] == ["a", "b"]
    assert set(document) >= {"trusted", "ranking", "uncertain_entries", "reasons"}


def test_a_method_that_misses_held_out_force_is_not_trusted_however_small_its_errors():
    verdict = choose_trusted({"a": (_result(0.001), _validation(20.0)),
                              "b": (_result(0.05), _validation(0.5))})
    assert verdict.trusted == "b" and verdict.standings["a"].misfit


def test_implausible_matrices_are_ranked_after_plausible_ones():
    verdict = choose_trusted({"a": (_result(0.001, definite=False), _validation(0.1)),
                              "b": (_result(0.05), _validation(0.1))})
    assert verdict.trusted == "b" and verdict.ranking == ("b", "a")


def test_a_tie_goes_to_the_better_held_out_prediction():
    verdict = choose_trusted({"ls": (_result(0.010), _validation(0.5)),
                              "wavelet": (_result(0.010, friction_model="free"),
                                          _validation(0.1))})
    assert verdict.trusted == "wavelet"


def test_immunity_to_the_friction_law_does_not_outweigh_a_smaller_predicted_error():
    """The friction law's cost is in each method's standard errors already."""
    verdict = choose_trusted({"ls": (_result(0.010), _validation(0.5)),
                              "wavelet": (_result(0.013, shift=0.013, friction_model="free"),
                                          _validation(0.1))})
    assert verdict.standings["wavelet"].friction_immune
    assert verdict.trusted == "ls"


def test_entries_another_method_contradicts_are_named_uncertain():
    verdict = choose_trusted({"a": (_result(0.001), _validation(0.1)),
                              "b": (_result(0.001, shift=0.05), _validation(0.1))})
    labels = verdict.to_dict()["uncertain_entries"]
    # every Mt entry of the paper's 20 differs by 5 % at 0.14 % combined error: all ten named
    assert labels == [f"Mt({i},{j})" for i, j in ((1, 1), (2, 2), (3, 3), (4, 4), (5, 5),
                                                   (6, 6), (1, 5), (2, 4), (4, 2), (5, 1))]


def test_a_close_call_is_named_and_a_clear_one_is_not():
    # 1 % apart at 1 and 1.1 % standard errors: each takes about half the difference
    close = choose_trusted({"a": (_result(0.010), _validation(0.1)),
                            "b": (_result(0.011, shift=0.01), _validation(0.1))})
    assert close.trusted == "a" and close.close == ("a", "b")
    assert close.to_dict()["close"] == ["a", "b"]
    assert any(reason.startswith("close call: a, b") for reason in close.reasons)
    # 3 % apart at 1 and 3 %: b takes nine tenths of the difference
    clear = choose_trusted({"a": (_result(0.010), _validation(0.1)),
                            "b": (_result(0.030, shift=0.03), _validation(0.1))})
    assert clear.close == ("a",) and not any("close call" in r for r in clear.reasons)
    # an implausible method is no close call, however small its errors
    implausible = choose_trusted({"a": (_result(0.010), _validation(0.1)),
                                  "b": (_result(0.010, definite=False), _validation(0.1))})
    assert implausible.close == ("a",)


def test_expected_worst_error_of_errors_with_means_against_a_monte_carlo():
    s = np.array([3.0, 2.0, 0.5, 0.0] + [1.0] * 16)
    m = np.array([-4.0, 1.0, 2.5, 3.0] + [0.2] * 16)  # a zero-variance error of 3 too
    draws = np.abs(m + np.random.default_rng(2).normal(size=(200_000, 20)) * s).max(axis=1)
    assert expected_worst_error(s, m) == pytest.approx(draws.mean(), abs=5 * draws.std() / 447)
    assert expected_worst_error(np.zeros(3), np.array([0.5, -2.0, 1.0])) == pytest.approx(
        2.0, abs=1e-3)  # the grid's step is top / 4000
    assert expected_worst_error(np.ones(2), np.array([0.0, np.nan])) == np.inf


def test_the_error_posterior_is_the_gaussian_conditioning_on_the_others_estimates():
    """Bt(1,5) (index 16) of a, against b (two members that differ: Bt(1,5) and Bt(5,1)) and
    c (one estimate for both): the posterior equals the Schur complement of the joint Gaussian
    of a's error and its differences from the three estimates, written out here without any
    pooling."""
    a, b, c = _result(0.001), _result(0.001), _result(0.001)
    a.B[0, 4] = a.B[4, 0] = 1000.0                        # one member: no partner of its own
    a.std_errors_B[0, 4] = a.std_errors_B[4, 0] = 100.0
    b.B[0, 4], b.std_errors_B[0, 4] = 1003.0, 10.0
    b.B[4, 0], b.std_errors_B[4, 0] = 1040.0, 5.0
    c.B[0, 4] = c.B[4, 0] = 950.0
    c.std_errors_B[0, 4] = c.std_errors_B[4, 0] = 30.0
    s_a, s, v = 100.0, np.array([10.0, 5.0, 30.0]), np.array([1003.0, 1040.0, 950.0])
    # e_a and the others' errors independent: d_k = v_a - v_k = e_a - e_k
    cov_ad = np.full(3, s_a ** 2)
    cov_dd = s_a ** 2 + np.diag(s ** 2)
    d = 1000.0 - v
    mean = cov_ad @ np.linalg.solve(cov_dd, d)
    var = s_a ** 2 - cov_ad @ np.linalg.solve(cov_dd, cov_ad)
    means, stds = error_posterior(a, [b, c])
    assert means[16] == pytest.approx(mean / 1000.0, rel=1e-9)
    assert stds[16] == pytest.approx(np.sqrt(var) / 1000.0, rel=1e-9)
    # a's own partner, where it differs, is one more estimate of the same quantity
    a.B[4, 0], a.std_errors_B[4, 0] = 1040.0, 5.0
    assert error_posterior(a, [])[0][16] == pytest.approx(
        100.0 ** 2 / (100.0 ** 2 + 5.0 ** 2) * (1000.0 - 1040.0) / 1000.0, rel=1e-12)
    a.B[4, 0], a.std_errors_B[4, 0] = 1000.0, 100.0
    # with nothing else the error keeps its own scale
    assert error_posterior(a, [])[1][16] == pytest.approx(0.1, rel=1e-12)
    assert error_posterior(a, [])[0][16] == 0.0


CORRELATED = np.array([[1.0, 0.7, 0.2], [0.7, 1.0, 0.3], [0.2, 0.3, 1.0]])


def _draws(rng, truth, scales, correlation, count):
    """``count`` sets of three fits around ``truth``: symmetric Mt, Bt whose relative errors
    (scales[k] per entry) correlate between the fits as ``correlation`` says."""
    root = np.linalg.cholesky(correlation)
    upper = np.triu(np.ones((6, 6), dtype=bool))
    for _ in range(count):
        fits = [_result(0.0) for _ in range(3)]
        for name in ("M", "B"):
            shared = np.einsum("kl,lij->kij", root, rng.normal(size=(3, 6, 6)))
            shared = np.where(upper, shared, np.swapaxes(shared, 1, 2))  # symmetric fits
            for fit, scale, z in zip(fits, scales, shared, strict=True):
                nominal = getattr(truth, name)
                getattr(fit, name)[:] = nominal * (1 + scale * z)
                getattr(fit, f"std_errors_{name}")[:] = np.abs(nominal) * scale
        yield fits


def test_the_error_posterior_is_calibrated_over_noise_draws():
    """250 draws of three methods' independent estimates of every entry around a truth,
    standard errors varying by entry: standardised by the posterior, a's errors are N(0, 1)
    and uncorrelated with their posterior mean (a wrong share of the difference would
    correlate)."""
    rng = np.random.default_rng(7)
    truth = _result(0.0)
    scales = rng.uniform(0.002, 0.03, size=(3, 6, 6))
    scales = np.triu(scales) + np.triu(scales, 1).transpose(0, 2, 1)
    nominal = np.abs([getattr(truth, m)[i, j] for m, i, j in PAPER_ENTRIES])
    z, shift = [], []
    for fits in _draws(rng, truth, scales, np.eye(3), 250):
        value = np.array([getattr(fits[0], m)[i, j] for m, i, j in PAPER_ENTRIES])
        # the posterior is relative to the estimate
        error = (value - np.sign(value) * nominal) / np.abs(value)
        mean, std = error_posterior(fits[0], fits[1:])
        z.append((error - mean) / std)
        shift.append(mean)
    z, shift = np.concatenate(z), np.concatenate(shift)
    n = z.size  # 5000: sampling errors of the mean and the variance about 1.4 % and 2 %
    assert abs(z.mean()) < 5 / np.sqrt(n)
    assert z.var() == pytest.approx(1.0, abs=5 * np.sqrt(2 / n))
    assert abs(np.corrcoef(z, shift)[0, 1]) < 5 / np.sqrt(n)


def test_a_standard_error_widened_for_a_model_error_a_precise_fit_shows_absent():
    """Method B's pair-widened coupling (6 %) is exact; least squares, 1 % everywhere, agrees
    there and is 1 % off elsewhere. Least squares measures the coupling's error to within its
    1 %, Method B measures least squares' other 18 entries' 1 %: Method B is trusted, as its
    errors without the widened entry say. Without the check against least squares its
    predicted largest error would be about 6 %."""
    wavelet, ls = _result(0.001), _result(0.01, shift=0.01)
    ls.B[:] *= 1.01
    ls.B[0, 4], ls.B[4, 0] = wavelet.B[0, 4], wavelet.B[4, 0]
    wavelet.std_errors_B[0, 4] = wavelet.std_errors_B[4, 0] = 0.06 * abs(wavelet.B[0, 4])
    verdict = choose_trusted({"wavelet": (wavelet, _validation(0.1)),
                              "ls": (ls, _validation(0.1))})
    assert verdict.trusted == "wavelet"
    assert verdict.standings["wavelet"].expected_worst < 0.02
    assert verdict.standings["ls"].expected_worst > verdict.standings["wavelet"].expected_worst
    assert expected_worst_error(np.r_[0.06, 0.06, np.full(18, 0.001)]) > 0.05


def test_a_method_several_of_its_errors_from_a_more_precise_one_is_not_trusted():
    """Method B 9 % off on Bt(6,6) at 2.5 of its 3.6 % standard error, least squares exact
    there at 1.8 % but with Mt(2,4) and Mt(4,2) at 4.5 % (the shape of a three-sine log of
    another platform): on their standard errors alone Method B predicts the smaller largest
    error; conditioned on least squares' estimate it takes four fifths of the difference on
    Bt(6,6), and least squares is trusted."""
    wavelet, ls = _result(0.010), _result(0.012)
    wavelet.std_errors_B[5, 5] = 0.036 * abs(wavelet.B[5, 5])
    ls.std_errors_B[5, 5] = 0.018 * abs(ls.B[5, 5])
    ls.std_errors_M[1, 3] = ls.std_errors_M[3, 1] = 0.045 * abs(ls.M[1, 3])
    wavelet.B[5, 5] *= 0.91
    alone = {name: expected_worst_error(entry_relative_std(result))
             for name, result in (("wavelet", wavelet), ("ls", ls))}
    assert alone["wavelet"] < alone["ls"]
    verdict = choose_trusted({"wavelet": (wavelet, _validation(0.1)),
                              "ls": (ls, _validation(0.1))})
    assert verdict.trusted == "ls"
    assert verdict.standings["wavelet"].expected_worst > 0.06


def test_the_scored_entries_follow_the_platform():
    """A symmetric platform scores the paper's 20 entries; an offset payload couples more."""
    from stewartid import load_platform, nominal_matrices
    from stewartid.reference.published import PAPER_ENTRIES

    paper = load_platform("paper")
    assert scored_entries(*nominal_matrices(paper)) == PAPER_ENTRIES
    offset = paper.replace(payload__mass=2000.0, payload__com=(0.3, -0.2, 0.4),
                           payload__inertia=(900.0, 800.0, 700.0, 0.0, 0.0, 0.0))
    found = scored_entries(*nominal_matrices(offset))
    assert set(PAPER_ENTRIES) < set(found)
    M, _ = nominal_matrices(offset)
    d = np.sqrt(np.diag(M))
    for matrix, i, j in set(found) - set(PAPER_ENTRIES):
        assert matrix == "M" and abs(M[i, j]) > 1e-2 * d[i] * d[j]


def test_the_policy_sets_the_close_call():
    """One threshold of the policy moves the verdict: a wider close factor names a close call
    that the default does not."""
    assessed = {"a": (_result(0.010), _validation(0.1)),
                "b": (_result(0.030, shift=0.03), _validation(0.1))}
    found = choose_trusted(assessed)
    assert found.close == ("a",)
    ratio = found.standings["b"].expected_worst / found.standings["a"].expected_worst
    wide = choose_trusted(assessed, policy=VerdictPolicy(close_factor=1.01 * ratio))
    assert wide.close == ("a", "b") and wide.policy.close_factor == 1.01 * ratio
