"""Constant-direction interval detection against analytic zero crossings."""

from __future__ import annotations

import numpy as np
import pytest

from stewartid.errors import ConfigError
from stewartid.identification.wavelet.intervals import (
    JOINT_RATE_NAMES,
    active_joints,
    check_intervals,
    constant_direction_intervals,
    joint_rates,
)
from stewartid.model.kinematics import leg_lengths

DT = 1e-3
T = np.arange(0.0, 4.0, DT) + DT / 3  # no sample exactly on a zero crossing


def test_intervals_are_between_zero_crossings_of_all_rates():
    # zero crossings at multiples of 0.5 s (first rate) and 0.25 + multiples of 1 s (second)
    rates = np.c_[np.sin(2 * np.pi * T), np.cos(np.pi * T)]
    got = constant_direction_intervals(T, rates, margin=0.0)
    crossings = np.sort(np.r_[np.arange(0.5, 4.0, 0.5), np.arange(0.5, 4.0, 1.0)])
    crossings = np.unique(np.round(crossings, 9))
    edges = np.r_[T[0], crossings, T[-1]]
    expected = np.c_[edges[:-1], edges[1:]]
    assert got.shape == expected.shape
    np.testing.assert_allclose(got, expected, atol=DT)


def test_margin_min_duration_and_ignored_joints():
    rates = np.c_[np.sin(2 * np.pi * T), 1e-4 * np.sin(2 * np.pi * 7.3 * T)]
    assert len(constant_direction_intervals(T, rates)) > 40  # the idle joint chops them
    kept = constant_direction_intervals(T, rates, margin=0.05, ignore_below=0.01)
    assert len(kept) == 8
    np.testing.assert_allclose(np.diff(kept, axis=1)[1:-1], 0.4, atol=DT)
    assert len(constant_direction_intervals(T, rates, margin=0.05, ignore_below=0.01,
                                            min_duration=0.45)) == 0
    np.testing.assert_array_equal(active_joints(rates, 0.01), [True, False])


def test_touching_zero_is_not_a_reversal():
    t = np.arange(10.0)
    rates = np.array([1, 1, 1, 0, 1, 1, -1, -1, -1, -1.0])[:, None]
    np.testing.assert_allclose(constant_direction_intervals(t, rates, margin=0.0),
                               [[0, 5], [6, 9]])


def test_hysteresis_keeps_noisy_crossings_outside_the_intervals():
    rng = np.random.default_rng(0)
    clean = np.c_[np.sin(2 * np.pi * T), 0.3 * np.sin(2 * np.pi * T + 0.01)]
    noise = np.c_[0.01 * rng.standard_normal((len(T), 2)), 1e-3 * rng.standard_normal(len(T))]
    rates = np.c_[clean, np.zeros(len(T))] + noise  # third joint: pure noise
    plain = constant_direction_intervals(T, rates, margin=0.0)
    assert len(plain) > 100
    got = constant_direction_intervals(T, rates, margin=0.0, hysteresis=[0.04, 0.04, 0.004])
    assert len(got) == 8
    crossings = np.arange(0.0, 4.01, 0.5)
    for start, stop in got:
        # every interval lies between two consecutive true zero crossings
        k = np.searchsorted(crossings, start)
        assert crossings[k - 1] <= start and stop <= crossings[k] + 1e-9


def test_joint_rates_layout_and_actuator_rates(paper):
    t = np.arange(0.0, 1.0, 1e-3)
    w = 2 * np.pi * 0.5
    q = np.tile(paper.neutral_pose, (len(t), 1))
    q_dot = np.zeros_like(q)
    q[:, 0] += 0.01 * np.sin(w * t)
    q[:, 4] += 0.004 * np.sin(w * t + 0.3)
    q_dot[:, 0] = 0.01 * w * np.cos(w * t)
    q_dot[:, 4] = 0.004 * w * np.cos(w * t + 0.3)
    rates = joint_rates(paper, q, q_dot)
    assert rates.shape == (len(t), 36) and len(JOINT_RATE_NAMES) == 36
    # actuator rates are the time derivative of the leg lengths
    lengths = leg_lengths(paper, q)
    np.testing.assert_allclose(rates[1:-1, 30:], np.gradient(lengths, t, axis=0)[1:-1],
                               rtol=1e-3, atol=1e-7)


def test_check_intervals_says_what_to_change():
    rates = np.sin(2 * np.pi * 2.0 * T)[:, None]
    good = check_intervals(T, rates, min_duration=0.2, min_count=3)
    assert good.ok and good.count >= 7
    bad = check_intervals(T, rates, min_duration=0.5)
    assert not bad.ok and "slower" in bad.message
    with pytest.raises(ConfigError, match="ignore_below must be a fraction"):
        constant_direction_intervals(T, rates, ignore_below=2.0)
