"""Dynamics against independent truth: kinetic and potential energy built from body
velocities, Lagrange's equations by finite differences, and energy conservation."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from stewartid.model.dynamics import (
    ModelTerms,
    forward_dynamics,
    friction_forces,
    gravity_forces,
    inverse_dynamics,
    kinetic_energy,
    mass_matrix,
    potential_energy,
    velocity_product_forces,
)
from stewartid.model.kinematics import inverse_kinematics, leg_lengths, rotation_matrix
from stewartid.model.linearization import viscous_matrix

BOX = np.array([0.2, 0.2, 0.2, 0.15, 0.15, 0.15])


def poses(platform, rng, n):
    return platform.neutral_pose + rng.uniform(-1, 1, (n, 6)) * BOX


def body_positions(platform, q):
    """Centres of mass of the lower and upper leg parts, and leg directions, from IK."""
    legs = inverse_kinematics(platform, q)
    i = platform.inertia
    lower = platform.base_joints + i.lower_leg_com * legs.directions[0]
    upper = legs.upper_joints[0] - i.upper_leg_com * legs.directions[0]
    return lower, upper, legs.directions[0]


def independent_kinetic_energy(platform, q, qd, h=1e-6):
    """1/2 sum m v^2 + 1/2 w^T I w of every body, velocities by central differences."""
    i = platform.inertia
    plus, minus = q + h * qd, q - h * qd
    lp, up, dp = body_positions(platform, plus)
    lm, um, dm = body_positions(platform, minus)
    _, _, u = body_positions(platform, q)
    v_lower, v_upper, u_dot = (lp - lm) / (2 * h), (up - um) / (2 * h), (dp - dm) / (2 * h)
    R = rotation_matrix(q[3:])
    W = (rotation_matrix(plus[3:]) - rotation_matrix(minus[3:])) / (2 * h) @ R.T
    omega = np.array([W[2, 1], W[0, 2], W[1, 0]])
    inertia_world = R @ np.diag(i.platform_inertia) @ R.T
    w_leg = np.cross(u, u_dot)
    return 0.5 * (
        i.platform_mass * qd[:3] @ qd[:3] + omega @ inertia_world @ omega
        + i.lower_leg_mass * np.sum(v_lower ** 2) + i.upper_leg_mass * np.sum(v_upper ** 2)
        + (i.lower_leg_inertia + i.upper_leg_inertia) * np.sum(w_leg ** 2)
    )


def test_mass_matrix_symmetric_positive_definite(paper, rng):
    M = mass_matrix(paper, poses(paper, rng, 50))
    # each entry is a sum of a few dozen products of size <= max|M|: its round-off, and so
    # the asymmetry, stays below 100 eps max|M| (1.3e-9 here; 2.4e-12 measured)
    np.testing.assert_allclose(M, np.swapaxes(M, 1, 2), rtol=0,
                               atol=100 * np.finfo(float).eps * np.abs(M).max())
    assert np.all(np.linalg.eigvalsh(M) > 0)


def test_kinetic_energy_matches_body_velocities(paper, rng):
    for q in poses(paper, rng, 5):
        qd = rng.normal(size=6) * np.array([0.1, 0.1, 0.1, 0.05, 0.05, 0.05])
        expected = independent_kinetic_energy(paper, q, qd)
        assert kinetic_energy(paper, q, qd) == pytest.approx(expected, rel=1e-8)


def test_gravity_is_gradient_of_potential(paper, rng):
    h = 1e-6
    for q in poses(paper, rng, 5):
        grad = np.array([(potential_energy(paper, q + h * e) - potential_energy(paper, q - h * e))
                         / (2 * h) for e in np.eye(6)])
        np.testing.assert_allclose(gravity_forces(paper, q), grad, rtol=1e-6, atol=1e-3)


def test_velocity_product_follows_lagrange(paper, rng):
    """h = dM/dt q_dot - 1/2 d(q_dot^T M q_dot)/dq, both by central differences of M."""
    h = 1e-6
    for q in poses(paper, rng, 4):
        qd = rng.normal(size=6) * np.array([0.2, 0.2, 0.2, 0.1, 0.1, 0.1])
        M_dot = (mass_matrix(paper, q + h * qd) - mass_matrix(paper, q - h * qd)) / (2 * h)
        grad_T = np.array([
            (kinetic_energy(paper, q + h * e, qd) - kinetic_energy(paper, q - h * e, qd)) / (2 * h)
            for e in np.eye(6)
        ])
        expected = M_dot @ qd - grad_T
        np.testing.assert_allclose(velocity_product_forces(paper, q, qd), expected,
                                   rtol=1e-5, atol=1e-5)


def test_inverse_dynamics_balances_power(paper, rng):
    """Independent truth: the actuators' power f · l_dot equals d(T + V)/dt plus the friction
    power, with T from body velocities, V and l from inverse kinematics, all by central
    differences along (q_dot, q_ddot); random accelerations probe every column of M."""
    plant = paper.replace(friction__coulomb=30.0)
    step = 1e-4
    for q in poses(plant, rng, 6):
        qd = rng.normal(size=6) * np.array([0.05, 0.05, 0.05, 0.03, 0.03, 0.03])
        qdd = rng.normal(size=6) * 0.5
        forces = inverse_dynamics(plant, q, qd, qdd)
        leg_rates = (leg_lengths(plant, q + step * qd) - leg_lengths(plant, q - step * qd)) \
            / (2 * step)
        kinetic_rate = (independent_kinetic_energy(plant, q + step * qd, qd + step * qdd)
                        - independent_kinetic_energy(plant, q - step * qd, qd - step * qdd)) \
            / (2 * step)
        potential_rate = (potential_energy(plant, q + step * qd)
                          - potential_energy(plant, q - step * qd)) / (2 * step)
        friction_power = friction_forces(plant, q, qd) @ qd
        scale = np.abs(forces) @ np.abs(leg_rates)
        assert forces @ leg_rates == pytest.approx(
            kinetic_rate + potential_rate + friction_power, abs=1e-6 * scale)


def test_forward_dynamics_inverts_inverse_dynamics(paper, rng):
    q = poses(paper, rng, 20)
    qd = rng.normal(size=(20, 6)) * 0.05
    qdd = rng.normal(size=(20, 6)) * 0.5
    forces = inverse_dynamics(paper.replace(friction__coulomb=30.0), q, qd, qdd)
    back = forward_dynamics(paper.replace(friction__coulomb=30.0), q, qd, forces)
    np.testing.assert_allclose(back, qdd, atol=1e-9)


def test_friction_dissipates_and_viscous_part_is_linear(paper, rng):
    q = poses(paper, rng, 10)
    qd = rng.normal(size=(10, 6)) * 0.05
    coulomb = paper.replace(friction__coulomb=30.0)
    assert np.all(np.einsum("ni,ni->n", friction_forces(coulomb, q, qd), qd) > 0)
    F = friction_forces(paper, q, qd)  # coulomb 0 in the preset
    np.testing.assert_allclose(F, np.einsum("nij,nj->ni", viscous_matrix(paper, q), qd),
                               rtol=1e-12, atol=1e-9)


def test_energy_is_conserved_without_friction(paper):
    """Constant leg forces balancing gravity at neutral are conservative: V_f = -sum f l."""
    plant = paper.replace(friction__gimbal_viscous=0.0, friction__coulomb=0.0)
    q0 = plant.neutral_pose
    f0 = inverse_dynamics(plant, q0, np.zeros(6), np.zeros(6))
    qd0 = np.array([0.02, -0.015, 0.01, 0.008, -0.01, 0.012])

    def rhs(_, state):
        return np.concatenate([state[6:], forward_dynamics(plant, state[:6], state[6:], f0)])

    sol = solve_ivp(rhs, (0, 2.0), np.concatenate([q0, qd0]), method="DOP853", rtol=1e-12,
                    atol=1e-14, dense_output=False, t_eval=np.linspace(0, 2, 41))
    assert sol.success
    q, qd = sol.y[:6].T, sol.y[6:].T
    lengths = ModelTerms(plant, q).leg_lengths
    energy = kinetic_energy(plant, q, qd) + potential_energy(plant, q) - lengths @ f0
    # relative to the kinetic energy that moves around (the potential's constant is arbitrary)
    drift = np.max(np.abs(energy - energy[0])) / kinetic_energy(plant, q0, qd0)
    assert drift < 1e-6
    assert np.ptp(kinetic_energy(plant, q, qd)) > 0.01 * kinetic_energy(plant, q0, qd0)


def test_lean_leg_terms_equal_the_full_model_terms(paper, rng):
    """The numpy leg terms (command tables, forward kinematics, identification) are the
    compiled kernel's gravity, leg Jacobian, lengths and joint Jacobians to the last bit; the
    tests above check those against energy, Lagrange's equations and finite differences."""
    from stewartid.model.leg_terms import BLOCK, leg_terms

    q = poses(paper, rng, BLOCK + 50)  # more than one block
    full = ModelTerms(paper, q)
    G, J, lengths, J_joint = leg_terms(
        paper.parameters(), paper.upper_joints, paper.base_joints, q, True)
    assert np.array_equal(G, full.gravity)
    assert np.array_equal(J, full.leg_jacobian)
    assert np.array_equal(lengths, full.leg_lengths)
    assert np.array_equal(J_joint, full.joint_jacobians)
    assert leg_terms(paper.parameters(), paper.upper_joints, paper.base_joints, q,
                     False).joint_jacobians.shape == (0, 6, 5, 6)


def test_interpreted_kernel_equals_the_compiled_one(paper, rng):
    """nominal_matrices runs the mass-matrix kernel interpreted for its one pose."""
    from stewartid.model import compiled as _kernels
    from stewartid.model import kernels as _kernel_code

    q, qd = poses(paper, rng, 1)[0], rng.normal(scale=0.1, size=6)
    shapes = ((6, 6), 6, 6, (6, 6), (6, 5, 6), 6)
    compiled, interpreted = ([np.empty(s) for s in shapes] for _ in range(2))
    args = (paper.parameters(), paper.upper_joints, paper.base_joints, q, qd)
    _kernels.model_terms(*args, *compiled)
    _kernel_code.model_terms(*args, *interpreted)
    for a, b in zip(compiled, interpreted, strict=True):
        np.testing.assert_allclose(b, a, rtol=1e-12, atol=1e-9)
