"""The sampling check: standard errors that see what a noise-free log's sampling does to an
estimate, and leave noise-limited results alone."""

from __future__ import annotations

import json

import numpy as np
import pytest

from linear_model_data import make_experiment, random_matrices
from stewartid.datasets.dataset import Dataset
from stewartid.identification.registry import registered_methods
from stewartid.identification.result import IdentificationResult
from stewartid.identification.sampling import RATIO_LIMIT, check_sampling, thinned


def _log(rate: float = 1000.0, seconds: float = 2.0) -> list[Dataset]:
    t = np.arange(int(rate * seconds)) / rate
    zeros = np.zeros((len(t), 6))
    return [Dataset(t=t, pose=zeros, lengths=zeros + 1.0, forces=zeros, name="exp1")]


def _fake_fit(bias: float, noise_std: float):
    """A fit whose diagonals are 1 + bias * (1/fs)^2 (a second-order sampling error) with a
    standard error noise_std * sqrt(1000 / fs) (white noise) plus the residual a second-order
    error leaves, 0.1 * bias * (1/fs)^2."""
    def fit(datasets: list[Dataset]) -> IdentificationResult:
        step = 1.0 / datasets[0].sample_rate
        value = 1.0 + bias * step ** 2
        std = noise_std * np.sqrt(1000.0 * step) + 0.1 * bias * step ** 2
        return IdentificationResult(M=np.eye(6) * value, B=np.eye(6) * value,
                                    std_errors_M=np.eye(6) * std + 1e-3 * (1 - np.eye(6)),
                                    std_errors_B=np.eye(6) * std + 1e-3 * (1 - np.eye(6)),
                                    condition_number=1.0, residual_rms=np.zeros(6),
                                    method="fake")
    return fit


def test_thinning_keeps_every_kth_sample_at_a_kth_of_the_rate():
    log = _log(1000.0, 1.0)[0]
    part = thinned(log, 3)
    assert len(part) == 334 and part.t[1] == pytest.approx(3e-3)
    assert part.sample_rate == pytest.approx(1000.0 / 3, rel=1e-9)
    assert part.name == log.name


def test_a_noise_limited_result_is_left_alone():
    fit, data = _fake_fit(bias=0.0, noise_std=1e-2), _log()
    result = check_sampling(fit, data, fit(data))
    summary = result.diagnostics["sampling"]
    assert not summary["limited"]
    assert summary["std_ratio"] == pytest.approx(np.sqrt(2), rel=1e-9)
    assert np.sqrt(2) < RATIO_LIMIT
    np.testing.assert_array_equal(result.std_errors_M, fit(data).std_errors_M)


def test_a_sampling_limited_result_gets_errors_that_cover_its_error():
    # noise-free: the residual-based error (0.1 of the sampling error) is 10 times too small
    fit, data = _fake_fit(bias=50.0, noise_std=0.0), _log()
    before = fit(data)
    error = before.M[0, 0] - 1.0
    assert error / before.std_errors_M[0, 0] == pytest.approx(10.0)
    result = check_sampling(fit, data, before)
    summary = result.diagnostics["sampling"]
    assert summary["limited"] and summary["std_ratio"] == pytest.approx(4.0, rel=1e-6)
    assert summary["factors"] == [2, 3, 4]
    # the largest change, at a quarter of the rate, is (16 - 1) times the error
    assert result.std_errors_M[0, 0] == pytest.approx(np.hypot(0.1, 15.0) * error, rel=1e-9)
    assert result.M[0, 0] == before.M[0, 0]


def test_a_thinned_log_too_short_is_not_checked():
    fit, data = _fake_fit(bias=50.0, noise_std=0.0), _log(rate=100.0, seconds=1.0)
    result = check_sampling(fit, data, fit(data))
    assert result.diagnostics["sampling"] == {
        "limited": False, "reason": "fewer than 64 samples at 1/2 of the rate"}


COMPARED = [spec for spec in registered_methods() if spec.preset_of is None and spec.compared]


@pytest.fixture(scope="module")
def noise_free(paper):
    """Six noise-free experiments of the linear model (one sine per DOF, 8 periods at 1 Hz,
    200 Hz), and its (Mt, Bt)."""
    M, B = random_matrices(np.random.default_rng(11))
    return [make_experiment(paper, M, B, k, frequency_hz=1.0, periods=8) for k in range(6)], M, B


@pytest.mark.parametrize("spec", COMPARED, ids=[spec.name for spec in COMPARED])
def test_standard_errors_are_calibrated_on_a_noise_free_log(spec, noise_free, paper):
    """Without noise the estimate's error is what the differentiation at 200 Hz and the
    method's numerics leave (1e-12 to 1e-3 relative): the residual-based errors alone put
    least squares 2116 and Method B 14 of them off; the reported ones must cover it."""
    data, M, B = noise_free
    estimator = spec.create().fit(data, paper)
    # round-off of the matrix's scale is the floor of any error (Method A's are 5e-12)
    ratios = np.concatenate([
        (np.abs(estimate - truth) / np.maximum(estimator.std_errors_[matrix],
                                               1e-9 * np.abs(truth).max())).ravel()
        for estimate, truth, matrix in ((estimator.M_, M, "M"), (estimator.B_, B, "B"))])
    assert np.mean(ratios <= 3.0) >= 0.95 and ratios.max() <= 4.5, (
        f"{spec.name}: {np.mean(ratios <= 3.0):.0%} within 3 SE, largest {ratios.max():.3g}")


def test_the_physical_model_widens_its_parameters_on_a_noise_free_plant_log():
    """Our plant's noise-free log (the paper's sines, 8 s, Coulomb 30 N m): the residual-based
    errors put 15 % of Mt, Bt beyond 3 SE (6.5 SE); the parameters' changes over the thinned
    fits join their variances and Mt, Bt follow."""
    from stewartid.model.linearization import nominal_matrices
    from stewartid.physical.estimator import PhysicalIdentifier
    from stewartid.platform import load_platform
    from stewartid.simulation import simulate_experiments

    platform = load_platform("paper").replace(friction__coulomb=30.0)
    data = simulate_experiments(platform, coulomb=30.0, duration_s=8.0).datasets
    M, B = nominal_matrices(platform)
    estimator = PhysicalIdentifier().fit(data, platform)
    assert estimator.result_.diagnostics["sampling"]["limited"]
    ratios = np.concatenate([
        (np.abs(estimate - truth) / np.maximum(estimator.std_errors_[matrix],
                                               1e-9 * np.abs(truth).max())).ravel()
        for estimate, truth, matrix in ((estimator.M_, M, "M"), (estimator.B_, B, "B"))])
    assert np.mean(ratios <= 3.0) >= 0.95 and ratios.max() <= 4.5
    # the reported errors are those of the widened covariance
    free = [k for k, name in enumerate(estimator.parameters_) if name not in estimator.fixed_]
    std = np.array(list(estimator.parameter_std_errors_.values()))
    np.testing.assert_allclose(std[free], np.sqrt(np.diag(estimator.covariance_))[free],
                               rtol=1e-12)


def test_the_report_says_which_results_the_sampling_limits(tmp_path, noise_free, paper):
    from stewartid import compare_methods, write_report

    data, M, B = noise_free
    comparison = compare_methods(data, paper, methods=("fourier", "ls"), folds=3, nominal=(M, B),
                                 nominal_source="the generating model")
    write_report(comparison, tmp_path)
    text = (tmp_path / "report.md").read_text()
    line = next(line for line in text.splitlines() if "Limited by the log's sampling" in line)
    # least squares' residual is round-off there (flagged), Method A's errors do not scale
    assert "Time-domain least squares" in line and "Method A" not in line
    # both methods are exact here to the model's approximation floor: a close call, either or
    # their consensus trusted (result.json); least squares' own result has the sampling summary
    assert json.loads((tmp_path / "result.json").read_text())["method"] in ("fourier", "ls", "consensus")
    run = next(run for run in comparison.runs if run.name == "ls")
    assert run.result.diagnostics["sampling"]["factors"]
