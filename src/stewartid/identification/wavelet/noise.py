"""Measurement noise estimated from the data (pose, forces) and the noise it puts on the joint rates."""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from stewartid.arrays import median
from stewartid.identification.preparation import Experiment
from stewartid.signals.differentiation import (
    DEFAULT_ORDER,
    differentiate,
    savgol_coefficients,
    window_samples,
)
from stewartid.signals.sign_rates import coulomb_sign_rates


def white_noise_covariance(q: np.ndarray, smooth: np.ndarray | None = None) -> np.ndarray:
    """Covariance Sigma (m, m) per sample of white noise on ``q`` (N, m), from second differences (6 Sigma).

    ``smooth``: a low-pass copy of ``q`` subtracted first.
    """
    r = q if smooth is None else q - smooth
    d2 = r[2:] - 2.0 * r[1:-1] + r[:-2]
    d2 = d2 - median(d2, axis=0)
    return d2.T @ d2 / (6.0 * max(len(d2), 1))


def mean_rate_jacobian(joint_jacobians: np.ndarray, leg_jacobian: np.ndarray) -> np.ndarray:
    """Rows (36, 6) of the joint-axis Jacobians (N, 6, 5, 6) then J_lq (N, 6, 6), averaged over
    the samples."""
    return np.concatenate([joint_jacobians.mean(axis=0).reshape(30, 6),
                           leg_jacobian.mean(axis=0)], axis=0)


def joint_rate_noise(covariance: np.ndarray, sample_rate: float, window: float,
                     joint_jacobians: np.ndarray, leg_jacobian: np.ndarray,
                     order: int = DEFAULT_ORDER, mean_jacobian: np.ndarray | None = None
                     ) -> np.ndarray:
    """Standard deviation (36,) of each Savitzky-Golay joint rate from pose noise, |c| sqrt(diag(J S J^T)).

    ``mean_jacobian``: :func:`mean_rate_jacobian` of the Jacobians, when already computed.
    """
    n = window_samples(window, sample_rate, order)
    gain = np.linalg.norm(savgol_coefficients(n, order, 1, 1.0 / sample_rate))
    jac = (mean_rate_jacobian(joint_jacobians, leg_jacobian) if mean_jacobian is None
           else mean_jacobian)
    variance = np.einsum("ij,jk,ik->i", jac, covariance, jac)
    return gain * np.sqrt(np.clip(variance, 0.0, None))


class NoiseModel(NamedTuple):
    """The smoothed motion of one experiment and the measurement noise around it.

    Attributes
    ----------
    window : float
        Savitzky-Golay window, s.
    q_dot, q_ddot : ndarray, shape (N, 6)
    pose_covariance : ndarray, shape (6, 6)
        White pose noise per sample, m^2, m rad, rad^2.
    force_variance : ndarray, shape (6,)
        White generalized-force noise per sample, N^2, N^2 m^2.
    rate_noise : ndarray, shape (36,)
        Pose noise on each joint rate.
    mean_jacobian : ndarray, shape (36, 6), optional
        :func:`mean_rate_jacobian` of the experiment, for the noise of other rates.
    """

    window: float
    q_dot: np.ndarray
    q_ddot: np.ndarray
    pose_covariance: np.ndarray
    force_variance: np.ndarray
    rate_noise: np.ndarray
    mean_jacobian: np.ndarray | None = None


def estimate_noise(experiment: Experiment, window: float) -> NoiseModel:
    """The noise model of one prepared experiment (with its joint-axis Jacobians)."""
    q, rate = experiment.q, 1.0 / experiment.period
    q_smooth, q_dot, q_ddot = differentiate(q, rate, window)
    covariance = white_noise_covariance(q, q_smooth)
    y = experiment.generalized_force
    force_variance = np.diag(white_noise_covariance(
        y, differentiate(y, rate, window, derivatives=(0,))[0]))
    mean_jacobian = mean_rate_jacobian(experiment.joint_jacobians, experiment.leg_jacobian)
    rate_noise = joint_rate_noise(covariance, rate, window, experiment.joint_jacobians,
                                  experiment.leg_jacobian, mean_jacobian=mean_jacobian)
    return NoiseModel(window=window, q_dot=q_dot, q_ddot=q_ddot, pose_covariance=covariance,
                      force_variance=force_variance, rate_noise=rate_noise,
                      mean_jacobian=mean_jacobian)


def measured_sign_rates(q: np.ndarray, sample_rate: float, window: float) -> np.ndarray:
    """Coulomb sign rates (N, 6) of a record with unknown pose noise, estimated against the pose
    smoothed as the regressor is (:func:`~stewartid.signals.sign_rates.coulomb_sign_rates`).
    """
    return coulomb_sign_rates(q, sample_rate, window, sign_pose_noise(q, sample_rate, window))[0]


def sign_pose_noise(q: np.ndarray, sample_rate: float, window: float) -> np.ndarray:
    """Covariance (6, 6) of the white pose noise of ``q`` (N, 6), against the pose smoothed as the
    regressor is (a window of ``window`` / 8, s)."""
    smooth = differentiate(q, sample_rate, window / 8, 5, (0,))[0]
    return white_noise_covariance(q, smooth)


__all__ = ["NoiseModel", "estimate_noise", "joint_rate_noise", "mean_rate_jacobian",
           "measured_sign_rates", "sign_pose_noise", "white_noise_covariance"]
