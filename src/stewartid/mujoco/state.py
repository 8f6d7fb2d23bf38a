"""Poses, rates and forces between our coordinates and the MuJoCo model's: closed poses, MuJoCo's
equations projected onto the six platform coordinates, and the leg servo.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np

from stewartid.model.kinematics import inverse_kinematics, rotation_matrix
from stewartid.mujoco.model import T, leg_frames, require_mujoco
from stewartid.platform import Platform

if TYPE_CHECKING:
    import mujoco


class Indices:
    """Addresses of the platform's free joint and of each leg's joints in a compiled model.

    Attributes
    ----------
    platform_qpos, platform_dof : int
        First qpos (7 values) and dof (6) of the free joint.
    slide_qpos, slide_dof : ndarray, shape (6,)
        Of the six slide joints.
    joint_qpos : ndarray, shape (6, 5)
        lower1, lower2, upper1, upper2, revolute per leg.
    leg_dofs : ndarray, shape (36,)
        Every dof that is not the platform's.
    """

    def __init__(self, model: mujoco.MjModel):
        mj = require_mujoco()

        def joint(name: str) -> int:
            return mj.mj_name2id(model, mj.mjtObj.mjOBJ_JOINT, name)

        j = joint("platform")
        self.platform_qpos = int(model.jnt_qposadr[j])
        self.platform_dof = int(model.jnt_dofadr[j])
        slides = [joint(f"leg{k + 1}_slide") for k in range(6)]
        self.slide_qpos = model.jnt_qposadr[slides].copy()
        self.slide_dof = model.jnt_dofadr[slides].copy()
        names = ("lower1", "lower2", "upper1", "upper2", "revolute")
        self.joint_qpos = np.array([[model.jnt_qposadr[joint(f"leg{k + 1}_{s}")] for s in names]
                                    for k in range(6)])
        platform_dofs = np.arange(self.platform_dof, self.platform_dof + 6)
        self.leg_dofs = np.setdiff1d(np.arange(model.nv), platform_dofs)
        self.platform_dofs = platform_dofs


def _rx(a: float) -> np.ndarray:
    c, s = math.cos(a), math.sin(a)
    return np.array([[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]])


def _ry(a: float) -> np.ndarray:
    c, s = math.cos(a), math.sin(a)
    return np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])


def euler_rate_matrix(angles: np.ndarray) -> np.ndarray:
    """E (3, 3) with omega_body = E @ [rx', ry', rz'] (paper frame), R = Rz Ry Rx, angles in rad."""
    rx, ry, rz = (float(a) for a in angles)
    Rz = rotation_matrix(np.array([0.0, 0.0, rz]))
    Rzy = rotation_matrix(np.array([0.0, ry, rz]))
    R = rotation_matrix(np.array([rx, ry, rz]))
    world = np.column_stack([Rzy[:, 0], Rz[:, 1], [0.0, 0.0, 1.0]])
    return R.T @ world


def platform_velocity_map(angles: np.ndarray) -> np.ndarray:
    """P (6, 6) from our rates q_dot to the free joint's velocity [v (world), omega (body)]:
    v = T [x', y', z'], omega = T E(angles) [rx', ry', rz'].
    """
    P = np.zeros((6, 6))
    P[:3, :3] = T
    P[3:, 3:] = T @ euler_rate_matrix(angles)
    return P


def joint_positions(platform: Platform, model: mujoco.MjModel, q: np.ndarray) -> np.ndarray:
    """Full ``qpos`` (model.nq,) placing the platform at pose ``q`` (m, rad) with every chain closed."""
    mj = require_mujoco()
    idx = Indices(model)
    q = np.asarray(q, dtype=float)
    R = rotation_matrix(q[3:])
    legs = inverse_kinematics(platform, q)
    frames = leg_frames(platform)
    qpos = model.qpos0.copy()
    a = idx.platform_qpos
    qpos[a:a + 3] = T @ q[:3]
    quat = np.empty(4)
    mj.mju_mat2Quat(quat, (T @ R @ T).ravel())
    qpos[a + 3:a + 7] = quat
    l0 = platform.neutral_leg_length
    for k in range(6):
        R0 = frames[k]
        v = R0.T @ legs.directions[0, k]  # leg direction in the neutral leg frame
        th2 = math.asin(max(-1.0, min(1.0, v[0])))
        th1 = math.atan2(-v[1], v[2])
        # upper hinges: the end body must keep its neutral orientation relative to the
        # platform; decompose Q = Rx(a) Ry(b) Rz(c) (intrinsic x-y-z, the hinge order)
        Q = (_rx(th1) @ _ry(th2)).T @ R0.T @ R @ R0
        b = math.asin(max(-1.0, min(1.0, Q[0, 2])))
        a_ = math.atan2(-Q[1, 2], Q[2, 2])
        c = math.atan2(-Q[0, 1], Q[0, 0])
        qpos[idx.joint_qpos[k]] = [th1, th2, a_, b, c]
        qpos[idx.slide_qpos[k]] = legs.lengths[0, k] - l0
    return qpos


def equality_jacobian(model: mujoco.MjModel, data: mujoco.MjData) -> np.ndarray:
    """The welds' rows (36, model.nv) of the constraint Jacobian (after ``mj_forward``)."""
    mj = require_mujoco()
    rows = data.efc_type[:data.nefc] == mj.mjtConstraint.mjCNSTR_EQUALITY
    J = np.asarray(data.efc_J[:data.nefc * model.nv]).reshape(data.nefc, model.nv)
    return J[rows]


def closure_map(model: mujoco.MjModel, data: mujoco.MjData) -> np.ndarray:
    """S (model.nv, 6) from the free joint's velocity to all joint velocities keeping the chains closed:
    v_l = -J_c,l^-1 J_c,p v_p; the welds do no work along S, so S^T projects MuJoCo's equations.
    """
    idx = Indices(model)
    J = equality_jacobian(model, data)
    S = np.zeros((model.nv, 6))
    S[idx.platform_dofs] = np.eye(6)
    S[idx.leg_dofs] = -np.linalg.solve(J[:, idx.leg_dofs], J[:, idx.platform_dofs])
    return S


def set_state(platform: Platform, model: mujoco.MjModel, data: mujoco.MjData, q: np.ndarray,
              q_dot: np.ndarray | None = None) -> None:
    """Put the model at pose ``q`` and rates ``q_dot`` (paper frame), closed, and run ``mj_forward``."""
    mj = require_mujoco()
    data.qpos[:] = joint_positions(platform, model, q)
    data.qvel[:] = 0.0
    data.qacc_warmstart[:] = 0.0
    mj.mj_forward(model, data)
    if q_dot is not None:
        S = closure_map(model, data)
        data.qvel[:] = S @ platform_velocity_map(np.asarray(q)[3:]) @ np.asarray(q_dot, float)
        mj.mj_forward(model, data)


def platform_state(model: mujoco.MjModel, data: mujoco.MjData) -> tuple[np.ndarray, np.ndarray]:
    """Pose and rates (6,) each of the platform in our coordinates (m, rad, paper frame)."""
    mj = require_mujoco()
    idx = Indices(model)
    a, d = idx.platform_qpos, idx.platform_dof
    Rm = np.empty(9)
    mj.mju_quat2Mat(Rm, data.qpos[a + 3:a + 7])
    R = T @ Rm.reshape(3, 3) @ T
    angles = np.array([math.atan2(R[2, 1], R[2, 2]), -math.asin(max(-1.0, min(1.0, R[2, 0]))),
                       math.atan2(R[1, 0], R[0, 0])])
    q = np.concatenate([T @ data.qpos[a:a + 3], angles])
    v = data.qvel[d:d + 6]
    q_dot = np.concatenate([T @ v[:3], np.linalg.solve(euler_rate_matrix(angles), T @ v[3:])])
    return q, q_dot


def dense_mass_matrix(model: mujoco.MjModel, data: mujoco.MjData) -> np.ndarray:
    """Joint-space mass matrix (nv, nv) of the current state (after ``mj_forward``)."""
    mj = require_mujoco()
    M = np.empty((model.nv, model.nv))
    if hasattr(data, "qM"):  # MuJoCo 3.x: mj_fullM(m, dst, qM)
        mj.mj_fullM(model, M, data.qM)
    else:  # MuJoCo 4: mj_fullM(m, d, dst)
        mj.mj_fullM(model, data, M)
    return M


def platform_space_terms(platform: Platform, model: mujoco.MjModel, data: mujoco.MjData,
                         q: np.ndarray) -> dict[str, np.ndarray]:
    """MuJoCo's equation of motion on our coordinates at rest at pose ``q``, by virtual work with V = S P.

    Returns ``mass_matrix`` V^T M V, ``gravity`` V^T qfrc_bias (6,), ``leg_jacobian`` (the slide rows
    of V), ``viscous`` V^T D V (D the joint damping), all (6, 6) unless said, and
    ``constraint_violation`` (m, largest weld error after assembly).
    """
    mj = require_mujoco()
    set_state(platform, model, data, q)
    idx = Indices(model)
    V = closure_map(model, data) @ platform_velocity_map(np.asarray(q)[3:])
    M = dense_mass_matrix(model, data)
    rows = data.efc_type[:data.nefc] == mj.mjtConstraint.mjCNSTR_EQUALITY
    return {
        "mass_matrix": V.T @ M @ V,
        "gravity": V.T @ data.qfrc_bias,
        "leg_jacobian": V[idx.slide_dof],
        "viscous": V.T @ np.diag(model.dof_damping) @ V,
        "constraint_violation": np.abs(data.efc_pos[:data.nefc][rows]).max(),
    }


def static_leg_forces(platform: Platform, model: mujoco.MjModel, data: mujoco.MjData,
                      q: np.ndarray) -> np.ndarray:
    """Actuator forces (6,) (N, extending) holding pose ``q`` at rest: J_lq^T f = G by MuJoCo."""
    t = platform_space_terms(platform, model, data, q)
    return np.linalg.solve(t["leg_jacobian"].T, t["gravity"])


def leg_lengths(platform: Platform, model: mujoco.MjModel, data: mujoco.MjData) -> np.ndarray:
    """Leg lengths (6,) (m) of the MuJoCo state: neutral length plus slide position."""
    return platform.neutral_leg_length + data.qpos[Indices(model).slide_qpos]


# -- the leg servo of the plant, on MuJoCo's actuators ----------------------------------------

def add_leg_servo(platform: Platform, model: mujoco.MjModel) -> None:
    """Give the leg motors, in place, the PD part of the plant's servo f = f_ff + K_p (l_cmd - l) +
    K_d (l_cmd' - l'): the l, l' terms as the motors' affine bias, the rest through ``ctrl``.
    """
    mj = require_mujoco()
    c = platform.controller
    # actuator length of a slide transmission is the slide's qpos, l - l_0
    model.actuator_biastype[:] = mj.mjtBias.mjBIAS_AFFINE
    model.actuator_biasprm[:, :3] = [0.0, -c.proportional_gain, -c.derivative_gain]


def servo_controls(platform: Platform, q_cmd: np.ndarray, q_dot_cmd: np.ndarray) -> np.ndarray:
    """``ctrl`` (N, 6) (N) of :func:`add_leg_servo` along commanded poses and rates (N, 6):
    f_ff + K_p (l_cmd - l_0) + K_d l_cmd', f_ff the forces holding the commanded pose if enabled.
    """
    from stewartid.model.dynamics import inverse_dynamics
    from stewartid.model.kinematics import leg_jacobian, leg_lengths

    c = platform.controller
    q_cmd = np.atleast_2d(q_cmd)
    q_dot_cmd = np.atleast_2d(q_dot_cmd)
    lengths = leg_lengths(platform, q_cmd)
    rates = np.einsum("nij,nj->ni", leg_jacobian(platform, q_cmd), q_dot_cmd)
    ctrl = (c.proportional_gain * (lengths - platform.neutral_leg_length)
            + c.derivative_gain * rates)
    if c.gravity_feedforward:
        rest = np.zeros_like(q_cmd)
        ctrl += inverse_dynamics(platform, q_cmd, rest, rest, friction=False)
    return ctrl
