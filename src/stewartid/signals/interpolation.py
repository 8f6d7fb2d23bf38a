"""A uniformly sampled signal between its samples: one cubic spline, exact to its bound up to the ends."""

from __future__ import annotations

import numpy as np

#: First derivative at the first of five equally spaced samples, times the spacing
#: (error h^4 x^(5) / 5).
ONE_SIDED_SLOPE = np.array([-25.0, 48.0, -36.0, 16.0, -3.0]) / 12.0


def spline_at(t: np.ndarray, values: np.ndarray, times: np.ndarray) -> np.ndarray:
    """The signal ``values`` (N,) or (N, C) sampled at ``t`` (N,), at ``times`` (M,) within the record.

    A cubic spline whose end slopes are five-point one-sided differences, which keep the error bound
    (5/384) h^4 max|x''''| up to the ends (Hall & Meyer 1976); ``t`` uniform over the first and last five.
    """
    # scipy.interpolate imported here: the command line needs it only with --delay
    from scipy.interpolate import CubicSpline

    t = np.asarray(t, dtype=float)
    values = np.asarray(values, dtype=float)
    ends: str | tuple = "not-a-knot"
    if len(t) >= 5:
        first = np.tensordot(ONE_SIDED_SLOPE, values[:5], axes=1) / (t[1] - t[0])
        last = -np.tensordot(ONE_SIDED_SLOPE, values[::-1][:5], axes=1) / (t[-1] - t[-2])
        ends = ((1, first), (1, last))
    return CubicSpline(t, values, axis=0, bc_type=ends)(times)


#: First derivative at the middle of five equally spaced samples, times the spacing
#: (error h^4 x^(5) / 30).
CENTRAL_SLOPE = np.array([1.0, -8.0, 0.0, 8.0, -1.0]) / 12.0
#: First derivative at the second of five equally spaced samples, times the spacing
#: (error h^4 x^(5) / 20).
SECOND_SLOPE = np.array([-3.0, -10.0, 18.0, -6.0, 1.0]) / 12.0


def hermite_uniform(values: np.ndarray, step: int, n: int) -> np.ndarray:
    """A signal known at samples 0, step, ..., (K - 1) step (``values`` (K, C), K >= 5) at every one of
    ``n`` samples, by piecewise cubic Hermite with five-point-difference knot slopes.
    """
    values = np.asarray(values, dtype=float)
    k = len(values)
    reverse = values[::-1]
    slopes = np.empty_like(values)
    slopes[2:-2] = np.tensordot(CENTRAL_SLOPE,
                                np.stack([values[i:k - 4 + i] for i in range(5)]), axes=1)
    slopes[0] = np.tensordot(ONE_SIDED_SLOPE, values[:5], axes=1)
    slopes[1] = np.tensordot(SECOND_SLOPE, values[:5], axes=1)
    slopes[-1] = -np.tensordot(ONE_SIDED_SLOPE, reverse[:5], axes=1)
    slopes[-2] = -np.tensordot(SECOND_SLOPE, reverse[:5], axes=1)
    index = np.arange(n)
    segment = np.minimum(index // step, k - 2)
    u = ((index - segment * step) / step)[:, None]
    return ((1 + 2 * u) * (1 - u) ** 2 * values[segment] + u * (1 - u) ** 2 * slopes[segment]
            + u ** 2 * (3 - 2 * u) * values[segment + 1]
            + u ** 2 * (u - 1) * slopes[segment + 1])


__all__ = ["CENTRAL_SLOPE", "ONE_SIDED_SLOPE", "SECOND_SLOPE", "hermite_uniform", "spline_at"]
