"""Piecewise cubic Hermite on uniform knots against the signals it interpolates: exact for a
cubic, within the classical error bound for a sine."""

from __future__ import annotations

import numpy as np
import pytest

from stewartid.signals.interpolation import hermite_uniform


def test_a_cubic_is_reproduced():
    t = np.arange(401, dtype=float)
    f = 1e-6 * t ** 3 - 2e-4 * t ** 2 + 0.3 * t - 5
    step = 8
    got = hermite_uniform(f[::step, None], step, len(t))[:, 0]
    # five-point slopes are exact for a cubic: only round-off, a few ulps of the largest value
    assert got == pytest.approx(f, abs=1e3 * np.finfo(float).eps * np.abs(f).max())


@pytest.mark.parametrize("step", [4, 8, 16])
def test_a_sine_within_the_hermite_error_bound(step):
    w = 0.02
    t = np.arange(50 * step + 1, dtype=float)
    f = np.sin(w * t + 0.3)
    got = hermite_uniform(f[::step, None], step, len(t))[:, 0]
    h = w * step
    # exact-slope Hermite: h^4 / 384; the slopes' error times the basis' 4/27: the one-sided
    # ends h^5 / 5, inside h^5 / 30
    inside = h ** 4 / 384 + (4 / 27) * h ** 5 / 30
    ends = h ** 4 / 384 + (4 / 27) * h ** 5 / 5
    error = np.abs(got - f)
    middle = slice(2 * step, len(t) - 2 * step)
    assert np.max(error[middle]) <= inside * (1 + 1e-6) + 1e-15
    assert np.max(error) <= ends * (1 + 1e-6) + 1e-15
    # at a knot the Hermite basis is exactly (1, 0, 0, 0): the sample itself
    assert np.array_equal(got[::step], f[::step])


@pytest.mark.parametrize("samples", [5, 6, 31, 33, 72, 73, 500, 20001])
def test_the_spline_is_scipys_clamped_spline(samples):
    """The knot slopes from the tridiagonal system's series against scipy's CubicSpline with the
    same end slopes, on random walks of 1 and 6 channels: within a few hundred ulps of the
    signal's scale (the system's round-off over 20,000 rows)."""
    from scipy.interpolate import CubicSpline

    from stewartid.signals.interpolation import ONE_SIDED_SLOPE, spline_at

    rng = np.random.default_rng(samples)
    t = 0.3 + np.arange(samples) / 1000.0
    times = np.concatenate([np.sort(rng.uniform(t[0], t[-1], 300)), [t[0], t[-1]],
                            np.clip(t + 0.0004, t[0], t[-1])])
    for channels in (1, 6):
        values = np.cumsum(rng.standard_normal((samples, channels)), axis=0)
        ends = ((1, np.tensordot(ONE_SIDED_SLOPE, values[:5], axes=1) / 1e-3),
                (1, -np.tensordot(ONE_SIDED_SLOPE, values[::-1][:5], axes=1) / 1e-3))
        expected = CubicSpline(t, values, axis=0, bc_type=ends)(times)
        scale = np.abs(values).max()
        assert np.abs(spline_at(t, values, times) - expected).max() <= 1e3 * np.finfo(float).eps * scale
        assert spline_at(t, values[:, 0], times).shape == (len(times),)


def test_the_spline_of_a_sine_within_its_error_bound_and_five_samples_at_least():
    from stewartid.signals.interpolation import spline_at

    w, h = 2 * np.pi * 3.0, 1e-3
    t = np.arange(2001) * h
    times = t[:-1] + 0.37 * h
    error = np.abs(spline_at(t, np.sin(w * t), times) - np.sin(w * times))
    # (5/384) h^4 max|x''''| with the five-point end slopes (Hall & Meyer), plus round-off
    assert error.max() <= 5 / 384 * (w * h) ** 4 * (1 + 1e-6) + 1e-14
    with pytest.raises(ValueError, match="five samples"):
        spline_at(t[:4], np.sin(w * t[:4]), t[:2])
