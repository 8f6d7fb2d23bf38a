"""Electric leg actuators (``[actuator] kind = "electric"``): a servo motor on a ball screw per leg.

Each motor's current follows its command through a first-order loop, i' = w_c (i_cmd - i), the
closed loop of a PI current controller tuned by pole-zero cancellation (K_p = L w_c, K_i = R w_c on
a winding of resistance R and inductance L, back-EMF fed forward), the usual tuning of servo
drives; the command is the leg servo's force demand over the force constant, within
+-peak_current. The leg force is force_constant i. The rotor and screw turn with the leg length
(a rigid screw), so their inertia is the reflected mass of the model, and the screw's friction the
friction along the leg: both are in the plant's dynamics already. The encoder reads the motor
angle, 2 pi (l - l_home) / screw_lead, in counts of ``encoder_resolution`` of leg travel.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from stewartid.platform.sections import (
    DEFAULT_CURRENT_BANDWIDTH,
    DEFAULT_ENCODER_RESOLUTION,
    Actuator,
)

# indices into the packed electric parameter vector
E_FORCE_CONSTANT, E_PEAK_CURRENT, E_OMEGA = range(3)

#: Largest RK4 step as a fraction of the current loop's time constant 1 / w_c: the step's
#: amplification of the loop's transient then differs from exp(-h w_c) by (h w_c)^5 / 120 < 3e-4,
#: and RK4 is stable up to h w_c = 2.78.
CURRENT_STEP_FRACTION = 0.5


def current_bandwidth(actuator: Actuator) -> float:
    """The current loop's -3 dB bandwidth (Hz): ``current_bandwidth`` or its default."""
    given = actuator.current_bandwidth
    return DEFAULT_CURRENT_BANDWIDTH if given is None else float(given)


def encoder_resolution(actuator: Actuator) -> float:
    """Leg travel per encoder count (m): ``encoder_resolution`` or its default; 0 for an ideal one."""
    given = actuator.encoder_resolution
    return DEFAULT_ENCODER_RESOLUTION if given is None else float(given)


def electric_parameters(actuator: Actuator) -> np.ndarray:
    """Pack the motors for the compiled plant: [force_constant (N/A), peak_current (A, inf when
    not given), w_c = 2 pi current_bandwidth (rad/s)]; zeros for a hydraulic ``actuator``.
    """
    if actuator.kind != "electric":
        return np.zeros(3)
    peak = math.inf if actuator.peak_current is None else float(actuator.peak_current)
    return np.array([float(actuator.force_constant), peak,
                     2.0 * math.pi * current_bandwidth(actuator)])


def force_limits(actuator: Actuator) -> tuple[float, float]:
    """(f_min, f_max) of the leg force (N): -+ force_constant peak_current, unbounded without one."""
    if actuator.peak_current is None:
        return -math.inf, math.inf
    f = float(actuator.force_constant) * float(actuator.peak_current)
    return -f, f


def largest_step(actuator: Actuator) -> float:
    """Largest integration step (s) that resolves the current loop: CURRENT_STEP_FRACTION / w_c."""
    return CURRENT_STEP_FRACTION / (2.0 * math.pi * current_bandwidth(actuator))


@njit(cache=True)
def current_rate(ep: np.ndarray, demand: float, current: float) -> float:
    """i' (A/s) of the current loop for a force demand (N) already within the force limits."""
    return ep[E_OMEGA] * (demand / ep[E_FORCE_CONSTANT] - current)


def step_response(t: np.ndarray, command: float, bandwidth_hz: float) -> np.ndarray:
    """The current loop's response (A) to a current step of ``command`` (A) at t = 0, at ``t`` (s):
    command (1 - exp(-2 pi f_c t)).
    """
    return command * -np.expm1(-2.0 * math.pi * bandwidth_hz * np.asarray(t, dtype=float))


def encoder_lengths(lengths: np.ndarray, resolution: float) -> np.ndarray:
    """Leg lengths (m) as the encoders give them: whole counts of ``resolution`` (m), homed at a
    length that is a whole number of counts; unchanged for an ideal encoder (0).
    """
    if resolution <= 0.0:
        return np.asarray(lengths, dtype=float).copy()
    return resolution * np.round(np.asarray(lengths, dtype=float) / resolution)


__all__ = ["CURRENT_STEP_FRACTION", "current_bandwidth", "current_rate", "electric_parameters",
           "encoder_lengths", "encoder_resolution", "force_limits", "largest_step",
           "step_response"]
