"""The weight the forces carry: evidence of an unknown payload in physical mode, a warning
naming payload mode otherwise, an error beyond five times the file's."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from stewartid.datasets.plausibility import PHYSICAL_CARRIED_WEIGHT, check_static_balance
from stewartid.errors import DataError, DataWarning
from stewartid.model.kinematics import compute_leg_terms


def _static_forces(platform, pose):
    """Leg forces that hold ``platform`` still at each pose: J^T f = G (independent of the
    check's own arithmetic only in that ``platform`` is not the one checked against)."""
    gravity, jacobian, _, _ = compute_leg_terms(platform, np.ascontiguousarray(pose))
    return np.linalg.solve(np.transpose(jacobian, (0, 2, 1)), gravity[..., None])[..., 0]


@pytest.fixture(scope="module")
def poses(paper):
    t = np.linspace(0.0, 4.0, 400)[:, None]
    return paper.neutral_pose + 0.02 * np.sin(2 * np.pi * 0.5 * t) * np.array([1, 1, 1, 0, 0, 0])


def _loaded(paper, mass):
    return paper.replace(payload__mass=mass, payload__com=(0.2, -0.1, 0.3),
                         payload__inertia=(2500.0, 2200.0, 3000.0, 0.0, 0.0, 0.0))


def test_a_heavy_payload_warns_and_names_payload_mode(paper, poses):
    forces = _static_forces(_loaded(paper, 3000.0), poses)
    with pytest.warns(DataWarning, match=r"1\.2\d times the weight.*--model physical --payload"):
        check_static_balance(poses, forces, paper, "exp1")


def test_physical_mode_takes_half_to_five_times_the_weight_as_evidence(paper, poses):
    for mass in (3000.0, 3.0 * paper.inertia.platform_mass):
        forces = _static_forces(_loaded(paper, mass), poses)
        with warnings.catch_warnings():
            warnings.simplefilter("error")
            check_static_balance(poses, forces, paper, "exp1", PHYSICAL_CARRIED_WEIGHT)
    light = 0.6 * _static_forces(paper, poses)
    check_static_balance(poses, light, paper, "exp1", PHYSICAL_CARRIED_WEIGHT)
    with pytest.raises(DataError, match="wrong platform file"):
        check_static_balance(poses, light, paper, "exp1")


def test_beyond_five_times_the_weight_is_an_error_in_either_mode(paper, poses):
    forces = 6.0 * _static_forces(paper, poses)
    for carried in ((0.8, 5.0), PHYSICAL_CARRIED_WEIGHT):
        with pytest.raises(DataError, match=r"6 times the weight.*wrong platform file"):
            check_static_balance(poses, forces, paper, "exp1", carried)
