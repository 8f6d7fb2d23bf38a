"""Hydraulic leg actuators (``[hydraulics]``; Merritt 1967): second-order servo-valve spool
x_v'' = w_v^2 (u - x_v) - 2 zeta_v w_v x_v', u in [-1, 1]; critically lapped turbulent orifices;
compressible chambers with internal leakage; force f = p_A A_A - p_B A_B.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from stewartid.errors import ConfigError
from stewartid.platform.sections import Hydraulics

# indices into the packed hydraulic parameter vector
H_AREA_A, H_AREA_B, H_SUPPLY, H_RETURN, H_BULK, H_DEAD, H_STROKE, H_MID = range(8)
H_GAIN, H_TRANSITION, H_VALVE_OMEGA, H_VALVE_ZETA, H_LEAK = range(8, 13)


def hydraulic_parameters(hydraulics: Hydraulics, mid_stroke_length: float) -> np.ndarray:
    """Pack ``[hydraulics]`` for the compiled plant, ``mid_stroke_length`` the neutral leg length (m):
    [A_A, A_B, p_s, p_r, beta, V_0, S, l_mid, K, p_t, w_v, zeta_v, C_i] (SI),
    K = Q_rated / sqrt(dp_rated / 2).
    """
    h = hydraulics
    gain = h.valve_rated_flow / math.sqrt(h.valve_rated_pressure_drop / 2.0)
    return np.array([
        h.piston_area, h.annulus_area, h.supply_pressure, h.return_pressure, h.bulk_modulus,
        h.dead_volume, h.stroke, mid_stroke_length, gain, h.orifice_transition_pressure,
        2.0 * math.pi * h.valve_bandwidth, h.valve_damping, h.leakage,
    ])


@njit(cache=True)
def orifice(dp: float, transition: float) -> float:
    """Regularised signed square root: dp / (dp^2 + p_t^2)^(1/4) (Pa^0.5)."""
    return dp / math.sqrt(math.sqrt(dp * dp + transition * transition))


@njit(cache=True)
def valve_flows(hp: np.ndarray, xv: float, pA: float, pB: float) -> tuple[float, float]:
    """Flows into chambers A, B (m^3/s) at spool position ``xv`` (fraction), phi = :func:`orifice`:
    x_v >= 0: Q_A = K x_v phi(p_s - p_A), Q_B = -K x_v phi(p_B - p_r);
    x_v < 0: Q_A = K x_v phi(p_A - p_r), Q_B = -K x_v phi(p_s - p_B).
    """
    K = hp[H_GAIN]
    pt = hp[H_TRANSITION]
    if xv >= 0.0:
        qa = K * xv * orifice(hp[H_SUPPLY] - pA, pt)
        qb = -K * xv * orifice(pB - hp[H_RETURN], pt)
    else:
        qa = K * xv * orifice(pA - hp[H_RETURN], pt)
        qb = -K * xv * orifice(hp[H_SUPPLY] - pB, pt)
    return qa, qb


@njit(cache=True)
def chamber_volumes(hp: np.ndarray, length: float) -> tuple[float, float]:
    """Oil volumes (m^3) V_A = V_0 + A_A (S/2 + x), V_B = V_0 + A_B (S/2 - x), x from mid-stroke."""
    x = length - hp[H_MID]
    half = 0.5 * hp[H_STROKE]
    return hp[H_DEAD] + hp[H_AREA_A] * (half + x), hp[H_DEAD] + hp[H_AREA_B] * (half - x)


@njit(cache=True)
def pressure_rates(hp: np.ndarray, xv: float, pA: float, pB: float, length: float,
                   length_rate: float) -> tuple[float, float]:
    """Chamber pressure rates (Pa/s): p_A' = beta / V_A (Q_A - A_A x' - C_i (p_A - p_B)),
    p_B' = beta / V_B (Q_B + A_B x' + C_i (p_A - p_B)).
    """
    qa, qb = valve_flows(hp, xv, pA, pB)
    va, vb = chamber_volumes(hp, length)
    leak = hp[H_LEAK] * (pA - pB)
    dpa = hp[H_BULK] / va * (qa - hp[H_AREA_A] * length_rate - leak)
    dpb = hp[H_BULK] / vb * (qb + hp[H_AREA_B] * length_rate + leak)
    return dpa, dpb


@njit(cache=True)
def actuator_force(hp: np.ndarray, pA: float, pB: float) -> float:
    """Force along the leg (N, positive extends): p_A A_A - p_B A_B."""
    return pA * hp[H_AREA_A] - pB * hp[H_AREA_B]


def force_limits(hydraulics: Hydraulics) -> tuple[float, float]:
    """(f_min, f_max) at standstill (N): p_r A_A - p_s A_B and p_s A_A - p_r A_B."""
    h = hydraulics
    return (h.return_pressure * h.piston_area - h.supply_pressure * h.annulus_area,
            h.supply_pressure * h.piston_area - h.return_pressure * h.annulus_area)


def static_state(hp: np.ndarray, force: float, length: float) -> tuple[float, float, float]:
    """Spool position (fraction) and chamber pressures (Pa) that hold ``force`` (N) at rest.

    At rest the valve only feeds the leakage and both edges see the same drop, so p_A + p_B = p_s + p_r;
    ``length`` is unused (uniform per-leg signature).

    Raises
    ------
    ConfigError
        If the cylinder cannot hold ``force`` with the given supply pressure.
    """
    ps, pr = hp[H_SUPPLY], hp[H_RETURN]
    aa, ab = hp[H_AREA_A], hp[H_AREA_B]
    f_min, f_max = pr * aa - ps * ab, ps * aa - pr * ab
    if not f_min < force < f_max:
        raise ConfigError(
            f"the actuators cannot hold the static leg force {force:.4g} N: with the "
            f"[hydraulics] supply pressure and areas they reach [{f_min:.4g}, {f_max:.4g}] N; "
            "raise supply_pressure or bore_diameter."
        )
    pa = (force + (ps + pr) * ab) / (aa + ab)
    pb = ps + pr - pa
    leak = hp[H_LEAK] * (pa - pb)
    drop = ps - pa if pa >= pb else pa - pr
    xv = leak / (hp[H_GAIN] * orifice(drop, hp[H_TRANSITION]))
    return float(xv), float(pa), float(pb)


def hydraulic_natural_frequency(hydraulics: Hydraulics, effective_mass: float,
                                piston_position: float = 0.0) -> float:
    """Natural frequency w_h = sqrt(beta (A_A^2 / V_A + A_B^2 / V_B) / m) (rad/s) of one leg moving
    ``effective_mass`` (kg), volumes at ``piston_position`` (m from mid-stroke).
    """
    h = hydraulics
    va = h.dead_volume + h.piston_area * (h.stroke / 2 + piston_position)
    vb = h.dead_volume + h.annulus_area * (h.stroke / 2 - piston_position)
    stiffness = h.bulk_modulus * (h.piston_area ** 2 / va + h.annulus_area ** 2 / vb)
    return math.sqrt(stiffness / effective_mass)
