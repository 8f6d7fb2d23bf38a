"""Linearisation about a pose q0 (Zhang 2020, Tables 3-6): Mt q_ddot + Bt q_dot + G(q0) + K_G (q - q0)
+ Fc = J_lq^T f_a, with Mt = M(q0), Bt the viscous gimbal friction, K_G = dG/dq at q0.

An ``[actuator]`` adds J_lq^T m_r J_lq to Mt (the reflected masses) and J_lq^T c J_lq to Bt (the
viscous friction along the legs), J_lq at q0.
"""

from __future__ import annotations

import numpy as np

from stewartid.model.joints import GIMBAL_AXES
from stewartid.model.kernels import model_terms
from stewartid.model.kinematics import compute_leg_terms, joint_rate_jacobians, leg_jacobian
from stewartid.model.regressor import (
    ACTUATOR_PARAMETERS,
    FRICTION_PARAMETERS,
    OFFSET_PARAMETERS,
    parameter_index,
    regressor_columns,
    standard_parameters,
)
from stewartid.platform import Platform


def viscous_matrix(platform: Platform, q: np.ndarray) -> np.ndarray:
    """Bt(q) = c * sum_{legs, gimbal axes} J_j^T J_j + c_leg J_lq^T J_lq; shape (6, 6) or (N, 6, 6).

    c (N m s/rad) from ``[friction] gimbal_viscous``, c_leg (N s/m) from ``[actuator] viscous``.
    """
    J_leg = leg_jacobian(platform, q) if platform.actuator.viscous != 0.0 else None
    return _viscous(platform, joint_rate_jacobians(platform, q), J_leg)


def _viscous(platform: Platform, joint_jacobians: np.ndarray,
             leg_jacobians: np.ndarray | None = None) -> np.ndarray:
    J = joint_jacobians[..., list(GIMBAL_AXES), :]
    B = platform.friction.gimbal_viscous * np.einsum("...lai,...laj->...ij", J, J)
    c = platform.actuator.viscous
    if c != 0.0:  # added only when present: hydraulic results stay bit for bit
        B = B + c * np.einsum("...li,...lj->...ij", leg_jacobians, leg_jacobians)
    return B


def nominal_matrices(platform: Platform, pose: np.ndarray | None = None
                     ) -> tuple[np.ndarray, np.ndarray]:
    """Nominal inertial and viscous matrices (Mt, Bt) of the linearised model.

    Parameters
    ----------
    platform : Platform
    pose : ndarray, shape (6,), optional
        Linearisation pose (m, rad); the neutral pose by default.

    Returns
    -------
    Mt : ndarray, shape (6, 6)
        The mass matrix at ``pose``, the legs' reflected masses included: kg, kg m, kg m^2 blocks.
    Bt : ndarray, shape (6, 6)
        N s/m, N s/rad, N m s/rad blocks; the gimbals' and the legs' viscous friction.
    """
    return nominal_terms(platform, pose)[:2]


def nominal_terms(platform: Platform, pose: np.ndarray | None = None
                  ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Mt, Bt (as :func:`nominal_matrices`) and G(q) (6,) (N, N m; G_z < 0) at ``pose``, in one evaluation."""
    q0 = platform.neutral_pose if pose is None else np.asarray(pose, dtype=float)
    M, h, G, J_leg, J_joint, lengths = (np.empty(shape) for shape in
                                        ((6, 6), 6, 6, (6, 6), (6, 5, 6), 6))
    # one pose: the kernel interpreted, which spares the command line numba's start
    model_terms(platform.parameters(), platform.upper_joints, platform.base_joints, q0,
                np.zeros(6), M, h, G, J_leg, J_joint, lengths)
    return M, _viscous(platform, J_joint, J_leg), G


def linearisation_remainder(platform: Platform, q: np.ndarray, q_dot: np.ndarray,
                            q_ddot: np.ndarray, pose: np.ndarray | None = None) -> np.ndarray:
    """What the inertial and viscous terms add to their linearisation at ``pose``, (N, 6) (N, N m).

    r = [M(q) - Mt] q_ddot + h(q, q_dot) + [Bt(q) - Bt] q_dot: subtracted from measured forces, it
    keeps the linearised model exact at any amplitude. M q_ddot + h + Bt(q) q_dot is the
    regressor without gravity times the platform's standard parameters, its Coulomb levels and
    sensor offsets left out (numpy: no compiled kernel to start).
    """
    Mt, Bt = nominal_matrices(platform, pose)
    parameters = standard_parameters(platform)
    coulomb = [name for name in FRICTION_PARAMETERS + ACTUATOR_PARAMETERS
               if name.startswith("coulomb")]
    parameters[parameter_index(coulomb + list(OFFSET_PARAMETERS))] = 0.0
    q, q_dot, q_ddot = (np.asarray(x, dtype=float) for x in (q, q_dot, q_ddot))
    Y = regressor_columns(platform, q.T, q_dot.T, q_ddot.T, gravity=False)   # (6, P, N)
    return np.tensordot(parameters, Y, axes=(0, 1)).T - q_ddot @ Mt.T - q_dot @ Bt.T


def gravity_stiffness(platform: Platform, pose: np.ndarray | None = None,
                      step: float = 1e-6) -> np.ndarray:
    """Gravity stiffness K_G = dG/dq (6, 6) at ``pose`` by central differences of the exact G(q)."""
    q0 = platform.neutral_pose if pose is None else np.asarray(pose, dtype=float)
    steps = step * np.eye(6)
    G_plus = compute_leg_terms(platform, q0 + steps).gravity
    G_minus = compute_leg_terms(platform, q0 - steps).gravity
    return ((G_plus - G_minus) / (2 * step)).T
