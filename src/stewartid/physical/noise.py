"""Errors in variables for the physical model: the share of the normal equations that pose noise,
through the Savitzky-Golay rates and accelerations, adds (subtracted for an unbiased fit).
"""

from __future__ import annotations

import numpy as np

from stewartid.identification.preparation import Experiment
from stewartid.model import matrix_regressors
from stewartid.model import regressor as reg
from stewartid.platform import Platform
from stewartid.signals.differentiation import (
    kernel_taps,
    savgol_coefficients,
    window_samples,
)
from stewartid.signals.filtered_rows import kernel_filter_rows


def derivative_noise_gains(sample_rate: float, window: float, savgol_window: float,
                           order: int) -> tuple[float, float]:
    """Variance of h * g1 * e and h * g2 * e per unit white variance (1/s^2, 1/s^4): kernel
    (``window`` s) convolved with Savitzky-Golay taps (``savgol_window`` s, ``order``).
    """
    h = kernel_taps(sample_rate, window)[0]
    n = window_samples(savgol_window, sample_rate, order)
    return tuple(float(np.sum(np.convolve(h, savgol_coefficients(n, order, d, 1 / sample_rate))
                              ** 2)) for d in (1, 2))


#: Kept rows per evaluation of the noise's Jacobians in :func:`regressor_noise`.
JACOBIAN_STRIDE = 5


def _factor(covariance: np.ndarray) -> np.ndarray:
    """L with L L^T = covariance (positive semidefinite)."""
    values, vectors = np.linalg.eigh(covariance)
    return vectors * np.sqrt(np.clip(values, 0.0, None))


def regressor_noise(experiments: list[Experiment], windows: list[float], row_step: int,
                    platform: Platform, savgol_fraction: float, order: int,
                    pose_noise: list[np.ndarray],
                    transforms: list[np.ndarray] | None = None, by_experiment: bool = False
                    ) -> np.ndarray:
    """Per channel, the sum over the kept rows of E[delta Y_i^T delta Y_i],

        delta Y ~ sum_c A_c(q) (h * g2 * e_c) + sum_c B_c(q) (h * g1 * e_c),  A = dY/dq_ddot, B = dY/dq_dot.

    Parameters
    ----------
    experiments : list of Experiment
    windows : list of float
        Kernel support per experiment (s).
    row_step : int
    platform : Platform
    savgol_fraction : float
        Savitzky-Golay window = ``window / savgol_fraction``.
    order : int
    pose_noise : list of ndarray, each shape (6, 6)
        :attr:`~stewartid.physical.regression.Regression.pose_noise`.
    transforms : list of ndarray, each shape (K_e, 6, 6), optional
        Map of each kept row's channels
        (:func:`~stewartid.physical.regression.leg_force_transforms`).
    by_experiment : bool
        Per-experiment sums instead of the total.

    Returns
    -------
    ndarray, shape (6, N_STANDARD, N_STANDARD), or (E, 6, N_STANDARD, N_STANDARD)
    """
    terms = np.zeros((len(experiments), 6, reg.N_STANDARD, reg.N_STANDARD))
    if transforms is None:
        transforms = [None] * len(experiments)
    for out, exp, window, sigma, transform in zip(terms, experiments, windows, pose_noise,
                                                  transforms, strict=True):
        rate = exp.sample_rate
        gains = derivative_noise_gains(rate, window, window / savgol_fraction, order)
        poses = kernel_filter_rows(exp.q, rate, window, row_step)
        # the Jacobians vary on the kernel's scale: every JACOBIAN_STRIDE-th row stands for
        # its neighbours
        rows, poses = len(poses), poses[::JACOBIAN_STRIDE]
        for jacobian, gain in ((matrix_regressors.viscous_regressor(platform, poses), gains[0]),
                               (matrix_regressors.inertia_regressor(platform, poses), gains[1])):
            if transform is not None:
                jacobian = np.einsum("kji,kicp->kjcp", transform[::JACOBIAN_STRIDE], jacobian,
                                     optimize=True)
            # jacobian[k, i, c, :]: d Y_i / d (rate or acceleration of c) at row k; only
            # columns not zero at every row add anything
            used = np.flatnonzero(np.any(jacobian != 0.0, axis=(0, 1, 2)))
            block = np.ix_(used, used)
            factor = np.swapaxes(_factor(sigma * gain), 0, 1)
            for i in range(6):  # (K d, p) per channel: one BLAS product each
                flat = (factor @ jacobian[:, i][..., used]).reshape(-1, len(used))
                out[i][block] += (flat.T @ flat) * (rows / len(poses))
    return terms if by_experiment else terms.sum(axis=0)


__all__ = ["JACOBIAN_STRIDE", "derivative_noise_gains", "regressor_noise"]
