"""Savitzky-Golay taps against exact rational arithmetic; the FFT convolution against direct sums."""

from __future__ import annotations

import math
from fractions import Fraction

import numpy as np
import pytest

from roundoff import convolution_bound
from stewartid.signals.differentiation import convolve_valid, savgol_coefficients


def exact_taps(n: int, order: int, deriv: int) -> list[Fraction]:
    """Taps for a unit sample period from the normal equations solved in rational numbers."""
    offsets = range(n // 2, n // 2 - n, -1)
    size = order + 1
    rows = [[Fraction(sum(o ** (i + j) for o in offsets)) for j in range(size)]
            + [Fraction(math.factorial(deriv) if i == deriv else 0)] for i in range(size)]
    for column in range(size):
        pivot = rows[column][column]
        rows[column] = [value / pivot for value in rows[column]]
        for row in range(size):
            if row != column and rows[row][column]:
                factor = rows[row][column]
                rows[row] = [a - factor * b for a, b in zip(rows[row], rows[column], strict=True)]
    solution = [rows[i][size] for i in range(size)]
    return [sum(solution[i] * Fraction(o) ** i for i in range(size)) for o in offsets]


@pytest.mark.parametrize("n", [7, 51, 401, 1001, 2001])
@pytest.mark.parametrize("deriv", [0, 1, 2])
def test_taps_are_exact_to_round_off_for_any_window(n, deriv):
    order, delta = 5, 1e-3
    exact = np.array([float(t) for t in exact_taps(n, order, deriv)]) / delta ** deriv
    taps = savgol_coefficients(n, order, deriv, delta)
    # lstsq on a Vandermonde matrix of condition ~10 (offsets in [-1, 1]): the error is a few
    # hundred ulps of the taps' l1 norm at most, whatever n
    assert np.abs(taps - exact).sum() <= 1e3 * np.finfo(float).eps * np.abs(exact).sum()


@pytest.mark.parametrize("shape", [(3000,), (8001, 6), (5000, 3, 2), (1500, 40)])
@pytest.mark.parametrize("length", [5, 51, 401, 1001])
@pytest.mark.parametrize("block_bytes", [1 << 26, 1 << 16])
def test_convolution_is_the_direct_sum(shape, length, block_bytes):
    # several kernels on one transform, trailing axes, blocks in one group or many
    rng = np.random.default_rng(length)
    x = rng.standard_normal(shape).cumsum(axis=0) + 50.0
    kernels = [rng.standard_normal(length) for _ in range(3)]
    got = convolve_valid(x, kernels, block_bytes)
    flat = x.reshape(len(x), -1)
    for kernel, out in zip(kernels, got, strict=True):
        assert out.shape == (len(x) - length + 1,) + shape[1:]
        direct = np.stack([np.convolve(column, kernel, mode="valid") for column in flat.T], 1)
        error = np.abs(out.reshape(len(direct), -1) - direct).max()
        assert error <= convolution_bound(kernel, np.abs(x).max())
