"""The physically consistent fit of the physical model (``PhysicalIdentifier(consistent=True)``).

- On noise-free records of a consistent model (every friction coefficient positive, a real
  payload) the constraints are inactive: the consistent fit is the unconstrained one.
- On an estimate that violates the pseudo-inertia condition the projection satisfies it and is
  the nearest point in the metric of the covariance: checked against an independent solution
  of the same small problem (J = L L^T, unconstrained in L, by scipy's L-BFGS-B).
- The pseudo-inertia matrix is positive semidefinite for real mass distributions and its
  smallest eigenvalue negative for a first moment no mass distribution can have.
"""

from __future__ import annotations

import sys

import numpy as np
import pytest
from scipy.optimize import minimize

from stewartid.datasets.dataset import Dataset
from stewartid.errors import ConfigError
from stewartid.model import regressor as reg
from stewartid.model.kinematics import leg_jacobian, leg_lengths
from stewartid.physical.estimator import PhysicalIdentifier
from stewartid.physical.parameter_fit import Body, nearest_consistent
from stewartid.simulation import DEFAULT_AMPLITUDES

pytest.importorskip("cvxpy")

#: Frequencies (Hz) of the all-DOFs multisine: DOF d of experiment k at HZ[(d + k) % 6].
HZ = (0.3, 0.45, 0.6, 0.75, 0.9, 1.05)
PAYLOAD = {"mass": 2000.0, "com": [-0.20, 0.30, -0.50],
           "inertia": [1800.0, 2200.0, 2600.0, -120.0, 80.0, 160.0]}


@pytest.fixture(scope="module")
def loaded(paper):
    return paper.replace(friction__coulomb=30.0,
                         **{f"payload__{key}": value for key, value in PAYLOAD.items()})


def true_parameters(platform):
    """The file's standard parameters with every friction coefficient positive (the plant
    model has no revolute viscosity and no actuator friction): no constraint is active."""
    pi = reg.standard_parameters(platform)
    for name, value in (("viscous[revolute]", 2000.0), ("viscous[actuator]", 500.0),
                        ("coulomb[actuator]", 80.0)):
        pi[reg.parameter_index([name])[0]] = value
    return pi


def regressor_records(platform, pi, sample_rate=200.0, duration=8.0, noise=0.0, seed=0):
    """Six all-DOFs multisine records whose leg forces give J_lq^T f = Y(q, q_dot, q_ddot) pi
    exactly (analytic rates), plus white force noise of standard deviation ``noise`` (N)."""
    rng = np.random.default_rng(seed)
    t = np.arange(int(duration * sample_rate)) / sample_rate
    out = []
    for k in range(6):
        q = np.tile(platform.neutral_pose, (len(t), 1))
        qd, qdd = np.zeros_like(q), np.zeros_like(q)
        for d in range(6):
            a, w, phase = 0.5 * DEFAULT_AMPLITUDES[d], 2 * np.pi * HZ[(d + k) % 6], 0.5 * d + k
            q[:, d] += a * np.sin(w * t + phase)
            qd[:, d] += a * w * np.cos(w * t + phase)
            qdd[:, d] -= a * w * w * np.sin(w * t + phase)
        tau = reg.regressor(platform, q, qd, qdd) @ pi
        forces = np.linalg.solve(np.swapaxes(leg_jacobian(platform, q), 1, 2), tau[..., None])
        forces = forces[..., 0] + noise * rng.standard_normal(tau.shape)
        out.append(Dataset(t=t, pose=q, lengths=leg_lengths(platform, q), forces=forces,
                           name=f"exp{k + 1}"))
    return out


@pytest.mark.parametrize("payload", [False, True])
def test_consistent_data_leave_the_estimate_unchanged(loaded, payload):
    """Noise-free records of a consistent model: the unconstrained estimate is consistent, so
    the consistent fit returns it (to the last bit) and reports no change."""
    pi = true_parameters(loaded)
    records = regressor_records(loaded, pi)
    platform = loaded.replace(payload=None) if payload else loaded
    free = PhysicalIdentifier(payload=payload).fit(records, platform)
    fitted = PhysicalIdentifier(payload=payload, consistent=True).fit(records, platform)
    mass = "payload.m" if payload else "m"
    expected = PAYLOAD["mass"] if payload else reg.base_parameters(loaded).combination[0] @ pi
    assert abs(free.parameters_[mass] - expected) < 1e-3 * expected  # the data are the model's
    assert fitted.parameters_ == free.parameters_
    np.testing.assert_array_equal(fitted.M_, free.M_)
    report = fitted.result_.diagnostics["consistent"]
    assert report["max_change_std_errors"] == 0.0 and report["objective"] == 0.0
    assert min(report["min_eigenvalue_pseudo_inertia"].values()) > 0


def test_pseudo_inertia_is_psd_exactly_for_real_bodies():
    """A box of point masses (built from its mass distribution, not the formula) has a PSD
    pseudo-inertia; moving its first moment beyond what the second moment allows
    (|h|^2 > m Sigma along h) makes the smallest eigenvalue negative."""
    rng = np.random.default_rng(3)
    points, masses = rng.uniform(-0.5, 0.5, (40, 3)) + [0.1, -0.2, 0.3], rng.uniform(1, 5, 40)
    second = np.einsum("k,ki,kj->ij", masses, points, points)
    inertia = np.trace(second) * np.eye(3) - second
    body = np.concatenate([[masses.sum()], masses @ points,
                           inertia[[0, 1, 2, 0, 0, 1], [0, 1, 2, 1, 2, 2]]])
    J = reg.pseudo_inertia(body)
    np.testing.assert_allclose(J[:3, :3], second, rtol=1e-12, atol=1e-12 * np.abs(second).max())
    assert np.linalg.eigvalsh(J)[0] > 0
    body[1] += 3.0 * np.sqrt(masses.sum() * second[0, 0])  # |h_x| beyond sqrt(m Sigma_xx)
    assert np.linalg.eigvalsh(reg.pseudo_inertia(body))[0] < 0


def _violating_problem():
    """A payload-like body whose first moment no mass distribution can have, one friction
    coefficient below zero, and a correlated covariance with parameters of different units."""
    values = np.array([500.0, 150.0, -80.0, 100.0, 20.0, 25.0, 22.0, -2.0, 1.5, 3.0,
                       -4.0, 30.0])
    rng = np.random.default_rng(5)
    std = np.array([5.0, 3.0, 3.0, 3.0, 4.0, 4.0, 4.0, 1.0, 1.0, 1.0, 2.0, 2.0])
    factor = rng.standard_normal((12, 12))
    correlation = factor @ factor.T + 6 * np.eye(12)
    d = np.sqrt(np.diag(correlation))
    covariance = correlation / np.outer(d, d) * np.outer(std, std)
    mapping = np.hstack([np.eye(10), np.zeros((10, 2))])
    body = Body("payload", mapping, np.zeros(10), 500.0)
    nonnegative = np.array([False] * 10 + [True, True])
    return values, covariance, body, nonnegative


def test_violating_estimate_is_projected_to_the_nearest_consistent_point():
    values, covariance, body, nonnegative = _violating_problem()
    scale = np.abs(body.pseudo_inertia(values)).max()
    assert np.linalg.eigvalsh(body.pseudo_inertia(values))[0] < -1e-3 * scale
    found = nearest_consistent(values, covariance, [body], nonnegative)
    assert found.solver != "none"
    assert np.linalg.eigvalsh(body.pseudo_inertia(found.values))[0] >= -1e-9 * scale
    assert found.values[10] >= -1e-9 * 2.0 and found.values[0] > 0
    inverse = np.linalg.inv(covariance)

    def objective(p):
        return (p - values) @ inverse @ (p - values)

    assert found.objective == pytest.approx(objective(found.values), rel=1e-9)
    std = np.sqrt(np.diag(covariance))
    np.testing.assert_allclose(found.change, (found.values - values) / std, atol=1e-12)
    # the same problem solved independently: J = L L^T (every PSD J, no constraint left),
    # the inertia from J by I = tr(Sigma) 1 - Sigma, friction bounded; local searches from
    # the unconstrained J clipped to PSD and perturbed starts
    reference = min((minimize(lambda x: objective(_from_cholesky(x)), start, method="L-BFGS-B",
                              bounds=[(None, None)] * 10 + [(0.0, None)] * 2,
                              options={"ftol": 1e-15, "gtol": 1e-10, "maxfun": 100000})
                     for start in _cholesky_starts(body.pseudo_inertia(values), values[10:])),
                    key=lambda r: r.fun)
    # Clarabel's relative gap tolerance (1e-8) bounds the objective's excess; by the
    # objective's curvature (smallest eigenvalue of the inverse correlation, >= 1/12 here)
    # the parameters then agree within sqrt(12 x 1e-8 x objective) standard errors (0.01)
    assert found.objective == pytest.approx(reference.fun, rel=1e-7)
    np.testing.assert_allclose((found.values - _from_cholesky(reference.x)) / std, 0.0,
                               atol=1e-2)


_ROWS, _COLS = np.tril_indices(4)


def _from_cholesky(x):
    """Body parameters and two friction coefficients from the lower triangle x[:10] of L
    (J = L L^T) and x[10:]: m = J_33, h = J_:3,3, I = tr(Sigma) 1 - Sigma."""
    L = np.zeros((4, 4))
    L[_ROWS, _COLS] = x[:10]
    J = L @ L.T
    inertia = np.trace(J[:3, :3]) * np.eye(3) - J[:3, :3]
    return np.concatenate([[J[3, 3]], J[:3, 3], inertia[[0, 1, 2, 0, 0, 1], [0, 1, 2, 1, 2, 2]],
                           x[10:]])


def _cholesky_starts(J, friction, count=6):
    values, vectors = np.linalg.eigh(J)
    clipped = (vectors * np.maximum(values, 1e-3 * values.max())) @ vectors.T
    x0 = np.concatenate([np.linalg.cholesky(clipped)[_ROWS, _COLS], np.maximum(friction, 0.0)])
    rng = np.random.default_rng(1)
    return [x0] + [x0 * (1 + 0.3 * rng.standard_normal(x0.shape)) for _ in range(count - 1)]


def test_estimator_enforces_the_payload_condition(loaded):
    """A point-mass payload (pseudo-inertia of rank one) and force noise: the unconstrained
    payload violates the condition, the consistent one satisfies it, moves little in
    standard errors and gives Mt from its parameters."""
    bare = loaded.replace(payload=None)
    mass, c = 800.0, np.array([0.3, -0.2, -0.4])
    about_reference = mass * (c @ c * np.eye(3) - np.outer(c, c))  # a point mass at c
    pi = true_parameters(bare)
    pi[:10] += np.concatenate([[mass], mass * c,
                               about_reference[[0, 1, 2, 0, 0, 1], [0, 1, 2, 1, 2, 2]]])
    records = regressor_records(bare, pi, noise=200.0, seed=2)
    free = PhysicalIdentifier(payload=True).fit(records, bare)
    fitted = PhysicalIdentifier(payload=True, consistent=True).fit(records, bare)

    def payload_J(parameters):
        return reg.pseudo_inertia(np.array([parameters[f"payload.{n}"]
                                            for n in reg.BODY_PARAMETERS]))

    scale = np.abs(payload_J(free.parameters_)).max()
    assert np.linalg.eigvalsh(payload_J(free.parameters_))[0] < 0
    assert np.linalg.eigvalsh(payload_J(fitted.parameters_))[0] >= -1e-9 * scale
    report = fitted.result_.diagnostics["consistent"]
    changes = np.array(list(report["change_std_errors"].values()))
    assert 0 < report["max_change_std_errors"] == pytest.approx(np.abs(changes).max())
    assert report["max_change_std_errors"] < 5.0
    assert report["unconstrained"] == free.parameters_
    assert fitted.result_.to_dict()["settings"]["consistent"] is True


def test_without_cvxpy_the_extra_is_named(loaded, monkeypatch):
    monkeypatch.setitem(sys.modules, "cvxpy", None)
    records = regressor_records(loaded, true_parameters(loaded), duration=4.0)
    with pytest.raises(ConfigError, match=r"stewartid\[convex\]"):
        PhysicalIdentifier(consistent=True).fit(records, loaded)
