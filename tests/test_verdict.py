"""The verdict's rule on constructed evidence: what each step decides, and the expected
largest error against a Monte Carlo of the same Gaussian errors."""

from __future__ import annotations

import numpy as np
import pytest

from stewartid.assessment.validation import Segment, ValidationResult
from stewartid.assessment.verdict import choose_trusted
from stewartid.identification.accuracy import (
    PRECISION_FACTOR,
    cross_checked_relative_std,
    expected_worst_error,
)
from stewartid.identification.result import IdentificationResult


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
    verdict = choose_trusted({"a": (_result(0.01), _validation(0.1)),
                              "b": (_result(0.05), _validation(0.1)),
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
    assert verdict.tied == ("ls", "wavelet") and verdict.trusted == "wavelet"


def test_immunity_to_the_friction_law_does_not_outweigh_a_smaller_predicted_error():
    """The friction law's cost is in each method's standard errors already."""
    verdict = choose_trusted({"ls": (_result(0.010), _validation(0.5)),
                              "wavelet": (_result(0.013, friction_model="free"),
                                          _validation(0.1))})
    assert verdict.standings["wavelet"].friction_immune
    assert verdict.tied == ("ls",) and verdict.trusted == "ls"


def test_entries_another_method_contradicts_are_named_uncertain():
    verdict = choose_trusted({"a": (_result(0.001), _validation(0.1)),
                              "b": (_result(0.001, shift=0.05), _validation(0.1))})
    labels = verdict.to_dict()["uncertain_entries"]
    # every Mt entry of the paper's 20 differs by 5 % at 0.14 % combined error: all ten named
    assert labels == [f"Mt({i},{j})" for i, j in ((1, 1), (2, 2), (3, 3), (4, 4), (5, 5),
                                                   (6, 6), (1, 5), (2, 4), (4, 2), (5, 1))]


def test_a_close_call_is_named_and_a_clear_one_is_not():
    close = choose_trusted({"a": (_result(0.010), _validation(0.1)),
                            "b": (_result(0.012), _validation(0.1)),
                            "c": (_result(0.020), _validation(0.1))})
    assert close.trusted == "a" and close.close == ("a", "b")
    assert close.to_dict()["close"] == ["a", "b"]
    assert any(reason.startswith("close call: a, b") for reason in close.reasons)
    clear = choose_trusted({"a": (_result(0.010), _validation(0.1)),
                            "b": (_result(0.013), _validation(0.1))})
    assert clear.close == ("a",) and not any("close call" in r for r in clear.reasons)
    # an implausible method is no close call, however small its errors
    implausible = choose_trusted({"a": (_result(0.010), _validation(0.1)),
                                  "b": (_result(0.010, definite=False), _validation(0.1))})
    assert implausible.close == ("a",)


def test_a_more_precise_estimate_measures_an_entrys_error():
    """Worked by hand on Bt(1,5) (index 16) and its partner Bt(5,1)."""
    a, b, c = _result(0.001), _result(0.001), _result(0.001)
    a.B[0, 4], a.std_errors_B[0, 4] = 1000.0, 100.0
    b.B[0, 4], b.std_errors_B[0, 4] = 1003.0, 10.0        # 10x as precise: measures
    b.B[4, 0], b.std_errors_B[4, 0] = 1040.0, 5.0         # the partner measures too
    c.std_errors_B[0, 4] = c.std_errors_B[4, 0] = 100.0 / (0.9 * PRECISION_FACTOR)  # too few
    relative, measured = cross_checked_relative_std(a, [b, c])
    assert measured == [16]
    assert relative[16] == pytest.approx(np.hypot(3.0, 10.0) / 1000.0, rel=1e-12)
    assert cross_checked_relative_std(a, [c])[1] == []


def test_a_standard_error_widened_for_a_model_error_a_precise_fit_shows_absent():
    """Method B's pair-widened coupling (6 %) is exact; least squares, 1 % everywhere and
    1 % off, measures it: Method B is trusted, as its errors without the widened entry
    say. Without the cross-check its predicted largest error would be about 6 %."""
    wavelet, ls = _result(0.001), _result(0.01, shift=0.01)
    ls.B[:] *= 1.01
    wavelet.std_errors_B[0, 4] = wavelet.std_errors_B[4, 0] = 0.06 * abs(wavelet.B[0, 4])
    verdict = choose_trusted({"wavelet": (wavelet, _validation(0.1)),
                              "ls": (ls, _validation(0.1))})
    assert verdict.trusted == "wavelet"
    assert verdict.standings["wavelet"].measured_entries == ("Bt(1,5)", "Bt(5,1)")
    assert verdict.standings["wavelet"].expected_worst < 0.02
    # Method B measures least squares' other 18 entries: 1 % off, as their errors said
    assert len(verdict.standings["ls"].measured_entries) == 18
    assert verdict.standings["ls"].expected_worst > 0.02
    assert expected_worst_error(np.r_[0.06, 0.06, np.full(18, 0.001)]) > 0.05
