"""Sensors: sampling, leg-length and actuator-force measurement errors, forward kinematics.

A measurement is quantise(true + bias + noise): Gaussian noise of standard deviation
``*_noise`` drawn from a seeded generator, a constant ``*_bias`` and rounding to a multiple
of ``*_resolution`` (none when 0). The force sensor stands for the two pressure transducers
of a leg (f = p_A A_A - p_B A_B); its errors are given in newtons. The measured pose is the
forward kinematics of the measured leg lengths, as on a real hexapod without pose sensors.
"""

from __future__ import annotations

import dataclasses

import numpy as np

from stewartid.errors import ConfigError
from stewartid.model.dynamics import inverse_dynamics
from stewartid.model.kinematics import forward_kinematics
from stewartid.platform import Platform
from stewartid.platform.sections import Sensors


@dataclasses.dataclass(frozen=True)
class SensorNoise:
    """Measurement errors of the leg-length and force sensors (all zero: ideal sensors).

    Attributes
    ----------
    length_noise, length_bias, length_resolution : float
        m (standard deviation, offset, quantisation step).
    force_noise, force_bias, force_resolution : float
        N.
    """

    length_noise: float = 0.0
    length_bias: float = 0.0
    length_resolution: float = 0.0
    force_noise: float = 0.0
    force_bias: float = 0.0
    force_resolution: float = 0.0

    def __post_init__(self) -> None:
        for f in dataclasses.fields(self):
            value = float(getattr(self, f.name))
            if not np.isfinite(value) or ("bias" not in f.name and value < 0):
                raise ConfigError(f"sensor {f.name} must be a finite value >= 0; got {value!r}.")
            object.__setattr__(self, f.name, value)

    @classmethod
    def from_sensors(cls, sensors: Sensors) -> SensorNoise:
        """The errors declared in a platform's ``[sensors]`` section."""
        return cls(**{f.name: getattr(sensors, f.name) for f in dataclasses.fields(cls)})

    @property
    def is_ideal(self) -> bool:
        """True when every error is zero."""
        return all(getattr(self, f.name) == 0.0 for f in dataclasses.fields(self))


#: The reference sensor noise (``stewartid simulate --noise``, ``noise_scale = 1`` in a
#: study): leg-length standard deviation (m) and force standard deviation as a fraction of
#: the static leg force at neutral (-).
REFERENCE_LENGTH_NOISE_M = 20e-6
REFERENCE_FORCE_NOISE = 0.005


def static_leg_force(platform: Platform) -> float:
    """Mean actuator force (N) holding the platform at rest at its neutral pose."""
    zero = np.zeros(6)
    return float(np.mean(np.abs(inverse_dynamics(platform, platform.neutral_pose, zero, zero))))


def reference_noise(platform: Platform, scale: float = 1.0) -> SensorNoise:
    """The platform's ``[sensors]`` errors with the noise set to ``scale`` times the reference.

    The reference is 20 µm on the leg lengths and 0.5 % of the static leg force
    (:func:`static_leg_force`) on the forces; biases and resolutions stay the platform's.

    Parameters
    ----------
    platform : Platform
    scale : float
        Multiple of the reference noise (-), >= 0; 0 gives noise-free lengths and forces.
    """
    if not (np.isfinite(scale) and scale >= 0):
        raise ConfigError(f"noise scale must be a finite number >= 0; got {scale!r}.")
    return dataclasses.replace(
        SensorNoise.from_sensors(platform.sensors),
        length_noise=scale * REFERENCE_LENGTH_NOISE_M,
        force_noise=scale * REFERENCE_FORCE_NOISE * static_leg_force(platform))


#: When :func:`sensor_noise` takes the reference noise of a channel instead of ``[sensors]``:
#: never, always, or only where ``[sensors]`` declares no noise.
REFERENCE_CHOICES = ("never", "always", "where_zero")


def sensor_noise(platform: Platform, reference: str = "never", length_noise: float | None = None,
                 force_noise: float | None = None) -> SensorNoise:
    """The sensor errors of a run: the platform's ``[sensors]``, the reference noise
    (:func:`reference_noise`) where ``reference`` asks, then the given standard deviations.

    Parameters
    ----------
    platform : Platform
    reference : {"never", "always", "where_zero"}
        Take the reference noise standard deviation of a channel never, always
        (``simulate --noise``), or where ``[sensors]`` declares none (``design``).
    length_noise : float, optional
        Leg-length noise standard deviation (m), overriding the above.
    force_noise : float, optional
        Force noise standard deviation (N), overriding the above.

    Returns
    -------
    SensorNoise
        Biases and resolutions are always the platform's.

    Raises
    ------
    ConfigError
        On an unknown ``reference`` or a negative or non-finite standard deviation.
    """
    if reference not in REFERENCE_CHOICES:
        raise ConfigError(f"reference must be one of {', '.join(REFERENCE_CHOICES)}; got "
                          f"{reference!r}.")
    noise = SensorNoise.from_sensors(platform.sensors)
    if reference != "never":
        standard, always = reference_noise(platform), reference == "always"
        noise = dataclasses.replace(
            noise,
            length_noise=noise.length_noise if noise.length_noise and not always
            else standard.length_noise,
            force_noise=noise.force_noise if noise.force_noise and not always
            else standard.force_noise)
    changes = {name: value for name, value in (("length_noise", length_noise),
                                               ("force_noise", force_noise)) if value is not None}
    return dataclasses.replace(noise, **changes) if changes else noise


def measure(true: np.ndarray, noise: float, bias: float, resolution: float,
            rng: np.random.Generator) -> np.ndarray:
    """quantise(true + bias + N(0, noise^2)) element-wise; same shape as ``true``."""
    out = np.asarray(true, dtype=float) + bias
    if noise > 0:
        out = out + rng.normal(0.0, noise, size=out.shape)
    if resolution > 0:
        out = resolution * np.round(out / resolution)
    return out


def measure_legs(lengths: np.ndarray, forces: np.ndarray, noise: SensorNoise,
                 rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
    """Measured leg lengths (m) and forces (N), both (N, 6), from the true ones."""
    return (measure(lengths, noise.length_noise, noise.length_bias, noise.length_resolution,
                    rng),
            measure(forces, noise.force_noise, noise.force_bias, noise.force_resolution, rng))


def measured_pose(platform: Platform, lengths: np.ndarray,
                  initial: np.ndarray | None = None) -> np.ndarray:
    """The forward-kinematics block: pose (N, 6) from measured leg lengths (N, 6).

    Newton iterations to a residual of 1e-12 m on the leg lengths, started from ``initial``
    (N, 6), e.g. the commanded poses that the controller knows, or from the neutral pose.
    """
    return forward_kinematics(platform, lengths, initial=initial, tolerance=1e-12)
