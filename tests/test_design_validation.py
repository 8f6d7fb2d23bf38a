"""The validation record of a design: every DOF at once, at frequencies of its own, within the
limits on the simulated plant."""

from __future__ import annotations

import numpy as np
import pytest

from stewartid.datasets.excitation import excitation_lines
from stewartid.design.export import read_excitation, simulate_excitations
from stewartid.design.limits import record_limit_use
from stewartid.design.optimise import commanded_use
from stewartid.design.validation import (
    VALIDATION_HZ,
    VALIDATION_USE,
    validation_record,
    write_validation_record,
)
from stewartid.simulation.sensors import SensorNoise


@pytest.fixture(scope="module")
def short(paper):
    return validation_record(paper, duration_s=8.0)


def test_the_motion_uses_the_intended_share_of_the_most_used_limit(paper, short):
    peak = max(commanded_use(paper, short).peak.values())
    # three rescalings of a use that is linear in the amplitudes up to the static forces
    assert peak == pytest.approx(VALIDATION_USE, rel=1e-2)


def test_velocity_and_acceleration_are_the_derivatives_of_the_pose(short):
    """Central differences of the analytic pose, error O(h^2) of the fifth derivative."""
    h = 1e-4
    t = np.linspace(0.5, 7.5, 57)
    q_plus, _, _ = short.evaluate_offsets(t + h)
    q_minus, _, _ = short.evaluate_offsets(t - h)
    q, q_dot, q_ddot = short.evaluate_offsets(t)
    scale = np.abs(q_ddot).max()
    assert (q_plus - q_minus) / (2 * h) == pytest.approx(q_dot, abs=1e-6 * scale)
    assert (q_plus - 2 * q + q_minus) / h ** 2 == pytest.approx(q_ddot, abs=1e-3 * scale)
    ends, _, _ = short.evaluate_offsets(np.array([0.0, short.duration]))
    assert np.all(ends == 0.0)


@pytest.mark.slow
def test_the_file_plays_on_the_plant_within_the_limits_with_every_dof_at_its_frequency(
        paper, tmp_path):
    path = write_validation_record(paper, tmp_path, rate_hz=500.0, duration_s=12.0)
    excitation = read_excitation(path, paper)
    run = simulate_excitations(paper, [excitation], noise=SensorNoise(), seed=0)
    (record,) = run.states
    assert max(record_limit_use(paper, record).peak.values()) < 1.0
    lines = excitation_lines(run.datasets)
    for dof, frequency in enumerate(VALIDATION_HZ):
        # each DOF's largest line within one frequency resolution of its own frequency
        assert min(abs(np.array(lines[dof]) - frequency)) <= 1.5 / 12.0, (dof, lines[dof])
