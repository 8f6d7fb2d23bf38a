"""The scikit-learn estimator contract, checked the same way on every registered method and
preset (modelled on scikit-learn's own estimator checks)."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from sklearn.base import clone

from linear_model_data import make_experiment, random_matrices
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


@pytest.fixture(scope="module")
def noisy_truth(paper):
    """Six experiments of the linear model, 8 periods, the forces measured with white noise
    of 0.5 % of each leg's mean force, in 6 realisations; and the true (Mt, Bt)."""
    M, B = random_matrices(np.random.default_rng(11))
    clean = [make_experiment(paper, M, B, k, frequency_hz=1.0, periods=8) for k in range(6)]
    rng = np.random.default_rng(12)
    sets = []
    for _ in range(6):
        sets.append([dataclasses.replace(d, forces=d.forces + 0.005 * np.abs(d.forces).mean(axis=0)
                                         * rng.normal(size=d.forces.shape)) for d in clean])
    return sets, M, B


def test_standard_errors_are_calibrated_on_a_small_noisy_case(spec, noisy_truth, paper):
    """Against the generating model: most of the 72 entries x 6 realisations within 3
    reported standard errors, and the errors not so pessimistic that the check is vacuous.
    With 432 draws of honest Gaussian errors, the share within 3 SE is 0.997 (binomial
    standard deviation 0.003), the RMS ratio 1 +- 0.03."""
    sets, M, B = noisy_truth
    ratios = []
    for data in sets:
        estimator = spec.create().fit(data, paper)
        for estimate, truth, matrix in ((estimator.M_, M, "M"), (estimator.B_, B, "B")):
            ratios.append(np.abs(estimate - truth) / estimator.std_errors_[matrix])
    ratios = np.concatenate([r.ravel() for r in ratios])
    assert np.mean(ratios <= 3.0) >= 0.95, f"{spec.name}: {np.mean(ratios <= 3.0):.2%} within 3 SE"
    assert np.sqrt(np.mean(ratios ** 2)) >= 0.2, spec.name
