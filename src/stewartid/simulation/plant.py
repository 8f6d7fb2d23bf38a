"""The compiled closed loop (plant, joint friction, actuators, leg servos), fixed-step RK4 in one numba
loop. State y (48): q, q_dot, PID integrators (m s), spools, spool rates (1/s), p_A, p_B (Pa),
motor currents (A), six each. The leg ``drive`` chooses the states that move: hydraulic legs
freeze the currents, electric legs the valves and pressures, ideal actuators all three and apply
the demands.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from stewartid.model import compiled
from stewartid.model import parameters as layout
from stewartid.model.joints import N_GIMBAL_AXES, N_JOINTS
from stewartid.simulation.controller import pid_force, valve_command
from stewartid.simulation.electric import E_FORCE_CONSTANT, current_rate
from stewartid.simulation.hydraulics import H_MID, H_STROKE, actuator_force, pressure_rates

# state layout
S_Q, S_QD, S_Z, S_XV, S_VV, S_PA, S_PB, S_I = 0, 6, 12, 18, 24, 30, 36, 42
N_STATES = 48
#: States of hydraulic and ideal legs (the currents, last, stay zero).
N_HYDRAULIC_STATES = 42
#: The leg drives of :func:`rhs`: demanded force applied exactly, valve-controlled cylinder,
#: servo motor with its current loop.
DRIVE_IDEAL, DRIVE_HYDRAULIC, DRIVE_ELECTRIC = 0, 1, 2
H_VALVE_OMEGA, H_VALVE_ZETA = 10, 11

#: Status codes returned by :func:`integrate`.
STATUS_OK, STATUS_STROKE, STATUS_NONFINITE = 0, 1, 2


@njit(cache=True)
def _solve_spd(M: np.ndarray, b: np.ndarray, L: np.ndarray, out: np.ndarray) -> None:
    """Solve M x = b for a symmetric positive definite 6x6 M by Cholesky, without allocating."""
    n = 6
    for i in range(n):
        for j in range(i + 1):
            s = M[i, j]
            for k in range(j):
                s -= L[i, k] * L[j, k]
            if i == j:
                L[i, i] = math.sqrt(s)
            else:
                L[i, j] = s / L[j, j]
    for i in range(n):
        s = b[i]
        for k in range(i):
            s -= L[i, k] * out[k]
        out[i] = s / L[i, i]
    for i in range(n - 1, -1, -1):
        s = out[i]
        for k in range(i + 1, n):
            s -= L[k, i] * out[k]
        out[i] = s / L[i, i]


@njit(cache=True)
def _scratch():
    """Scratch arrays of :func:`rhs` after ``dy``."""
    return (np.empty((6, 6)), np.empty(6), np.empty(6), np.empty((6, 6)), np.empty((6, 5, 6)),
            np.empty(6), np.empty(6), np.empty(6), np.empty(6), np.empty(6), np.zeros((6, 6)),
            np.empty(6))


@njit(cache=True)
def rhs(y, dy, cmd_length, cmd_rate, cmd_force, params, upper, base, hp, cp, ep, drive,
        smoothing, M, h, G, J, Jj, lengths, rates, force, demand, work, chol, qdd):
    """Closed-loop state derivative into ``dy``, for this instant's commanded leg lengths (m), rates
    (m/s) and feed-forward (N), legs driven by ``drive`` (``DRIVE_*``); the remaining arrays are
    scratch outputs (model terms, leg forces).
    """
    q = y[S_Q:S_Q + 6]
    qd = y[S_QD:S_QD + 6]
    compiled.model_terms(params, upper, base, q, qd, M, h, G, J, Jj, lengths)
    for i in range(6):
        s = 0.0
        for c in range(6):
            s += J[i, c] * qd[c]
        rates[i] = s
    for i in range(6):
        f_d, z_dot = pid_force(cp, cmd_length[i] - lengths[i], cmd_rate[i] - rates[i],
                               y[S_Z + i], cmd_force[i])
        demand[i] = f_d
        dy[S_Z + i] = z_dot
        dy[S_I + i] = 0.0
        if drive == DRIVE_HYDRAULIC:
            xv = y[S_XV + i]
            vv = y[S_VV + i]
            pa = y[S_PA + i]
            pb = y[S_PB + i]
            f = actuator_force(hp, pa, pb)
            u = valve_command(cp, f_d, f)
            w = hp[H_VALVE_OMEGA]
            dy[S_XV + i] = vv
            dy[S_VV + i] = w * w * (u - xv) - 2.0 * hp[H_VALVE_ZETA] * w * vv
            dpa, dpb = pressure_rates(hp, xv, pa, pb, lengths[i], rates[i])
            dy[S_PA + i] = dpa
            dy[S_PB + i] = dpb
            force[i] = f
        elif drive == DRIVE_ELECTRIC:
            dy[S_XV + i] = 0.0
            dy[S_VV + i] = 0.0
            dy[S_PA + i] = 0.0
            dy[S_PB + i] = 0.0
            current = y[S_I + i]
            dy[S_I + i] = current_rate(ep, f_d, current)
            force[i] = ep[E_FORCE_CONSTANT] * current
        else:
            dy[S_XV + i] = 0.0
            dy[S_VV + i] = 0.0
            dy[S_PA + i] = 0.0
            dy[S_PB + i] = 0.0
            force[i] = f_d
    # generalized forces: J^T f - h - G - friction
    for c in range(6):
        s = -h[c] - G[c]
        for i in range(6):
            s += J[i, c] * force[i]
        work[c] = s
    viscous = params[layout.VISCOUS]
    coulomb = params[layout.COULOMB]
    for i in range(6):
        for j in range(N_JOINTS):
            w = 0.0
            for c in range(6):
                w += Jj[i, j, c] * qd[c]
            tau = compiled.joint_friction_torque(w, j < N_GIMBAL_AXES, viscous, coulomb, smoothing)
            for c in range(6):
                work[c] -= tau * Jj[i, j, c]
    leg_viscous = params[layout.LEG_VISCOUS]
    leg_coulomb = params[layout.LEG_COULOMB]
    if leg_viscous != 0.0 or leg_coulomb != 0.0:  # friction along the legs ([actuator])
        for i in range(6):
            f = compiled.joint_friction_torque(rates[i], True, leg_viscous, leg_coulomb, smoothing)
            for c in range(6):
                work[c] -= f * J[i, c]
    _solve_spd(M, work, chol, qdd)
    for c in range(6):
        dy[S_Q + c] = qd[c]
        dy[S_QD + c] = qdd[c]


@njit(cache=True)
def integrate(y0, step, substeps, n_out, cmd_length, cmd_rate, cmd_force, params, upper, base,
              hp, cp, ep, drive, smoothing):
    """Integrate the closed loop with RK4 (step h, s) and record every ``substeps`` steps, n_out samples.

    Commands (2 substeps (n_out - 1) + 1, 6) are on the half-step grid t = k h / 2; ``drive`` one of
    ``DRIVE_*``; ``smoothing`` in rad/s. Returns (status, where, leg, states
    (n_out, 48), qdd, lengths, rates, force, demand (n_out, 6)): status 0 ok, 1 leg ``leg`` left its
    stroke, 2 non-finite state; ``where`` the sample integration stopped at (n_out if finished).
    """
    n = N_STATES
    states = np.zeros((n_out, n))
    rec_qdd = np.zeros((n_out, 6))
    rec_len = np.zeros((n_out, 6))
    rec_rate = np.zeros((n_out, 6))
    rec_force = np.zeros((n_out, 6))
    rec_demand = np.zeros((n_out, 6))
    M, h, G, J, Jj, lengths, rates, force, demand, work, chol, qdd = _scratch()
    y = y0.copy()
    yt = np.empty(n)
    k1 = np.empty(n)
    k2 = np.empty(n)
    k3 = np.empty(n)
    k4 = np.empty(n)
    half_stroke = 0.5 * hp[H_STROKE]
    total = substeps * (n_out - 1)
    for s in range(total + 1):
        g = 2 * s
        rhs(y, k1, cmd_length[g], cmd_rate[g], cmd_force[g], params, upper, base, hp, cp,
            ep, drive, smoothing, M, h, G, J, Jj, lengths, rates, force, demand, work, chol,
            qdd)
        if s % substeps == 0:
            r = s // substeps
            states[r] = y
            for c in range(6):
                rec_qdd[r, c] = qdd[c]
                rec_len[r, c] = lengths[c]
                rec_rate[r, c] = rates[c]
                rec_force[r, c] = force[c]
                rec_demand[r, c] = demand[c]
            for i in range(6):
                if abs(lengths[i] - hp[H_MID]) > half_stroke:
                    return STATUS_STROKE, r, i, states, rec_qdd, rec_len, rec_rate, \
                        rec_force, rec_demand
            for c in range(n):
                if not math.isfinite(y[c]):
                    return STATUS_NONFINITE, r, -1, states, rec_qdd, rec_len, rec_rate, \
                        rec_force, rec_demand
        if s == total:
            break
        for c in range(n):
            yt[c] = y[c] + 0.5 * step * k1[c]
        rhs(yt, k2, cmd_length[g + 1], cmd_rate[g + 1], cmd_force[g + 1], params, upper, base,
            hp, cp, ep, drive, smoothing, M, h, G, J, Jj, lengths, rates, force, demand, work,
            chol, qdd)
        for c in range(n):
            yt[c] = y[c] + 0.5 * step * k2[c]
        rhs(yt, k3, cmd_length[g + 1], cmd_rate[g + 1], cmd_force[g + 1], params, upper, base,
            hp, cp, ep, drive, smoothing, M, h, G, J, Jj, lengths, rates, force, demand, work,
            chol, qdd)
        for c in range(n):
            yt[c] = y[c] + step * k3[c]
        rhs(yt, k4, cmd_length[g + 2], cmd_rate[g + 2], cmd_force[g + 2], params, upper, base,
            hp, cp, ep, drive, smoothing, M, h, G, J, Jj, lengths, rates, force, demand, work,
            chol, qdd)
        for c in range(n):
            y[c] += step / 6.0 * (k1[c] + 2.0 * k2[c] + 2.0 * k3[c] + k4[c])
    return STATUS_OK, n_out, -1, states, rec_qdd, rec_len, rec_rate, rec_force, rec_demand


@njit(cache=True)
def linearize(y0, scales, cmd_length, cmd_rate, cmd_force, params, upper, base, hp, cp, ep,
              drive, smoothing):
    """State matrix A = d(dy/dt)/dy (48, 48) at ``y0``, commands frozen, by central differences of
    steps ``scales`` (48,): O(scale^2) on the smooth right-hand side.
    """
    n = N_STATES
    M, h, G, J, Jj, lengths, rates, force, demand, work, chol, qdd = _scratch()
    plus = np.empty(n)
    minus = np.empty(n)
    y = y0.copy()
    A = np.empty((n, n))
    for j in range(n):
        e = scales[j]
        y[j] = y0[j] + e
        rhs(y, plus, cmd_length, cmd_rate, cmd_force, params, upper, base, hp, cp, ep, drive,
            smoothing, M, h, G, J, Jj, lengths, rates, force, demand, work, chol, qdd)
        y[j] = y0[j] - e
        rhs(y, minus, cmd_length, cmd_rate, cmd_force, params, upper, base, hp, cp, ep, drive,
            smoothing, M, h, G, J, Jj, lengths, rates, force, demand, work, chol, qdd)
        y[j] = y0[j]
        for i in range(n):
            A[i, j] = (plus[i] - minus[i]) / (2.0 * e)
    return A
