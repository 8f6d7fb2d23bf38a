"""Harmonic coefficients over whole periods, and the Coulomb bias the force's third harmonic shows.

A Coulomb force switching with a sine's velocity is a square wave: its first harmonic lands
in Method A's Bt, its third is left unexplained by any linear term.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from scipy.special import chdtri

from stewartid.signals.differentiation import savgol_gain


def harmonic_coefficients(x: np.ndarray, t: np.ndarray, frequencies_hz: Sequence[float]
                          ) -> np.ndarray:
    """In-phase and quadrature coefficients of ``x`` at ``frequencies_hz`` over a segment.

    Least-squares fit of x(t) = c0 + sum_f [x_c cos(2 pi f t) + x_s sin(2 pi f t)]; over whole
    periods of one frequency these are the Fourier coefficients.

    Parameters
    ----------
    x : ndarray, shape (N, m)
    t : ndarray, shape (N,)
        Time (s).
    frequencies_hz : sequence of float

    Returns
    -------
    ndarray, shape (2 * F, m)
        Rows (cos f1, sin f1, cos f2, sin f2, ...).
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
    """Savitzky-Golay gain of q_ddot, q_dot and q at each frequency.

    The filter has zero phase, so dividing the harmonic coefficients by it removes its
    amplitude bias exactly.

    Returns
    -------
    ndarray, shape (2 * F, 18)
        Rows (cos f1, sin f1, ...) as :func:`harmonic_coefficients`; columns q_ddot, q_dot, q.
    """
    gains = np.ones((2 * len(frequencies_hz), 18))
    for k, f in enumerate(frequencies_hz):
        for d, columns in ((2, slice(0, 6)), (1, slice(6, 12)), (0, slice(12, 18))):
            gains[2 * k:2 * k + 2, columns] = savgol_gain(f, sample_rate, window, order, d)
    return gains


def third_harmonic_blocks(signals: np.ndarray, t: np.ndarray, slices: Sequence[slice],
                          frequency_hz: float, sample_rate: float, window: float, order: int
                          ) -> np.ndarray:
    """(cos, sin) coefficients at 3 f of the motion and the generalized force, per block.

    The motion's coefficients are corrected for the differentiator's gain at 3 f.

    Parameters
    ----------
    signals : ndarray, shape (N, 24)
        q_ddot, q_dot, q - q0 and the generalized force side by side.
    t : ndarray, shape (N,)
        Time (s).
    slices : sequence of slice
        The whole-period blocks.
    frequency_hz, sample_rate, window, order
        The excitation frequency f and the Savitzky-Golay differentiation's settings.

    Returns
    -------
    ndarray, shape (blocks, 2, 24)
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
    """Bias of the first-harmonic estimates that the force's third harmonic implies.

    A square wave's first harmonic is :data:`SQUARE_WAVE_RATIO` times its third, of unknown
    phase; it is propagated through the least-squares solution and summed in quadrature over
    experiments.

    Parameters
    ----------
    pinv : ndarray, shape (p, n_equations)
        Pseudo-inverse of the first-harmonic regressor.
    rows : sequence of ndarray of int
        Per experiment, the (cos, sin) equation rows of each of its blocks, shape (blocks, 2).
    third : sequence of ndarray, shape (6,)
        Per experiment, the third-harmonic amplitude of each force channel (N, N m).

    Returns
    -------
    ndarray, shape (6, p)
        Bias bound of every parameter of every channel's equation.
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

    The mean residual coefficients at 3 f are tested as a whole: the sum over experiments of
    their Mahalanobis norm is chi-squared with 12 degrees of freedom per experiment without
    friction. Above the point of :data:`THIRD_HARMONIC_LEVEL` every channel keeps its
    amplitude; below it all are zero.

    Parameters
    ----------
    coefficients : sequence of (ndarray, shape (blocks, 2, 6)) or None
        Per experiment, the (cos, sin) coefficients at 3 f of each channel's residual force,
        per block (N, N m); None for an experiment of several frequencies (not tested).
    noise_covariance : ndarray, shape (6, 6)
        Covariance of one block's harmonic coefficient across the channels.

    Returns
    -------
    amplitude : list of ndarray, shape (6,)
        Per experiment, the third-harmonic amplitude read as friction (N, N m).
    statistic : float
        The chi-squared statistic.
    threshold : float
        Its point at :data:`THIRD_HARMONIC_LEVEL`.
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
    threshold = float(chdtri(dof, THIRD_HARMONIC_LEVEL)) if dof else np.inf
    if not statistic > threshold:
        amplitudes = [np.zeros_like(a) for a in amplitudes]
    return amplitudes, statistic, threshold


def residual_third_harmonic(blocks: np.ndarray, theta: np.ndarray) -> np.ndarray:
    """Third-harmonic coefficients of the force that the fitted linear model leaves.

    Parameters
    ----------
    blocks : ndarray, shape (blocks, 2, 24)
        As :func:`third_harmonic_blocks` returns.
    theta : ndarray, shape (6, p)
        Fitted parameters: Mt, Bt (and K) side by side, p = 12 or 18.

    Returns
    -------
    ndarray, shape (blocks, 2, 6)
    """
    return blocks[..., 18:] - blocks[..., :theta.shape[1]] @ theta.T


__all__ = ["SQUARE_WAVE_RATIO", "THIRD_HARMONIC_LEVEL", "friction_bias_bound",
           "harmonic_coefficients", "motion_gains", "residual_third_harmonic", "third_harmonic",
           "third_harmonic_blocks"]
