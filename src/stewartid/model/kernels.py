"""Per-sample kernels of the platform model, in plain Python: the one definition.

:mod:`stewartid.model.compiled` compiles every function here with numba; run as they are, they
give the same numbers for a handful of samples in a process that has not started numba's
code generator (importing numba and loading the cached machine code cost about 0.5 s).
The kernels call each other by their global names, which the compiled copies resolve to
the compiled kernels. Only what numba compiles belongs here.

One kernel, :func:`model_terms`, evaluates every pose-dependent term of the model at one
sample, so the simulator pays for the leg geometry once per right-hand-side call. The batched
functions of :mod:`stewartid.model.dynamics` loop over samples in compiled code around it; the
pose-only terms (leg lengths, J_lq, G, joint Jacobians) that kinematics, command tables and
identification need are computed by :mod:`stewartid.model.leg_terms` in numpy, equal to these to
the last bit.

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

#: Indices into the packed parameter vector built by Platform.parameters().
P_MASS, P_IXX, P_IYY, P_IZZ = 0, 1, 2, 3
P_M_UPPER, P_M_LOWER, P_D_UPPER, P_D_LOWER, P_I_UPPER, P_I_LOWER = 4, 5, 6, 7, 8, 9
P_VISCOUS, P_COULOMB, P_GRAVITY = 10, 11, 12

#: Joint axes per leg and which of them carry viscous friction (the gimbal axes).
N_JOINTS = 5
GIMBAL_AXES = (0, 1, 2, 3)


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


def _cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    out = np.empty(3)
    out[0] = a[1] * b[2] - a[2] * b[1]
    out[1] = a[2] * b[0] - a[0] * b[2]
    out[2] = a[0] * b[1] - a[1] * b[0]
    return out


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

    Notes
    -----
    Written with scalar loops and a handful of scratch arrays: the simulator calls it four
    times per integration step, and small-matrix products (BLAS calls) and temporaries
    would dominate its cost.
    """
    m = params[P_MASS]
    m_u, m_l = params[P_M_UPPER], params[P_M_LOWER]
    d_u, d_l = params[P_D_UPPER], params[P_D_LOWER]
    I_leg = params[P_I_UPPER] + params[P_I_LOWER]
    g = params[P_GRAVITY]

    R = rotation(q[3], q[4], q[5])
    E = euler_rate_map(q[4], q[5])
    omega = np.empty(3)
    for k in range(3):
        omega[k] = E[k, 0] * qd[3] + E[k, 1] * qd[4] + E[k, 2] * qd[5]

    Mn = np.zeros((6, 6))
    hn = np.zeros(6)
    Gn = np.zeros(6)
    # per-leg scratch
    r = np.empty(3)
    ui = np.empty(3)
    JA = np.empty((3, 6))
    Judot = np.empty((3, 6))
    Jw = np.empty((3, 6))
    Jcl = np.empty((3, 6))
    Jcu = np.empty((3, 6))
    vA = np.empty(3)
    udot = np.empty(3)
    aA = np.empty(3)
    udd = np.empty(3)
    acl = np.empty(3)
    acu = np.empty(3)
    wd = np.empty(3)
    w_rel = np.empty(3)

    # platform: M = diag(m, m, m, R Ib R^T), h = [0, omega x (Iw omega)]
    for k in range(3):
        Mn[k, k] = m
    for a in range(3):
        for b in range(3):
            Mn[3 + a, 3 + b] = (R[a, 0] * params[P_IXX] * R[b, 0]
                                + R[a, 1] * params[P_IYY] * R[b, 1]
                                + R[a, 2] * params[P_IZZ] * R[b, 2])
    Iwo0 = Mn[3, 3] * omega[0] + Mn[3, 4] * omega[1] + Mn[3, 5] * omega[2]
    Iwo1 = Mn[4, 3] * omega[0] + Mn[4, 4] * omega[1] + Mn[4, 5] * omega[2]
    Iwo2 = Mn[5, 3] * omega[0] + Mn[5, 4] * omega[1] + Mn[5, 5] * omega[2]
    hn[3] = omega[1] * Iwo2 - omega[2] * Iwo1
    hn[4] = omega[2] * Iwo0 - omega[0] * Iwo2
    hn[5] = omega[0] * Iwo1 - omega[1] * Iwo0
    Gn[2] = -m * g

    for i in range(6):
        l = _leg_geometry(R, upper, base, q, i, r, ui, JA)
        lengths[i] = l
        vA[0] = qd[0] + (omega[1] * r[2] - omega[2] * r[1])
        vA[1] = qd[1] + (omega[2] * r[0] - omega[0] * r[2])
        vA[2] = qd[2] + (omega[0] * r[1] - omega[1] * r[0])
        ld = ui[0] * vA[0] + ui[1] * vA[1] + ui[2] * vA[2]
        for k in range(3):
            udot[k] = (vA[k] - ld * ui[k]) / l
        # aA = omega x (omega x r)
        wr0 = omega[1] * r[2] - omega[2] * r[1]
        wr1 = omega[2] * r[0] - omega[0] * r[2]
        wr2 = omega[0] * r[1] - omega[1] * r[0]
        aA[0] = omega[1] * wr2 - omega[2] * wr1
        aA[1] = omega[2] * wr0 - omega[0] * wr2
        aA[2] = omega[0] * wr1 - omega[1] * wr0
        uu = udot[0] * udot[0] + udot[1] * udot[1] + udot[2] * udot[2]
        ua = ui[0] * aA[0] + ui[1] * aA[1] + ui[2] * aA[2]
        for k in range(3):
            # P aA with P = I - u u^T
            udd[k] = ((aA[k] - ui[k] * ua) - l * uu * ui[k] - 2.0 * ld * udot[k]) / l
        for c in range(6):
            uJ = ui[0] * JA[0, c] + ui[1] * JA[1, c] + ui[2] * JA[2, c]
            J_leg[i, c] = uJ
            for k in range(3):
                Judot[k, c] = (JA[k, c] - ui[k] * uJ) / l
            Jw[0, c] = (ui[1] * JA[2, c] - ui[2] * JA[1, c]) / l
            Jw[1, c] = (ui[2] * JA[0, c] - ui[0] * JA[2, c]) / l
            Jw[2, c] = (ui[0] * JA[1, c] - ui[1] * JA[0, c]) / l
            for k in range(3):
                Jcl[k, c] = d_l * Judot[k, c]
                Jcu[k, c] = JA[k, c] - d_u * Judot[k, c]
        for k in range(3):
            acl[k] = d_l * udd[k]
            acu[k] = aA[k] - d_u * udd[k]
        wd[0] = ui[1] * udd[2] - ui[2] * udd[1]
        wd[1] = ui[2] * udd[0] - ui[0] * udd[2]
        wd[2] = ui[0] * udd[1] - ui[1] * udd[0]
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
            Gn[a] -= g * (m_l * Jcl[2, a] + m_u * Jcu[2, a])
        _joint_axes(ui, Jw, w_rel, J_joint[i])

    # map the twist equations to q coordinates: nu = T qd, nu_dot = T qdd + [0, Edot rates],
    # T = blockdiag(I, E); M = T^T Mn T, h = T^T (hn + Mn bias), G = T^T Gn, J = J T
    bias = euler_rate_map_derivative_product(q[4], q[5], qd[3:])
    for a in range(6):
        hn[a] += Mn[a, 3] * bias[0] + Mn[a, 4] * bias[1] + Mn[a, 5] * bias[2]
    MT = np.empty((6, 6))  # Mn T
    for a in range(6):
        for b in range(3):
            MT[a, b] = Mn[a, b]
            MT[a, 3 + b] = Mn[a, 3] * E[0, b] + Mn[a, 4] * E[1, b] + Mn[a, 5] * E[2, b]
    for b in range(6):
        for a in range(3):
            M[a, b] = MT[a, b]
            M[3 + a, b] = E[0, a] * MT[3, b] + E[1, a] * MT[4, b] + E[2, a] * MT[5, b]
    for a in range(3):
        h[a] = hn[a]
        G[a] = Gn[a]
        h[3 + a] = E[0, a] * hn[3] + E[1, a] * hn[4] + E[2, a] * hn[5]
        G[3 + a] = E[0, a] * Gn[3] + E[1, a] * Gn[4] + E[2, a] * Gn[5]
    for i in range(6):
        _rotation_columns(J_leg[i], E)
        for j in range(N_JOINTS):
            _rotation_columns(J_joint[i, j], E)


def _leg_geometry(R, upper, base, q, i, r, u, JA):
    """Leg i: r = R upper_i, unit leg vector u (into ``r``, ``u``, (3,)), J_A = [I, -[r]x]
    (velocity of the upper joint point from the twist, into ``JA`` (3, 6)); returns the leg
    length (m)."""
    s = 0.0
    for k in range(3):
        r[k] = R[k, 0] * upper[i, 0] + R[k, 1] * upper[i, 1] + R[k, 2] * upper[i, 2]
        u[k] = q[k] + r[k] - base[i, k]
        s += u[k] * u[k]
    length = math.sqrt(s)
    for k in range(3):
        u[k] /= length
    for k in range(3):
        for c in range(6):
            JA[k, c] = 0.0
    JA[0, 0] = 1.0
    JA[1, 1] = 1.0
    JA[2, 2] = 1.0
    JA[0, 4] = r[2]
    JA[0, 5] = -r[1]
    JA[1, 3] = -r[2]
    JA[1, 5] = r[0]
    JA[2, 3] = r[1]
    JA[2, 4] = -r[0]
    return length


def _joint_axes(u, Jw, w_rel, J_joint_leg):
    """Rates of a leg's five joint axes per twist component (into ``J_joint_leg`` (5, 6)),
    from its unit vector ``u`` and angular-velocity Jacobian ``Jw`` (3, 6); ``w_rel`` (3,) is
    scratch. Leg frame e1 = unit(z x u), e2 = u x e1."""
    nx, ny = -u[1], u[0]
    nn = math.sqrt(nx * nx + ny * ny)
    e10, e11 = nx / nn, ny / nn
    e20 = -u[2] * e11
    e21 = u[2] * e10
    e22 = u[0] * e11 - u[1] * e10
    for c in range(6):
        for k in range(3):
            w_rel[k] = -Jw[k, c]
        if c >= 3:
            w_rel[c - 3] += 1.0
        J_joint_leg[0, c] = e10 * Jw[0, c] + e11 * Jw[1, c]
        J_joint_leg[1, c] = e20 * Jw[0, c] + e21 * Jw[1, c] + e22 * Jw[2, c]
        J_joint_leg[2, c] = e10 * w_rel[0] + e11 * w_rel[1]
        J_joint_leg[3, c] = e20 * w_rel[0] + e21 * w_rel[1] + e22 * w_rel[2]
        J_joint_leg[4, c] = u[0] * w_rel[0] + u[1] * w_rel[1] + u[2] * w_rel[2]


def _rotation_columns(row, E):
    """Map the angular part of a twist row (6,) to Euler-angle rates in place: row[3:] E."""
    x0 = row[3]
    x1 = row[4]
    x2 = row[5]
    for b in range(3):
        row[3 + b] = x0 * E[0, b] + x1 * E[1, b] + x2 * E[2, b]


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
