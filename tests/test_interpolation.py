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
