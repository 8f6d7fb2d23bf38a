"""Variance components of Method B's weak-form rows.

Pose-noise covariance, its bias on the normal equations, the excess residual variance (Paule and Mandel 1982).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from stewartid.identification.wavelet.weak_form import StackedEquations


def pose_covariance(gram: np.ndarray, sigma: np.ndarray, coefficients: np.ndarray
                    ) -> np.ndarray:
    """Row covariance Q (n, R, R) pose noise causes in one channel per interval.

    Q_rs = sum_ab (c_a Sigma c_b) <phi_r^(a), phi_s^(b)>; ``gram`` (n, 3, 3, R, R), ``sigma`` (n, 6, 6),
    ``coefficients`` c_a (n, 3, 6) from :func:`pose_coefficients`.
    """
    n, rows = gram.shape[0], gram.shape[-1]
    c = coefficients @ sigma @ coefficients.transpose(0, 2, 1)                 # (n, 3, 3)
    return (c.reshape(n, 1, 9) @ gram.reshape(n, 9, rows * rows)).reshape(n, rows, rows)


def noise_bias(weights: np.ndarray, gram: np.ndarray, sigma: np.ndarray,
               sensitivity: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Expected noise parts (12, 12), (12,) of sum X^T W X and sum X^T W y over intervals, one channel.

    Regressor noise [<phi'', n>, -<phi', n>], target noise <phi, k_i n>; ``sensitivity`` k_i (n, 6).
    """
    n, rows = gram.shape[0], gram.shape[-1]
    t = (gram.reshape(n, 9, rows * rows) @ weights.reshape(n, rows * rows, 1)
         ).reshape(n, 3, 3)                                             # sum_rs W_rs G_ab,rs
    mm = np.einsum("n,njk->jk", t[:, 2, 2], sigma)
    mb = -np.einsum("n,njk->jk", t[:, 2, 1], sigma)
    bb = np.einsum("n,njk->jk", t[:, 1, 1], sigma)
    sk = np.einsum("njk,nk->nj", sigma, sensitivity)
    target = np.r_[np.einsum("n,nj->j", t[:, 2, 0], sk), -np.einsum("n,nj->j", t[:, 1, 0], sk)]
    return np.block([[mm, mb], [mb.T, bb]]), target


def compensate(normal: np.ndarray, rhs: np.ndarray, weights: np.ndarray, gram: np.ndarray,
               sigma: np.ndarray, sensitivity: np.ndarray
               ) -> tuple[np.ndarray, np.ndarray, bool]:
    """Normal equations less :func:`noise_bias` unless that breaks definiteness, and whether corrected."""
    bias, bias_rhs = noise_bias(weights, gram, sigma, sensitivity)
    try:
        np.linalg.cholesky(normal - bias)
    except np.linalg.LinAlgError:
        return normal, rhs, False
    return normal - bias, rhs - bias_rhs, True


def pose_coefficients(sensitivity: np.ndarray, theta_i: np.ndarray) -> np.ndarray:
    """(n, 3, 6) coefficients of :func:`pose_covariance` for theta_i = [m, b]: rows k_i, b, -m."""
    n = len(sensitivity)
    return np.stack([sensitivity, np.broadcast_to(theta_i[6:], (n, 6)),
                     np.broadcast_to(-theta_i[:6], (n, 6))], axis=1)


def chi2_excess(variances: np.ndarray, squares: np.ndarray, dof: float) -> float:
    """e >= 0 with sum_k squares_k / (variances_k + e) = dof (Paule-Mandel); 0 if already below."""
    lam = np.maximum(variances, 0.0).ravel()
    s = np.asarray(squares, dtype=float).ravel()
    keep = s > 0
    lam, s = lam[keep], s[keep]
    zero = lam == 0   # noise-free rows: chi2 is infinite at e = 0
    if not np.any(zero) and np.sum(s / lam) <= dof:
        return 0.0
    # Newton on h(e) = 1/chi2(e) - 1/dof, concave and increasing (1/chi2 is a parallel sum of
    # affine functions of e): from the left the iterates rise monotonically to the root, in a
    # few steps since h is nearly affine. At e = 0 with zero variances, h and h' are limits.
    e = float(np.sum(s[zero])) / dof if np.any(zero) else 0.0
    for _ in range(100):
        u = s / (lam + e)
        chi2 = float(np.sum(u))
        step = (1.0 / dof - 1.0 / chi2) * chi2 ** 2 / float(np.sum(u / (lam + e)))
        if not step > 4 * np.finfo(float).eps * e:
            break
        e += step
    return e


def excess_variance(covariance: np.ndarray, residual: np.ndarray, dof: int) -> float:
    """e >= 0 with sum_n r_n^T (V_n + e I)^-1 r_n = dof: the white variance per row beyond V."""
    lam, vectors = np.linalg.eigh(covariance)
    return chi2_excess(lam, np.einsum("nrk,nr->nk", vectors, residual) ** 2, dof)


def row_noise(stacked: StackedEquations, designs: Sequence[np.ndarray],
              targets: Sequence[np.ndarray], z: np.ndarray, extra: float = 0) -> np.ndarray:
    """Force-side noise variance (n, 6) per interval and channel: white part plus chi-square excess.

    ``extra``: unknowns per channel fitted beside z (their part already out of ``targets``).
    """
    n, k_rows = stacked.regressors.shape[:2]
    gram = np.ascontiguousarray(stacked.gram[..., :k_rows, :k_rows])  # reshaped per channel
    floor = 1e-24 * np.maximum(np.mean(stacked.targets.reshape(-1, 6) ** 2, axis=0), 1e-300)
    noise = np.zeros((n, 6))
    for i in range(6):
        q_inv = pose_covariance(gram, stacked.sigma,
                                pose_coefficients(stacked.sensitivity[:, i],
                                                  z[12 * i:12 * i + 12]))
        residual = targets[i][:, :k_rows] - designs[i][:, :k_rows] @ z
        excess = excess_variance(stacked.white[:, i, None, None] * np.eye(k_rows) + q_inv,
                                 residual, residual.size - 12 - extra)
        noise[:, i] = np.maximum(stacked.white[:, i] + excess, floor[i])
    return noise


__all__ = ["chi2_excess", "compensate", "excess_variance", "noise_bias", "pose_coefficients",
           "pose_covariance", "row_noise"]
