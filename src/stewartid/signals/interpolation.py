"""A uniformly sampled signal between its samples: one cubic spline, exact to its error bound
up to the ends of the record (channel delays in the simulator, force alignment before a fit)."""

from __future__ import annotations

import numpy as np

#: First derivative at the first of five equally spaced samples, times the spacing
#: (error h^4 x^(5) / 5).
ONE_SIDED_SLOPE = np.array([-25.0, 48.0, -36.0, 16.0, -3.0]) / 12.0


def spline_at(t: np.ndarray, values: np.ndarray, times: np.ndarray) -> np.ndarray:
    """The sampled signal at ``times``, by a cubic spline through its samples.

    The end slopes are five-point one-sided differences, which keep the complete spline's error
    bound (5/384) h^4 max|x''''| up to the ends of the record (Hall & Meyer 1976).

    Parameters
    ----------
    t : ndarray, shape (N,)
        Sample times (s), strictly increasing, uniform over the first and last five.
    values : ndarray, shape (N,) or (N, C)
        Sampled signal, any unit.
    times : ndarray, shape (M,)
        Where to evaluate (s), within [t[0], t[-1]].

    Returns
    -------
    ndarray, shape (M,) or (M, C)
        Unit of ``values``.

    References
    ----------
    C. A. Hall, W. W. Meyer, Optimal error bounds for cubic spline interpolation, J. Approx.
    Theory 16 (1976) 105-122, doi:10.1016/0021-9045(76)90040-X.
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
    """A signal known every ``step``-th sample, at every sample: piecewise cubic Hermite.

    Knot slopes are five-point differences of the knot values (central inside, one-sided at the
    ends): a cubic spline's error order without its linear system.

    Parameters
    ----------
    values : ndarray, shape (K, C)
        The signal at samples 0, step, ..., (K - 1) step, K >= 5.
    step : int
        Samples between knots.
    n : int
        Samples wanted, at most (K - 1) step + 1.

    Returns
    -------
    ndarray, shape (n, C)
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
