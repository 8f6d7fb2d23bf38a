"""Measurement noise estimated from the data, and how it propagates into the wavelet
equations of Method B.

- :func:`white_noise_covariance`: covariance of white noise per sample (pose, forces);
- :func:`joint_rate_noise`: the noise it causes on the Savitzky-Golay joint rates (for the
  hysteresis thresholds of the interval detection);
- :func:`generalized_force_sensitivity`: how pose noise enters the generalized force (for
  the errors-in-variables correction).
"""

from __future__ import annotations

import numpy as np

from stewartid.platform import Platform
from stewartid.signals.differentiation import (
    DEFAULT_ORDER,
    savgol_coefficients,
    window_samples,
)


def white_noise_covariance(q: np.ndarray, smooth: np.ndarray | None = None) -> np.ndarray:
    """Covariance of white measurement noise on a smooth signal, from second differences.

    For a smooth signal, q[n+1] - 2 q[n] + q[n-1] is the noise e[n+1] - 2 e[n] + e[n-1]
    (covariance 6 Sigma for white noise) plus q_ddot dt^2. The latter is removed by taking
    the differences of q minus a smoothed copy (a low-pass smoother leaves the noise's second
    differences almost untouched), so noise-free data give a covariance near zero. The pose
    of a hexapod is the forward kinematics of the measured leg lengths, so its noise is
    correlated across the six coordinates; the full covariance is returned.

    Parameters
    ----------
    q : ndarray, shape (N, m)
        Measured signals, e.g. poses (m, rad) or generalized forces (N, N m).
    smooth : ndarray, shape (N, m), optional
        A low-pass smoothed copy of ``q`` (e.g. the Savitzky-Golay output); None: raw
        second differences.

    Returns
    -------
    ndarray, shape (m, m)
        Sigma per sample (units of q squared).
    """
    r = q if smooth is None else q - smooth
    d2 = r[2:] - 2.0 * r[1:-1] + r[:-2]
    d2 = d2 - np.median(d2, axis=0)
    return d2.T @ d2 / (6.0 * max(len(d2), 1))


def joint_rate_noise(covariance: np.ndarray, sample_rate: float, window: float,
                     joint_jacobians: np.ndarray, leg_jacobian: np.ndarray) -> np.ndarray:
    """Standard deviation of each Savitzky-Golay joint rate caused by pose noise.

    The velocity filter is a linear combination of samples with coefficients c, so white
    pose noise of covariance Sigma gives q_dot noise of covariance |c|^2 Sigma, and the joint
    rates J q_dot the standard deviations |c| sqrt(diag(J Sigma J^T)) (Jacobians averaged over
    the record; the motion is small).

    Parameters
    ----------
    covariance : ndarray, shape (6, 6)
        Pose noise per sample (:func:`white_noise_covariance`).
    sample_rate, window : float
        Hz and the differentiation window (s).
    joint_jacobians : ndarray, shape (N, 6, 5, 6)
    leg_jacobian : ndarray, shape (N, 6, 6)

    Returns
    -------
    ndarray, shape (36,)
        Columns as :data:`~stewartid.identification.wavelet.intervals.JOINT_RATE_NAMES`.
    """
    n = window_samples(window, sample_rate, DEFAULT_ORDER)
    gain = np.linalg.norm(savgol_coefficients(n, DEFAULT_ORDER, 1, 1.0 / sample_rate))
    jac = np.concatenate([joint_jacobians.mean(axis=0).reshape(30, 6),
                          leg_jacobian.mean(axis=0)], axis=0)
    variance = np.einsum("ij,jk,ik->i", jac, covariance, jac)
    return gain * np.sqrt(np.clip(variance, 0.0, None))


def generalized_force_sensitivity(platform: Platform, q: np.ndarray, forces: np.ndarray,
                                  gravity: bool = True, step: float = 1e-6) -> np.ndarray:
    """K = d(J_lq(q)^T f - G(q)) / dq at the mean pose and mean leg forces, shape (6, 6).

    Pose noise enters the generalized force through the Jacobian (the static leg load times
    the change of the leg directions) and through G(q); K maps it there, so the
    errors-in-variables correction can account for noise shared by regressors and targets.
    Central differences of ``step`` (m, rad).
    """
    from stewartid.model.kinematics import compute_leg_terms

    q0, f0 = q.mean(axis=0), forces.mean(axis=0)
    poses = np.repeat(q0[None], 12, axis=0)
    for j in range(6):
        poses[2 * j, j] += step
        poses[2 * j + 1, j] -= step
    # the numpy pose-only terms: equal to the compiled model terms, without numba's start
    terms = compute_leg_terms(platform, poses)
    y = np.einsum("nji,j->ni", terms.leg_jacobian, f0)
    if gravity:
        y = y - terms.gravity
    return ((y[0::2] - y[1::2]) / (2 * step)).T


__all__ = ["generalized_force_sensitivity", "joint_rate_noise", "white_noise_covariance"]
