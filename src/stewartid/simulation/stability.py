"""Closed-loop equilibrium at rest and the poles of the loop linearised about it: an unstable servo
grows a limit cycle no rigid-body model explains, so every experiment is checked first.
"""

from __future__ import annotations

import numpy as np

from stewartid.errors import ConfigError
from stewartid.model.dynamics import COULOMB_SMOOTHING, ModelTerms
from stewartid.platform import Platform
from stewartid.simulation import plant
from stewartid.simulation.controller import command_tables, controller_parameters
from stewartid.simulation.electric import electric_parameters
from stewartid.simulation.hydraulics import hydraulic_parameters, static_state

#: Largest growth rate (1/s) accepted as numerically zero: an e-fold in 1000 s, longer than
#: any record.
GROWTH_TOLERANCE = 1e-3


def initial_state(platform: Platform, q0: np.ndarray, feedforward_force: np.ndarray,
                  hp: np.ndarray, cp: np.ndarray) -> np.ndarray:
    """Closed-loop equilibrium (48,) at rest at pose ``q0``: forces hold the pose, valves feed the
    leakage (electric legs: the motors carry the holding currents), integrators hold the demand;
    ``feedforward_force`` (6,) in N.

    Raises
    ------
    ConfigError
        If electric legs need more than their peak current to hold the pose.
    """
    t = ModelTerms(platform, q0)
    J, G = t.leg_jacobian[0], t.gravity[0]
    f0 = np.linalg.solve(J.T, G)
    y = np.zeros(plant.N_STATES)
    y[plant.S_Q:plant.S_Q + 6] = q0
    hydraulic = platform.hydraulic_legs
    demand = f0.copy()
    for i in range(6):
        if hydraulic:
            xv, pa, pb = static_state(hp, float(f0[i]), float(t.leg_lengths[0, i]))
            y[plant.S_XV + i] = xv
            y[plant.S_PA + i] = pa
            y[plant.S_PB + i] = pb
            demand[i] = f0[i] + xv / cp[3]
    if platform.electric_legs:
        y[plant.S_I:plant.S_I + 6] = f0 / platform.actuator.force_constant
        _require_holding_current(platform, f0)
    ki = cp[1]
    if ki > 0:
        y[plant.S_Z:plant.S_Z + 6] = (demand - feedforward_force) / ki
    return y


def _require_holding_current(platform: Platform, forces: np.ndarray) -> None:
    a = platform.actuator
    worst = float(np.max(np.abs(forces))) / a.force_constant
    if a.peak_current is not None and not worst < a.peak_current:
        raise ConfigError(
            f"the motors cannot hold the platform at rest: a leg needs {worst:.4g} A, above "
            f"[actuator] peak_current = {a.peak_current:g} A; raise peak_current or "
            "force_constant.")


def leg_drive(platform: Platform) -> int:
    """The plant's ``DRIVE_*`` code of the platform's legs (``[actuator]``, ``[hydraulics] mode``)."""
    if platform.hydraulic_legs:
        return plant.DRIVE_HYDRAULIC
    return plant.DRIVE_ELECTRIC if platform.electric_legs else plant.DRIVE_IDEAL


def _difference_steps(y0: np.ndarray) -> np.ndarray:
    steps = np.empty(plant.N_STATES)
    steps[plant.S_Q:plant.S_Q + 6] = 1e-7       # m, rad
    steps[plant.S_QD:plant.S_QD + 6] = 1e-7     # m/s, rad/s: below the Coulomb smoothing
    steps[plant.S_Z:plant.S_Z + 6] = 1e-9       # m s
    steps[plant.S_XV:plant.S_XV + 6] = 1e-7     # fraction of full opening
    steps[plant.S_VV:plant.S_VV + 6] = 1e-5     # 1/s
    steps[plant.S_PA:plant.S_PA + 12] = 1e-7 * np.maximum(np.abs(y0[plant.S_PA:plant.S_PB + 6]),
                                                          1e5)
    steps[plant.S_I:plant.S_I + 6] = 1e-7 * np.maximum(np.abs(y0[plant.S_I:]), 1.0)  # A
    return steps


def loop_poles(y0: np.ndarray, cmd_length: np.ndarray, cmd_rate: np.ndarray,
               cmd_force: np.ndarray, params: np.ndarray, upper: np.ndarray,
               base: np.ndarray, hp: np.ndarray, cp: np.ndarray, drive: int,
               smoothing: float = COULOMB_SMOOTHING, ep: np.ndarray | None = None) -> np.ndarray:
    """Eigenvalues (1/s) of the loop linearised at ``y0``, legs driven by ``drive`` (``DRIVE_*``,
    electric ones by the motors ``ep``): (42,) for hydraulic and ideal legs, frozen ideal-actuator
    states giving zeros; (24,) for electric legs, whose valves and pressures do not exist.
    """
    ep = np.zeros(3) if ep is None else ep
    A = plant.linearize(y0, _difference_steps(y0), cmd_length, cmd_rate, cmd_force, params,
                        upper, base, hp, cp, ep, int(drive), float(smoothing))
    if drive == plant.DRIVE_ELECTRIC:
        moving = np.r_[plant.S_Q:plant.S_Z + 6, plant.S_I:plant.S_I + 6]
    else:  # the currents' rows and columns are zero: the matrix of the hydraulic plant
        moving = np.arange(plant.N_HYDRAULIC_STATES)
    return np.linalg.eigvals(A[np.ix_(moving, moving)])


def closed_loop_poles(platform: Platform, pose: np.ndarray | None = None) -> np.ndarray:
    """Poles (1/s) of the servo loop linearised at rest at ``pose`` (neutral by default), by
    decreasing real part: (42,), or (24,) for electric legs (see :func:`loop_poles`); s = sigma + i w
    has damping -sigma / |s| and oscillates at w / (2 pi) Hz.
    """
    q0 = platform.neutral_pose if pose is None else np.asarray(pose, dtype=float)
    q0 = np.ascontiguousarray(q0, dtype=float).reshape(1, 6)
    params = platform.parameters()
    upper = np.ascontiguousarray(platform.upper_joints)
    base = np.ascontiguousarray(platform.base_joints)
    cmd_len, cmd_rate, cmd_force = command_tables(
        params, upper, base, q0, np.zeros_like(q0), bool(platform.controller.gravity_feedforward))
    hp = hydraulic_parameters(platform.hydraulics, platform.neutral_leg_length)
    cp = controller_parameters(platform)
    y0 = initial_state(platform, q0[0], cmd_force[0], hp, cp)
    poles = loop_poles(y0, cmd_len[0], cmd_rate[0], cmd_force[0], params, upper, base, hp, cp,
                       leg_drive(platform), ep=electric_parameters(platform.actuator))
    return poles[np.argsort(-poles.real)]


def require_stable(poles: np.ndarray, platform: Platform, where: str) -> None:
    """Raise if a pole grows faster than :data:`GROWTH_TOLERANCE`.

    Raises
    ------
    ConfigError
        Naming the unstable mode and the gains to lower.
    """
    worst = poles[np.argmax(poles.real)]
    if worst.real <= GROWTH_TOLERANCE:
        return
    c = platform.controller
    if platform.electric_legs:
        raise ConfigError(
            f"{where}: the leg servo loop is unstable (a mode at "
            f"{abs(worst.imag) / (2 * np.pi):.1f} Hz grows at {worst.real:.3g} 1/s) and would "
            "settle into a limit cycle; lower the [controller] PID gains (derivative_gain "
            f"{c.derivative_gain:g} N s/m, proportional_gain {c.proportional_gain:g} N/m) or "
            "raise [actuator] current_bandwidth.")
    raise ConfigError(
        f"{where}: the leg servo loop is unstable (a mode at {abs(worst.imag) / (2 * np.pi):.1f}"
        f" Hz grows at {worst.real:.3g} 1/s) and would settle into a limit cycle; lower "
        f"[controller] force_loop_gain (now {c.force_loop_gain:g} 1/N) or the PID gains "
        f"(proportional_gain {c.proportional_gain:g} N/m)."
    )
