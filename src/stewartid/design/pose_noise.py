"""Pose noise's share of the physical model's predicted covariance: white pose noise reaches the
scores as sum_i G_i e_i through the differentiated rates, adding sum_i G_i Sigma_q G_i^T to the
sandwich's B (Coulomb signs left out).
"""

from __future__ import annotations

import numpy as np
import scipy.signal

from stewartid.model import matrix_regressors
from stewartid.model import regressor as reg
from stewartid.model.kinematics import leg_jacobian
from stewartid.platform import Platform
from stewartid.simulation.sensors import SensorNoise

#: Relative step of the rates in the central differences of the rigid-body forces (the
#: velocity products are quadratic: exact up to round-off).
RATE_STEP = 1e-3


def pose_covariance(noise: SensorNoise, jacobian: np.ndarray) -> np.ndarray:
    """Sigma_q = J_lq^-1 Sigma_l J_lq^-T (K, 6, 6), m^2, rad^2, from ``length_noise`` and J_lq (K, 6, 6)."""
    sigma = np.broadcast_to(np.asarray(noise.length_noise, dtype=float), 6)
    inverse = np.linalg.inv(jacobian)
    return np.einsum("kij,j,klj->kil", inverse, sigma ** 2, inverse, optimize=True)


def rate_sensitivity(platform: Platform, q: np.ndarray, q_dot: np.ndarray,
                     q_ddot: np.ndarray, theta: np.ndarray) -> np.ndarray:
    """d(Y theta)/d q_dot (K, 6, 6) along a motion (Coulomb signs left out)."""
    out = matrix_regressors.viscous_regressor(platform, q) @ theta
    step = RATE_STEP * max(float(np.max(np.abs(q_dot))), 1e-12)
    for c in range(6):
        shift = np.zeros(6)
        shift[c] = step
        ahead, behind = (reg.regressor_columns(platform, q.T, (q_dot + s).T, q_ddot.T,
                                               gravity=False, friction=False)
                         for s in (shift, -shift))
        out[:, :, c] += np.einsum("ipk,p->ki", ahead - behind, theta) / (2 * step)
    return out


def pose_noise_scores(platform: Platform, noise: SensorNoise, rate_hz: float,
                      states: tuple[np.ndarray, np.ndarray, np.ndarray], ends: np.ndarray,
                      taps: list[np.ndarray], rows: np.ndarray, transforms: np.ndarray,
                      weights: np.ndarray, theta: np.ndarray) -> np.ndarray:
    """Pose noise's share (p, p) of B, in the units of
    :func:`~stewartid.design.physical.information.sandwich_covariance`.

    Parameters
    ----------
    platform : Platform
    noise : SensorNoise
    rate_hz : float
    states : tuple of ndarray, each shape (K, 6)
        q, q_dot, q_ddot, records in sequence.
    ends : ndarray, shape (R + 1,)
        Each record's first row, then K.
    taps : list of ndarray
        Each record's kernel at ``rate_hz``.
    rows : ndarray, shape (K', 6, p)
        Filtered rows in leg forces.
    transforms : ndarray, shape (K', 6, 6)
        J_lq^-T at those rows.
    weights : ndarray, shape (6,)
    theta : ndarray, shape (N_STANDARD,)
    """
    p = rows.shape[2]
    B = np.zeros((p, p))
    if not np.any(np.asarray(noise.length_noise, dtype=float) > 0):
        return B
    dt, start = 1.0 / rate_hz, 0
    for (a, b), h in zip(zip(ends[:-1], ends[1:], strict=True), taps, strict=True):
        q, q_dot, q_ddot = (x[a:b] for x in states)
        filtered = b - a - len(h) + 1
        part = slice(start, start + filtered)
        start += filtered
        Z = np.einsum("kip,i,kij->kpj", rows[part], weights, transforms[part], optimize=True)
        U = scipy.signal.convolve(Z, h[:, None, None], mode="full")  # (b - a, p, 6)
        P = np.einsum("kpi,kic->kpc", U,
                      matrix_regressors.inertia_regressor(platform, q) @ theta, optimize=True)
        Q = np.einsum("kpi,kic->kpc", U, rate_sensitivity(platform, q, q_dot, q_ddot, theta),
                      optimize=True)
        G = np.gradient(np.gradient(P, dt, axis=0), dt, axis=0) - np.gradient(Q, dt, axis=0)
        B += np.einsum("kpc,kcd,kqd->pq", G, pose_covariance(noise, leg_jacobian(platform, q)),
                       G, optimize=True)
    return B


__all__ = ["RATE_STEP", "pose_covariance", "pose_noise_scores", "rate_sensitivity"]
