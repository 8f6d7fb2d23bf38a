"""Measurement noise estimated from the data (pose, forces) and the noise it puts on the joint
rates: the noise-model step of Method B.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from stewartid.identification.preparation import Experiment
from stewartid.signals.differentiation import (
    DEFAULT_ORDER,
    differentiate,
    savgol_coefficients,
    window_samples,
)


def white_noise_covariance(q: np.ndarray, smooth: np.ndarray | None = None) -> np.ndarray:
    """Covariance of white measurement noise on a smooth signal, from second differences.

    The second differences of q minus a smoothed copy are the noise's, of covariance 6 Sigma
    for white noise; noise-free data give a covariance near zero.

    Parameters
    ----------
    q : ndarray, shape (N, m)
        Measured signals, e.g. poses (m, rad) or generalized forces (N, N m).
    smooth : ndarray, shape (N, m), optional
        A low-pass smoothed copy of ``q``; None: raw second differences.

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
                     joint_jacobians: np.ndarray, leg_jacobian: np.ndarray,
                     order: int = DEFAULT_ORDER) -> np.ndarray:
    """Standard deviation of each Savitzky-Golay joint rate caused by pose noise.

    |c| sqrt(diag(J Sigma J^T)), with c the velocity filter's coefficients and J the Jacobians
    averaged over the record.

    Parameters
    ----------
    covariance : ndarray, shape (6, 6)
        Pose noise per sample (:func:`white_noise_covariance`).
    sample_rate, window : float
        Hz and the differentiation window (s).
    joint_jacobians : ndarray, shape (N, 6, 5, 6)
    leg_jacobian : ndarray, shape (N, 6, 6)
    order : int
        Savitzky-Golay order of the rates.

    Returns
    -------
    ndarray, shape (36,)
        Columns as :data:`~stewartid.identification.wavelet.intervals.JOINT_RATE_NAMES`.
    """
    n = window_samples(window, sample_rate, order)
    gain = np.linalg.norm(savgol_coefficients(n, order, 1, 1.0 / sample_rate))
    jac = np.concatenate([joint_jacobians.mean(axis=0).reshape(30, 6),
                          leg_jacobian.mean(axis=0)], axis=0)
    variance = np.einsum("ij,jk,ik->i", jac, covariance, jac)
    return gain * np.sqrt(np.clip(variance, 0.0, None))


class NoiseModel(NamedTuple):
    """The smoothed motion of one experiment and the measurement noise around it.

    Attributes
    ----------
    window : float
        Savitzky-Golay window (s).
    q_dot, q_ddot : ndarray, shape (N, 6)
        Savitzky-Golay derivatives of the pose (m/s, rad/s; m/s^2, rad/s^2).
    pose_covariance : ndarray, shape (6, 6)
        White pose noise per sample (m^2, m rad, rad^2), :func:`white_noise_covariance`.
    force_variance : ndarray, shape (6,)
        White noise variance per sample of the generalized force (N^2, N^2 m^2).
    rate_noise : ndarray, shape (36,)
        Standard deviation the pose noise causes on each joint rate (:func:`joint_rate_noise`;
        columns as :data:`~stewartid.identification.wavelet.intervals.JOINT_RATE_NAMES`).
    """

    window: float
    q_dot: np.ndarray
    q_ddot: np.ndarray
    pose_covariance: np.ndarray
    force_variance: np.ndarray
    rate_noise: np.ndarray


def estimate_noise(experiment: Experiment, window: float) -> NoiseModel:
    """The noise model of one prepared experiment.

    Parameters
    ----------
    experiment : Experiment
        Prepared with its joint-axis Jacobians
        (:func:`~stewartid.identification.preparation.prepare_experiment`).
    window : float
        Savitzky-Golay window (s).

    Returns
    -------
    NoiseModel
    """
    q, rate = experiment.q, 1.0 / experiment.period
    q_smooth, q_dot, q_ddot = differentiate(q, rate, window)
    covariance = white_noise_covariance(q, q_smooth)
    y = experiment.generalized_force
    force_variance = np.diag(white_noise_covariance(y, differentiate(y, rate, window)[0]))
    rate_noise = joint_rate_noise(covariance, rate, window, experiment.joint_jacobians,
                                  experiment.leg_jacobian)
    return NoiseModel(window=window, q_dot=q_dot, q_ddot=q_ddot, pose_covariance=covariance,
                      force_variance=force_variance, rate_noise=rate_noise)


__all__ = ["NoiseModel", "estimate_noise", "joint_rate_noise", "white_noise_covariance"]
