"""Kinematics against independent truth: FK o IK, finite differences, scipy rotations."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation

from roundoff import EPS
from stewartid.errors import KinematicsError
from stewartid.model.kinematics import (
    forward_kinematics,
    inverse_kinematics,
    joint_rate_jacobians,
    leg_jacobian,
    leg_lengths,
    rotation_matrix,
)

BOX = np.array([0.3, 0.3, 0.3, 0.2, 0.2, 0.2])


def random_poses(platform, rng, n):
    return platform.neutral_pose + rng.uniform(-1, 1, (n, 6)) * BOX


def test_rotation_is_rz_ry_rx(rng):
    angles = rng.uniform(-0.5, 0.5, (20, 3))
    expected = Rotation.from_euler("xyz", angles).as_matrix()  # extrinsic x, y, z = Rz Ry Rx
    # entries <= 1, sums of two products of three sines/cosines, each within 4 ulps where
    # numpy vectorises them (some CPUs), against scipy's own construction: 32 eps each side
    np.testing.assert_allclose(rotation_matrix(angles), expected, atol=64 * EPS)


def test_neutral_legs_are_equal(paper):
    np.testing.assert_allclose(leg_lengths(paper, paper.neutral_pose), 3.40995, atol=1e-5)


@settings(max_examples=40, deadline=None)
@given(st.lists(st.floats(-1, 1), min_size=6, max_size=6))
def test_forward_inverse_round_trip(paper, unit):
    q = paper.neutral_pose + np.array(unit) * BOX
    q_back = forward_kinematics(paper, leg_lengths(paper, q))
    assert np.max(np.abs(q_back - q)) < 1e-9


def test_forward_kinematics_batched_round_trip(paper, rng):
    q = random_poses(paper, rng, 500)
    q_back = forward_kinematics(paper, leg_lengths(paper, q))
    assert np.max(np.abs(q_back - q)) < 1e-9


def test_leg_jacobian_matches_central_differences(paper, rng):
    h = 1e-6
    for q in random_poses(paper, rng, 10):
        J = leg_jacobian(paper, q)
        numeric = np.column_stack([
            (leg_lengths(paper, q + h * e) - leg_lengths(paper, q - h * e)) / (2 * h)
            for e in np.eye(6)
        ])
        np.testing.assert_allclose(J, numeric, atol=1e-8)


def angular_velocity(R_minus, R_plus, R, h):
    """omega (world) from [omega]x = R_dot R^T by central differences."""
    W = (R_plus - R_minus) / (2 * h) @ R.T
    return np.array([W[2, 1], W[0, 2], W[1, 0]])


def test_joint_rate_jacobians_match_independent_finite_differences(paper, rng):
    """Rebuild joint rates from leg directions and platform attitude, differentiated numerically."""
    h = 1e-6
    for q in random_poses(paper, rng, 5):
        qd = rng.normal(size=6)
        J = joint_rate_jacobians(paper, q)
        plus, minus = q + h * qd, q - h * qd
        u = inverse_kinematics(paper, q).directions[0]
        u_dot = (inverse_kinematics(paper, plus).directions[0]
                 - inverse_kinematics(paper, minus).directions[0]) / (2 * h)
        omega = angular_velocity(rotation_matrix(minus[3:]), rotation_matrix(plus[3:]),
                                 rotation_matrix(q[3:]), h)
        for leg in range(6):
            w_leg = np.cross(u[leg], u_dot[leg])
            w_rel = omega - w_leg
            e1 = np.cross([0.0, 0.0, 1.0], u[leg])
            e1 /= np.linalg.norm(e1)
            e2 = np.cross(u[leg], e1)
            expected = [e1 @ w_leg, e2 @ w_leg, e1 @ w_rel, e2 @ w_rel, u[leg] @ w_rel]
            np.testing.assert_allclose(J[leg] @ qd, expected, atol=1e-7)


def test_gimbal_axes_are_orthogonal_to_the_leg(paper, rng):
    """No lower-gimbal rate for a motion along the leg; revolute rate is spin about the leg."""
    q = paper.neutral_pose
    J = joint_rate_jacobians(paper, q)
    u = inverse_kinematics(paper, q).directions[0]
    for leg in range(6):
        along = np.concatenate([u[leg], np.zeros(3)])
        # zero analytically; round-off of a 6-term dot product with a unit vector
        np.testing.assert_allclose(J[leg, :2] @ along, 0.0, atol=16 * EPS * np.abs(J[leg, :2]).max())


def test_forward_kinematics_reports_unreachable_lengths(paper):
    with pytest.raises(KinematicsError, match="did not converge"):
        forward_kinematics(paper, np.array([1.0, 9.0, 1.0, 9.0, 1.0, 9.0]), max_iterations=10)
    with pytest.raises(KinematicsError, match="finite and positive"):
        forward_kinematics(paper, np.full(6, np.nan))
