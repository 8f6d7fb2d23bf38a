"""The shape of Coulomb friction's sign near a reversal, and least squares averaged over it.

Fits with both shapes are averaged by Akaike weights (Burnham and Anderson 2002, ch. 4); a fit
with the exact sign measures how far the soft sign's band moves them.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Sequence

import numpy as np

from stewartid.identification.solvers import LeastSquaresSolution

#: The shapes of sign(w) near w = 0, of slope 1/s there.
COULOMB_SHAPES = ("algebraic", "erf")
#: The variant of the exact sign, s = 0 (:func:`widened_by_exact_sign`).
EXACT_SIGN = "exact"
#: erf(x) rounds to +-1 from here on (1 - erf(5.93) = 5.0e-17, under half the spacing of the
#: doubles below 1).
ERF_SATURATION = 5.93


def shaped_sign(rates: np.ndarray, smoothing: float, shape: str = "algebraic") -> np.ndarray:
    """sign(w) regularised over s: ``"algebraic"`` w / sqrt(w^2 + s^2), ``"erf"`` erf(sqrt(pi) w / (2 s)),
    ``"exact"`` sign(w) whatever s.

    ``rates`` and ``smoothing`` in rad/s; slope 1/s at 0; s = 0 gives the exact sign.
    """
    if smoothing == 0 or shape == EXACT_SIGN:
        return np.sign(rates)
    if shape == "algebraic":
        return rates / np.sqrt(rates ** 2 + smoothing ** 2)
    if shape == "erf":
        # the standard library's erf, not scipy's (slow to import, in every worker of a fit),
        # called only where the double is not exactly +-1
        scaled = np.asarray(math.sqrt(math.pi) / (2.0 * smoothing) * rates, dtype=float)
        signs = np.sign(scaled, out=np.empty_like(scaled))
        band = np.abs(scaled) < ERF_SATURATION
        inside = scaled[band].tolist()
        signs[band] = np.fromiter(map(math.erf, inside), float, count=len(inside))
        return signs
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


def widened_by_exact_sign(model: LeastSquaresSolution, best: LeastSquaresSolution,
                          exact: LeastSquaresSolution) -> tuple[LeastSquaresSolution, float]:
    """``model``, the soft sign's fit, its standard errors widened by the exact sign's.

    How a rig's friction turns over inside the soft sign's band (stiction, a constraint solver's
    softness) is not the model's law; the exact sign is the band's other end. With p the Akaike
    weight of ``exact`` against ``best`` (the soft sign's likeliest shape), each standard error s
    becomes sqrt(s^2 + p max(0, d^2 - s^2)), d the distance of the exact sign's estimate: the
    part of d beyond the noise, where the data prefer the exact sign. Estimates are unchanged.
    Returns the widened solution and p.
    """
    p = float(akaike_weights([best, exact])[1])

    def widened(value, std, other):
        return np.sqrt(std ** 2 + p * np.maximum(0.0, (other - value) ** 2 - std ** 2))

    return dataclasses.replace(
        model, theta_std=widened(model.theta, model.theta_std, exact.theta),
        shared_std=widened(model.shared, model.shared_std, exact.shared)), p


__all__ = ["COULOMB_SHAPES", "EXACT_SIGN", "akaike_weights", "average_solutions", "shaped_sign",
           "widened_by_exact_sign"]
