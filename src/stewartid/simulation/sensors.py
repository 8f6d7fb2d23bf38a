"""Sensors: measured = quantise(true(t - delay) + bias + noise + hum + drift) on leg lengths and
forces (a leg's pressure transducers, in N), seeded; the pose is the forward kinematics of the
measured lengths, as on a rig without pose sensors.
"""

from __future__ import annotations

import dataclasses
from numbers import Integral
from typing import Any

import numpy as np

from stewartid.datasets.dataset import Dataset
from stewartid.errors import ConfigError
from stewartid.fields import FieldSpec, Interval, ListOf, check, field_spec, nonnegative, positive, spec
from stewartid.model.dynamics import inverse_dynamics
from stewartid.model.kinematics import forward_kinematics
from stewartid.platform import Platform
from stewartid.platform.sections import Sensors
from stewartid.simulation.electric import encoder_lengths
from stewartid.simulation.imperfections import (
    delay_signal,
    lowpass_noise,
    mains_hum,
    random_walk,
)

_SENSORS_FIELDS = {f.name: f for f in dataclasses.fields(Sensors)}


def _as_in_sensors(name: str) -> Any:
    """A field declared as the platform's ``[sensors] name``, default 0."""
    return dataclasses.field(default=0.0, metadata=_SENSORS_FIELDS[name].metadata)


#: Errors given either once for the six legs or as six values, one per leg.
PER_LEG = ("length_noise", "force_noise")
#: Settings that shape an error without being one (ideal sensors whatever their value).
SHAPES = ("force_lowpass_order", "hum_frequency")
#: The errors of the leg-length channels (any of them nonzero: the pose is recomputed).
LENGTH_ERRORS = ("length_noise", "length_bias", "length_resolution", "length_delay",
                 "length_drift")


@dataclasses.dataclass(frozen=True)
class SensorNoise:
    """Measurement errors of the leg-length and force sensors (defaults: ideal sensors).

    Errors are drawn in the order of the attributes, so switching on a hum or a drift leaves the
    noise of the same seed unchanged.

    Attributes
    ----------
    length_noise, force_noise : float or tuple of 6 float
        Standard deviation (m, N), per leg when six; the force noise white, or after ``force_lowpass``.
    length_bias, length_resolution, force_bias, force_resolution : float
        Offsets and quantisation steps (m, N).
    length_delay, force_delay : float
        Channel delay behind the motion (s).
    force_lowpass : float
        -3 dB cut-off of the Butterworth filter colouring the force noise (Hz); 0: white.
    force_lowpass_order : int
    hum_amplitude, hum_frequency : float
        Mains hum on every force channel (N, random phase per leg) and its frequency (Hz).
    length_drift, force_drift : float
        Standard deviation at the record's end of a random walk per channel (m, N).
    """

    length_noise: float | tuple[float, ...] = _as_in_sensors("length_noise")
    length_bias: float = _as_in_sensors("length_bias")
    length_resolution: float = _as_in_sensors("length_resolution")
    force_noise: float | tuple[float, ...] = _as_in_sensors("force_noise")
    force_bias: float = _as_in_sensors("force_bias")
    force_resolution: float = _as_in_sensors("force_resolution")
    length_delay: float = spec("s", "delay of the leg-length channels behind the motion",
                               nonnegative(0.0, 1.0), 0.0)
    force_delay: float = spec("s", "delay of the force channels behind the motion",
                              nonnegative(0.0, 1.0), 0.0)
    force_lowpass: float = spec("Hz", "cut-off of the low-pass filter colouring the force "
                                "noise (0: white noise)", nonnegative(0.0, 1e6), 0.0)
    force_lowpass_order: int = spec("-", "order of the Butterworth filter colouring the force "
                                    "noise", Interval(Integral, 1, 12, "both"), 4)
    hum_amplitude: float = spec("N", "amplitude of the mains hum on the forces",
                                nonnegative(0.0, 1e7), 0.0)
    hum_frequency: float = spec("Hz", "mains frequency", positive(1.0, 1e5), 50.0)
    length_drift: float = spec("m", "standard deviation of the leg-length drift at the end "
                               "of the record", nonnegative(0.0, 0.1), 0.0)
    force_drift: float = spec("N", "standard deviation of the force drift at the end of the "
                              "record", nonnegative(0.0, 1e7), 0.0)

    def __post_init__(self) -> None:
        for f in dataclasses.fields(self):
            declared = field_spec(f)
            allowed = [declared.constraint]
            value = declared.normalise(getattr(self, f.name))
            if f.name in PER_LEG:
                allowed.append(ListOf(declared.constraint, length=6))
                value = FieldSpec(declared.unit, declared.doc, allowed[-1]).normalise(value)
            check(f"The {f.name!r} parameter of SensorNoise", value, allowed, declared.unit)
            if isinstance(declared.constraint, Interval) and declared.constraint.kind is Integral:
                value = int(value)
            object.__setattr__(self, f.name, value)

    @classmethod
    def from_sensors(cls, sensors: Sensors) -> SensorNoise:
        """The errors declared in a platform's ``[sensors]`` section."""
        names = {f.name for f in dataclasses.fields(cls)} & set(_SENSORS_FIELDS)
        return cls(**{name: getattr(sensors, name) for name in names})

    @property
    def is_ideal(self) -> bool:
        """True when every error is zero."""
        return not any(np.any(getattr(self, f.name)) for f in dataclasses.fields(self)
                       if f.name not in SHAPES)

    @property
    def changes_lengths(self) -> bool:
        """True when the measured leg lengths differ from the true ones."""
        return any(np.any(getattr(self, name)) for name in LENGTH_ERRORS)

    @property
    def needs_sampling(self) -> bool:
        """True when an error depends on the sample times (a delay, filter or hum)."""
        return bool(self.length_delay or self.force_delay or self.hum_amplitude
                    or (self.force_lowpass and np.any(self.force_noise)))

    def check_sampling(self, sample_rate: float) -> None:
        """Refuse a filter cut-off or hum frequency at or above the Nyquist frequency.

        Raises
        ------
        ConfigError
            Naming the setting, the Nyquist frequency and the sample rate.
        """
        nyquist = sample_rate / 2
        for name, used in (("force_lowpass", self.force_lowpass > 0),
                           ("hum_frequency", self.hum_amplitude > 0)):
            if used and not getattr(self, name) < nyquist:
                raise ConfigError(
                    f"SensorNoise {name} = {getattr(self, name):g} Hz is not below the Nyquist "
                    f"frequency {nyquist:g} Hz of the {sample_rate:g} Hz sampling; lower it or "
                    "sample faster.")


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
    """The platform's ``[sensors]`` errors with the noise at ``scale`` (>= 0) times the reference:
    20 µm on the leg lengths, 0.5 % of the static leg force on the forces.
    """
    if not (np.isfinite(scale) and scale >= 0):
        raise ConfigError(f"noise scale must be a finite number >= 0; got {scale!r}.")
    return dataclasses.replace(
        SensorNoise.from_sensors(platform.sensors),
        length_noise=scale * REFERENCE_LENGTH_NOISE_M,
        force_noise=scale * REFERENCE_FORCE_NOISE * static_leg_force(platform))


#: The reference noise of an electric leg's current sensing (``simulate --noise``): standard
#: deviation as a fraction of each channel's RMS over the record (-).
REFERENCE_CURRENT_NOISE = 0.005


#: When :func:`sensor_noise` takes the reference noise of a channel instead of ``[sensors]``:
#: never, always, or only where ``[sensors]`` declares no noise.
REFERENCE_CHOICES = ("never", "always", "where_zero")


def sensor_noise(platform: Platform, reference: str = "never", length_noise: float | None = None,
                 force_noise: float | None = None) -> SensorNoise:
    """A run's sensor errors: the platform's ``[sensors]``, the reference noise where ``reference``
    asks, then the given standard deviations (m, N); biases and resolutions stay the platform's.

    ``reference``: "never", "always" (``simulate --noise``) or "where_zero" (channels ``[sensors]``
    leaves noise-free, ``design``).

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


def quantise(values: np.ndarray, resolution: float) -> np.ndarray:
    """``values`` rounded to the nearest multiple of ``resolution`` (unchanged when 0)."""
    return resolution * np.round(values / resolution) if resolution > 0 else values


def measure(true: np.ndarray, noise: float, bias: float, resolution: float,
            rng: np.random.Generator) -> np.ndarray:
    """quantise(true + bias + N(0, noise^2)) element-wise."""
    out = np.asarray(true, dtype=float) + bias
    if noise > 0:
        out = out + rng.normal(0.0, noise, size=out.shape)
    return quantise(out, resolution)


def measure_legs(lengths: np.ndarray, forces: np.ndarray, noise: SensorNoise,
                 rng: np.random.Generator, t: np.ndarray | None = None,
                 ) -> tuple[np.ndarray, np.ndarray]:
    """Measured leg lengths (m) and forces (N), both (N, 6), from the true ones.

    ``rng`` draws, only for nonzero errors: length noise, force noise, hum phases, length drift,
    force drift. ``t`` (N,) (s, uniform) is needed for delays, filtered noise and hum.

    Raises
    ------
    ConfigError
        If ``t`` is missing where needed, or a filter or hum frequency is not below Nyquist.
    """
    n = len(lengths)
    rate = None
    if noise.needs_sampling:
        if t is None:
            raise ConfigError("sensor delays, filtered noise and hum need the sample times; "
                              "pass t to measure_legs.")
        rate = (n - 1) / (t[-1] - t[0])
        noise.check_sampling(rate)
    measured_lengths = delay_signal(t, lengths, noise.length_delay) + noise.length_bias
    measured_forces = delay_signal(t, forces, noise.force_delay) + noise.force_bias
    if np.any(noise.length_noise):
        measured_lengths = measured_lengths + rng.normal(0.0, np.asarray(noise.length_noise),
                                                         size=measured_lengths.shape)
    if np.any(noise.force_noise) and noise.force_lowpass:
        measured_forces = measured_forces + lowpass_noise(
            rng, n, np.asarray(noise.force_noise), noise.force_lowpass,
            noise.force_lowpass_order, rate)
    elif np.any(noise.force_noise):
        measured_forces = measured_forces + rng.normal(0.0, np.asarray(noise.force_noise),
                                                       size=measured_forces.shape)
    if noise.hum_amplitude:
        measured_forces = measured_forces + mains_hum(t, noise.hum_amplitude,
                                                      noise.hum_frequency, rng)
    if noise.length_drift:
        measured_lengths = measured_lengths + random_walk(n, noise.length_drift, rng)
    if noise.force_drift:
        measured_forces = measured_forces + random_walk(n, noise.force_drift, rng)
    return (quantise(measured_lengths, noise.length_resolution),
            quantise(measured_forces, noise.force_resolution))


def measure_electric_legs(lengths: np.ndarray, forces: np.ndarray, noise: SensorNoise,
                          rng: np.random.Generator, t: np.ndarray | None = None,
                          encoder_resolution: float = 0.0, current_noise: float = 0.0,
                          ) -> tuple[np.ndarray, np.ndarray]:
    """Measured leg lengths (m) and force equivalents force_constant i (N) of electric legs, (N, 6)
    each, from the true ones.

    The encoders give whole counts of ``encoder_resolution`` (m of leg travel); the current sensing
    adds noise of ``current_noise`` times each channel's RMS over the record, in quadrature with
    ``noise.force_noise``; then every error of ``noise`` applies as in :func:`measure_legs`.
    """
    if current_noise > 0:
        rms = np.sqrt(np.mean(np.asarray(forces, dtype=float) ** 2, axis=0))
        combined = np.hypot(np.broadcast_to(noise.force_noise, (6,)), current_noise * rms)
        noise = dataclasses.replace(noise, force_noise=tuple(float(v) for v in combined))
    return measure_legs(encoder_lengths(lengths, encoder_resolution), forces, noise, rng, t)


def measured_pose(platform: Platform, lengths: np.ndarray,
                  initial: np.ndarray | None = None) -> np.ndarray:
    """Pose (N, 6) from measured leg lengths (N, 6) by Newton to 1e-12 m, from ``initial`` (e.g. the
    commanded poses) or the neutral pose.
    """
    return forward_kinematics(platform, lengths, initial=initial, tolerance=1e-12)


def degrade(dataset: Dataset, platform: Platform, noise: SensorNoise,
            rng: np.random.Generator | int | None = None) -> Dataset:
    """A copy of a data set (same times and name) measured by the imperfect sensors ``noise``.

    Lengths and forces go through :func:`measure_legs` (the first sample held before the record for
    the delays); the pose is the forward kinematics of the measured lengths. ``rng`` is a generator
    or seed (0 when None).

    Raises
    ------
    ConfigError
        If a filter or hum frequency is not below the data set's Nyquist frequency.

    Examples
    --------
    >>> from stewartid.simulation import SensorNoise, degrade  # doctest: +SKIP
    >>> late = degrade(clean, platform, SensorNoise(force_delay=2e-3, hum_amplitude=20.0), 1)
    """
    rng = rng if isinstance(rng, np.random.Generator) else np.random.default_rng(rng or 0)
    lengths, forces = measure_legs(dataset.lengths, dataset.forces, noise, rng, t=dataset.t)
    pose = (measured_pose(platform, lengths, dataset.pose) if noise.changes_lengths
            else dataset.pose.copy())
    return Dataset(t=dataset.t.copy(), pose=pose, lengths=lengths, forces=forces,
                   name=dataset.name)
