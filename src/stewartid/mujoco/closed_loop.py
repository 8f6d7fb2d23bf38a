"""An experiment played on the MuJoCo model (the plant's leg servo on ideal force actuators) and
logged like a rig's record: an independent engine for the same command.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Protocol

import numpy as np

from stewartid.datasets.dataset import Dataset
from stewartid.model.dynamics import ModelTerms
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
    integral term); electric legs (``platform.electric_legs``) as the plant drives them, see
    :func:`_simulate_electric`. Each sample is MuJoCo's exact state, without sensor errors. The command is
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
    if platform.electric_legs:
        return _simulate_electric(platform, excitation, duration, step, integrator)
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
    return _record(platform, model, data, control, lambda state: state.actuator_force,
                   n_samples, per_sample, excitation.name)


def _simulate_electric(platform: Platform, excitation: Commanded, duration: float, step: float,
                       integrator: str) -> Dataset:
    """:func:`simulate_mujoco` for electric legs: the plant's whole servo on MuJoCo's motors.

    Every integrator stage, the control callback evaluates the plant's PID law (gravity
    feed-forward, integral term, clamp to +-peak_current with the same anti-windup) on MuJoCo's
    slide positions and rates, and commands the current; MuJoCo integrates the current loops and
    the integral terms as actuator states (:func:`~stewartid.mujoco.model.build_mjcf`). The
    step is no longer than the plant's for the current loop. The data set's forces are
    force_constant times MuJoCo's currents.
    """
    from stewartid.simulation.controller import command_tables, controller_parameters
    from stewartid.simulation.electric import largest_step

    mj = mjcf.require_mujoco()
    rate = platform.sensors.sample_rate
    per_sample = steps_per_sample(rate, min(step, largest_step(platform.actuator)))
    step = 1.0 / (rate * per_sample)
    n_samples = int(np.floor(duration * rate + 1e-9)) + 1
    model = mjcf.load_model(platform, integrator=integrator, timestep=step)
    data = mj.MjData(model)
    half = step / 2
    q_cmd, qd_cmd, _ = excitation.evaluate(np.arange(2 * (n_samples - 1) * per_sample + 3) * half)
    params = platform.parameters()
    cmd_len, cmd_rate, cmd_force = command_tables(
        params, np.ascontiguousarray(platform.upper_joints),
        np.ascontiguousarray(platform.base_joints), q_cmd, qd_cmd,
        bool(platform.controller.gravity_feedforward))
    c = platform.controller
    cp = controller_parameters(platform)
    f_min, f_max = cp[4], cp[5]
    kt = platform.actuator.force_constant
    slides = mujoco_state.Indices(model)
    l0 = platform.neutral_leg_length

    def control(_model: object, state: object) -> None:
        k = int(round(state.time / half))
        error = cmd_len[k] - (l0 + state.qpos[slides.slide_qpos])
        rate_error = cmd_rate[k] - state.qvel[slides.slide_dof]
        demand = (cmd_force[k] + c.proportional_gain * error + c.integral_gain * state.act[6:]
                  + c.derivative_gain * rate_error)
        # the plant's anti-windup: the integral stops while the demand saturates outward
        high, low = demand > f_max, demand < f_min
        state.ctrl[6:] = np.where((high & (error > 0)) | (low & (error < 0)), 0.0, error)
        state.ctrl[:6] = np.clip(demand, f_min, f_max) / kt

    mujoco_state.set_state(platform, model, data, q_cmd[0], qd_cmd[0])
    start = ModelTerms(platform, q_cmd[0])
    held = np.linalg.solve(start.leg_jacobian[0].T, start.gravity[0])
    data.act[:6] = held / kt
    data.act[6:] = (held - cmd_force[0]) / c.integral_gain if c.integral_gain > 0 else 0.0
    return _record(platform, model, data, control, lambda state: kt * state.act[:6],
                   n_samples, per_sample, excitation.name)


def _record(platform: Platform, model: object, data: object,
            control: Callable[[object, object], None], force: Callable[[object], np.ndarray],
            n_samples: int, per_sample: int, name: str) -> Dataset:
    """``n_samples`` samples of MuJoCo's exact state, ``per_sample`` steps apart, under the
    process-global control callback ``control`` (restored after); ``force(data)``: the leg
    forces (6,) at a sample, N."""
    mj = mjcf.require_mujoco()
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
            forces[i] = force(data)
    finally:
        mj.set_mjcb_control(previous)
    rate = platform.sensors.sample_rate
    return Dataset(np.arange(n_samples) / rate, pose, lengths, forces, name=name)
