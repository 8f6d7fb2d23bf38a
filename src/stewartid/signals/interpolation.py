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
    out = np.empty((n, values.shape[1]))
    # the whole segments share one step's weights: broadcast over them, no sample gathered
    full = min(n, (k - 1) * step) // step
    out[:full * step].reshape(full, step, values.shape[1])[:] = _hermite(
        (np.arange(step) / step)[:, None], values[:full, None], slopes[:full, None],
        values[1:full + 1, None], slopes[1:full + 1, None])
    index = np.arange(full * step, n)   # a part of a segment, or beyond the last knot
    segment = np.minimum(index // step, k - 2)
    out[full * step:] = _hermite(((index - segment * step) / step)[:, None], values[segment],
                                 slopes[segment], values[segment + 1], slopes[segment + 1])
    return out


def _hermite(u: np.ndarray, start: np.ndarray, start_slope: np.ndarray, end: np.ndarray,
             end_slope: np.ndarray) -> np.ndarray:
    """The cubic Hermite segment at u in [0, 1] (..., 1), from its end values and slopes times
    the knot spacing (..., C)."""
    return ((1 + 2 * u) * (1 - u) ** 2 * start + u * (1 - u) ** 2 * start_slope
            + u ** 2 * (3 - 2 * u) * end + u ** 2 * (u - 1) * end_slope)


__all__ = ["CENTRAL_SLOPE", "ONE_SIDED_SLOPE", "SECOND_SLOPE", "hermite_uniform", "spline_at"]
