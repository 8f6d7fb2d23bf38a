"""Compiled per-sample kernels of the platform model (numba).

One kernel, :func:`model_terms`, evaluates every pose-dependent term of the model at one
sample, so the simulator pays for the leg geometry once per right-hand-side call. The public,
batched functions in :mod:`stewartid.kinematics` and :mod:`stewartid.dynamics` loop over
samples in compiled code around it.

Coordinates: q = [x, y, z, rx, ry, rz] (m, rad; R = Rz(rz) Ry(ry) Rx(rx)), q_dot its time
derivative (Euler-angle rates). Internally the body equations are written in the twist
nu = [v, omega] (world frame, at the reference point) and mapped to q with
nu = T(q) q_dot, T = blockdiag(I, E(q)).

Leg bodies (per leg, zero inertia about the leg's own axis):
lower part turns about the lower gimbal point B with the leg, centre of mass at B + d_l u;
upper part turns with the leg and slides with the stroke, centre of mass at A - d_u u.

Joint axes per leg, in the order [lower 1, lower 2, upper 1, upper 2, revolute]: an
orthonormal leg frame e1 = unit(z x u) (horizontal), e2 = u x e1, u; gimbal rates are the
components of the leg's angular velocity (lower) and of the platform's angular velocity
relative to the leg (upper) on e1 and e2, the revolute rate is the relative rate about u.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

#: Indices into the packed parameter vector built by Platform.parameters().
P_MASS, P_IXX, P_IYY, P_IZZ = 0, 1, 2, 3
P_M_UPPER, P_M_LOWER, P_D_UPPER, P_D_LOWER, P_I_UPPER, P_I_LOWER = 4, 5, 6, 7, 8, 9
P_VISCOUS, P_COULOMB, P_GRAVITY = 10, 11, 12

#: Joint axes per leg and which of them carry viscous friction (the gimbal axes).
N_JOINTS = 5
GIMBAL_AXES = (0, 1, 2, 3)


@njit(cache=True)
def rotation(rx: float, ry: float, rz: float) -> np.ndarray:
    """R = Rz(rz) Ry(ry) Rx(rx), shape (3, 3)."""
    cx, sx = math.cos(rx), math.sin(rx)
    cy, sy = math.cos(ry), math.sin(ry)
    cz, sz = math.cos(rz), math.sin(rz)
    R = np.empty((3, 3))
    R[0, 0] = cz * cy
    R[0, 1] = cz * sy * sx - sz * cx
    R[0, 2] = cz * sy * cx + sz * sx
    R[1, 0] = sz * cy
    R[1, 1] = sz * sy * sx + cz * cx
    R[1, 2] = sz * sy * cx - cz * sx
    R[2, 0] = -sy
    R[2, 1] = cy * sx
    R[2, 2] = cy * cx
    return R


@njit(cache=True)
def euler_rate_map(ry: float, rz: float) -> np.ndarray:
    """E with omega_world = E [rx_dot, ry_dot, rz_dot] for R = Rz Ry Rx, shape (3, 3)."""
    cy, sy = math.cos(ry), math.sin(ry)
    cz, sz = math.cos(rz), math.sin(rz)
    E = np.zeros((3, 3))
    E[0, 0] = cz * cy
    E[1, 0] = sz * cy
    E[2, 0] = -sy
    E[0, 1] = -sz
    E[1, 1] = cz
    E[2, 2] = 1.0
    return E


@njit(cache=True)
def euler_rate_map_derivative_product(ry: float, rz: float, rates: np.ndarray) -> np.ndarray:
    """dE/dt times the Euler-angle rates, shape (3,): the omega_dot not due to angle accelerations."""
    cy, sy = math.cos(ry), math.sin(ry)
    cz, sz = math.cos(rz), math.sin(rz)
    dx, dy, dz = rates[0], rates[1], rates[2]
    out = np.empty(3)
    out[0] = (-sz * cy * dz - cz * sy * dy) * dx - cz * dz * dy
    out[1] = (cz * cy * dz - sz * sy * dy) * dx - sz * dz * dy
    out[2] = -cy * dy * dx
    return out


@njit(cache=True)
def _cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    out = np.empty(3)
    out[0] = a[1] * b[2] - a[2] * b[1]
    out[1] = a[2] * b[0] - a[0] * b[2]
    out[2] = a[0] * b[1] - a[1] * b[0]
    return out


@njit(cache=True)
def leg_geometry(upper: np.ndarray, base: np.ndarray, q: np.ndarray):
    """Leg vectors of one pose.

    Returns
    -------
    r : (6, 3) lever arms reference point -> upper joint, world frame (m)
    lengths : (6,) leg lengths (m)
    u : (6, 3) unit leg vectors, base joint -> upper joint
    """
    R = rotation(q[3], q[4], q[5])
    r = np.empty((6, 3))
    u = np.empty((6, 3))
    lengths = np.empty(6)
    for i in range(6):
        for k in range(3):
            r[i, k] = R[k, 0] * upper[i, 0] + R[k, 1] * upper[i, 1] + R[k, 2] * upper[i, 2]
        s = 0.0
        for k in range(3):
            u[i, k] = q[k] + r[i, k] - base[i, k]
            s += u[i, k] * u[i, k]
        lengths[i] = math.sqrt(s)
        for k in range(3):
            u[i, k] /= lengths[i]
    return r, lengths, u


@njit(cache=True)
def model_terms(params, upper, base, q, qd, M, h, G, J_leg, J_joint, lengths):
    """Evaluate every model term at one sample, in q coordinates (written into the outputs).

    Parameters
    ----------
    params : (13,) packed parameters (Platform.parameters()).
    upper : (6, 3) upper joints, platform frame, relative to the reference point (m).
    base : (6, 3) base joints, fixed frame (m).
    q, qd : (6,) pose (m, rad) and its rate (m/s, rad/s).
    M : (6, 6) out, mass matrix.
    h : (6,) out, velocity-product (Coriolis and centrifugal) forces.
    G : (6,) out, gravity forces (M qdd + h + G + F = J_leg^T f).
    J_leg : (6, 6) out, leg-length rates = J_leg qd.
    J_joint : (6, 5, 6) out, joint axis rates = J_joint[leg] qd.
    lengths : (6,) out, leg lengths (m).
    """
    m = params[P_MASS]
    m_u, m_l = params[P_M_UPPER], params[P_M_LOWER]
    d_u, d_l = params[P_D_UPPER], params[P_D_LOWER]
    I_leg = params[P_I_UPPER] + params[P_I_LOWER]
    g = params[P_GRAVITY]

    R = rotation(q[3], q[4], q[5])
    E = euler_rate_map(q[4], q[5])
    omega = E @ qd[3:]
    r, L, u = leg_geometry(upper, base, q)

    Mn = np.zeros((6, 6))
    hn = np.zeros(6)
    Gn = np.zeros(6)
    Jl = np.zeros((6, 6))
    Jj = np.zeros((6, 5, 6))

    # platform
    Ib = np.diag(params[P_IXX:P_IZZ + 1].copy())
    Iw = R @ Ib @ R.T
    for k in range(3):
        Mn[k, k] = m
    Mn[3:, 3:] = Iw
    hn[3:] = _cross(omega, Iw @ omega)
    Gn[2] = -m * g

    JA = np.zeros((3, 6))
    for i in range(6):
        l = L[i]
        lengths[i] = l
        ui = u[i]
        ri = r[i]
        # J_A = [I, -[r]x]: velocity of the upper joint point from the twist
        JA[:, :] = 0.0
        JA[0, 0] = 1.0
        JA[1, 1] = 1.0
        JA[2, 2] = 1.0
        JA[0, 4] = ri[2]
        JA[0, 5] = -ri[1]
        JA[1, 3] = -ri[2]
        JA[1, 5] = ri[0]
        JA[2, 3] = ri[1]
        JA[2, 4] = -ri[0]
        vA = qd[:3] + _cross(omega, ri)
        ld = ui @ vA
        udot = (vA - ld * ui) / l
        aA = _cross(omega, _cross(omega, ri))
        P = np.eye(3) - np.outer(ui, ui)
        udd = (P @ aA - l * (udot @ udot) * ui - 2.0 * ld * udot) / l
        Judot = P @ JA / l
        Jw = np.zeros((3, 6))
        for c in range(6):
            Jw[:, c] = _cross(ui, JA[:, c]) / l
        Jcl = d_l * Judot
        Jcu = JA - d_u * Judot
        acl = d_l * udd
        acu = aA - d_u * udd
        wd = _cross(ui, udd)
        Mn += m_l * (Jcl.T @ Jcl) + m_u * (Jcu.T @ Jcu) + I_leg * (Jw.T @ Jw)
        hn += m_l * (Jcl.T @ acl) + m_u * (Jcu.T @ acu) + I_leg * (Jw.T @ wd)
        for c in range(6):
            Gn[c] -= g * (m_l * Jcl[2, c] + m_u * Jcu[2, c])
        Jl[i, :] = ui @ JA
        # leg frame for the joint axes
        nx, ny = -ui[1], ui[0]
        nn = math.sqrt(nx * nx + ny * ny)
        e1 = np.array([nx / nn, ny / nn, 0.0])
        e2 = _cross(ui, e1)
        for c in range(6):
            w_leg = Jw[:, c]
            w_rel = -w_leg
            if c >= 3:
                w_rel[c - 3] += 1.0
            Jj[i, 0, c] = e1 @ w_leg
            Jj[i, 1, c] = e2 @ w_leg
            Jj[i, 2, c] = e1 @ w_rel
            Jj[i, 3, c] = e2 @ w_rel
            Jj[i, 4, c] = ui @ w_rel

    # map the twist equations to q coordinates: nu = T qd, nu_dot = T qdd + [0, Edot rates]
    bias = np.zeros(6)
    bias[3:] = euler_rate_map_derivative_product(q[4], q[5], qd[3:])
    hn += Mn @ bias
    T = np.eye(6)
    T[3:, 3:] = E
    M[:, :] = T.T @ Mn @ T
    h[:] = T.T @ hn
    G[:] = T.T @ Gn
    J_leg[:, :] = Jl @ T
    for i in range(6):
        J_joint[i] = Jj[i] @ T


@njit(cache=True)
def joint_friction(params, J_joint, qd, smoothing):
    """Generalized joint friction forces (N, N m) at one sample, regularised Coulomb.

    Viscous on the gimbal axes, Coulomb Fc * rate / sqrt(rate^2 + smoothing^2) on all five.
    """
    c = params[P_VISCOUS]
    fc = params[P_COULOMB]
    F = np.zeros(6)
    for i in range(6):
        for j in range(N_JOINTS):
            rate = J_joint[i, j] @ qd
            tau = fc * rate / math.sqrt(rate * rate + smoothing * smoothing)
            if j < 4:
                tau += c * rate
            F += tau * J_joint[i, j]
    return F


@njit(cache=True)
def forward_dynamics_sample(params, upper, base, q, qd, forces, smoothing, friction):
    """qdd at one sample for actuator forces ``forces`` (N); friction on when ``friction``."""
    M = np.empty((6, 6))
    h = np.empty(6)
    G = np.empty(6)
    Jl = np.empty((6, 6))
    Jj = np.empty((6, 5, 6))
    lengths = np.empty(6)
    model_terms(params, upper, base, q, qd, M, h, G, Jl, Jj, lengths)
    rhs = Jl.T @ forces - h - G
    if friction:
        rhs -= joint_friction(params, Jj, qd, smoothing)
    return np.linalg.solve(M, rhs)


@njit(cache=True)
def batch_terms(params, upper, base, q, qd):
    """model_terms over samples: q, qd of shape (N, 6)."""
    n = q.shape[0]
    M = np.empty((n, 6, 6))
    h = np.empty((n, 6))
    G = np.empty((n, 6))
    Jl = np.empty((n, 6, 6))
    Jj = np.empty((n, 6, 5, 6))
    lengths = np.empty((n, 6))
    for k in range(n):
        model_terms(params, upper, base, q[k], qd[k], M[k], h[k], G[k], Jl[k], Jj[k], lengths[k])
    return M, h, G, Jl, Jj, lengths


@njit(cache=True)
def batch_friction(params, J_joint, qd, smoothing):
    """joint_friction over samples."""
    n = qd.shape[0]
    F = np.empty((n, 6))
    for k in range(n):
        F[k] = joint_friction(params, J_joint[k], qd[k], smoothing)
    return F
