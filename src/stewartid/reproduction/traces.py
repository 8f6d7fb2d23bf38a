"""The model's force components along a simulated experiment, and the commanded poses, for a
reproduction's signal figures."""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np

from stewartid.platform import Platform


def experiment_trace(platform: Platform, dataset: Any, excited: int, frequency_hz: float,
                     reference: np.ndarray | None = None, record: Any = None):
    """Everything the signal figures need from one simulated experiment.

    Force components are the model's terms at the simulator's true motion when ``record`` is
    given, else at the measured pose differentiated as an identifier would; the actuators' force
    is always measured. ``excited``: coordinate 0-5; ``frequency_hz`` sets the differentiation
    window; ``reference``: commanded pose, shape (N, 6) (m, rad)."""
    from stewartid.identification.wavelet.intervals import (
        constant_direction_intervals,
        joint_rates,
    )
    from stewartid.model.dynamics import ModelTerms, friction_forces
    from stewartid.reports.drawing import ExperimentTrace
    from stewartid.signals.differentiation import default_window, differentiate

    t = np.asarray(dataset.t, dtype=float)
    pose = np.asarray(dataset.pose, dtype=float)
    if record is not None:
        q, q_dot, q_ddot = (np.asarray(record.q), np.asarray(record.q_dot),
                            np.asarray(record.q_ddot))
    else:
        q = pose
        _, q_dot, q_ddot = differentiate(pose, dataset.sample_rate,
                                         default_window(frequency_hz))
    terms = ModelTerms(platform, q, q_dot)
    measured = terms if record is None else ModelTerms(platform, pose)
    rates = joint_rates(platform, q, q_dot, terms.joint_jacobians, terms.leg_jacobian)
    intervals = constant_direction_intervals(t, rates, ignore_below=0.01)
    viscous = friction_forces(platform.replace(friction__coulomb=0.0), q, q_dot)
    friction = friction_forces(platform, q, q_dot)
    gravity_0 = ModelTerms(platform, platform.neutral_pose).gravity[0]
    actuators = np.einsum("nji,nj->ni", measured.leg_jacobian, np.asarray(dataset.forces))
    forces = {
        "inertial": np.einsum("nij,nj->ni", terms.mass_matrix, q_ddot) + terms.velocity_product,
        "viscous": viscous,
        "coulomb": friction - viscous,
        "gravity": terms.gravity - gravity_0,
        "actuators": actuators - gravity_0,
    }
    return ExperimentTrace(name=str(dataset.name), excited=int(excited), t=t, pose=pose,
                           neutral=np.asarray(platform.neutral_pose, dtype=float),
                           reference=reference, joint_rates=rates, intervals=intervals,
                           forces=forces)


def reference_poses(platform: Platform, frequency_hz: float, times: Sequence[np.ndarray]
                    ) -> list[np.ndarray | None]:
    """Commanded poses of the paper's six experiments at the given sample times."""
    try:
        from stewartid.simulation.excitation import paper_experiments
    except ImportError:
        return [None] * len(times)
    excitations = paper_experiments(platform, frequency_hz=frequency_hz)
    return [excitation.evaluate(np.asarray(t))[0] for excitation, t in
            zip(excitations, times, strict=False)]


__all__ = ["experiment_trace", "reference_poses"]
