"""Harmonic coefficients over whole periods; the Coulomb bias the force's third harmonic shows.

A Coulomb square wave's first harmonic lands in Method A's Bt, its third in no linear term.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from stewartid.identification.quantiles import chi2_upper_quantile
from stewartid.signals.differentiation import savgol_gain


def harmonic_coefficients(x: np.ndarray, t: np.ndarray, frequencies_hz: Sequence[float]
                          ) -> np.ndarray:
    """(cos f1, sin f1, cos f2, ...) coefficients (2 F, m) of x(t) = c0 + sum_f [x_c cos + x_s sin].

    Least squares on ``x`` (N, m) at times ``t`` (N,), s; over whole periods, the Fourier coefficients.
    """
    columns = [np.ones_like(t)]
    for f in frequencies_hz:
        columns += [np.cos(2 * np.pi * f * t), np.sin(2 * np.pi * f * t)]
    design = np.column_stack(columns)
    # normal equations: the columns are nearly orthogonal over whole periods
    coefficients = np.linalg.solve(design.T @ design, design.T @ x)
    return coefficients[1:]


def motion_gains(frequencies_hz: Sequence[float], sample_rate: float, window: float,
                 order: int) -> np.ndarray:
    """Savitzky-Golay gain (2 F, 18) of q_ddot, q_dot, q, rows as :func:`harmonic_coefficients`."""
    gains = np.ones((2 * len(frequencies_hz), 18))
    for k, f in enumerate(frequencies_hz):
        for d, columns in ((2, slice(0, 6)), (1, slice(6, 12)), (0, slice(12, 18))):
            gains[2 * k:2 * k + 2, columns] = savgol_gain(f, sample_rate, window, order, d)
    return gains


def third_harmonic_blocks(signals: np.ndarray, t: np.ndarray, slices: Sequence[slice],
                          frequency_hz: float, sample_rate: float, window: float, order: int
                          ) -> np.ndarray:
    """(cos, sin) coefficients at 3 f per whole-period block; (blocks, 2, 24).

    ``signals`` (N, 24): q_ddot, q_dot, q - q0 and the generalized force; the motion's corrected for
    the differentiator's gain at 3 f.
    """
    gains = np.concatenate([motion_gains([3 * frequency_hz], sample_rate, window, order),
                            np.ones((2, 6))], axis=1)
    return np.array([harmonic_coefficients(signals[sl], t[sl], [3 * frequency_hz]) / gains
                     for sl in slices])


#: The first harmonic of a square wave over its third: the friction force at the excitation
#: frequency that a third harmonic of the force implies.
SQUARE_WAVE_RATIO = 3.0


def friction_bias_bound(pinv: np.ndarray, rows: Sequence[np.ndarray],
                        third: Sequence[np.ndarray]) -> np.ndarray:
    """Bias bound (6, p) on the first-harmonic estimates implied by the force's third harmonic.

    A square wave's first harmonic is :data:`SQUARE_WAVE_RATIO` times its third, of unknown phase;
    propagated through ``pinv`` and summed in quadrature over experiments. ``rows``: per experiment,
    each block's (cos, sin) equation rows; ``third``: per experiment, amplitudes (6,), N, N m.
    """
    bound = np.zeros((len(third[0]) if len(third) else 6, pinv.shape[0]))
    for experiment_rows, amplitude in zip(rows, third, strict=True):
        gain = np.hypot(pinv[:, experiment_rows[:, 0]].sum(axis=1),
                        pinv[:, experiment_rows[:, 1]].sum(axis=1))
        bound += (SQUARE_WAVE_RATIO * np.outer(amplitude, gain)) ** 2
    return np.sqrt(bound)


#: Significance level of the test for friction in the third harmonic that the linear model
#: leaves (so that the noise's own third harmonic is not read as friction).
THIRD_HARMONIC_LEVEL = 0.01


def third_harmonic(coefficients: Sequence[np.ndarray | None], noise_covariance: np.ndarray
                   ) -> tuple[list[np.ndarray], float, float]:
    """Third-harmonic amplitude per experiment and force channel that the data show as friction.

    The summed Mahalanobis norm of the residual coefficients at 3 f is chi-squared (12 dof per
    experiment) without friction; above its :data:`THIRD_HARMONIC_LEVEL` point every amplitude is
    kept, below all are zero. Returns (amplitudes (6,) per experiment, statistic, threshold).
    """
    precision = np.linalg.pinv(noise_covariance)
    # the channels' noise-free directions: a third harmonic there is shown by any amount
    noiseless = np.eye(len(noise_covariance)) - noise_covariance @ precision
    rank = int(np.linalg.matrix_rank(noise_covariance))
    amplitudes, statistic, dof = [], 0.0, 0
    for blocks in coefficients:
        if blocks is None:
            amplitudes.append(np.zeros(6))
            continue
        mean = blocks.mean(axis=0)
        if np.linalg.norm(mean @ noiseless.T) > 1e-9 * np.linalg.norm(mean):
            statistic = np.inf
        statistic += len(blocks) * float(np.einsum("ki,ij,kj->", mean, precision, mean))
        dof += 2 * rank
        amplitudes.append(np.hypot(mean[0], mean[1]))
    threshold = chi2_upper_quantile(dof, THIRD_HARMONIC_LEVEL) if dof else np.inf
    if not statistic > threshold:
        amplitudes = [np.zeros_like(a) for a in amplitudes]
    return amplitudes, statistic, threshold


def residual_third_harmonic(blocks: np.ndarray, theta: np.ndarray) -> np.ndarray:
    """Third-harmonic coefficients (blocks, 2, 6) of the force the fitted ``theta`` (6, p) leaves."""
    return blocks[..., 18:] - blocks[..., :theta.shape[1]] @ theta.T


__all__ = ["SQUARE_WAVE_RATIO", "THIRD_HARMONIC_LEVEL", "friction_bias_bound",
           "harmonic_coefficients", "motion_gains", "residual_third_harmonic", "third_harmonic",
           "third_harmonic_blocks"]
