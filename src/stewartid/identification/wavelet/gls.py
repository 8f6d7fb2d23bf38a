"""Generalized least squares for the weak-form equations, with pose noise propagated.

The rows of one interval, <phi_r, y> = Mt <phi_r'', q> - Bt <phi_r', q> (+ the constant for
the mean row), carry two kinds of noise:

- the force side (leg-force noise through J^T, what the gravity model leaves): white on the
  samples, so of variance s_i per row of channel i (the rows are orthonormal on the samples);
- the pose noise n (white, covariance Sigma per sample), which enters every regressor and,
  through y = J(q)^T f - G(q), the target (k_i n, k_i the row of K = dy/dq). Channel i's
  residual then holds sum_a c_a . <phi_r^(a), n> with c_0 = k_i, c_1 = b_i, c_2 = -m_i
  (m_i, b_i the rows of Mt and Bt), of covariance between rows r and s

      Q_rs = sum_ab (c_a Sigma c_b) <phi_r^(a), phi_s^(b)>

  (the ``noise_gram`` of :class:`~stewartid.identification.wavelet.weak_form.IntervalEquations`).

The second derivative makes the pose noise the larger part on the narrow test functions: on
the example data set with 20 µm leg-length noise it is 3-40x the force noise, growing with
the function's order. Equal weights then spend the narrow functions' noise on Mt, and the
noise in the regressors attenuates Mt by its share of their power (0.1-0.35 % on the Mt
diagonal there, measured as a bias over seeds). Both are removed as in WENDy: each
interval's rows are weighted by the inverse of their covariance s_i I + Q (iteratively, since Q
depends on the estimate), and the expected noise parts of the weighted normal equations,
sum_rs W_rs <phi_r^(a), phi_s^(b)> Sigma per block (and the targets' share through K), are
subtracted (the bias-compensated, errors-in-variables normal equations).

Sigma comes from the data (:func:`~stewartid.identification.wavelet.noise.white_noise_covariance`
per experiment), and so does the white force noise of each experiment (the same estimator on
the generalized force); s_i is that white part plus, when the weighted residuals hold more
than noise explains (model error), the excess that brings their chi-square to its degrees of
freedom. The white part must be measured, not left to the moments: with 20 µm pose noise the
pose part is 99.9 % of the residual power on the narrow test functions, the moments'
difference of two large numbers came out negative on most channels, and the widest
functions, where the force noise is the larger part, were then weighted as if noise-free
(weighted residuals 8-34 times their expected size, standard errors up to 45 times the
spread over seeds).

References
----------
Bortz, D. M., Messenger, D. A., Dukic, V. "Direct Estimation of Parameters in ODE Models Using
WENDy: Weak-Form Estimation of Nonlinear Dynamics." Bull. Math. Biol. 85, 110 (2023).
doi:10.1007/s11538-023-01208-6

Söderström, T. "Errors-in-variables methods in system identification." Automatica 43(6),
939-958 (2007). doi:10.1016/j.automatica.2006.11.025
"""

from __future__ import annotations

import warnings
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from stewartid.errors import DataWarning
from stewartid.identification.solvers import _check_rank, regressor_names
from stewartid.platform import COORDINATES

#: Unknowns of [Mt Bt].
N_THETA = 72


@dataclass(frozen=True)
class WeakFormSolution:
    """Solution of :func:`solve_weak_form`.

    Attributes
    ----------
    theta, theta_std : ndarray, shape (6, 12)
        [Mt Bt] and standard errors.
    coulomb, coulomb_std : ndarray, shape (n_types,)
        Coulomb level per joint type (N m), NaN without shared friction.
    offsets : ndarray, shape (n_experiments, 6)
        Constant per experiment (N, N m), NaN without shared friction.
    noise_std : ndarray, shape (6,)
        Force-side noise per row and channel, sqrt(s_i) (N s^(1/2), N m s^(1/2)).
    pose_noise_share : ndarray, shape (6,)
        Share of the invariant rows' residual power that the pose noise explains.
    constant_scatter : ndarray, shape (6,)
        tau: spread of the interval constants around the friction structure (N, N m).
    condition_number : float
        Of the column-equilibrated invariant regression.
    n_equations : int
        Rows per channel.
    """

    theta: np.ndarray
    theta_std: np.ndarray
    coulomb: np.ndarray
    coulomb_std: np.ndarray
    offsets: np.ndarray
    noise_std: np.ndarray
    pose_noise_share: np.ndarray
    constant_scatter: np.ndarray
    condition_number: float
    n_equations: int


def _pose_covariance(gram: np.ndarray, sigma: np.ndarray, coefficients: np.ndarray
                     ) -> np.ndarray:
    """Q per interval, (n, R, R): the row covariance the pose noise causes in one channel.

    gram (n, 3, 3, R, R) of the test functions and their derivatives, sigma (n, 6, 6), and
    coefficients (n, 3, 6): what multiplies <phi^(a), n> in the channel's residual, a = 0
    (the target's sensitivity k_i), 1 (b_i) and 2 (-m_i).
    """
    c = np.einsum("naj,njk,nbk->nab", coefficients, sigma, coefficients)
    return np.einsum("nab,nabrs->nrs", c, gram)


def _noise_bias(weights: np.ndarray, gram: np.ndarray, sigma: np.ndarray,
                sensitivity: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Expected noise parts of sum X^T W X (12, 12) and of sum X^T W y (12,) over intervals
    for one channel, the regressors' noise being [<phi'', n>, -<phi', n>] and the target's
    <phi, k_i n> (sensitivity (n, 6) = k_i per interval)."""
    t = np.einsum("nrs,nabrs->nab", weights, gram)                     # sum_rs W_rs G_ab,rs
    mm = np.einsum("n,njk->jk", t[:, 2, 2], sigma)
    mb = -np.einsum("n,njk->jk", t[:, 2, 1], sigma)
    bb = np.einsum("n,njk->jk", t[:, 1, 1], sigma)
    sk = np.einsum("njk,nk->nj", sigma, sensitivity)
    target = np.r_[np.einsum("n,nj->j", t[:, 2, 0], sk), -np.einsum("n,nj->j", t[:, 1, 0], sk)]
    return np.block([[mm, mb], [mb.T, bb]]), target


def _coefficients(sensitivity: np.ndarray, theta_i: np.ndarray) -> np.ndarray:
    """(n, 3, 6) coefficients of :func:`_pose_covariance` for channel row theta_i = [m, b]."""
    n = len(sensitivity)
    return np.stack([sensitivity, np.broadcast_to(theta_i[6:], (n, 6)),
                     np.broadcast_to(-theta_i[:6], (n, 6))], axis=1)


def _chi2_excess(variances: np.ndarray, squares: np.ndarray, dof: float) -> float:
    """e >= 0 with sum_k squares_k / (variances_k + e) = dof (0 when the left side is already
    at most dof at e = 0): the variance that residuals of expected variances ``variances``
    hold beyond them, matched in weighted chi-square (the Paule-Mandel estimator of
    random-effects meta-analysis). Both arrays of any one shape, variances >= 0."""
    lam = np.maximum(variances, 0.0)
    with np.errstate(divide="ignore", over="ignore", invalid="ignore"):  # noise-free rows
        if np.sum(np.where(squares > 0, squares / lam, 0.0)) <= dof:
            return 0.0
    low, high = 0.0, float(np.sum(squares)) / max(dof, 1)   # chi2(high) <= dof
    for _ in range(60):  # bisection on the monotone chi2(e), to 1e-18 of the bracket
        mid = 0.5 * (low + high)
        low, high = (mid, high) if np.sum(squares / (lam + mid)) > dof else (low, mid)
    return high


def _excess_variance(covariance: np.ndarray, residual: np.ndarray, dof: int) -> float:
    """e >= 0 with sum_n r_n^T (V_n + e I)^-1 r_n = dof: the white variance per row the
    residuals (n, R) hold beyond their expected covariance V (n, R, R), model error.

    Weighted, because the pose part of V is orders of magnitude larger on the narrow test
    functions than on the wide ones: the plain moment (sum |r|^2 - tr V) / (n R) is then the
    difference of two numbers whose randomness alone exceeds the force noise."""
    lam, vectors = np.linalg.eigh(covariance)
    return _chi2_excess(lam, np.einsum("nrk,nr->nk", vectors, residual) ** 2, dof)


def _weighted_normal(design: np.ndarray, weights: np.ndarray, target: np.ndarray
                     ) -> tuple[np.ndarray, np.ndarray]:
    """sum_n D_n^T W_n D_n and sum_n D_n^T W_n t_n for designs (n, R, u), weights (n, R, R)
    and targets (n, R), as two matrix products."""
    weighted = weights @ design                                         # (n, R, u)
    flat = design.reshape(-1, design.shape[-1])
    return (flat.T @ weighted.reshape(flat.shape),
            weighted.reshape(flat.shape).T @ target.ravel())


def solve_weak_form(equations: Sequence, n_experiments: int, shared_friction: bool = True,
                    iterations: int = 5, max_condition: float = 1e8,
                    pose_covariance: np.ndarray | None = None,
                    force_sensitivity: np.ndarray | None = None,
                    force_variance: np.ndarray | None = None) -> WeakFormSolution:
    """Generalized least squares for [Mt Bt] (and the friction structure), pose noise
    propagated and its bias compensated (module docstring).

    Parameters
    ----------
    equations : sequence of IntervalEquations
        All with the same number K of invariant rows.
    n_experiments : int
    shared_friction : bool
        Use the mean rows with the friction structure of
        :mod:`~stewartid.identification.wavelet.weak_form`; False: the invariant rows alone (every
        interval constant free).
    iterations : int
        Reweighting passes.
    max_condition : float
        Rank check of the invariant regression (names the DOF never excited).
    pose_covariance : ndarray, shape (n_experiments, 6, 6), optional
        White pose-noise covariance per sample of each experiment (m^2, m rad, rad^2);
        None: noise-free poses (weights from the force side only).
    force_sensitivity : ndarray, shape (n_experiments, 6, 6), optional
        K = d(J^T f - G) / dq of each experiment
        (:func:`~stewartid.identification.wavelet.noise.generalized_force_sensitivity`): the pose
        noise the targets share with the regressors. None: zero.
    force_variance : ndarray, shape (n_experiments, 6), optional
        White noise variance per sample of each experiment's generalized force (N^2,
        N^2 m^2), e.g. :func:`~stewartid.identification.wavelet.noise.white_noise_covariance`
        of it; None: zero (the force noise then comes from the residuals alone).

    Returns
    -------
    WeakFormSolution
    """
    x = np.stack([e.regressors for e in equations])                    # (n, K, 12)
    y = np.stack([e.targets for e in equations])                       # (n, K, 6)
    n, k_rows = x.shape[:2]
    owner = np.array([e.experiment for e in equations])
    gram_all = np.stack([e.noise_gram for e in equations])          # (n, 3, 3, K+1, K+1)
    sigma = (np.zeros((n, 6, 6)) if pose_covariance is None
             else np.asarray(pose_covariance, dtype=float)[owner])
    sensitivity = (np.zeros((n, 6, 6)) if force_sensitivity is None
                   else np.asarray(force_sensitivity, dtype=float)[owner])      # (n, 6, 6)
    white = (np.zeros((n, 6)) if force_variance is None
             else np.asarray(force_variance, dtype=float)[owner])             # (n, 6)
    flat = x.reshape(-1, 12)
    condition = _check_rank(flat.T @ flat, regressor_names("q_ddot", "q_dot"), max_condition)
    n_types = equations[0].coulomb.shape[0]
    n_nuisance = 6 * n_experiments + n_types if shared_friction else 0
    n_unknowns = N_THETA + n_nuisance
    rows = k_rows + 1 if shared_friction else k_rows

    # per channel: design (n, rows, n_unknowns), target (n, rows), gram (n, 3, rows, rows)
    designs, targets = [], []
    if shared_friction:
        xm = np.stack([e.mean_regressors for e in equations])
        ym = np.stack([e.mean_target for e in equations])
        weight = np.array([e.weight for e in equations])
        wm = np.stack([e.coulomb for e in equations])                   # (n, types, 6)
    for i in range(6):
        design = np.zeros((n, rows, n_unknowns))
        design[:, :k_rows, 12 * i:12 * i + 12] = x
        target = y[:, :, i]
        if shared_friction:
            design[:, k_rows, 12 * i:12 * i + 12] = xm
            design[np.arange(n), k_rows, N_THETA + 6 * owner + i] = weight
            design[:, k_rows, N_THETA + 6 * n_experiments:] = wm[:, :, i]
            target = np.concatenate([target, ym[:, i:i + 1]], axis=1)
        designs.append(design)
        targets.append(target)
    gram = gram_all[..., :rows, :rows]
    gram_inv = gram_all[..., :k_rows, :k_rows]

    # start: each channel's invariant rows, force-side weights only
    theta = np.linalg.lstsq(flat, y.reshape(-1, 6), rcond=None)[0].T
    # floor: noise-free data must not give infinite weights
    floor = 1e-24 * np.maximum(np.mean(y.reshape(-1, 6) ** 2, axis=0), 1e-300)
    noise = np.zeros((n, 6))  # s per interval and channel
    pose_share = np.zeros(6)

    uncorrected = np.zeros(6, dtype=bool)  # channels of the last pass left uncorrected

    def compensated(normal: np.ndarray, rhs: np.ndarray, w: np.ndarray, g: np.ndarray,
                    i: int) -> tuple[np.ndarray, np.ndarray]:
        bias, bias_rhs = _noise_bias(w, g, sigma, sensitivity[:, i])
        try:  # noise so large that the correction leaves no information: no correction
            np.linalg.cholesky(normal - bias)
        except np.linalg.LinAlgError:
            uncorrected[i] = True
            return normal, rhs
        uncorrected[i] = False
        return normal - bias, rhs - bias_rhs

    # invariant rows alone (the estimate the scatter is measured with)
    for i in range(6):
        for _ in range(max(1, iterations)):
            q_inv = _pose_covariance(gram_inv, sigma, _coefficients(sensitivity[:, i], theta[i]))
            residual = y[:, :, i] - x @ theta[i]
            power, pose = float(np.sum(residual ** 2)), float(np.trace(q_inv, 0, 1, 2).sum())
            excess = _excess_variance(white[:, i, None, None] * np.eye(k_rows) + q_inv,
                                      residual, residual.size - 12)
            noise[:, i] = np.maximum(white[:, i] + excess, floor[i])
            pose_share[i] = min(pose / max(power, 1e-300), 1.0)
            w = np.linalg.inv(noise[:, i, None, None] * np.eye(k_rows) + q_inv)
            normal, rhs = compensated(*_weighted_normal(x, w, y[:, :, i]), w, gram_inv, i)
            theta[i] = np.linalg.solve(normal, rhs)

    def channel_covariance(i: int, theta_i: np.ndarray) -> np.ndarray:
        v = noise[:, i, None, None] * np.eye(rows) + _pose_covariance(gram, sigma,
                                                       _coefficients(sensitivity[:, i], theta_i))
        if shared_friction:
            v[:, -1, -1] += (scatter[i] * weight) ** 2
        return v

    scatter = np.zeros(6)
    if shared_friction:
        # the scatter of the interval constants around the friction structure, measured with
        # the invariant estimate: a joint fit would bend Bt to hide a structure that does
        # not hold, and so report a scatter too small to notice it
        variance = np.stack([channel_covariance(i, theta[i])[:, -1, -1]
                             for i in range(6)], axis=1)                  # (n, 6), tau = 0
        base = ym - xm @ theta.T
        nuisance_design = np.stack([d[:, -1, N_THETA:] for d in designs], axis=1)  # (n,6,u)
        scaled = nuisance_design / np.sqrt(variance)[:, :, None]
        fitted = np.linalg.lstsq(scaled.reshape(-1, n_nuisance),
                                 (base / np.sqrt(variance)).ravel(), rcond=None)[0]
        mean_residual = base - nuisance_design @ fitted
        # tau^2 per channel with sum_k r_k^2 / (v_k + tau^2 w_k^2) = dof, i.e. the chi-square
        # excess of r_k / w_k over v_k / w_k. Not the plain moment sum(r^2 - v) / sum(w^2):
        # the intervals' noise variances v differ 100-fold, the moment was ruled by the
        # noisiest, came out zero on half the seeds and 20x the typical value on others,
        # and the estimates of Bt followed it (kurtosis 4-9 over seeds, twice the spread)
        dof = n - n_nuisance / 6
        scatter = np.sqrt([_chi2_excess(variance[:, i] / weight ** 2,
                                        (mean_residual[:, i] / weight) ** 2, dof)
                           for i in range(6)])

    z = np.zeros(n_unknowns)
    z[:N_THETA] = theta.ravel()
    for _ in range(max(1, iterations) if shared_friction else 1):
        normal = np.zeros((n_unknowns, n_unknowns))
        rhs = np.zeros(n_unknowns)
        weights = []
        for i in range(6):
            block = slice(12 * i, 12 * i + 12)
            w = np.linalg.inv(channel_covariance(i, z[block]))
            weights.append(w)
            part, part_rhs = _weighted_normal(designs[i], w, targets[i])
            normal += part
            rhs += part_rhs
            normal[block, block], rhs[block] = compensated(normal[block, block], rhs[block], w,
                                                           gram, i)
        scale = np.sqrt(np.abs(np.diag(normal)))
        scale = np.where(scale > 0, scale, 1.0)
        z = np.linalg.solve(normal / np.outer(scale, scale), rhs / scale) / scale

    if uncorrected.any():
        names = ", ".join(c for c, u in zip(COORDINATES, uncorrected, strict=True) if u)
        warnings.warn(f"pose noise too large for the errors-in-variables correction of the "
                      f"{names} equations: their rows of Mt and Bt keep the attenuation the "
                      f"noise causes (biased towards zero by its share of the regressors' "
                      f"power); longer intervals or less pose noise remove it", DataWarning,
                      stacklevel=3)

    # standard errors: the model's (GLS with the compensated normal matrix) and a
    # cluster-robust sandwich over intervals (model errors such as a friction reversal
    # inside an interval show in the spread between intervals, not in the noise level)
    scores = np.zeros((n, n_unknowns))
    squares, n_rows = 0.0, 0
    for i in range(6):
        residual = targets[i] - designs[i] @ z
        weighted = (weights[i] @ residual[:, :, None])[:, :, 0]
        scores += (weighted[:, None, :] @ designs[i])[:, 0, :]
        squares += float(np.sum(residual * weighted))
        n_rows += residual.size
    # the equilibrated normal matrix is well conditioned (checked above): an inverse, not
    # pinv's SVD of the 111 x 111 shared-friction system
    bread = np.linalg.inv(normal / np.outer(scale, scale)) / np.outer(scale, scale)
    model_cov = bread * max(squares / max(n_rows - n_unknowns, 1), 1e-300)
    g = n
    robust_cov = (g / max(g - 1, 1) * (n_rows - 1) / max(n_rows - n_unknowns, 1)
                  * bread @ (scores.T @ scores) @ bread)
    std = np.sqrt(np.maximum(np.diag(model_cov), np.diag(robust_cov)))
    theta = z[:N_THETA].reshape(6, 12)
    if shared_friction:
        offsets = z[N_THETA:N_THETA + 6 * n_experiments].reshape(n_experiments, 6)
        coulomb, coulomb_std = z[N_THETA + 6 * n_experiments:], std[N_THETA + 6 * n_experiments:]
    else:
        offsets = np.full((n_experiments, 6), np.nan)
        coulomb = coulomb_std = np.full(n_types, np.nan)
    return WeakFormSolution(
        theta=theta, theta_std=std[:N_THETA].reshape(6, 12), coulomb=coulomb,
        coulomb_std=coulomb_std, offsets=offsets, noise_std=np.sqrt(noise.mean(axis=0)),
        pose_noise_share=pose_share, constant_scatter=scatter, condition_number=condition,
        n_equations=int(n * k_rows))


__all__ = ["WeakFormSolution", "solve_weak_form"]
