"""Time-domain least squares with Coulomb terms against the linear model it assumes."""

from __future__ import annotations

import numpy as np
import pytest

from linear_model_data import AMPLITUDES, make_experiment, random_matrices
from stewartid.errors import IdentificationError
from stewartid.identification.least_squares import (
    LeastSquaresIdentifier,
    coulomb_regressors,
)
from stewartid.identification.long_run import (
    long_run_covariance,
    record_sandwich,
    score_sandwich,
    with_larger_variances,
)
from stewartid.identification.solvers import integrated_autocorrelation, solve_least_squares
from stewartid.model.joints import JOINT_TYPES
from stewartid.model.kinematics import joint_rate_jacobians
from stewartid.model.regressor import parameter_index, random_states, regressor
from stewartid.physical.parameter_fit import solve_parameters


def _coulomb(levels):
    def force(t, q, qd, J):
        return np.einsum("nsi,s->ni", coulomb_regressors(J, qd, 0.0), levels)
    return force


def test_coulomb_regressors_are_the_regressors_coulomb_columns(paper):
    """S_type = sum J_j^T sign(J_j q_dot) per joint type (joint-axis Jacobians, numpy) against
    the regressor's Coulomb columns, which build the same forces as wrenches of the leg
    geometry, at random states and at an exact and a regularised sign."""
    q, q_dot, _ = random_states(paper, 200, seed=5)
    columns = parameter_index([f"coulomb[{t}]" for t in JOINT_TYPES])
    J = joint_rate_jacobians(paper, q)
    for smoothing in (0.0, 0.02):
        Y = regressor(paper, q, q_dot, np.zeros_like(q), gravity=False,
                      coulomb_smoothing=smoothing)
        expected = Y[..., columns].transpose(0, 2, 1)
        got = coulomb_regressors(J, q_dot, smoothing)
        assert np.abs(got - expected).max() <= 1e-12 * np.abs(expected).max()


def test_recovers_mt_bt_offsets_and_coulomb_levels(paper):
    M, B = random_matrices(np.random.default_rng(3))
    levels = np.array([30.0, 20.0, 10.0])
    offset = np.array([50.0, -20.0, 300.0, 5.0, -8.0, 2.0])
    data = []
    for k in range(6):
        # a second, slower sine in another DOF: joints switch at different times
        extra = [((k + 2) % 6, AMPLITUDES[(k + 2) % 6] / 3, 2 * np.pi * 0.37, 0.5)]
        data.append(make_experiment(paper, M, B, k, extra=extra, offset=offset,
                                    coulomb=_coulomb(levels), periods=5))
    est = LeastSquaresIdentifier(coulomb_smoothing=0.0).fit(data, paper)
    assert est.M_ == pytest.approx(M, abs=2e-3 * np.abs(M).max())
    assert est.B_ == pytest.approx(B, abs=2e-3 * np.abs(B).max())
    got = np.array([est.coulomb_[name] for name in JOINT_TYPES])
    assert got == pytest.approx(levels, rel=0.02)
    # the offsets share part of their column space with the Coulomb terms (mean sign)
    assert est.offsets_ == pytest.approx(np.tile(offset, (6, 1)), abs=0.03 * 300.0)


def test_symmetric_constraint(paper):
    M, B = random_matrices(np.random.default_rng(4))
    data = [make_experiment(paper, M, B, k) for k in range(6)]
    est = LeastSquaresIdentifier(coulomb=False, symmetric=True).fit(data, paper)
    assert est.M_ == pytest.approx(est.M_.T)
    assert est.M_ == pytest.approx(M, abs=1e-4 * np.abs(M).max())


def test_solver_standard_errors_match_scatter():
    rng = np.random.default_rng(0)
    theta = rng.normal(size=(6, 13))
    errors = []
    for _ in range(40):
        phi = np.column_stack([rng.normal(size=(300, 12)), np.ones(300)])
        y = phi @ theta.T + rng.normal(size=(300, 6)) * np.array([1, 1, 1, 10, 10, 10])
        sol = solve_least_squares(phi, y)
        errors.append((sol.theta - theta) / sol.theta_std)
    assert np.std(errors) == pytest.approx(1.0, abs=0.1)


def test_solver_without_standard_errors_gives_the_same_fit():
    # shared columns and autocorrelated, segmented residuals: every branch the errors skip
    rng = np.random.default_rng(3)
    phi = np.column_stack([rng.normal(size=(600, 12)), np.ones(600)])
    shared = rng.normal(size=(600, 2, 6))
    y = (phi @ rng.normal(size=(6, 13)).T + np.einsum("ksi,s->ki", shared, [0.5, -2.0])
         + np.cumsum(rng.normal(size=(600, 6)), axis=0) * 0.1)
    full = solve_least_squares(phi, y, shared, autocorrelated=True, segments=[(300, 20)] * 2)
    bare = solve_least_squares(phi, y, shared, autocorrelated=True, segments=[(300, 20)] * 2,
                               standard_errors=False)
    for name in ("theta", "shared", "residual_rms", "effective_equations"):
        assert np.array_equal(getattr(bare, name), getattr(full, name)), name
    assert bare.condition_number == full.condition_number
    assert np.isnan(bare.theta_std).all() and np.isnan(bare.shared_std).all()


def test_solver_names_the_unexcited_dof():
    rng = np.random.default_rng(1)
    phi = rng.normal(size=(100, 12))
    phi[:, 4] = 0.0
    names = [f"{g}[{c}]" for g in ("q_ddot", "q_dot") for c in ("x", "y", "z", "rx", "ry", "rz")]
    with pytest.raises(IdentificationError, match="DOF ry was never excited"):
        solve_least_squares(phi, rng.normal(size=(100, 6)), regressor_names=names)


def test_integrated_autocorrelation():
    rng = np.random.default_rng(2)
    white = rng.normal(size=20000)
    assert integrated_autocorrelation(white) == pytest.approx(1.0, abs=0.2)
    smooth = np.convolve(white, np.ones(20) / 20, mode="valid")
    assert integrated_autocorrelation(smooth) == pytest.approx(20.0, rel=0.2)


def _ar1(rng, rho, shape):
    """Stationary AR(1) noise of unit variance along axis 0."""
    from scipy import signal

    white = rng.normal(size=shape) * np.sqrt(1 - rho ** 2)
    white[0] /= np.sqrt(1 - rho ** 2)
    return signal.lfilter([1.0], [1.0, -rho], white, axis=0)


def test_integrated_autocorrelation_of_ar1():
    """AR(1) of coefficient rho: tau = sum_k rho^|k| = (1 + rho) / (1 - rho)."""
    rng = np.random.default_rng(5)
    for rho in (0.5, 0.9):
        taus = [integrated_autocorrelation(_ar1(rng, rho, 50_000)) for _ in range(4)]
        assert np.mean(taus) == pytest.approx((1 + rho) / (1 - rho), rel=0.1)


def test_autocorrelated_standard_errors_match_monte_carlo():
    """Slow regressors (sines of 40-400 samples' period) and AR(1) residuals (rho 0.8, a
    low-pass filtered sensor): the estimate's variance is tau = 9 times the white-noise
    formula's. With ``autocorrelated`` the standard errors match the scatter over 60
    records (|error| / SE of spread 1, within the Monte Carlo's 10 %); without it they are
    sqrt(tau) = 3 times too small."""
    rng = np.random.default_rng(6)
    k = np.arange(4000)
    phi = np.column_stack([np.sin(2 * np.pi * k / period + period)
                           for period in np.geomspace(40, 400, 12)] + [np.ones(len(k))])
    theta = rng.normal(size=(6, 13))
    honest, white = [], []
    for _ in range(60):
        y = phi @ theta.T + _ar1(rng, 0.8, (len(k), 6))
        for flag, out in ((True, honest), (False, white)):
            sol = solve_least_squares(phi, y, autocorrelated=flag)
            out.append((sol.theta - theta) / sol.theta_std)
    assert np.std(honest) == pytest.approx(1.0, abs=0.1)
    assert np.std(white) == pytest.approx(3.0, rel=0.15)


def test_long_run_covariance_of_moving_average_and_high_pass_noise():
    """The long-run variance (the sum of every autocovariance) of white noise of unit
    variance through a filter h is (sum h)^2: 1 for a moving average of 20 samples (whose
    variance is 1/20), 0 for a first difference (whose variance is 2, with no positive
    autocorrelation for an autocorrelation time to add). Both are correlated over 20 lags
    at most, where the sum is truncated without bias; its relative sampling error is about
    sqrt(2 (2 L + 1) / K) = 2 % (L = 20, K = 200 000): 0.1 is five of them."""
    rng = np.random.default_rng(11)
    white = rng.normal(size=200_020)
    average = np.convolve(white, np.ones(20) / 20, mode="valid")[:200_000]
    difference = np.diff(white)[:200_000]
    for series, expected in ((average, 1.0), (difference, 0.0)):
        B = long_run_covariance(series[:, None], [(len(series), 20)])[0, 0] / len(series)
        assert B == pytest.approx(expected, abs=0.1)
    # products at every fourth row only: the moving average varies slowly against it
    strided = long_run_covariance(average[:, None], [(len(average), 20)], stride=4)
    assert strided[0, 0] / len(average) == pytest.approx(1.0, abs=0.1)
    # two records: no lag crosses them, and their sums add
    halves = long_run_covariance(average[:, None], [(100_000, 20)] * 2)[0, 0] / len(average)
    assert halves == pytest.approx(1.0, abs=0.1)


def test_long_run_variances_are_unbiased_where_the_clipped_covariance_is_not():
    """Scores X_k (e_k+1 - 0.8 e_k) of six slowly varying regressors and one white noise:
    the variance of their sum is sum_j (X_j-1 - 0.8 X_j)^2 exactly, a small remainder of
    the lag-0 and lag-1 autocovariances, so the long-run sum's sampling error gives it
    eigenvalues of either sign. Its diagonal as it is averages to the exact variance over
    2000 draws (sampling error of the mean about 2.5 %: 0.1 is four of them); with the
    negative eigenvalues zeroed it came out 1.45-1.6 times it. ``psd="variances"`` keeps
    the diagonal as it is (the clipped one where negative: never a zero standard error) on
    a positive semidefinite matrix."""
    rng = np.random.default_rng(5)
    K, n = 4000, 6
    t = np.arange(K) / K
    X = np.stack([np.sin(2 * np.pi * (k + 1) * t + k) for k in range(n)], axis=1)
    padded = np.vstack([np.zeros((1, n)), X, np.zeros((1, n))])
    exact = np.sum((padded[:-1] - 0.8 * padded[1:]) ** 2, axis=0)
    raw, clipped = [], []
    for _ in range(2000):
        e = rng.normal(size=K + 1)
        scores = X * (e[1:] - 0.8 * e[:-1])[:, None]
        raw.append(np.diag(score_sandwich(np.eye(n), scores, [(K, 6)], psd=False)))
        clipped.append(np.diag(score_sandwich(np.eye(n), scores, [(K, 6)])))
    assert np.allclose(np.mean(raw, axis=0) / exact, 1.0, atol=0.1)
    assert np.all(np.mean(clipped, axis=0) / exact > 1.3)
    # the diagonal as it is; where it came out negative (18 % here), the clipped one's
    mixed = score_sandwich(np.eye(n), scores, [(K, 6)], psd="variances")
    assert np.allclose(np.diag(mixed), np.where(raw[-1] > 0, raw[-1], clipped[-1]),
                       rtol=1e-12, atol=0.0)
    assert np.linalg.eigvalsh(mixed).min() > -1e-9 * np.abs(mixed).max()


def test_the_larger_variances_keep_the_first_covariance_correlations():
    """Worked by hand: variances (4, 1, 0) against (1, 9, 2.25) give (4, 9, 2.25); the first
    pair's correlation 0.5 stays, so their covariance becomes 0.5 * 2 * 3 = 3."""
    first = np.array([[4.0, 1.0, 0.0], [1.0, 1.0, 0.0], [0.0, 0.0, 0.0]])
    other = np.diag([1.0, 9.0, 2.25])
    expected = np.array([[4.0, 3.0, 0.0], [3.0, 9.0, 0.0], [0.0, 0.0, 2.25]])
    np.testing.assert_allclose(with_larger_variances(first, other), expected, rtol=1e-12)


def test_record_sandwich_worked_by_hand():
    """Three records of 2, 1 and 1 rows whose scores sum to (2, 0), (0, 1), (-2, -1):
    B = 3/2 * sum of their outer products = [[12, 3], [3, 3]]. Adding the same score to
    every row (an errors-in-variables correction's shape) moves the record sums by their
    share of the total, which is taken out: B is unchanged; so is a shift that differs
    between records when each record's is given."""
    scores = np.array([[1.0, 0.0], [1.0, 0.0], [0.0, 1.0], [-2.0, -1.0]])
    segments = [(2, 1), (1, 1), (1, 1)]
    expected = np.array([[12.0, 3.0], [3.0, 3.0]])
    np.testing.assert_allclose(record_sandwich(np.eye(2), scores, segments), expected,
                               rtol=1e-12)
    np.testing.assert_allclose(record_sandwich(np.eye(2), scores + [0.7, -0.3], segments),
                               expected, rtol=1e-12)
    # a shift that differs between records, taken out when given per record
    shift = np.array([[1.0, 0.0], [1.0, 0.0], [0.0, 2.0], [0.0, 0.0]])
    np.testing.assert_allclose(record_sandwich(np.eye(2), scores + shift, segments,
                                               expected=[[2.0, 0.0], [0.0, 2.0], [0.0, 0.0]]),
                               expected, rtol=1e-12)


def test_standard_errors_see_model_error_that_differs_between_records():
    """Each of 8 records carries a model error b_r times a regressor column (b_r ~ N(0, 0.05^2),
    as a friction law that is off by a different amount in each record), on white noise of
    unit variance. The estimate's scatter is mostly that of the mean of b_r, which no
    short-lag covariance of the residual sees (scatter 3-4 times its errors); the scores
    summed per record see it. With 8 records the errors are themselves estimated with 7
    degrees of freedom: scatter / SE is at most that of Student's t, sqrt(7 / 5) = 1.18."""
    rng = np.random.default_rng(3)
    t = np.arange(2000) / 100.0
    records, z, short = 8, [], []
    X = np.stack([np.column_stack([np.sin(1.3 * t + c), np.cos(0.7 * t + 2 * c)])
                  for c in range(6)], axis=1)  # (rows, 6 channels, 2)
    for _ in range(60):
        errors = rng.normal(0.0, 0.05, records)
        y = np.concatenate([X @ [1.0, -2.0] + b * X[..., 0] + rng.normal(size=(len(t), 6))
                            for b in errors])
        rows = np.concatenate([X] * records)
        segments = [(len(t), 5)] * records
        fit = solve_parameters(rows, y, ["a", "b"], np.zeros(2), segments=segments)
        std = np.sqrt(np.diag(fit.covariance))
        z.append((fit.values - [1.0, -2.0]) / std)
        residual = y - rows @ fit.values
        inverse = np.linalg.inv(np.einsum("kcp,kcq->pq", rows, rows))
        scores = np.einsum("kcp,kc->kp", rows, residual)
        short.append((fit.values - [1.0, -2.0])
                     / np.sqrt(np.diag(score_sandwich(inverse, scores, segments))))
    # t with 7 degrees of freedom at most (the reported error is the larger of several),
    # within two of the Monte Carlo's 9 % errors; the short-lag errors alone 3-4 times small
    assert 0.75 < np.std(np.array(z)[:, 0]) < 1.18 * 1.18
    assert np.std(np.array(short)[:, 0]) > 2.5


def test_errors_in_variables_correction_per_record_is_no_model_error():
    """y = a x + e on 6 channels, x measured with white noise u whose variance alternates
    between 0.2 and 1 over 6 records (as pose noise through a filter that follows each
    record's frequencies). The corrected estimate's scores sum, per record, to -a var(u_r)
    per row: a record-to-record difference that noise alone gives. Given per record, it is
    taken out and the reported errors match the scatter over 200 fits (its uncertainty 5 %;
    the reported error is the larger of two, one of 5 degrees of freedom, so scatter / error
    is 0.85-0.89 over three seeds); shared out by rows as one total, the difference reads as
    model error and the errors come out 15 times too large."""
    rng = np.random.default_rng(5)
    n, a, records = 400, 2.0, 6
    variance = np.tile([0.2, 1.0], records // 2)
    x0 = 1.0 + 0.5 * np.sin(np.arange(n) / 7.0)[:, None] * np.ones(6)
    segments = [(n, 1)] * records
    rows = np.concatenate([x0] * records)[..., None]
    noise = np.einsum("r,c->rc", variance * n, np.ones(6))[..., None, None]  # (R, 6, 1, 1)
    z = {True: [], False: []}
    for _ in range(200):
        u = rng.normal(size=(records * n, 6)) * np.sqrt(np.repeat(variance, n))[:, None]
        y = a * rows[..., 0] + 0.3 * rng.normal(size=(records * n, 6))
        measured = rows + u[..., None]
        for by_record in (True, False):
            fit = solve_parameters(measured, y, ["a"], np.zeros(1), regressor_noise=(
                noise if by_record else noise.sum(axis=0)), segments=segments)
            z[by_record].append((fit.values[0] - a) / np.sqrt(fit.covariance[0, 0]))
    assert 0.8 < np.std(z[True]) < 1.2
    assert np.std(z[False]) < 0.5


def test_standard_errors_with_a_high_pass_residual_are_never_too_small():
    """Residual = AR(1) (long-run variance (1 + rho) / (1 - rho)) plus a first difference of
    white noise (long-run variance 0, but variance and a negative lag-one autocorrelation):
    slow regressors see only the first. The autocorrelation time stops at the negative lag
    and counts the variance instead: with rho 0.9 and a difference of variance 8 it counts
    9 where the truth is 19 (standard errors sqrt(19/9) = 1.45 times too small); the scores'
    long-run covariance gets 19, and the larger of the two is reported (scatter / SE within
    the Monte Carlo's 10 % of 1). With rho 0.8 and a difference of variance 18, the time
    counts 19 where the truth is 9: the reported errors are 1.45 times too large, never too
    small."""
    rng = np.random.default_rng(12)
    k = np.arange(4000)
    phi = np.column_stack([np.sin(2 * np.pi * k / period + period)
                           for period in np.geomspace(80, 400, 12)] + [np.ones(len(k))])
    theta = rng.normal(size=(6, 13))
    for rho, difference, expected in ((0.9, 2.0, 1.0), (0.8, 3.0, 1 / 1.45)):
        z = []
        for _ in range(60):
            y = phi @ theta.T + _ar1(rng, rho, (len(k), 6)) + difference * np.diff(
                rng.normal(size=(len(k) + 1, 6)), axis=0)
            sol = solve_least_squares(phi, y, autocorrelated=True, segments=[(len(k), 60)])
            z.append((sol.theta - theta) / sol.theta_std)
        assert np.std(z) == pytest.approx(expected, rel=0.1)


@pytest.mark.slow
def test_example_c10_least_squares(example_dir, example_platform, example_truth):
    est = LeastSquaresIdentifier().fit([example_dir], example_platform)
    for level in est.coulomb_.values():
        assert level == pytest.approx(example_truth["coulomb"], rel=0.1)
    table = est.result_.comparison_table(example_truth["Mt"], example_truth["Bt"])
    diag = table[table.i == table.j]
    assert diag["error_percent"].max() < 1.0


@pytest.mark.slow
def test_pose_noise_in_the_regressors_is_corrected(paper):
    """Errors in variables: white pose noise, carried into q_ddot by the kernel's h'', adds
    its variance to every q_ddot column's energy and pulls the Mt diagonal down (here about
    0.35 %, 3-5 standard errors of the mean over 4 seeds). With the noise's share of the
    normal equations removed (the default) the mean error is within 3 standard errors of
    the mean; without it the bias shows."""
    import dataclasses

    from stewartid.model.kinematics import leg_lengths

    M, B = random_matrices(np.random.default_rng(3))
    clean = [make_experiment(paper, M, B, k, frequency_hz=0.5, periods=8, sample_rate=1000.0,
                             extra=[(k, AMPLITUDES[k] * 0.3, 2 * np.pi * 2.3, 0.4)])
             for k in range(6)]
    rng = np.random.default_rng(4)
    found = {False: [], True: []}
    for _ in range(4):
        noisy = []
        for d in clean:
            pose = d.pose + 4e-4 * rng.normal(size=d.pose.shape) * np.array([1, 1, 1, .5, .5, .5])
            noisy.append(dataclasses.replace(d, pose=pose, lengths=leg_lengths(paper, pose)))
        for corrected in (False, True):
            fitted = LeastSquaresIdentifier(coulomb=False, noise_correction=corrected).fit(
                noisy, paper)
            found[corrected].append((np.diag(fitted.M_) / np.diag(M) - 1,
                                     np.diag(fitted.std_errors_["M"]) / np.diag(M)))
    for corrected, bound in ((True, 3.0), (False, None)):
        errors = np.array([e for e, _ in found[corrected]])
        of_mean = np.array([s for _, s in found[corrected]]).mean(axis=0) / np.sqrt(4)
        z = errors.mean(axis=0) / of_mean
        if corrected:
            assert np.all(np.abs(z) <= bound), z
        else:
            assert np.sum(z < -2.0) >= 5, z
