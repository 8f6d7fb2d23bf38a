"""Rigid-body dynamics with six two-part legs and joint friction (Kane's method, z down):
M(q) q_ddot + h(q, q_dot) + G(q) + F(q, q_dot) = J_lq(q)^T f_a, f_a actuator forces (N,
positive extends). Functions take q, q_dot, q_ddot of shape (6,) or (N, 6).

The ``[actuator]`` section adds, per leg, a reflected mass m_r moving with the leg length (the
rotor and screw of an electric leg) and friction along the leg. Its inertial force m_r l_ddot,
with l_ddot = J_lq q_ddot + J_lq_dot q_dot, is in M (J_lq^T m_r J_lq) and in h; its weight is
carried by the leg's housing, not by the actuator, so G is unchanged. The friction along the legs
(viscous c l_dot, Coulomb Fc sign(l_dot), regularised as the joints') is in F. f_a is then the
force the motor exerts (for an electric leg, force constant times current).
"""

from __future__ import annotations

import numpy as np

from stewartid.model.kinematics import as_batch, inverse_kinematics, rotation_matrix
from stewartid.platform import GRAVITY, Platform

#: Default Coulomb regularisation rate (rad/s).
COULOMB_SMOOTHING = 1e-4


class ModelTerms:
    """Every term of the equation of motion at a batch of N samples.

    Attributes
    ----------
    mass_matrix, leg_jacobian : ndarray, shape (N, 6, 6)
    velocity_product, gravity, leg_lengths : ndarray, shape (N, 6)
    joint_jacobians : ndarray, shape (N, 6, 5, 6)
    """

    def __init__(self, platform: Platform, q: np.ndarray, q_dot: np.ndarray | None = None):
        from stewartid.model import compiled  # numba: only the full model terms need it

        q2, self.single = as_batch(q)
        qd2 = np.zeros_like(q2) if q_dot is None else as_batch(q_dot, "q_dot")[0]
        if qd2.shape != q2.shape:
            raise ValueError(f"q_dot must have the shape of q {q2.shape}; got {qd2.shape}.")
        (self.mass_matrix, self.velocity_product, self.gravity, self.leg_jacobian,
         self.joint_jacobians, self.leg_lengths) = compiled.batch_terms(
            platform.parameters(), platform.upper_joints, platform.base_joints, q2, qd2)


def _out(x: np.ndarray, single: bool) -> np.ndarray:
    return x[0] if single else x


def mass_matrix(platform: Platform, q: np.ndarray) -> np.ndarray:
    """Mass matrix M(q), symmetric positive definite, with the legs' reflected masses; shape (6, 6) or
    (N, 6, 6).
    """
    t = ModelTerms(platform, q)
    return _out(t.mass_matrix, t.single)


def velocity_product_forces(platform: Platform, q: np.ndarray, q_dot: np.ndarray) -> np.ndarray:
    """Coriolis and centrifugal forces h(q, q_dot) (N, N m); shape (6,) or (N, 6)."""
    t = ModelTerms(platform, q, q_dot)
    return _out(t.velocity_product, t.single)


def gravity_forces(platform: Platform, q: np.ndarray) -> np.ndarray:
    """Gravity term G(q) of platform and leg parts (N, N m); G_z < 0 as gravity pulls along +z."""
    t = ModelTerms(platform, q)
    return _out(t.gravity, t.single)


def friction_forces(platform: Platform, q: np.ndarray, q_dot: np.ndarray,
                    coulomb_smoothing: float = COULOMB_SMOOTHING) -> np.ndarray:
    """Joint friction F(q, q_dot) as generalized forces (N, N m).

    Viscous on the 4 gimbal axes, Coulomb on all 5 axes of a leg, regularised as
    Fc w / sqrt(w^2 + s^2), w the joint rate, s = ``coulomb_smoothing`` (rad/s); with an
    ``[actuator]`` friction along the legs, J_lq^T (c l_dot + Fc l_dot / sqrt(l_dot^2 + s^2)),
    s then in m/s.
    """
    t = ModelTerms(platform, q, q_dot)
    return _out(_joint_friction(platform, t, q_dot, coulomb_smoothing), t.single)


def _joint_friction(platform: Platform, terms: ModelTerms, q_dot: np.ndarray,
                    coulomb_smoothing: float) -> np.ndarray:
    from stewartid.model import compiled  # numba, started only when a model term is computed

    qd2, _ = as_batch(q_dot, "q_dot")
    params = platform.parameters()
    F = compiled.batch_friction(params, terms.joint_jacobians, qd2, float(coulomb_smoothing))
    actuator = platform.actuator
    if actuator.viscous != 0.0 or actuator.coulomb != 0.0:  # none: hydraulic results unchanged
        F += compiled.batch_leg_friction(params, terms.leg_jacobian, qd2, float(coulomb_smoothing))
    return F


def inverse_dynamics(platform: Platform, q: np.ndarray, q_dot: np.ndarray, q_ddot: np.ndarray,
                     friction: bool = True,
                     coulomb_smoothing: float = COULOMB_SMOOTHING) -> np.ndarray:
    """Actuator forces f_a (N, positive extending), shape (6,) or (N, 6), that produce ``q_ddot``."""
    t = ModelTerms(platform, q, q_dot)
    qdd2, _ = as_batch(q_ddot, "q_ddot")
    rhs = np.einsum("nij,nj->ni", t.mass_matrix, qdd2) + t.velocity_product + t.gravity
    if friction:
        rhs += _joint_friction(platform, t, q_dot, coulomb_smoothing)
    f = np.linalg.solve(np.swapaxes(t.leg_jacobian, 1, 2), rhs[..., None])[..., 0]
    return _out(f, t.single)


def forward_dynamics(platform: Platform, q: np.ndarray, q_dot: np.ndarray, forces: np.ndarray,
                     friction: bool = True,
                     coulomb_smoothing: float = COULOMB_SMOOTHING) -> np.ndarray:
    """Accelerations q_ddot (m/s^2, rad/s^2) under actuator forces ``forces`` (N)."""
    t = ModelTerms(platform, q, q_dot)
    f2, _ = as_batch(forces, "forces")
    rhs = np.einsum("nji,nj->ni", t.leg_jacobian, f2) - t.velocity_product - t.gravity
    if friction:
        rhs -= _joint_friction(platform, t, q_dot, coulomb_smoothing)
    qdd = np.linalg.solve(t.mass_matrix, rhs[..., None])[..., 0]
    return _out(qdd, t.single)


def kinetic_energy(platform: Platform, q: np.ndarray, q_dot: np.ndarray) -> np.ndarray:
    """Kinetic energy 1/2 q_dot^T M(q) q_dot (J), the reflected masses' 1/2 m_r l_dot^2 included;
    shape () or (N,).
    """
    t = ModelTerms(platform, q)
    qd2, _ = as_batch(q_dot, "q_dot")
    T = 0.5 * np.einsum("ni,nij,nj->n", qd2, t.mass_matrix, qd2)
    return T[0] if t.single else T


def potential_energy(platform: Platform, q: np.ndarray) -> np.ndarray:
    """Gravitational potential energy of platform, payload and leg parts (J): V = -g sum(m z_com); the
    reflected masses have none (their weight rests on the leg housings).
    """
    q2, single = as_batch(q)
    legs = inverse_kinematics(platform, q2)
    i, body = platform.inertia, platform.moving_body
    z_body = q2[:, 2] + rotation_matrix(q2[:, 3:])[:, 2, :] @ body.com
    z_lower = platform.base_joints[None, :, 2] + i.lower_leg_com * legs.directions[..., 2]
    z_upper = legs.upper_joints[..., 2] - i.upper_leg_com * legs.directions[..., 2]
    V = -GRAVITY * (body.mass * z_body + i.lower_leg_mass * z_lower.sum(1)
                    + i.upper_leg_mass * z_upper.sum(1))
    return V[0] if single else V
