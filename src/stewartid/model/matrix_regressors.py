"""Mt(q) and Bt(q) as linear functions of the standard parameters: the mass matrix and the
matrix of every term linear in the rates, from the regressor
(:func:`~stewartid.model.regressor.regressor`) at rest."""

from __future__ import annotations

import numpy as np

from stewartid.model.kinematics import as_batch
from stewartid.model.regressor import N_STANDARD, VISCOUS_PARAMETERS, parameter_index, regressor
from stewartid.platform import Platform


def inertia_regressor(platform: Platform, pose: np.ndarray | None = None) -> np.ndarray:
    """The mass matrix as a linear function of the parameters: M(q) = A @ pi.

    Column k of M is Y(q, 0, e_k) pi - Y(q, 0, 0) pi (the gravity and offset columns do not
    depend on the acceleration; friction and velocity products vanish at rest).

    Parameters
    ----------
    platform : Platform
    pose : ndarray, shape (6,) or (N, 6), optional
        Pose(s) (m, rad); the neutral pose by default.

    Returns
    -------
    ndarray, shape (6, 6, N_STANDARD) or (N, 6, 6, N_STANDARD)
        A[i, k] is the row of M[i, k] in the standard parameters.
    """
    q, single = as_batch(platform.neutral_pose if pose is None else pose)
    n = len(q)
    steps = np.tile(np.vstack([np.zeros(6), np.eye(6)]), (n, 1))
    Y = regressor(platform, np.repeat(q, 7, 0), np.zeros((7 * n, 6)), steps).reshape(
        n, 7, 6, N_STANDARD)
    A = np.swapaxes(Y[:, 1:] - Y[:, :1], 1, 2)
    return A[0] if single else A


def viscous_regressor(platform: Platform, pose: np.ndarray | None = None) -> np.ndarray:
    """The viscous matrix as a linear function of the parameters: Bt(q) = A @ pi.

    Bt collects every term linear in the rates: the joints' viscous friction per type and
    the actuators'; the velocity products are quadratic and vanish from the linearisation.

    Parameters
    ----------
    platform : Platform
    pose : ndarray, shape (6,) or (N, 6), optional
        Pose(s) (m, rad); the neutral pose by default.

    Returns
    -------
    ndarray, shape (6, 6, N_STANDARD) or (N, 6, 6, N_STANDARD)
        Zero outside the columns of :data:`VISCOUS_PARAMETERS`.
    """
    q, single = as_batch(platform.neutral_pose if pose is None else pose)
    n = len(q)
    Y = regressor(platform, np.repeat(q, 6, 0), np.tile(np.eye(6), (n, 1)),
                  np.zeros((6 * n, 6))).reshape(n, 6, 6, N_STANDARD)
    A = np.zeros_like(Y)
    viscous = parameter_index(VISCOUS_PARAMETERS)
    A[..., viscous] = Y[..., viscous]
    A = np.swapaxes(A, 1, 2)
    return A[0] if single else A


__all__ = ["inertia_regressor", "viscous_regressor"]
