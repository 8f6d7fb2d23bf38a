"""The scikit-learn estimator contract, checked the same way on every registered method and
preset (modelled on scikit-learn's own estimator checks)."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from sklearn.base import clone

from linear_model_data import AMPLITUDES, make_experiment, random_matrices
from stewartid.errors import ConfigError, NotFittedError, StewartidError
from stewartid.identification.base import BaseIdentifier
from stewartid.identification.registry import registered_methods

SPECS = registered_methods()


@pytest.fixture(scope="module")
def data(paper):
    """Six short experiments of the linear model (one sine per DOF)."""
    M, B = random_matrices(np.random.default_rng(5))
    return [make_experiment(paper, M, B, k, frequency_hz=1.0, periods=4) for k in range(6)]


@pytest.fixture(params=SPECS, ids=[spec.name for spec in SPECS])
def spec(request):
    return request.param


def test_registry_lists_the_builtin_methods_first():
    assert [spec.name for spec in SPECS][:3] == ["wavelet", "fourier", "ls"]
    assert all(spec.preset_of is None for spec in SPECS[:3])
    assert {spec.letter for spec in SPECS} >= {"A", "B"}


def test_init_only_stores_settings(spec):
    estimator = spec.create()
    assert isinstance(estimator, BaseIdentifier)
    params = estimator.get_params()
    assert params == estimator.get_params(deep=False)
    for name, value in spec.defaults.items():
        assert params[name] == value
    assert not [name for name in vars(estimator) if name.endswith("_")]


def test_clone_round_trips(spec):
    estimator = spec.create()
    copy = clone(estimator)
    assert type(copy) is type(estimator) and copy is not estimator
    assert copy.get_params() == estimator.get_params()


def test_set_params_changes_settings_and_refuses_unknown_ones(spec):
    estimator = spec.create()
    assert estimator.set_params(gravity=False) is estimator
    assert estimator.get_params()["gravity"] is False
    assert clone(estimator).get_params()["gravity"] is False
    with pytest.raises(ConfigError, match="has no setting 'magic'"):
        estimator.set_params(magic=1)


def test_reading_a_result_before_fit_raises_not_fitted(spec):
    estimator = spec.create()
    with pytest.raises(NotFittedError, match="not fitted yet"):
        _ = estimator.M_
    assert not hasattr(estimator, "result_")
    assert issubclass(NotFittedError, StewartidError | AttributeError | ValueError)


def test_fit_requires_the_platform(spec, data):
    with pytest.raises(TypeError, match="platform"):
        spec.create().fit(data)


def test_fit_returns_self_with_learned_attributes(spec, data, paper):
    estimator = spec.create()
    assert estimator.fit(data, paper) is estimator
    learned = [name for name in vars(estimator) if not name.startswith("_")
               and name not in estimator.get_params()]
    assert learned and all(name.endswith("_") for name in learned)
    assert estimator.M_.shape == estimator.B_.shape == (6, 6)
    assert estimator.result_.method == spec.estimator_class.method
    # a clone of a fitted estimator has its settings but nothing learned
    copy = clone(estimator)
    assert copy.get_params() == estimator.get_params() and not hasattr(copy, "M_")


def test_declared_constraints_name_settings_and_accept_the_defaults(spec):
    estimator = spec.create()
    constraints = type(estimator)._parameter_constraints
    assert constraints and set(constraints) <= set(estimator.get_params())
    estimator._validate_params()  # the defaults (a preset's too) satisfy their constraints


def test_a_bad_setting_is_refused_in_one_message_form(spec, paper):
    name = next(iter(type(spec.create())._parameter_constraints))
    estimator = spec.create(**{name: object()})
    owner = type(estimator).__name__
    with pytest.raises(ConfigError, match=rf"^The '{name}' parameter of {owner} must be .+\. "
                                          r"Got <object object at \w+> instead\.$"):
        estimator.fit([], paper)


def rigid_body_experiments(platform) -> list:
    """Six experiments of the rigid-body model itself (the physical estimator's model class):
    every DOF at once, DOF d of experiment k at 0.4 + 0.15 ((d + k) mod 6) Hz, 8 s at 200 Hz,
    the actuator forces of the model's inverse dynamics (friction included)."""
    from stewartid.datasets.dataset import Dataset
    from stewartid.model.dynamics import inverse_dynamics
    from stewartid.model.kinematics import leg_lengths

    t = np.arange(1600) / 200.0
    out = []
    for k in range(6):
        q = np.tile(platform.neutral_pose, (len(t), 1))
        qd, qdd = np.zeros_like(q), np.zeros_like(q)
        for d in range(6):
            a, w = AMPLITUDES[d], 2 * np.pi * (0.4 + 0.15 * ((d + k) % 6))
            q[:, d] += a * np.sin(w * t + d)
            qd[:, d] += a * w * np.cos(w * t + d)
            qdd[:, d] -= a * w ** 2 * np.sin(w * t + d)
        out.append(Dataset(t=t, pose=q, lengths=leg_lengths(platform, q),
                           forces=inverse_dynamics(platform, q, qd, qdd), name=f"exp{k + 1}"))
    return out


@pytest.fixture(scope="module")
def noisy_truth(paper):
    """Per model class, six experiments in 6 realisations of white force noise (0.5 % of each
    leg's mean force), and the true (Mt, Bt): for the matrices' estimators the linear model
    along single sines, 8 periods; for the physical model the rigid-body model itself, the
    truth its Mt, Bt at neutral."""
    from stewartid.model.linearization import nominal_matrices

    M, B = random_matrices(np.random.default_rng(11))
    linear = [make_experiment(paper, M, B, k, frequency_hz=1.0, periods=8) for k in range(6)]
    return {"linear": (_noisy(linear), M, B),
            "rigid": (_noisy(rigid_body_experiments(paper)), *nominal_matrices(paper))}


def _noisy(clean: list) -> list:
    rng = np.random.default_rng(12)
    return [[dataclasses.replace(d, forces=d.forces + 0.005 * np.abs(d.forces).mean(axis=0)
                                 * rng.normal(size=d.forces.shape)) for d in clean]
            for _ in range(6)]


@pytest.mark.slow
def test_standard_errors_are_calibrated_on_a_small_noisy_case(spec, noisy_truth, paper):
    """Against the generating model: most of the 72 entries x 6 realisations within 3
    reported standard errors, and the errors not so pessimistic that the check is vacuous.
    With 432 draws of honest Gaussian errors, the share within 3 SE is 0.997 (binomial
    standard deviation 0.003), the RMS ratio 1 +- 0.03."""
    sets, M, B = noisy_truth["rigid" if spec.name == "physical" else "linear"]
    ratios = []
    for data in sets:
        estimator = spec.create().fit(data, paper)
        for estimate, truth, matrix in ((estimator.M_, M, "M"), (estimator.B_, B, "B")):
            # an entry the model holds at zero (the physical model's structural zeros) has a
            # zero standard error: round-off of the matrix's scale is its floor
            floor = 1e-9 * np.abs(truth).max()
            ratios.append(np.abs(estimate - truth)
                          / np.maximum(estimator.std_errors_[matrix], floor))
    ratios = np.concatenate([r.ravel() for r in ratios])
    assert np.mean(ratios <= 3.0) >= 0.95, f"{spec.name}: {np.mean(ratios <= 3.0):.2%} within 3 SE"
    assert np.sqrt(np.mean(ratios ** 2)) >= 0.2, spec.name
