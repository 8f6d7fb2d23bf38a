"""Kinematics of the 6-6 Stewart platform, batched (time on axis 0; a pose (6,) or (N, 6) gives
results of the same leading shape). Pose q = [x, y, z, rx, ry, rz] of the reference point, paper
frame (x forward, y right, z down; m, rad), R = Rz(rz) Ry(ry) Rx(rx); q_dot are Euler-angle rates.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import NamedTuple

import numpy as np

from stewartid.errors import KinematicsError
from stewartid.model.joints import JOINT_TYPES
from stewartid.model.kernels import rotation_entries
from stewartid.model.leg_terms import LegTerms, leg_terms, leg_vectors
from stewartid.platform import Platform


def as_batch(q: np.ndarray, name: str = "q") -> tuple[np.ndarray, bool]:
    """A pose-like array (6,) or (N, 6) as a contiguous float batch (N, 6), and whether it was one row.

    Raises
    ------
    ValueError
        If ``q`` has another shape; ``name`` names it.
    """
    q = np.asarray(q, dtype=float)
    single = q.ndim == 1
    q2 = np.ascontiguousarray(q[None] if single else q)
    if q2.ndim != 2 or q2.shape[1] != 6:
        raise ValueError(f"{name} must have shape (6,) or (N, 6); got {q.shape}.")
    return q2, single


def rotation_matrix(angles: np.ndarray) -> np.ndarray:
    """Rotation matrices R = Rz(rz) Ry(ry) Rx(rx), (3, 3) or (N, 3, 3), of angles (3,) or (N, 3) (rad)."""
    a = np.asarray(angles, dtype=float)
    entries = rotation_entries(*(f(a[..., k]) for k in range(3) for f in (np.cos, np.sin)))
    return np.stack(entries, -1).reshape(*a.shape[:-1], 3, 3)


class LegState(NamedTuple):
    """Result of :func:`inverse_kinematics`.

    Attributes
    ----------
    lengths : ndarray, shape (N, 6)
        Lower to upper gimbal point (m).
    directions : ndarray, shape (N, 6, 3)
        Unit leg vectors, base towards platform joint.
    upper_joints : ndarray, shape (N, 6, 3)
        Upper joints in the fixed frame (m).
    """

    lengths: np.ndarray
    directions: np.ndarray
    upper_joints: np.ndarray


def inverse_kinematics(platform: Platform, q: np.ndarray) -> LegState:
    """Leg lengths, directions and joint positions at poses ``q``, (6,) or (N, 6) (m, rad)."""
    q2, _ = as_batch(q)
    _, _, r, u, lengths = leg_vectors(platform.upper_joints, platform.base_joints, q2)
    upper = np.stack([q2[:, k:k + 1] + r[k] for k in range(3)], -1)
    return LegState(lengths, np.stack(u, -1), upper)


def leg_lengths(platform: Platform, q: np.ndarray) -> np.ndarray:
    """Leg lengths (m) for poses ``q``: shape (6,) for one pose, (N, 6) for a batch."""
    q2, single = as_batch(q)
    lengths = inverse_kinematics(platform, q2).lengths
    return lengths[0] if single else lengths


def compute_leg_terms(platform: Platform, q: np.ndarray, joints: bool = False,
                      pose_terms: bool = True) -> LegTerms:
    """G(q), J_lq, leg lengths and (if ``joints``) joint-rate Jacobians at poses ``q`` (N, 6).

    Without the inertia terms; ``pose_terms=False`` leaves ``gravity`` and ``leg_jacobian`` empty.
    """
    return leg_terms(platform.parameters(), platform.upper_joints, platform.base_joints, q,
                     joints, pose_terms)


def leg_jacobian(platform: Platform, q: np.ndarray) -> np.ndarray:
    """Leg Jacobian J_lq, shape (6, 6) or (N, 6, 6): leg-length rates = J_lq q_dot.

    J_lq^T f maps actuator forces (N) to generalized forces (N, N m).
    """
    q2, single = as_batch(q)
    J_leg = compute_leg_terms(platform, q2)[1]
    return J_leg[0] if single else J_leg


def joint_rate_jacobians(platform: Platform, q: np.ndarray) -> np.ndarray:
    """Jacobians of the five rotational joint axes of every leg, shape (6, 5, 6) or (N, 6, 5, 6).

    Joint rates (rad/s) = J[..., leg, axis, :] @ q_dot, axes as
    :data:`stewartid.model.joints.JOINT_AXES`; gimbal axes e1 = unit(z x u), e2 = u x e1.
    """
    q2, single = as_batch(q)
    J_joint = compute_leg_terms(platform, q2, joints=True, pose_terms=False)[3]
    return J_joint[0] if single else J_joint


def joint_axis_rates(joint_jacobians: np.ndarray, q_dot: np.ndarray,
                     out: np.ndarray | None = None) -> np.ndarray:
    """Rates (N, 6, 5) of every joint axis (rad/s): ``joint_jacobians`` (N, 6, 5, 6) times
    ``q_dot`` (N, 6); ``out`` (N, 30), written and returned (as (N, 30)) when given."""
    n = len(q_dot)
    if out is not None:
        np.matmul(np.reshape(joint_jacobians, (n, 30, 6)), np.reshape(q_dot, (n, 6, 1)),
                  out=out[:, :, None])
        return out
    rates = np.reshape(joint_jacobians, (n, 30, 6)) @ np.reshape(q_dot, (n, 6, 1))
    return rates.reshape(n, 6, 5)


def joint_type_forces(torques: np.ndarray, joint_jacobians: np.ndarray,
                      types: Sequence[Sequence[int]] = tuple(JOINT_TYPES.values()),
                      out: np.ndarray | None = None) -> np.ndarray:
    """Generalized forces (N, N m) of torques on the joint axes, summed per joint type.

    sum over legs and the axes a of each type of torques[..., leg, a] J[n, leg, a, :].

    Parameters
    ----------
    torques : ndarray, shape (N, 6, 5) or (N, R, 6, 5)
        N m per joint axis (legs, then axes as :data:`~stewartid.model.joints.JOINT_AXES`),
        R torque sets per sample.
    joint_jacobians : ndarray, shape (N, 6, 5, 6)
    types : sequence of sequences of int
        The axes of each type; :data:`~stewartid.model.joints.JOINT_TYPES` by default.
    out : ndarray, shape (N, R, T, 6), optional
        Written and returned (R = 1 for torques (N, 6, 5)).

    Returns
    -------
    ndarray, shape (N, T, 6) or (N, R, T, 6)
        T = ``len(types)``.
    """
    n = len(torques)
    # per sample and axis, the (R, legs) torques times that axis's (legs, 6) Jacobian rows
    by_axis = (np.moveaxis(np.reshape(torques, (n, -1, 6, 5)), -1, 1)
               @ joint_jacobians.transpose(0, 2, 1, 3))                       # (N, 5, R, 6)
    if out is None:
        out = np.empty((n, by_axis.shape[2], len(types), 6))
    for k, axes in enumerate(types):
        np.copyto(out[:, :, k], by_axis[:, axes[0]])
        for a in axes[1:]:
            out[:, :, k] += by_axis[:, a]
    return out.reshape(*torques.shape[:-2], len(types), 6)


def forward_kinematics(platform: Platform, lengths: np.ndarray, initial: np.ndarray | None = None,
                       tolerance: float = 1e-12, max_iterations: int = 30) -> np.ndarray:
    """Poses (m, rad) from leg lengths (6,) or (N, 6) (m) by Newton-Raphson, all samples at once.

    Parameters
    ----------
    initial : ndarray, shape (6,) or (N, 6), optional
        Starting poses; the neutral pose by default.
    tolerance : float
        On the largest leg-length residual (m).

    Raises
    ------
    KinematicsError
        If some sample does not converge or meets a singular Jacobian.
    """
    l2, single = as_batch(lengths, "lengths")
    if not np.all(np.isfinite(l2)) or np.any(l2 <= 0):
        raise KinematicsError("leg lengths must be finite and positive for forward kinematics.")
    q = np.tile(platform.neutral_pose, (len(l2), 1)) if initial is None else \
        np.array(np.broadcast_to(as_batch(initial, "initial")[0], l2.shape))
    residual = np.inf
    active = np.arange(len(q))  # samples not yet converged: only they are iterated
    for _ in range(max_iterations):
        _, J, current, _ = compute_leg_terms(platform, q[active])
        error = current - l2[active]
        residual_active = np.max(np.abs(error), axis=1)
        keep = residual_active >= tolerance
        active, J, error = active[keep], J[keep], error[keep]
        if len(active) == 0:
            return q[0] if single else q
        cond = np.linalg.cond(J)
        singular = ~np.isfinite(cond) | (cond > 1e12)
        if np.any(singular):
            worst = int(np.argmax(singular))
            raise KinematicsError(
                f"forward kinematics met a singular leg Jacobian at sample {active[worst]} "
                f"(condition number {cond[worst]:.3g}); check the leg lengths and the "
                "platform description, or give a better initial pose."
            )
        q[active] -= np.linalg.solve(J, error[..., None])[..., 0]
        residual = np.zeros(len(q))
        residual[active] = residual_active[keep]
    bad = int(np.argmax(residual))
    raise KinematicsError(
        f"forward kinematics did not converge in {max_iterations} iterations at sample {bad} "
        f"(leg-length residual {residual[bad]:.3g} m); the lengths may be unreachable for "
        "this platform, or the initial pose too far away."
    )
