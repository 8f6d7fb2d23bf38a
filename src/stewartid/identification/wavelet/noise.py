"""Measurement noise estimated from the data, and how it propagates into the wavelet
equations of Method B.

- :func:`white_noise_covariance`: covariance of white noise per sample (pose, forces);
- :func:`joint_rate_noise`: the noise it causes on the Savitzky-Golay joint rates (for the
  hysteresis thresholds of the interval detection);
- :func:`estimate_noise`: both, for one prepared experiment (the noise-model step of
  Method B).

How pose noise enters the generalized force, for the errors-in-variables correction, is a
model term: :func:`~stewartid.identification.preparation.generalized_force_sensitivity`.
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
                     joint_jacobians: np.ndarray, leg_jacobian: np.ndarray,
                     order: int = DEFAULT_ORDER) -> np.ndarray:
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
    """The noise model of one prepared experiment: pose and generalized force smoothed with
    a Savitzky-Golay window, the white noise each holds around its smoothed copy, and what
    the pose noise puts on the joint rates (from the Jacobians the experiment holds).

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
