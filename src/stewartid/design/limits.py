"""Operating limits of a hexapod (:func:`resolve_limits`) and the fraction of each a motion
uses per sample (:func:`limit_use`, 1 = the limit).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping

import numpy as np

from stewartid.errors import ConfigError
from stewartid.model.dynamics import inverse_dynamics
from stewartid.model.kinematics import inverse_kinematics, rotation_matrix
from stewartid.platform import Platform
from stewartid.simulation.hydraulics import force_limits

#: The limits, in the order of the columns of :attr:`LimitUse.use`.
LIMIT_NAMES = ("stroke", "leg_velocity", "leg_acceleration", "actuator_force", "gimbal_angle")
#: Force use reported where an electric motor's current is at peak_current (saturated): the
#: motion asked for more than the limit, by an amount the clamped current no longer shows.
SATURATED_USE = 1.01
#: Relative distance to peak_current within which a current counts as saturated: the current
#: loop reaches its clamped command to 1e-6 within 2.2 time constants.
SATURATION_TOLERANCE = 1e-6


@dataclasses.dataclass(frozen=True)
class OperatingLimits:
    """The ``[limits]`` section with derived defaults filled in.

    Attributes
    ----------
    stroke_min, stroke_max : float
        Leg-length range (m).
    leg_velocity, leg_acceleration : float
        m/s, m/s^2.
    actuator_force : float
        N.
    gimbal_angle : float
        Deflection from the neutral leg direction at either gimbal (rad).
    neutral_length : float
        Leg length at neutral (m), the stroke use's reference.
    """

    stroke_min: float
    stroke_max: float
    leg_velocity: float
    leg_acceleration: float
    actuator_force: float
    gimbal_angle: float
    neutral_length: float

    def to_dict(self) -> dict[str, float]:
        """JSON-ready values."""
        return dataclasses.asdict(self)


def resolve_limits(platform: Platform) -> OperatingLimits:
    """The platform's limits, missing ones from its other sections: stroke centred on the neutral
    length, velocity from rated flow / piston area, force from the smaller stall force; for an
    electric ``[actuator]``, velocity screw_speed x screw_lead and force peak_current x
    force_constant when those are given.

    Raises
    ------
    ConfigError
        Neutral leg length outside [stroke_min, stroke_max].
    """
    given, hydraulics, actuator = platform.limits, platform.hydraulics, platform.actuator
    neutral = platform.neutral_leg_length
    f_min, f_max = force_limits(hydraulics)
    velocity = hydraulics.valve_rated_flow / hydraulics.piston_area
    force = min(abs(f_min), abs(f_max))
    if actuator.kind == "electric":
        if actuator.screw_speed is not None:  # [actuator] makes screw_lead given with it
            velocity = actuator.screw_speed * actuator.screw_lead
        if actuator.peak_current is not None:
            force = actuator.peak_current * actuator.force_constant
    limits = OperatingLimits(
        stroke_min=(neutral - hydraulics.stroke / 2 if given.stroke_min is None
                    else given.stroke_min),
        stroke_max=(neutral + hydraulics.stroke / 2 if given.stroke_max is None
                    else given.stroke_max),
        leg_velocity=velocity if given.leg_velocity is None else given.leg_velocity,
        leg_acceleration=given.leg_acceleration,
        actuator_force=force if given.actuator_force is None else given.actuator_force,
        gimbal_angle=given.gimbal_angle, neutral_length=neutral)
    if not limits.stroke_min < neutral < limits.stroke_max:
        raise ConfigError(
            f"[limits] the neutral leg length {neutral:.4f} m must lie inside [stroke_min, "
            f"stroke_max] = [{limits.stroke_min:.4f}, {limits.stroke_max:.4f}] m.")
    return limits


@dataclasses.dataclass(frozen=True)
class LimitUse:
    """Fraction of every limit used along a motion.

    Attributes
    ----------
    t : ndarray, shape (N,)
        s.
    use : ndarray, shape (N, 5)
        Largest |value| / limit over the legs per :data:`LIMIT_NAMES`; stroke from neutral
        toward the end the leg moves to.
    """

    t: np.ndarray
    use: np.ndarray

    @property
    def peak(self) -> dict[str, float]:
        """Largest use of every limit over the motion."""
        return {name: float(self.use[:, k].max()) for k, name in enumerate(LIMIT_NAMES)}

    @property
    def exceeded(self) -> list[str]:
        """Names of the limits used beyond 1."""
        return [name for name, value in self.peak.items() if value > 1.0]


def gimbal_angles(platform: Platform, q: np.ndarray) -> np.ndarray:
    """Deflection (N, 6, 2), rad, of every leg from neutral at the lower [..., 0] and upper [..., 1]
    gimbal, at poses ``q`` (N, 6).
    """
    q = np.atleast_2d(np.asarray(q, dtype=float))
    u = inverse_kinematics(platform, q).directions
    u0 = inverse_kinematics(platform, platform.neutral_pose).directions[0]
    body = np.einsum("nji,nkj->nki", rotation_matrix(q[:, 3:]), u)
    lower = np.arccos(np.clip(np.einsum("nki,ki->nk", u, u0), -1.0, 1.0))
    upper = np.arccos(np.clip(np.einsum("nki,ki->nk", body, u0), -1.0, 1.0))
    return np.stack([lower, upper], axis=-1)


def require_within_limits(platform: Platform, pose: np.ndarray, subject: str) -> None:
    """Refuse an absolute ``pose`` (6,) with a leg outside its stroke or a gimbal beyond
    ``[limits] gimbal_angle``; ``subject`` names it (``"--pose"``).

    Raises
    ------
    ConfigError
        Naming the leg, the limit and the neutral pose.
    """
    limits = resolve_limits(platform)
    q = np.asarray(pose, dtype=float).reshape(1, 6)
    lengths = inverse_kinematics(platform, q).lengths[0]
    neutral = ",".join(f"{v:g}" for v in platform.neutral_pose)
    hint = (f"give an absolute pose in the paper frame (m, rad, z down; neutral is {neutral})")
    leg = int(np.argmax(np.maximum(limits.stroke_min - lengths, lengths - limits.stroke_max)))
    if not limits.stroke_min <= lengths[leg] <= limits.stroke_max:
        raise ConfigError(
            f"{subject} is outside the workspace: leg {leg + 1} would be {lengths[leg]:.4g} m "
            f"long, outside its stroke {limits.stroke_min:.4g} to {limits.stroke_max:.4g} m; "
            f"{hint}.")
    angles = gimbal_angles(platform, q)[0]
    leg, end = np.unravel_index(np.argmax(angles), angles.shape)
    if not angles[leg, end] <= limits.gimbal_angle:
        raise ConfigError(
            f"{subject} is outside the workspace: the {('lower', 'upper')[end]} gimbal of leg "
            f"{leg + 1} would turn {angles[leg, end]:.3g} rad, beyond [limits] gimbal_angle = "
            f"{limits.gimbal_angle:g} rad; {hint}.")


def limit_use(platform: Platform, limits: OperatingLimits, t: np.ndarray, q: np.ndarray,
              lengths: np.ndarray, length_rates: np.ndarray,
              length_accelerations: np.ndarray, forces: np.ndarray) -> LimitUse:
    """Fraction of every limit used at every sample of a motion.

    Parameters
    ----------
    platform : Platform
    limits : OperatingLimits
    t : ndarray, shape (N,)
    q : ndarray, shape (N, 6)
        m, rad.
    lengths, length_rates, length_accelerations : ndarray, shape (N, 6)
        m, m/s, m/s^2.
    forces : ndarray, shape (N, 6)
        N.
    """
    stretch = lengths - limits.neutral_length
    stroke = np.where(stretch >= 0, stretch / (limits.stroke_max - limits.neutral_length),
                      -stretch / (limits.neutral_length - limits.stroke_min))
    use = np.column_stack([
        stroke.max(axis=1),
        np.abs(length_rates).max(axis=1) / limits.leg_velocity,
        np.abs(length_accelerations).max(axis=1) / limits.leg_acceleration,
        np.abs(forces).max(axis=1) / limits.actuator_force,
        gimbal_angles(platform, q).max(axis=(1, 2)) / limits.gimbal_angle,
    ])
    return LimitUse(t=np.asarray(t, dtype=float), use=use)


def rest_use(platform: Platform) -> dict[str, float]:
    """Use of every limit at rest at the neutral pose: the static leg forces' share of
    ``actuator_force``, zero for the others.
    """
    q = platform.neutral_pose.reshape(1, 6)
    zeros = np.zeros((1, 6))
    lengths = inverse_kinematics(platform, q).lengths
    return limit_use(platform, resolve_limits(platform), np.zeros(1), q, lengths, zeros, zeros,
                     inverse_dynamics(platform, q, zeros, zeros)).peak


def amplitude_scale(peak: Mapping[str, float], rest: Mapping[str, float], target: float
                    ) -> float:
    """Factor on a record's amplitudes that brings its most used limit to ``target``.

    Each limit's use is taken as affine in the amplitude, from its use at rest (:func:`rest_use`)
    to its ``peak``: the static leg forces do not scale with the motion, and on a light electric
    platform they are most of the force, so a proportional scale would leave the force use above
    the target after any number of rounds.

    Raises
    ------
    ConfigError
        When the platform at rest already uses ``target`` or more of a limit.
    """
    scales = []
    for name in LIMIT_NAMES:
        if peak[name] <= rest[name]:
            continue
        if rest[name] >= target:
            raise ConfigError(
                f"the platform at rest already uses {rest[name]:.0%} of its {name} limit, not "
                f"below the {target:.0%} a design may use; raise --max-use or check [limits] "
                "(or [actuator] peak_current).")
        scales.append((target - rest[name]) / (peak[name] - rest[name]))
    return min(scales, default=1.0)


def record_limit_use(platform: Platform, record) -> LimitUse:
    """Limit use of a simulated record's true states (leg accelerations by central differences).

    An electric leg's servo demand and current loop are held within peak_current, so a saturated
    motor's force reads the limit exactly while the motion asks for more: where a current sits at
    peak_current its force use is :data:`SATURATED_USE`, beyond 1, so that
    :attr:`LimitUse.exceeded` names it and a design is scaled down from it.
    """
    accelerations = np.gradient(record.length_rates, record.t, axis=0)
    limits = resolve_limits(platform)
    use = limit_use(platform, limits, record.t, record.q, record.lengths, record.length_rates,
                    accelerations, record.forces)
    peak = platform.actuator.peak_current
    if getattr(record, "currents", None) is not None and peak is not None:
        saturated = np.any(np.abs(record.currents) >= (1.0 - SATURATION_TOLERANCE) * peak, axis=1)
        use.use[saturated, LIMIT_NAMES.index("actuator_force")] = SATURATED_USE
    return use
