"""Leg-length servo: continuous-time PID f_d = f_ff + K_p e + K_i z + K_d (l_cmd' - l'), z' = e,
e = l_cmd - l, clamped to the cylinder's range (electric legs: the motor's peak current), with
gravity feed-forward f_ff = J_lq^-T G(q_cmd); for hydraulic actuators an inner force loop
u = k_f (f_d - f) in [-1, 1], for electric ones the current command f_d / force_constant.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from stewartid.model.leg_terms import leg_terms
from stewartid.platform import Platform
from stewartid.simulation.electric import force_limits as electric_force_limits
from stewartid.simulation.hydraulics import force_limits

# indices into the packed controller parameter vector
C_KP, C_KI, C_KD, C_KF, C_FMIN, C_FMAX = range(6)


def controller_parameters(platform: Platform) -> np.ndarray:
    """Pack ``[controller]`` and the force limits: [K_p (N/m), K_i (N/(m s)), K_d (N s/m), k_f (1/N),
    f_min, f_max (N)]; the limits are the cylinders' stall forces, or for electric legs the motors'
    peak current times the force constant.
    """
    c = platform.controller
    if platform.actuator.kind == "electric":
        f_min, f_max = electric_force_limits(platform.actuator)
    else:
        f_min, f_max = force_limits(platform.hydraulics)
    return np.array([c.proportional_gain, c.integral_gain, c.derivative_gain,
                     c.force_loop_gain, f_min, f_max])


@njit(cache=True)
def pid_force(cp: np.ndarray, error: float, error_rate: float, integral: float,
              feedforward: float) -> tuple[float, float]:
    """Clamped force demand (N) and integrator input (m) of one leg; z stops while f_d saturates outward."""
    f = feedforward + cp[C_KP] * error + cp[C_KI] * integral + cp[C_KD] * error_rate
    z_dot = error
    if f > cp[C_FMAX]:
        f = cp[C_FMAX]
        if error > 0.0:
            z_dot = 0.0
    elif f < cp[C_FMIN]:
        f = cp[C_FMIN]
        if error < 0.0:
            z_dot = 0.0
    return f, z_dot


@njit(cache=True)
def valve_command(cp: np.ndarray, demand: float, force: float) -> float:
    """Inner force loop: valve opening in [-1, 1] for a force error (N)."""
    u = cp[C_KF] * (demand - force)
    if u > 1.0:
        return 1.0
    if u < -1.0:
        return -1.0
    return u


def command_tables(params, upper, base, q_cmd, qd_cmd, feedforward):
    """Leg-length commands (m), rates (m/s) and, if ``feedforward``, J_lq^-T G (N), each (N, 6), along
    commanded poses and rates ``q_cmd``, ``qd_cmd`` (N, 6).
    """
    G, J, lengths, _ = leg_terms(params, upper, base, np.ascontiguousarray(q_cmd))
    rates, forces = _rates_and_feedforward(J, G, np.ascontiguousarray(qd_cmd), feedforward)
    return lengths, rates, forces


@njit(cache=True)
def _rates_and_feedforward(J, G, qd_cmd, feedforward):
    n = qd_cmd.shape[0]
    rates = np.empty((n, 6))
    forces = np.zeros((n, 6))
    A = np.empty((6, 7))
    for k in range(n):
        for i in range(6):
            s = 0.0
            for c in range(6):
                s += J[k, i, c] * qd_cmd[k, c]
            rates[k, i] = s
        if feedforward:
            _solve_transposed(J[k], G[k], A, forces[k])
    return rates, forces


@njit(cache=True)
def _solve_transposed(J, b, A, x):
    """Solve J^T x = b (6x6) by partial pivoting into ``x`` (``A`` (6, 7) scratch; cheaper than LAPACK)."""
    n = 6
    for i in range(n):
        for j in range(n):
            A[i, j] = J[j, i]
        A[i, n] = b[i]
    for c in range(n):
        p = c
        for r in range(c + 1, n):
            if abs(A[r, c]) > abs(A[p, c]):
                p = r
        if p != c:
            for j in range(n + 1):
                A[c, j], A[p, j] = A[p, j], A[c, j]
        for r in range(c + 1, n):
            f = A[r, c] / A[c, c]
            for j in range(c, n + 1):
                A[r, j] -= f * A[c, j]
    for i in range(n - 1, -1, -1):
        s = A[i, n]
        for j in range(i + 1, n):
            s -= A[i, j] * x[j]
        x[i] = s / A[i, i]
