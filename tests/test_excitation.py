"""Excitation trajectories and their constant-direction intervals."""

from __future__ import annotations

import numpy as np
import pytest

from stewartid.errors import ConfigError
from stewartid.identification.wavelet.intervals import check_intervals, joint_rates
from stewartid.simulation import Sine, multisine_excitation, paper_experiments


def test_derivatives_match_finite_differences(paper):
    exc = multisine_excitation(paper, [Sine(0, 0.01, 0.5), Sine(0, 0.005, 1.3, 0.4),
                                       Sine(4, 0.01, 0.7)], fade_in=1.5)
    t = np.linspace(0.0, 4.0, 40001)
    q, qd, qdd = exc.evaluate(t)
    np.testing.assert_allclose(np.gradient(q, t, axis=0)[1:-1], qd[1:-1], atol=1e-8)
    np.testing.assert_allclose(np.gradient(qd, t, axis=0)[1:-1], qdd[1:-1], atol=1e-5)


def test_fade_in_starts_at_rest(paper):
    q, qd, qdd = paper_experiments(paper)[3].evaluate(np.array([0.0]))
    np.testing.assert_array_equal(q[0], paper.neutral_pose)
    assert not qd.any() and not qdd.any()


def test_paper_set_yields_constant_direction_intervals(paper):
    for exc in paper_experiments(paper):
        t = np.arange(2.0, 10.0, 1e-3)
        q, qd, _ = exc.evaluate(t)
        check = check_intervals(t, joint_rates(paper, q, qd), min_duration=0.8, min_count=7,
                                ignore_below=1e-3)
        assert check.ok, f"{exc.name}: {check.message}"


def test_bad_sine_is_refused():
    with pytest.raises(ConfigError, match="dof must be"):
        Sine(6, 0.01, 0.5)
    with pytest.raises(ConfigError, match="frequency_hz must be > 0"):
        Sine(0, 0.01, -1.0)
