"""A uniformly sampled signal between its samples: one cubic spline, exact to its bound up to the ends."""

from __future__ import annotations

import numpy as np

#: First derivative at the first of five equally spaced samples, times the spacing
#: (error h^4 x^(5) / 5).
ONE_SIDED_SLOPE = np.array([-25.0, 48.0, -36.0, 16.0, -3.0]) / 12.0


def spline_at(t: np.ndarray, values: np.ndarray, times: np.ndarray) -> np.ndarray:
    """The signal ``values`` (N,) or (N, C) sampled at ``t`` (N,), at ``times`` (M,) within the record.

    A cubic spline whose end slopes are five-point one-sided differences, which keep the error bound
    (5/384) h^4 max|x''''| up to the ends (Hall & Meyer 1976); ``t`` uniform (a record's clock),
    N >= 5. Its knot slopes solve the spline's tridiagonal system here, in numpy
    (scipy.interpolate costs more to import than the records take to align).

    Raises
    ------
    ValueError
        Fewer than five samples.
    """
    t = np.asarray(t, dtype=float)
    values = np.asarray(values, dtype=float)
    if len(t) < 5:
        raise ValueError(f"spline_at needs five samples or more; got {len(t)}.")
    flat = values.reshape(len(t), -1)
    h = (t[-1] - t[0]) / (len(t) - 1)
    slopes = np.empty_like(flat)   # dx/dt at the knots
    slopes[0] = np.tensordot(ONE_SIDED_SLOPE, flat[:5], axes=1) / h
    slopes[-1] = -np.tensordot(ONE_SIDED_SLOPE, flat[::-1][:5], axes=1) / h
    # C2 at the inner knots: m_(i-1) + 4 m_i + m_(i+1) = 3 (x_(i+1) - x_(i-1)) / h
    rhs = 3.0 * (flat[2:] - flat[:-2]) / h
    rhs[0] -= slopes[0]
    rhs[-1] -= slopes[-1]
    slopes[1:-1] = _solve_one_four_one(rhs)
    position = np.clip((np.asarray(times, dtype=float) - t[0]) / h, 0.0, len(t) - 1.0)
    knot = np.minimum(position.astype(int), len(t) - 2)
    u = (position - knot)[:, None]
    out = _hermite(u, flat[knot], h * slopes[knot], flat[knot + 1], h * slopes[knot + 1])
    return out.reshape((len(out),) + values.shape[1:])


#: Rows of :func:`_solve_one_four_one` eliminated one by one, after which its factor is
#: 2 - sqrt(3) to round-off (it converges by (2 - sqrt(3))^2 a row); the terms its sums keep,
#: beyond which (2 - sqrt(3))^k is below 1e-23.
EXACT_ROWS, SERIES_TERMS = 32, 40


def _solve_one_four_one(rhs: np.ndarray) -> np.ndarray:
    """x (n, C) with x_(i-1) + 4 x_i + x_(i+1) = rhs_i (x_0 = x_(n+1) = 0) by Thomas' elimination,
    whose factors c_k = 1 / (4 - c_(k-1)) reach c = 2 - sqrt(3) within :data:`EXACT_ROWS` rows:
    beyond them both sweeps are first-order recurrences with that factor, summed as geometric
    series of :data:`SERIES_TERMS` terms (vector operations, not a loop over the rows)."""
    n = len(rhs)
    factors = np.empty(n)
    factors[0] = 0.25
    for k in range(1, min(n, EXACT_ROWS)):
        factors[k] = 1.0 / (4.0 - factors[k - 1])
    factors[EXACT_ROWS:] = 2.0 - np.sqrt(3.0)
    c = 2.0 - np.sqrt(3.0)
    powers = (-c) ** np.arange(SERIES_TERMS + 1)
    # forward, g_k = c_k (rhs_k - g_(k-1)); past the exact rows g_k = c sum_j (-c)^j rhs_(k-j)
    g = np.empty_like(rhs)
    start = min(n, EXACT_ROWS + SERIES_TERMS)
    g[0] = factors[0] * rhs[0]
    for k in range(1, start):
        g[k] = factors[k] * (rhs[k] - g[k - 1])
    if start < n:
        tail = np.zeros_like(rhs[start:])
        for j, weight in enumerate(powers):
            tail += weight * rhs[start - j:n - j]
        g[start:] = c * tail
    # back, x_k = g_k - c_k x_(k+1) from x_(n-1) = g_(n-1): past the exact rows
    # x_k = sum_j (-c)^j g_(k+j), the sum stopping at the end of the record
    x = np.empty_like(rhs)
    first = min(n, EXACT_ROWS)
    padded = np.concatenate([g, np.zeros((SERIES_TERMS,) + g.shape[1:])])
    x[first:] = 0.0
    for j, weight in enumerate(powers):
        x[first:] += weight * padded[first + j:n + j]
    for k in range(first - 1, -1, -1):
        x[k] = g[k] - factors[k] * (x[k + 1] if k + 1 < n else 0.0)
    return x


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
