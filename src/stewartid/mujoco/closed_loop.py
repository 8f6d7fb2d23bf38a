"""An experiment played on the MuJoCo model (the plant's leg servo on ideal force actuators) and
logged like a rig's record: an independent engine for the same command.
"""

from __future__ import annotations

from typing import Protocol

import numpy as np

from stewartid.datasets.dataset import Dataset
from stewartid.mujoco import model as mjcf
from stewartid.mujoco import state as mujoco_state
from stewartid.platform import Platform


class Commanded(Protocol):
    """A commanded motion: an excitation or a command file's tabulated excitation."""

    name: str
    #: Highest frequency in the motion (Hz): what the log's rate must resolve.
    max_frequency: float

    def evaluate(self, t: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Pose, rate and acceleration (N, 6) at ``t`` (s)."""
        ...


def steps_per_sample(rate: float, step: float) -> int:
    """MuJoCo steps per sample at ``rate`` (Hz), ``step`` (s) rounded down to divide the period."""
    return max(1, int(np.ceil(1.0 / (rate * step) - 1e-9)))


def simulate_mujoco(platform: Platform, excitation: Commanded, duration: float, *,
                    step: float = mjcf.DEFAULT_TIMESTEP, integrator: str = "RK4") -> Dataset:
    """Play ``excitation`` on the MuJoCo model and record it at the sensors' rate, named as the excitation.

    Ideal force actuators under the PD part of the plant's servo with gravity feed-forward (no
    integral term); each sample is MuJoCo's exact state, without sensor errors. The command is
    evaluated at every integrator stage through MuJoCo's process-global control callback: one
    simulation per process at a time.

    Parameters
    ----------
    platform : Platform
        Mechanism, friction, ``[controller]`` gains and ``[sensors] sample_rate``.
    excitation : Commanded
    duration : float
        Record length (s).
    step : float
        MuJoCo's time step (s), rounded down to divide the sample period.
    integrator : {"RK4", "implicitfast", "implicit", "Euler"}
        Its stages must lie on the half-step command table.

    Raises
    ------
    ImportError
        If MuJoCo is not installed.
    ValueError
        If ``duration`` or ``step`` is not positive.
    """
    mj = mjcf.require_mujoco()
    if not (np.isfinite(duration) and duration > 0):
        raise ValueError(f"duration must be > 0 s; got {duration!r}.")
    if not (np.isfinite(step) and step > 0):
        raise ValueError(f"step must be > 0 s; got {step!r}.")
    rate = platform.sensors.sample_rate
    per_sample = steps_per_sample(rate, step)
    step = 1.0 / (rate * per_sample)
    n_samples = int(np.floor(duration * rate + 1e-9)) + 1
    model = mjcf.load_model(platform, integrator=integrator, timestep=step)
    data = mj.MjData(model)
    mujoco_state.add_leg_servo(platform, model)
    half = step / 2
    q_cmd, qd_cmd, _ = excitation.evaluate(np.arange(2 * (n_samples - 1) * per_sample + 3) * half)
    table = mujoco_state.servo_controls(platform, q_cmd, qd_cmd)

    def control(_model: object, state: object) -> None:
        state.ctrl[:] = table[int(round(state.time / half))]

    mujoco_state.set_state(platform, model, data, q_cmd[0], qd_cmd[0])
    pose = np.empty((n_samples, 6))
    lengths = np.empty((n_samples, 6))
    forces = np.empty((n_samples, 6))
    previous = mj.get_mjcb_control()
    mj.set_mjcb_control(control)
    try:
        for i in range(n_samples):
            for _ in range(per_sample if i else 0):
                mj.mj_step(model, data)
            mj.mj_forward(model, data)  # the forces at the sample's own command
            pose[i] = mujoco_state.platform_state(model, data)[0]
            lengths[i] = mujoco_state.leg_lengths(platform, model, data)
            forces[i] = data.actuator_force
    finally:
        mj.set_mjcb_control(previous)
    return Dataset(np.arange(n_samples) / rate, pose, lengths, forces, name=excitation.name)
