"""An experiment played on the MuJoCo model: the plant's leg servo on ideal force actuators,
logged like a rig's record.

The independent engine as a source of logs: the same command as
:func:`stewartid.simulation.simulate_experiment`, MuJoCo's own integration of the 42-joint
mechanism closed by welds (:mod:`~stewartid.mujoco.model`), and a record in the package's
:class:`~stewartid.datasets.dataset.Dataset` (pose, leg lengths, actuator forces) that every
identifier reads. What differs from our plant is what would differ on another simulator: the
rigid-body algorithms, the Cardan chains' axes, MuJoCo's friction constraints instead of our
regularised Coulomb law, its integrator, and no hydraulics (the actuators are ideal).
"""

from __future__ import annotations

from typing import Protocol

import numpy as np

from stewartid.datasets.dataset import Dataset
from stewartid.mujoco import model as mjcf
from stewartid.mujoco import state as mujoco_state
from stewartid.platform import Platform


class Commanded(Protocol):
    """A commanded motion: a :class:`~stewartid.simulation.excitation.Excitation` or a command
    file's :class:`~stewartid.design.export.TabulatedExcitation`."""

    name: str

    def evaluate(self, t: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Pose, rate and acceleration at ``t`` (s), each of shape (N, 6)."""
        ...


def simulate_mujoco(platform: Platform, excitation: Commanded, duration: float, *,
                    step: float = 2.5e-4, integrator: str = "RK4") -> Dataset:
    """Play ``excitation`` on the MuJoCo model and record it at the sensors' rate.

    The legs are ideal force actuators under the PD part of the plant's leg-length servo with
    its gravity feed-forward (:func:`~stewartid.mujoco.state.add_leg_servo`; MuJoCo would need
    an extra state per leg for the integral term, which is left out). The command enters each
    step at the step's midpoint value. Every sample is MuJoCo's exact state: the platform's
    pose, the slides' leg lengths and the actuator forces, the latter with the command at
    the sample's time (the forces a load cell would read then). No sensor errors: add them
    with :func:`stewartid.simulation.degrade`.

    Parameters
    ----------
    platform : Platform
        Mechanism, friction, ``[controller]`` gains and ``[sensors] sample_rate``.
    excitation : Commanded
        The commanded motion (a sine excitation, or a command file read by
        :func:`stewartid.design.export.read_excitation`).
    duration : float
        Record length (s).
    step : float
        MuJoCo's time step (s); rounded down to divide the sample period. The recorded forces
        depart from the rigid-body dynamics of the recorded motion by O(step^2): on the paper
        platform with a 2 t payload, 2.5 N rms at 0.5 ms and 0.5 N at 0.25 ms (forces up to
        44 kN; our reference force noise is 0.5 % of the static leg force, about 140 N there).
        Most of it acts like a damper along the legs: 21 N s/m at 0.5 ms, 5.3 at 0.25 ms and
        1.3 at 0.125 ms, proportional to each of the servo's gains and not to the welds' time
        constant: the stiff servo integrated by RK4 with its command held over each step (a
        mass m on the same servo, integrated so, shows K_p K_d step^2 / (12 m), 31 N s/m at
        0.5 ms for m = 2700 kg; none with the command evaluated at every stage). At
        0.25 ms it raises the heave damping Bt(3,3) of the paper platform by 0.9 % and the
        other Bt entries by 0.15 %: compare noise-free fits at that level.
    integrator : {"RK4", "implicitfast", "implicit", "Euler"}
        MuJoCo integrator.

    Returns
    -------
    Dataset
        Samples at t = 0, 1/rate, ... up to ``duration``; named as the excitation.

    Raises
    ------
    ImportError
        If MuJoCo is not installed (``pip install "stewartid[mujoco]"``).
    ValueError
        If ``duration`` or ``step`` is not positive.
    """
    mj = mjcf.require_mujoco()
    if not (np.isfinite(duration) and duration > 0):
        raise ValueError(f"duration must be > 0 s; got {duration!r}.")
    if not (np.isfinite(step) and step > 0):
        raise ValueError(f"step must be > 0 s; got {step!r}.")
    rate = platform.sensors.sample_rate
    per_sample = max(1, int(np.ceil(1.0 / (rate * step) - 1e-9)))
    step = 1.0 / (rate * per_sample)
    n_samples = int(np.floor(duration * rate + 1e-9)) + 1
    model = mjcf.load_model(platform, integrator=integrator, timestep=step)
    data = mj.MjData(model)
    mujoco_state.add_leg_servo(platform, model)
    q_mid, qd_mid, _ = excitation.evaluate((np.arange((n_samples - 1) * per_sample) + 0.5) * step)
    ctrl = mujoco_state.servo_controls(platform, q_mid, qd_mid)
    t = np.arange(n_samples) / rate  # as simulate_experiment's
    q_at, qd_at, _ = excitation.evaluate(t)
    ctrl_at = mujoco_state.servo_controls(platform, q_at, qd_at)
    mujoco_state.set_state(platform, model, data, q_at[0], qd_at[0])
    pose = np.empty((n_samples, 6))
    lengths = np.empty((n_samples, 6))
    forces = np.empty((n_samples, 6))
    for i in range(n_samples):
        if i:
            for k in range((i - 1) * per_sample, i * per_sample):
                data.ctrl[:] = ctrl[k]
                mj.mj_step(model, data)
        data.ctrl[:] = ctrl_at[i]
        mj.mj_forward(model, data)  # the forces at the sample's own command
        pose[i] = mujoco_state.platform_state(model, data)[0]
        lengths[i] = mujoco_state.leg_lengths(platform, model, data)
        forces[i] = data.actuator_force
    return Dataset(t, pose, lengths, forces, name=excitation.name)
