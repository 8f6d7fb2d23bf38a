"""The linear model at large motions: the model's departure from its linearisation, and the
identifiers that subtract it, against the platform model's own inverse dynamics."""

from __future__ import annotations

import numpy as np
import pytest

from stewartid.datasets.dataset import Dataset
from stewartid.identification.registry import create_identifier
from stewartid.model.dynamics import ModelTerms, inverse_dynamics
from stewartid.model.kinematics import leg_lengths
from stewartid.model.linearization import linearisation_remainder, nominal_matrices
from stewartid.reference.published import PAPER_ENTRIES, relative_error_percent
from stewartid.simulation import DEFAULT_AMPLITUDES


def sine_motion(platform, dof, scale, frequency=0.5, duration=6.0, rate=1000.0):
    """Time, pose, rate and acceleration of a sine of ``scale`` times the paper's amplitude
    on ``dof`` about the neutral pose."""
    t = np.arange(0.0, duration, 1.0 / rate)
    w = 2 * np.pi * frequency
    a = scale * DEFAULT_AMPLITUDES[dof]
    q = np.tile(platform.neutral_pose, (len(t), 1))
    q_dot, q_ddot = np.zeros_like(q), np.zeros_like(q)
    q[:, dof] += a * np.sin(w * t)
    q_dot[:, dof] = a * w * np.cos(w * t)
    q_ddot[:, dof] = -a * w ** 2 * np.sin(w * t)
    return t, q, q_dot, q_ddot


def model_records(platform, scale):
    """The paper's six experiments at ``scale`` times its amplitudes, with the actuator forces
    of the model's inverse dynamics (friction as the platform describes it)."""
    out = []
    for k in range(6):
        t, q, q_dot, q_ddot = sine_motion(platform, k, scale)
        forces = inverse_dynamics(platform, q, q_dot, q_ddot)
        out.append(Dataset(t=t, pose=q, lengths=leg_lengths(platform, q), forces=forces,
                           name=f"exp{k + 1}"))
    return out


def largest_error(estimator, platform) -> float:
    M, B = nominal_matrices(platform)
    return max(abs(relative_error_percent((estimator.M_ if m == "M" else estimator.B_)[i, j],
                                          (M if m == "M" else B)[i, j]))
               for m, i, j in PAPER_ENTRIES)


@pytest.mark.parametrize("actuator", [{}, {"reflected_mass": 40.0, "viscous": 2000.0}],
                         ids=["hydraulic", "reflected mass and leg friction"])
def test_remainder_completes_the_equation_of_motion(paper, actuator):
    """J_lq^T f - G(q) of the inverse dynamics (viscous friction only) is Mt q_ddot + Bt q_dot
    + r at random states far from the neutral pose: r from the numpy regressor, the inverse
    dynamics from the compiled per-sample model (reflected masses and friction along the legs
    included), the viscous part from the joint-friction kernel on one side and the regressor's
    viscous columns on the other."""
    platform = paper.replace(friction__coulomb=0.0,
                             **{f"actuator__{key}": value for key, value in actuator.items()})
    rng = np.random.default_rng(3)
    q = platform.neutral_pose + rng.uniform(-1, 1, (40, 6)) * [0.2, 0.2, 0.2, 0.1, 0.1, 0.1]
    q_dot, q_ddot = rng.normal(size=(40, 6)), rng.normal(size=(40, 6)) * 3
    f = inverse_dynamics(platform, q, q_dot, q_ddot)
    terms = ModelTerms(platform, q)
    y = np.einsum("nji,nj->ni", terms.leg_jacobian, f) - terms.gravity
    M, B = nominal_matrices(platform)
    expected = q_ddot @ M.T + q_dot @ B.T + linearisation_remainder(platform, q, q_dot, q_ddot)
    scale = np.abs(y).max(axis=0)
    assert np.all(np.abs(y - expected) <= 1e-9 * scale)


def test_remainder_is_second_order_in_the_amplitude(paper):
    """The linearisation's error on a sine grows with the square of its amplitude: doubling
    the amplitude multiplies the remainder by 4, to first order in the amplitude (here 1 %)."""
    for dof in (1, 3):
        small, large = (linearisation_remainder(paper, *sine_motion(paper, dof, s)[1:])
                        for s in (1.0, 2.0))
        ratio = np.linalg.norm(large) / np.linalg.norm(small)
        assert ratio == pytest.approx(4.0, rel=0.02)


@pytest.mark.slow
@pytest.mark.parametrize("method", ["wavelet", "ls"])
def test_linearisation_identified_at_ten_times_the_amplitude(paper, method):
    """Noise-free records of the model (no Coulomb friction) at ten times the paper's
    amplitudes: with the remainder subtracted the identified matrices are the linearisation's
    (the error is the Savitzky-Golay rates' and the kernels', < 0.05 %); without it they
    average M(q) and the velocity products over the motion (> 0.3 %)."""
    platform = paper.replace(friction__coulomb=0.0)
    data = model_records(platform, 10.0)
    exact = create_identifier(method).fit(data, platform)
    averaged = create_identifier(method, remainder=False).fit(data, platform)
    assert largest_error(exact, platform) < 0.05
    assert largest_error(averaged, platform) > 0.3


@pytest.mark.slow
def test_free_constants_keep_the_coulomb_force_inside_the_intervals(paper):
    """Ten times the paper's amplitudes with the platform's Coulomb friction on every joint
    axis (30 N m): the idle revolute joints reverse inside the constant-direction intervals
    and the pose changes the generalized Coulomb force there. Method B's free constants then
    keep the Coulomb levels on their invariant rows (a soft-sign rate is chosen) and the
    revolute level comes out near the model's (on the plant's logs without them Mt(4,2) was
    3.5 % off)."""
    platform = paper.replace(friction__coulomb=30.0)
    est = create_identifier("wavelet", friction="free").fit(model_records(platform, 10.0),
                                                          platform)
    diagnostics = est.result_.diagnostics
    assert diagnostics["soft_sign_rate"] is not None
    assert diagnostics["coulomb"]["revolute"] == pytest.approx(30.0, abs=3.0)
    assert largest_error(est, platform) < 0.5
