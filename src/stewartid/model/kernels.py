"""Per-sample kernels of the platform model in plain Python, the one definition that
:mod:`stewartid.model.compiled` compiles with numba (only what numba compiles belongs here).
Twist nu = [v, omega] = T(q) q_dot, T = blockdiag(I, E); see ``docs/conventions.md``.
"""

from __future__ import annotations

import math

import numpy as np

from stewartid.model import parameters as layout
from stewartid.model.joints import N_GIMBAL_AXES, N_JOINTS

# -- per-sample geometry: arithmetic only, on floats (kernels) or arrays (numpy leg terms) ----


def rotation_entries(cx, sx, cy, sy, cz, sz):
    """Entries of R = Rz Ry Rx row by row, from the cosines and sines of rx, ry, rz."""
    return (cz * cy, cz * sy * sx - sz * cx, cz * sy * cx + sz * sx,
            sz * cy, sz * sy * sx + cz * cx, sz * sy * cx - cz * sx,
            -sy, cy * sx, cy * cx)


def euler_rate_entries(cy, sy, cz, sz):
    """Entries (E00, E10, E20, E01, E11) of E, omega = E [rx_dot, ry_dot, rz_dot]; E22 = 1, others 0."""
    return cz * cy, sz * cy, -sy, -sz, cz


def leg_vector(R, x, y, z, a0, a1, a2, b0, b1, b2):
    """(r0, r1, r2, u0, u1, u2, length) of one leg: r = R a, u the unit vector from base joint b to the
    upper joint, at position (x, y, z) and rotation entries ``R``; a in the platform frame, all m.
    """
    r0 = R[0] * a0 + R[1] * a1 + R[2] * a2
    r1 = R[3] * a0 + R[4] * a1 + R[5] * a2
    r2 = R[6] * a0 + R[7] * a1 + R[8] * a2
    s0 = x + r0 - b0
    s1 = y + r1 - b1
    s2 = z + r2 - b2
    length = np.sqrt(s0 * s0 + s1 * s1 + s2 * s2)
    return r0, r1, r2, s0 / length, s1 / length, s2 / length, length


def twist_column(c, r0, r1, r2, zero, one):
    """Column c of J_A = [I, -[r]x], ``zero`` and ``one`` at its structural zeros and ones."""
    if c == 0:
        return one, zero, zero
    if c == 1:
        return zero, one, zero
    if c == 2:
        return zero, zero, one
    if c == 3:
        return zero, -r2, r1
    if c == 4:
        return r2, zero, -r0
    return -r1, r0, zero


def leg_rate(u0, u1, u2, b0, b1, b2):
    """Leg-length rate u . b for the joint velocity b (a column of J_A)."""
    return u0 * b0 + u1 * b1 + u2 * b2


def leg_angular_rate(u0, u1, u2, b0, b1, b2, length):
    """The leg's angular velocity u x b / l for the joint velocity b (a column of J_A)."""
    return ((u1 * b2 - u2 * b1) / length, (u2 * b0 - u0 * b2) / length,
            (u0 * b1 - u1 * b0) / length)


def centre_of_mass_rates(b, u, rate, length, d_upper, d_lower):
    """One component of the rates of u and of the lower and upper parts' centres of mass."""
    u_rate = (b - u * rate) / length
    return u_rate, d_lower * u_rate, b - d_upper * u_rate


def leg_gravity(g, m_upper, m_lower, lower_z, upper_z):
    """One leg's gravity force on a twist component, from the vertical rates of its centres of mass."""
    return g * (m_lower * lower_z + m_upper * upper_z)


def body_gravity(R, g, m, c0, c1, c2):
    """The moving body's gravity force on twist components z, rx, ry: -m g and -(R c) x (0, 0, m g)."""
    w = m * g
    return -w, -w * (R[3] * c0 + R[4] * c1 + R[5] * c2), w * (R[0] * c0 + R[1] * c1 + R[2] * c2)


def leg_frame(u0, u1, u2):
    """Leg frame e1 = unit(z x u), e2 = u x e1 as (e10, e11, e20, e21, e22); e12 = 0."""
    nx, ny = -u1, u0
    nn = np.sqrt(nx * nx + ny * ny)
    e10, e11 = nx / nn, ny / nn
    return e10, e11, -u2 * e11, u2 * e10, u0 * e11 - u1 * e10


def joint_rate_column(c, frame, u0, u1, u2, w0, w1, w2):
    """Rates of the five joint axes per unit of twist component c.

    Gimbal rates: components on e1, e2 of the leg's angular velocity (lower) and of the platform's
    relative to the leg (upper); the revolute rate is the relative rate about u.
    """
    e10, e11, e20, e21, e22 = frame
    lower_1 = e10 * w0 + e11 * w1
    lower_2 = e20 * w0 + e21 * w1 + e22 * w2
    if c < 3:
        return lower_1, lower_2, -lower_1, -lower_2, -(u0 * w0 + u1 * w1 + u2 * w2)
    v0 = 1.0 - w0 if c == 3 else -w0
    v1 = 1.0 - w1 if c == 4 else -w1
    v2 = 1.0 - w2 if c == 5 else -w2
    return (lower_1, lower_2, e10 * v0 + e11 * v1, e20 * v0 + e21 * v1 + e22 * v2,
            u0 * v0 + u1 * v1 + u2 * v2)


def euler_columns(x0, x1, x2, E):
    """The angular part of a twist row in Euler-angle rates: [x0, x1, x2] E."""
    E00, E10, E20, E01, E11 = E
    return x0 * E00 + x1 * E10 + x2 * E20, x0 * E01 + x1 * E11, x2


# -- the full model at one sample ---------------------------------------------------------


def trigonometry(q):
    """Cosines and sines (cx, sx, cy, sy, cz, sz) of the angles of pose ``q`` (6,)."""
    return (math.cos(q[3]), math.sin(q[3]), math.cos(q[4]), math.sin(q[4]),
            math.cos(q[5]), math.sin(q[5]))


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


def model_terms(params, upper, base, q, qd, M, h, G, J_leg, J_joint, lengths):
    """Every model term at one sample, in q coordinates, written into the outputs.

    Scalar loops: the simulator calls it four times per step, where small BLAS calls would dominate.

    Parameters
    ----------
    params : (N_PARAMETERS,) packed parameters (:mod:`stewartid.model.parameters`).
    upper, base : (6, 3) upper joints (platform frame, from the reference point), base joints (m).
    q, qd : (6,) pose (m, rad) and its rate.
    M, h, G, J_leg, J_joint, lengths : out, (6, 6), (6,), (6,), (6, 6), (6, 5, 6), (6,).
    """
    cx, sx, cy, sy, cz, sz = trigonometry(q)
    R = rotation_entries(cx, sx, cy, sy, cz, sz)
    E = euler_rate_entries(cy, sy, cz, sz)
    omega = np.empty(3)  # E qd[3:]
    omega[0] = E[0] * qd[3] + E[3] * qd[4]
    omega[1] = E[1] * qd[3] + E[4] * qd[4]
    omega[2] = E[2] * qd[3] + qd[5]
    Mn = np.zeros((6, 6))
    hn = np.zeros(6)
    Gn = np.zeros(6)
    _body_terms(params, R, omega, Mn, hn, Gn)
    # per-leg scratch: velocities of the two centres of mass and the leg's angular velocity
    # per twist component, their velocity-product accelerations
    Jcl = np.empty((3, 6))
    Jcu = np.empty((3, 6))
    Jw = np.empty((3, 6))
    acl = np.empty(3)
    acu = np.empty(3)
    wd = np.empty(3)
    reflected = params[layout.REFLECTED_MASS]
    for i in range(6):
        lengths[i], leg_bias = _leg_kinematics(params, R, q, qd, omega, upper[i], base[i],
                                               J_leg[i], J_joint[i], Jcl, Jcu, Jw, acl, acu, wd)
        _add_leg_inertia(params, Jcl, Jcu, Jw, acl, acu, wd, Mn, hn, Gn)
        if reflected != 0.0:  # skipped at zero: hydraulic results stay bit for bit
            _add_reflected_mass(reflected, J_leg[i], leg_bias, Mn, hn)
    _to_pose_coordinates(q, qd, E, Mn, hn, Gn, M, h, G, J_leg, J_joint)


def _body_terms(params, R, omega, Mn, hn, Gn):
    """The moving body's share into the twist-coordinate ``Mn``, ``hn``, ``Gn`` (Newton-Euler about
    the reference point, c = R c_body, I = R I_body R^T): M = [[m 1, -m [c]x], [m [c]x, I]],
    h = [m omega x (omega x c), omega x (I omega)], G = -[m g e_z, c x m g e_z].
    """
    m = params[layout.MASS]
    ixx, iyy, izz = params[layout.IXX], params[layout.IYY], params[layout.IZZ]
    ixy, ixz, iyz = params[layout.IXY], params[layout.IXZ], params[layout.IYZ]
    cb0, cb1, cb2 = params[layout.COM_X], params[layout.COM_Y], params[layout.COM_Z]
    for k in range(3):
        Mn[k, k] = m
    for a in range(3):
        Ra0, Ra1, Ra2 = R[3 * a], R[3 * a + 1], R[3 * a + 2]
        for b in range(3):
            Rb0, Rb1, Rb2 = R[3 * b], R[3 * b + 1], R[3 * b + 2]
            # the diagonal part first, summed as for a platform alone
            Mn[3 + a, 3 + b] = ((Ra0 * ixx * Rb0 + Ra1 * iyy * Rb1 + Ra2 * izz * Rb2)
                                + (ixy * (Ra0 * Rb1 + Ra1 * Rb0) + ixz * (Ra0 * Rb2 + Ra2 * Rb0)
                                   + iyz * (Ra1 * Rb2 + Ra2 * Rb1)))
    # first moment m c in the world frame, and the coupling blocks -m [c]x and m [c]x
    s0 = m * (R[0] * cb0 + R[1] * cb1 + R[2] * cb2)
    s1 = m * (R[3] * cb0 + R[4] * cb1 + R[5] * cb2)
    s2 = m * (R[6] * cb0 + R[7] * cb1 + R[8] * cb2)
    Mn[0, 4], Mn[0, 5], Mn[1, 3], Mn[1, 5], Mn[2, 3], Mn[2, 4] = s2, -s1, -s2, s0, s1, -s0
    Mn[4, 0], Mn[5, 0], Mn[3, 1], Mn[5, 1], Mn[3, 2], Mn[4, 2] = s2, -s1, -s2, s0, s1, -s0
    ws0 = omega[1] * s2 - omega[2] * s1
    ws1 = omega[2] * s0 - omega[0] * s2
    ws2 = omega[0] * s1 - omega[1] * s0
    hn[0] = omega[1] * ws2 - omega[2] * ws1
    hn[1] = omega[2] * ws0 - omega[0] * ws2
    hn[2] = omega[0] * ws1 - omega[1] * ws0
    Iwo0 = Mn[3, 3] * omega[0] + Mn[3, 4] * omega[1] + Mn[3, 5] * omega[2]
    Iwo1 = Mn[4, 3] * omega[0] + Mn[4, 4] * omega[1] + Mn[4, 5] * omega[2]
    Iwo2 = Mn[5, 3] * omega[0] + Mn[5, 4] * omega[1] + Mn[5, 5] * omega[2]
    hn[3] = omega[1] * Iwo2 - omega[2] * Iwo1
    hn[4] = omega[2] * Iwo0 - omega[0] * Iwo2
    hn[5] = omega[0] * Iwo1 - omega[1] * Iwo0
    Gn[2], Gn[3], Gn[4] = body_gravity(R, params[layout.GRAVITY], m, cb0, cb1, cb2)


def _leg_kinematics(params, R, q, qd, omega, a, b, J_leg_row, J_joint_leg, Jcl, Jcu, Jw,
                    acl, acu, wd):
    """One leg's J_leg row, joint and velocity Jacobians into the arguments; returns its length (m)
    and the leg acceleration at zero twist rate, u . (omega x (omega x r)) + l |u_dot|^2 (m/s^2).
    """
    d_u, d_l = params[layout.D_UPPER], params[layout.D_LOWER]
    r0, r1, r2, u0, u1, u2, l = leg_vector(R, q[0], q[1], q[2], a[0], a[1], a[2],
                                           b[0], b[1], b[2])
    # velocity of the upper joint (qd[:3] + omega x r), the leg-length rate and u's rate
    v0 = qd[0] + (omega[1] * r2 - omega[2] * r1)
    v1 = qd[1] + (omega[2] * r0 - omega[0] * r2)
    v2 = qd[2] + (omega[0] * r1 - omega[1] * r0)
    ld = u0 * v0 + u1 * v1 + u2 * v2
    ud0, ud1, ud2 = (v0 - ld * u0) / l, (v1 - ld * u1) / l, (v2 - ld * u2) / l
    # acceleration of the upper joint at zero twist rate: omega x (omega x r)
    wr0 = omega[1] * r2 - omega[2] * r1
    wr1 = omega[2] * r0 - omega[0] * r2
    wr2 = omega[0] * r1 - omega[1] * r0
    aA = (omega[1] * wr2 - omega[2] * wr1, omega[2] * wr0 - omega[0] * wr2,
          omega[0] * wr1 - omega[1] * wr0)
    u = (u0, u1, u2)
    udot = (ud0, ud1, ud2)
    uu = ud0 * ud0 + ud1 * ud1 + ud2 * ud2
    ua = u0 * aA[0] + u1 * aA[1] + u2 * aA[2]
    for k in range(3):
        # P aA with P = I - u u^T
        udd = ((aA[k] - u[k] * ua) - l * uu * u[k] - 2.0 * ld * udot[k]) / l
        acl[k] = d_l * udd
        acu[k] = aA[k] - d_u * udd
        wd[k] = udd  # crossed with u below
    wd0 = u1 * wd[2] - u2 * wd[1]
    wd1 = u2 * wd[0] - u0 * wd[2]
    wd2 = u0 * wd[1] - u1 * wd[0]
    wd[0], wd[1], wd[2] = wd0, wd1, wd2
    frame = leg_frame(u0, u1, u2)
    for c in range(6):
        b0, b1, b2 = twist_column(c, r0, r1, r2, 0.0, 1.0)
        rate = leg_rate(u0, u1, u2, b0, b1, b2)
        J_leg_row[c] = rate
        w0, w1, w2 = leg_angular_rate(u0, u1, u2, b0, b1, b2, l)
        Jw[0, c], Jw[1, c], Jw[2, c] = w0, w1, w2
        _, Jcl[0, c], Jcu[0, c] = centre_of_mass_rates(b0, u0, rate, l, d_u, d_l)
        _, Jcl[1, c], Jcu[1, c] = centre_of_mass_rates(b1, u1, rate, l, d_u, d_l)
        _, Jcl[2, c], Jcu[2, c] = centre_of_mass_rates(b2, u2, rate, l, d_u, d_l)
        rows = joint_rate_column(c, frame, u0, u1, u2, w0, w1, w2)
        for j in range(N_JOINTS):
            J_joint_leg[j, c] = rows[j]
    return l, ua + l * uu


def _add_leg_inertia(params, Jcl, Jcu, Jw, acl, acu, wd, Mn, hn, Gn):
    """Add one leg's two parts to ``Mn``, ``hn``, ``Gn`` (Kane's method)."""
    m_u, m_l = params[layout.M_UPPER], params[layout.M_LOWER]
    I_leg = params[layout.I_UPPER] + params[layout.I_LOWER]
    g = params[layout.GRAVITY]
    for a in range(6):
        for b in range(6):
            s = 0.0
            for k in range(3):
                s += (m_l * Jcl[k, a] * Jcl[k, b] + m_u * Jcu[k, a] * Jcu[k, b]
                      + I_leg * Jw[k, a] * Jw[k, b])
            Mn[a, b] += s
        s = 0.0
        for k in range(3):
            s += m_l * Jcl[k, a] * acl[k] + m_u * Jcu[k, a] * acu[k] + I_leg * Jw[k, a] * wd[k]
        hn[a] += s
        Gn[a] -= leg_gravity(g, m_u, m_l, Jcl[2, a], Jcu[2, a])


def _add_reflected_mass(mass, J_leg_row, leg_bias, Mn, hn):
    """Add one leg's reflected mass m_r (kg), moving with the leg length, to ``Mn`` and ``hn``.

    Its inertial force along the leg is m_r l_ddot, l_ddot = J_leg nu_dot + ``leg_bias``; its
    weight is carried by the leg's housing, so it adds no gravity term.
    """
    for a in range(6):
        for b in range(6):
            Mn[a, b] += mass * J_leg_row[a] * J_leg_row[b]
        hn[a] += mass * J_leg_row[a] * leg_bias


def _to_pose_coordinates(q, qd, E, Mn, hn, Gn, M, h, G, J_leg, J_joint):
    """Twist to q coordinates, T = blockdiag(I, E): M = T^T Mn T, h = T^T (hn + Mn bias), G = T^T Gn,
    J = J T.
    """
    bias = euler_rate_map_derivative_product(q[4], q[5], qd[3:])
    for a in range(6):
        hn[a] += Mn[a, 3] * bias[0] + Mn[a, 4] * bias[1] + Mn[a, 5] * bias[2]
    for a in range(6):  # Mn T, in place
        Mn[a, 3], Mn[a, 4], Mn[a, 5] = euler_columns(Mn[a, 3], Mn[a, 4], Mn[a, 5], E)
    for b in range(6):
        M[0, b], M[1, b], M[2, b] = Mn[0, b], Mn[1, b], Mn[2, b]
        M[3, b], M[4, b], M[5, b] = euler_columns(Mn[3, b], Mn[4, b], Mn[5, b], E)
    for a in range(3):
        h[a] = hn[a]
        G[a] = Gn[a]
    h[3], h[4], h[5] = euler_columns(hn[3], hn[4], hn[5], E)
    G[3], G[4], G[5] = euler_columns(Gn[3], Gn[4], Gn[5], E)
    for i in range(6):
        J_leg[i, 3], J_leg[i, 4], J_leg[i, 5] = euler_columns(
            J_leg[i, 3], J_leg[i, 4], J_leg[i, 5], E)
        for j in range(N_JOINTS):
            J_joint[i, j, 3], J_joint[i, j, 4], J_joint[i, j, 5] = euler_columns(
                J_joint[i, j, 3], J_joint[i, j, 4], J_joint[i, j, 5], E)


def joint_friction_torque(rate, gimbal, viscous, coulomb, smoothing):
    """Friction torque (N m) of one axis at ``rate`` (rad/s): viscous if ``gimbal``, Coulomb
    c r / sqrt(r^2 + s^2).
    """
    tau = 0.0
    if coulomb > 0.0:
        tau = coulomb * rate / math.sqrt(rate * rate + smoothing * smoothing)
    if gimbal:
        tau += viscous * rate
    return tau


def joint_friction(params, J_joint, qd, smoothing):
    """Generalized joint friction forces (N, N m) at one sample."""
    F = np.zeros(6)
    for i in range(6):
        for j in range(N_JOINTS):
            rate = J_joint[i, j] @ qd
            F += joint_friction_torque(rate, j < N_GIMBAL_AXES, params[layout.VISCOUS],
                                       params[layout.COULOMB], smoothing) * J_joint[i, j]
    return F


def leg_friction(params, J_leg, qd, smoothing):
    """Generalized forces (N, N m) of the friction along the legs at one sample: J_lq^T (c l_dot +
    Fc l_dot / sqrt(l_dot^2 + s^2)), the joints' law with the leg rate l_dot (m/s), s in m/s.
    """
    F = np.zeros(6)
    viscous, coulomb = params[layout.LEG_VISCOUS], params[layout.LEG_COULOMB]
    if viscous == 0.0 and coulomb == 0.0:
        return F
    for i in range(6):
        rate = J_leg[i] @ qd
        F += joint_friction_torque(rate, True, viscous, coulomb, smoothing) * J_leg[i]
    return F


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
        rhs -= leg_friction(params, Jl, qd, smoothing)
    return np.linalg.solve(M, rhs)


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


def batch_friction(params, J_joint, qd, smoothing):
    """joint_friction over samples."""
    n = qd.shape[0]
    F = np.empty((n, 6))
    for k in range(n):
        F[k] = joint_friction(params, J_joint[k], qd[k], smoothing)
    return F


def batch_leg_friction(params, J_leg, qd, smoothing):
    """leg_friction over samples."""
    n = qd.shape[0]
    F = np.empty((n, 6))
    for k in range(n):
        F[k] = leg_friction(params, J_leg[k], qd[k], smoothing)
    return F
