"""Error bounds shared by the numerical tests: machine epsilon and the pose error that a
forward kinematics stopped at a leg-length residual leaves, on any CPU."""

from __future__ import annotations

import numpy as np

from stewartid.model.kinematics import leg_jacobian, leg_lengths

#: Unit round-off of float64 (2.2e-16).
EPS = float(np.finfo(float).eps)


def newton_pose_bound(platform, poses: np.ndarray, tolerance: float = 1e-12) -> float:
    """Largest pose error (m, rad) of a Newton forward kinematics stopped at a residual.

    The iteration stops once every leg length is within ``tolerance`` (m) of its target, a
    residual evaluated with a round-off of a few eps times the leg length; to first order the
    pose error is ``J^-1`` times that residual.

    Parameters
    ----------
    platform : Platform
    poses : ndarray, shape (N, 6) or (6,)
        Poses (m, rad) at which the forward kinematics converged.
    tolerance : float
        The iteration's stopping residual (m); ``forward_kinematics`` stops at 1e-12.

    Returns
    -------
    float
        ``max_N ||J_lq^-1||_inf * (tolerance + 8 eps max l)``.
    """
    poses = np.atleast_2d(poses)
    inverse_norm = np.abs(np.linalg.inv(leg_jacobian(platform, poses))).sum(axis=2).max()
    return float(inverse_norm * (tolerance + 8 * EPS * leg_lengths(platform, poses).max()))


def convolution_bound(kernel: np.ndarray, x_max: float) -> float:
    """Largest difference between two float64 evaluations of one convolution, a direct sum
    and :func:`~stewartid.signals.differentiation.convolve_valid`'s overlap-save FFT, of a
    signal bounded by ``x_max``: each within (L + log2(nfft)) eps sum|kernel| x_max (L taps,
    nfft that function's transform length), on any CPU."""
    length = len(kernel)
    nfft = max(1024, 1 << int(np.ceil(np.log2(8 * length))))
    return float(2 * (length + np.log2(nfft)) * EPS * np.abs(kernel).sum() * x_max)
