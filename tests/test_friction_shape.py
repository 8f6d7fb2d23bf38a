"""The Coulomb sign's shapes near a reversal, and least squares averaged over them, against
hand values, finite differences and plants whose friction has one shape or the other, or turns
over far inside the model's band."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from roundoff import EPS
from stewartid.identification.friction_shape import (
    COULOMB_SHAPES,
    EXACT_SIGN,
    akaike_weights,
    average_solutions,
    shaped_sign,
    widened_by_exact_sign,
)
from stewartid.identification.registry import create_identifier
from stewartid.identification.solvers import LeastSquaresSolution
from stewartid.model.linearization import nominal_matrices
from stewartid.simulation import DEFAULT_AMPLITUDES, Sine, multisine_excitation, simulate_experiment
from stewartid.simulation.sensors import SensorNoise


@pytest.mark.parametrize("shape", COULOMB_SHAPES)
def test_shapes_have_slope_one_over_s_at_zero_and_saturate(shape):
    s, h = 1e-4, 1e-9
    slope = (shaped_sign(np.array(h), s, shape) - shaped_sign(np.array(-h), s, shape)) / (2 * h)
    # central difference of an odd function: truncation O(h^2 / s^3), far below this
    assert slope == pytest.approx(1.0 / s, rel=1e-6)
    w = np.array([-1.0, -1e-2, 1e-2, 1.0])
    assert np.allclose(shaped_sign(w, s, shape), np.sign(w), atol=1e-4)
    assert np.array_equal(shaped_sign(w, 0.0, shape), np.sign(w))


def test_erf_saturates_faster_than_the_algebraic_sign():
    # at three smoothing rates: 1 - 3 / sqrt(10) = 5.1e-2 against 1 - erf(3 sqrt(pi) / 2) = 1.7e-4
    w = np.array(3e-4)
    assert 1 - shaped_sign(w, 1e-4, "algebraic") == pytest.approx(1 - 3 / np.sqrt(10), rel=1e-9)
    assert 1 - shaped_sign(w, 1e-4, "erf") < 2e-4


def test_erf_shape_is_erf_across_and_past_its_saturation():
    """The band shortcut against erf at every point: the standard library's exactly (the same
    function), scipy's within its last bit or two (two implementations accurate to an ulp)."""
    import math

    from scipy.special import erf

    s = 1e-4
    # rates across the band, around the saturation point (|w| = 5.93 * 2 s / sqrt(pi) = 6.7e-4)
    # and far beyond, both signs, zero, NaN and infinities
    w = np.concatenate([np.linspace(-1e-3, 1e-3, 4001), np.geomspace(1e-12, 1e3, 3001),
                        -np.geomspace(1e-12, 1e3, 3001), [0.0, -0.0, np.nan, np.inf, -np.inf]])
    x = np.sqrt(np.pi) / (2 * s) * w
    got = shaped_sign(w, s, "erf")
    assert np.array_equal(got, [math.erf(v) for v in x], equal_nan=True)
    assert np.array_equal(np.signbit(got), np.signbit(x))
    assert np.allclose(got, erf(x), rtol=4 * EPS, atol=0.0, equal_nan=True)
    assert shaped_sign(np.array(2e-4), s, "erf") == math.erf(np.sqrt(np.pi))


def test_exact_shape_is_the_sign_whatever_the_smoothing():
    w = np.array([-1e-9, -1e-6, 0.0, 1e-6, 1e-9])
    assert np.array_equal(shaped_sign(w, 1e-4, EXACT_SIGN), np.sign(w))


def test_unknown_shape_is_refused():
    with pytest.raises(ValueError, match="unknown Coulomb shape"):
        shaped_sign(np.ones(3), 1e-4, "tanh")


def _solution(theta, std, rms, n):
    return LeastSquaresSolution(
        theta=np.full((6, 12), theta), theta_std=np.full((6, 12), std), shared=np.array([theta]),
        shared_std=np.array([std]), condition_number=10.0, residual_rms=np.full(6, rms),
        n_equations=1000, effective_equations=np.full(6, n))


def test_akaike_weights_by_hand():
    # l_k = -1/2 sum_c n log(rms_k^2): the difference is 6 n log(rms_b / rms_a)
    a, b = _solution(1.0, 1.0, 1.0, 10.0), _solution(3.0, 1.0, 1.01, 10.0)
    ratio = np.exp(-60.0 * np.log(1.01))
    assert akaike_weights([a, b]) == pytest.approx([1 / (1 + ratio), ratio / (1 + ratio)],
                                                   rel=1e-12)
    # the sample size is the first fit's: a second fit's autocorrelation does not weigh
    c = dataclasses.replace(b, effective_equations=np.full(6, 1e6))
    assert akaike_weights([a, c]) == pytest.approx(akaike_weights([a, b]), rel=1e-12)


def test_average_is_the_mixture_mean_and_variance():
    a, b = _solution(1.0, 1.0, 1.0, 10.0), _solution(3.0, 2.0, 1.0, 10.0)
    out = average_solutions([a, b], np.array([0.25, 0.75]))
    # mean 2.5; variance 0.25 (1 + 1.5^2) + 0.75 (4 + 0.5^2) = 0.8125 + 3.1875 = 4
    assert np.allclose(out.theta, 2.5, rtol=4 * EPS)
    assert np.allclose(out.theta_std, 2.0, rtol=4 * EPS)
    assert np.allclose(out.shared_std, 2.0, rtol=4 * EPS)
    only = average_solutions([a, b], np.array([1.0, 0.0]))
    assert np.array_equal(only.theta, a.theta) and np.array_equal(only.theta_std, a.theta_std)


def test_exact_sign_widens_by_its_distance_beyond_the_noise():
    model = _solution(1.0, 1.0, 1.0, 10.0)
    # the exact sign fits far better: p = 1 / (1 + exp(-60 log 2)) = 1 - 8.7e-19
    far, near = _solution(4.0, 1.0, 0.5, 10.0), _solution(1.5, 1.0, 0.5, 10.0)
    out, p = widened_by_exact_sign(model, model, far)
    assert p == pytest.approx(1.0, abs=1e-15)
    # distance 3 beyond a standard error of 1: sqrt(1 + (9 - 1)) = 3
    assert np.allclose(out.theta_std, 3.0, rtol=4 * EPS)
    assert np.allclose(out.shared_std, 3.0, rtol=4 * EPS)
    assert np.array_equal(out.theta, model.theta)
    # a distance within the standard error is the noise's: nothing added
    out, _ = widened_by_exact_sign(model, model, near)
    assert np.array_equal(out.theta_std, model.theta_std)
    # the exact sign fitting worse (p = 8.7e-19) leaves the errors as they were to round-off
    out, p = widened_by_exact_sign(far, far, model)
    assert p == pytest.approx(2.0 ** -60, rel=1e-9)
    assert np.allclose(out.theta_std, 1.0, rtol=4 * EPS)


def _sine_logs(platform, simulate, duration):
    return [simulate(platform, multisine_excitation(
        platform, [Sine(k, DEFAULT_AMPLITUDES[k], 1.0)], name=f"exp{k + 1}"), duration)
        for k in range(6)]


def _ours(platform, excitation, duration):
    return simulate_experiment(platform, excitation, duration, noise=SensorNoise(),
                               rng=np.random.default_rng(0))[0]


def _bt_diagonal_errors(estimator, B):
    return np.abs(np.diag(estimator.B_) - np.diag(B)) / np.diag(B)


@pytest.mark.slow
def test_our_plant_shows_its_algebraic_sign(paper):
    # the plant's joint friction is the algebraic sign over 1e-4 rad/s
    platform = paper.replace(friction__coulomb=30.0)
    data = _sine_logs(platform, _ours, 3.0)
    _, B = nominal_matrices(platform)
    est = create_identifier("ls", sampling_check=False).fit(data, platform)
    assert est.coulomb_shape_weights_["algebraic"] > 0.999
    assert est.result_.diagnostics["exact_sign_weight"] < 1e-6
    assert np.max(_bt_diagonal_errors(est, B)) < 1e-4


@pytest.mark.slow
def test_friction_sharper_than_the_band_is_in_the_standard_errors(paper):
    # our plant with its joints' sign turning over within 1e-6 rad/s, a hundredth of the model's
    # band (a rig's dry friction, MuJoCo's constraint), noise-free three-sine logs: the fit
    # keeps the Bt diagonal 0.4-1.9 % low, which its noise-free errors put up to 4.2 of them off
    platform = paper.replace(friction__coulomb=30.0)
    sines = ((0.3, 0.6, 0.0), (0.7, 0.3, 1.0), (1.5, 0.15, 2.0))
    data = [simulate_experiment(platform, multisine_excitation(
        platform, [Sine(k, share * DEFAULT_AMPLITUDES[k], hz, phase) for hz, share, phase in sines],
        name=f"exp{k + 1}"), 20.0, noise=SensorNoise(), coulomb_smoothing=1e-6)[0]
        for k in range(6)]
    M, B = nominal_matrices(platform)
    est = create_identifier("ls", sampling_check=False).fit(data, platform)
    assert est.result_.diagnostics["exact_sign_weight"] > 0.99
    errors = np.concatenate([(est.M_ - M).ravel(), (est.B_ - B).ravel()])
    stds = np.concatenate([est.std_errors_["M"].ravel(), est.std_errors_["B"].ravel()])
    assert np.max(_bt_diagonal_errors(est, B)) > 3e-3  # the bias is there
    assert np.all(np.abs(errors) <= 3.0 * stds)


@pytest.mark.slow
def test_mujoco_constraint_friction_shows_the_erf_sign(paper):
    pytest.importorskip("mujoco")
    from stewartid.mujoco.closed_loop import simulate_mujoco

    # MuJoCo's dry friction is a constraint: sharper than the algebraic sign; fitting that
    # shape alone left the Bt diagonal 0.5-1.3 % low, the erf shape half as far
    platform = paper.replace(friction__coulomb=30.0)
    data = _sine_logs(platform, simulate_mujoco, 3.0)
    _, B = nominal_matrices(platform)
    average = create_identifier("ls", sampling_check=False).fit(data, platform)
    algebraic = create_identifier("ls", sampling_check=False,
                                  coulomb_shape="algebraic").fit(data, platform)
    assert average.coulomb_shape_weights_["erf"] > 0.999
    assert np.all(_bt_diagonal_errors(average, B) < 0.7 * _bt_diagonal_errors(algebraic, B))


def test_report_says_how_the_data_weigh_the_shapes():
    from stewartid.reports.identification.friction_text import friction_shape_lines

    class Result:
        diagnostics = {"coulomb_shape_weights": {"algebraic": 0.003, "erf": 0.997}}

    assert "algebraic 0.00, erf 1.00 (they show the shape)" in friction_shape_lines(Result)[0]
    Result.diagnostics = {"coulomb_shape_weights": {"algebraic": 0.4, "erf": 0.6}}
    assert "cannot tell the shape" in friction_shape_lines(Result)[0]
    Result.diagnostics = {"coulomb_shape_weights": {"erf": 1.0}}  # one shape asked for
    assert friction_shape_lines(Result) == []
    Result.diagnostics = {"coulomb_shape_weights": {"algebraic": 0.0, "erf": 1.0},
                          "exact_sign_weight": 0.97}
    assert "exact sign at 0.97" in friction_shape_lines(Result)[1]
    Result.diagnostics["exact_sign_weight"] = 1e-6  # our plant's smooth law: nothing to say
    assert len(friction_shape_lines(Result)) == 1
