"""Excitation trajectories and their constant-direction intervals."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.ndimage import maximum_filter1d

from stewartid.datasets.excitation import running_maximum
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


def test_spectral_lines_ignore_the_edge_of_the_blanked_low_band():
    """A faded sine over a slow swell: the largest value just above the blanked band is that
    band's edge, not a line; the line is the sine's, its height that of a Hann-windowed sine
    (A n / 4 for amplitude A over n samples), not an overflow of the peak interpolation."""
    from stewartid.datasets.excitation import spectral_lines

    rate, n = 1000.0, 12001
    t = np.arange(n) / rate
    fade = np.clip(t / 2, 0, 1) * np.clip((12 - t) / 2, 0, 1)
    x = 0.0126 * fade * np.sin(2 * np.pi * 0.53 * t) + 0.01 * np.exp(-((t - 6) / 3) ** 2)
    lines = spectral_lines(x, rate, fraction=0.0)
    assert lines.frequencies_hz[0] == pytest.approx(0.53, abs=0.01)
    assert lines.largest <= 0.0126 * n / 4 * 1.01


def test_channel_lines_are_each_channels_own_lines():
    # one transform of every channel gives what a transform of each channel alone gives
    from stewartid.datasets.excitation import channel_lines, spectral_lines

    rng = np.random.default_rng(5)
    t = np.arange(3000) / 200.0
    motion = np.column_stack([np.sin(2 * np.pi * f * t) + 0.3 * np.sin(2 * np.pi * 3 * f * t)
                              for f in (0.4, 1.1, 2.7)]) + 1e-3 * rng.standard_normal((3000, 3))
    for k, lines in enumerate(channel_lines(motion, 200.0, fraction=0.1)):
        alone = spectral_lines(motion[:, k], 200.0, fraction=0.1)
        assert len(lines) == 2
        assert np.array_equal(lines.frequencies_hz, alone.frequencies_hz)
        assert np.array_equal(lines.amplitudes, alone.amplitudes)
        assert lines.largest == alone.largest


@settings(max_examples=60, deadline=None)
@given(st.integers(1, 300), st.integers(0, 70), st.integers(0, 2**32 - 1))
def test_running_maximum_is_scipy_maximum_filter(n, reach, seed):
    """The spectra's sidelobe test: the largest value within reach, zero beyond the ends."""
    rng = np.random.default_rng(seed)
    x = rng.random(n) * (rng.random(n) < 0.3)
    expected = maximum_filter1d(x, size=2 * reach + 1, mode="constant")
    np.testing.assert_array_equal(running_maximum(x, reach), expected)
