"""Mt(q) and Bt(q) as linear functions of the standard parameters, from the regressor at rest."""

from __future__ import annotations

import numpy as np

from stewartid.model.kinematics import as_batch
from stewartid.model.regressor import (
    N_STANDARD,
    VISCOUS_PARAMETERS,
    parameter_index,
    regressor_columns,
)
from stewartid.platform import Platform


def inertia_regressor(platform: Platform, pose: np.ndarray | None = None) -> np.ndarray:
    """The mass matrix as a linear function of the parameters: M(q) = A @ pi.

    Column k of M is Y(q, 0, e_k) pi - Y(q, 0, 0) pi. ``pose`` (6,) or (N, 6), m, rad (neutral by
    default); A has shape (6, 6, N_STANDARD) or (N, 6, 6, N_STANDARD).
    """
    q, single = as_batch(platform.neutral_pose if pose is None else pose)
    n = len(q)
    poses = np.repeat(q.T, 6, 1)  # time last: pose j, unit acceleration k at j * 6 + k
    Y = regressor_columns(platform, poses, np.zeros_like(poses), np.tile(np.eye(6), n),
                          gravity=False, friction=False)
    A = Y.reshape(6, N_STANDARD, n, 6).transpose(2, 0, 3, 1)
    return A[0] if single else np.ascontiguousarray(A)


def viscous_regressor(platform: Platform, pose: np.ndarray | None = None) -> np.ndarray:
    """The viscous matrix as a linear function of the parameters: Bt(q) = A @ pi.

    Every term linear in the rates (joint and actuator viscous friction; velocity products vanish).
    Shapes as :func:`inertia_regressor`, zero outside
    :data:`~stewartid.model.regressor.VISCOUS_PARAMETERS`.
    """
    q, single = as_batch(platform.neutral_pose if pose is None else pose)
    n = len(q)
    poses = np.repeat(q.T, 6, 1)  # time last: pose j, unit rate k at j * 6 + k
    Y = regressor_columns(platform, poses, np.tile(np.eye(6), n), np.zeros_like(poses),
                          gravity=False, rigid=False).reshape(6, N_STANDARD, n, 6)
    A = np.zeros((n, 6, 6, N_STANDARD))
    viscous = parameter_index(VISCOUS_PARAMETERS)
    A[..., viscous] = Y[:, viscous].transpose(2, 0, 3, 1)
    return A[0] if single else A


__all__ = ["inertia_regressor", "viscous_regressor"]
