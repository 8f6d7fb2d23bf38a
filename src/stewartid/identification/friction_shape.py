"""The shape of Coulomb friction's sign near a reversal, and least squares averaged over it.

Fits with both shapes are averaged by Akaike weights (Burnham and Anderson 2002, ch. 4).
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Sequence

import numpy as np

from stewartid.identification.solvers import LeastSquaresSolution

#: The shapes of sign(w) near w = 0, of slope 1/s there.
COULOMB_SHAPES = ("algebraic", "erf")


def shaped_sign(rates: np.ndarray, smoothing: float, shape: str = "algebraic") -> np.ndarray:
    """sign(w) regularised over s: ``"algebraic"`` w / sqrt(w^2 + s^2), ``"erf"`` erf(sqrt(pi) w / (2 s)).

    ``rates`` and ``smoothing`` in rad/s; slope 1/s at 0; s = 0 gives the exact sign.
    """
    if smoothing == 0:
        return np.sign(rates)
    if shape == "algebraic":
        return rates / np.sqrt(rates ** 2 + smoothing ** 2)
    if shape == "erf":
        from scipy.special import erf

        return erf(math.sqrt(math.pi) / (2.0 * smoothing) * rates)
    raise ValueError(f"unknown Coulomb shape {shape!r}; one of {', '.join(COULOMB_SHAPES)}")


def akaike_weights(solutions: Sequence[LeastSquaresSolution]) -> np.ndarray:
    """Akaike weights of equal-size variants fitted on the same rows: l_k = -1/2 sum_c n_c log(RSS_c)."""
    n = solutions[0].effective_equations
    log_likelihood = np.array([-0.5 * np.sum(n * np.log(np.maximum(s.residual_rms, 1e-300) ** 2))
                               for s in solutions])
    weights = np.exp(log_likelihood - log_likelihood.max())
    return weights / weights.sum()


def average_solutions(solutions: Sequence[LeastSquaresSolution], weights: np.ndarray
                      ) -> LeastSquaresSolution:
    """The weighted mean of fits, with the mixture's variance (within plus between)."""
    w = np.asarray(weights, dtype=float)

    def mean_and_std(values, stds):
        values, stds = np.asarray(values), np.asarray(stds)
        mean = np.tensordot(w, values, axes=1)
        variance = np.tensordot(w, stds ** 2 + (values - mean) ** 2, axes=1)
        return mean, np.sqrt(variance)

    theta, theta_std = mean_and_std([s.theta for s in solutions],
                                    [s.theta_std for s in solutions])
    shared, shared_std = mean_and_std([s.shared for s in solutions],
                                      [s.shared_std for s in solutions])
    return dataclasses.replace(
        solutions[0], theta=theta, theta_std=theta_std, shared=shared, shared_std=shared_std,
        condition_number=max(s.condition_number for s in solutions),
        residual_rms=np.sqrt(np.tensordot(w, [s.residual_rms ** 2 for s in solutions], axes=1)))


__all__ = ["COULOMB_SHAPES", "akaike_weights", "average_solutions", "shaped_sign"]
