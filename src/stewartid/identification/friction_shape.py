"""The shape of Coulomb friction's sign near a reversal, and least squares averaged over it.

Away from a reversal a joint's Coulomb torque is F sign(w). Within a few 1e-4 rad/s of one it
is whatever the rig does there (stiction, a constraint solver's softness, a regularised sign),
which one log rarely shows, and a joint that barely moves (a leg's revolute axis) spends much
of a record there. Two shapes of the same slope 1/s at w = 0 bracket it:

- ``"algebraic"``: w / sqrt(w^2 + s^2), saturating slowly (1 - s^2 / (2 w^2));
- ``"erf"``: erf(sqrt(pi) w / (2 s)), saturating as a Gaussian tail (a hard sign seen through
  a little noise).

Least squares fits both and averages them by their Akaike weights, the spread between the two
fits added to each variance (model averaging: Buckland, Burnham & Augustin, Biometrics 53,
1997; Burnham & Anderson, Model Selection and Multimodel Inference, ch. 4, 2002). A log that
shows the shape (noise-free, or many slow reversals) weights it near 1; a log that cannot tell
averages the two and says so in the standard errors. On logs of the MuJoCo model of
``example_c10``'s platform, whose dry friction is a constraint, the algebraic shape alone left
the rotational Bt diagonal 1.6 / 1.5 / 5.0 % off on noise-free three-sine logs and one entry
4.7 standard errors off with the reference noise; the average 0.8 / 0.8 / 2.7 % and 3.3. On
logs of our plant, whose friction is the algebraic sign, nothing changed (the noisy logs'
largest errors 3.60 % -> 3.62 % on average).
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
    """sign(rates), regularised over ``smoothing`` (rad/s) with one of :data:`COULOMB_SHAPES`.

    Parameters
    ----------
    rates : ndarray, any shape
        Joint rates w (rad/s).
    smoothing : float
        s (rad/s): the slope at w = 0 is 1/s; 0 gives the exact sign.
    shape : {"algebraic", "erf"}

    Returns
    -------
    ndarray, shape of ``rates``
        In [-1, 1].
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
    """Akaike weights of least-squares fits of one model's variants on the same rows.

    Each fit's Gaussian log-likelihood with its channels' variances estimated is
    -1/2 sum_c n_c log(RSS_c), with n_c the first fit's independent rows per channel
    (:attr:`~stewartid.identification.solvers.LeastSquaresSolution.effective_equations`;
    one sample size for all, so that the differences are the residuals'). The variants have
    as many unknowns, so the weights are exp(l_k - max l) normalised.

    Returns
    -------
    ndarray, shape (len(solutions),)
    """
    n = solutions[0].effective_equations
    log_likelihood = np.array([-0.5 * np.sum(n * np.log(np.maximum(s.residual_rms, 1e-300) ** 2))
                               for s in solutions])
    weights = np.exp(log_likelihood - log_likelihood.max())
    return weights / weights.sum()


def average_solutions(solutions: Sequence[LeastSquaresSolution], weights: np.ndarray
                      ) -> LeastSquaresSolution:
    """The weighted mean of fits, each variance the weighted mean of the fits' variances plus
    their squared departures from the mean (the mixture's variance; Burnham & Anderson 2002,
    ch. 4)."""
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
