"""Experiments on the MuJoCo model with the plant's sensor errors (``simulate --engine mujoco``)."""

from __future__ import annotations

import dataclasses
from collections.abc import Callable, Sequence
from typing import Any

import stewartid
from stewartid.datasets.dataset import Dataset
from stewartid.model.linearization import nominal_matrices
from stewartid.mujoco.closed_loop import simulate_mujoco, steps_per_sample
from stewartid.mujoco.model import DEFAULT_TIMESTEP, require_mujoco
from stewartid.parallel import run_in_order
from stewartid.platform import Platform
from stewartid.simulation.electric import encoder_resolution, largest_step
from stewartid.simulation.experiments import (
    SimulationResult,
    check_timing,
    electric_meta,
    logged_force_constant,
    noise_generator,
)
from stewartid.simulation.sensors import (
    SensorNoise,
    degrade,
    measure_electric_legs,
    measured_pose,
)

#: What the MuJoCo model's legs are, for the record's metadata.
ACTUATORS = ("ideal force actuators under the leg-length servo's PD law with gravity "
             "feed-forward (no hydraulics, no integral term)")


#: What electric legs are in the MuJoCo model, for the record's metadata.
ELECTRIC_ACTUATORS = ("servo motors: first-order current loops (actuator filter states) limited to "
                      "peak_current, under the leg-length servo's PID law with gravity "
                      "feed-forward (integral terms as actuator integrator states)")


def _play(run: tuple) -> Any:
    platform, excitation, duration, noise, seed, k, count, step, current_noise = run
    clean = simulate_mujoco(platform, excitation, duration, step=step)
    rng = noise_generator(seed, k, count)
    if platform.electric_legs:
        lengths, forces = measure_electric_legs(
            clean.lengths, clean.forces, noise, rng, clean.t,
            encoder_resolution(platform.actuator), current_noise)
        measured = Dataset(clean.t, measured_pose(platform, lengths, clean.pose), lengths,
                           forces)
    else:
        measured = degrade(clean, platform, noise, rng)
    return dataclasses.replace(measured, name=f"exp{k + 1}")


def simulate_on_mujoco(platform: Platform, excitations: Sequence[Any],
                       durations: Sequence[float], noise: SensorNoise | None = None,
                       seed: int = 0, step: float = DEFAULT_TIMESTEP,
                       progress: Callable[[int, int, str], Any] | None = None,
                       jobs: int = 1, excitation_meta: dict | None = None,
                       current_noise: float = 0.0) -> SimulationResult:
    """Play excitations on the MuJoCo model, experiment k named ``exp{k+1}``, with sensor errors.

    The result has no true states; ``meta["engine"]`` is ``"mujoco"``.

    Parameters
    ----------
    platform : Platform
    excitations : sequence of Commanded
    durations : sequence of float
        s.
    noise : SensorNoise, optional
        ``[sensors]`` by default.
    seed : int
        One independent noise stream per experiment, as the plant's.
    step : float
        MuJoCo's time step (s).
    progress : callable, optional
        ``progress(done, total, name)``.
    jobs : int
        Worker processes (the control callback is process-global); the data do not depend on it.
    excitation_meta : dict, optional
        The metadata's ``excitation`` entry; the experiments' names by default.
    current_noise : float
        Electric legs: noise of each motor current as a fraction of its RMS, as the plant's.

    Raises
    ------
    ImportError
        If MuJoCo is not installed.
    ConfigError
        On a non-positive record length or a frequency not below Nyquist.
    """
    mujoco = require_mujoco()
    noise = SensorNoise.from_sensors(platform.sensors) if noise is None else noise
    rate = platform.sensors.sample_rate
    noise.check_sampling(rate)
    for excitation, duration in zip(excitations, durations, strict=True):
        check_timing(duration, rate, excitation.max_frequency)
    runs = [(platform, excitation, float(duration), noise, seed, k, len(excitations), step,
             current_noise)
            for k, (excitation, duration) in enumerate(zip(excitations, durations, strict=True))]

    def finished(done: int, total: int, index: int) -> None:
        progress(done, total, excitations[index].name)

    datasets = run_in_order(_play, runs, jobs, finished if progress is not None else None)
    M, B = nominal_matrices(platform)
    meta = {"engine": "mujoco", "platform": platform.to_dict(),
            "platform_name": platform.name,
            "excitation": excitation_meta or {"sources": [e.name for e in excitations]},
            "integration": {"engine": "mujoco", "version": mujoco.__version__,
                            "integrator": "RK4",
                            "step": 1.0 / (rate * steps_per_sample(rate, step))},
            "actuators": ACTUATORS, "noise": dataclasses.asdict(noise), "seed": int(seed),
            "nominal": {"M": M.tolist(), "B": B.tolist()}, "version": stewartid.__version__}
    if platform.electric_legs:
        meta["integration"]["step"] = 1.0 / (rate * steps_per_sample(
            rate, min(step, largest_step(platform.actuator))))
        meta["actuators"] = ELECTRIC_ACTUATORS
        meta.update(electric_meta(platform, current_noise))
    return SimulationResult(list(datasets), meta, [], logged_force_constant(platform))


__all__ = ["ACTUATORS", "ELECTRIC_ACTUATORS", "simulate_on_mujoco"]
