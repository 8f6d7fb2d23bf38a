"""Which Coulomb regressors Method B's rows carry.

Fits over soft-sign transition rates averaged by Akaike weight, and whether the levels are kept.
"""

from __future__ import annotations

import dataclasses
import warnings
from collections.abc import Callable, Sequence

import numpy as np

from stewartid.errors import DataWarning
from stewartid.identification.quantiles import chi2_upper_quantile
from stewartid.identification.sign_window import widened_by_sign_window
from stewartid.identification.wavelet.gls import WeakFormSolution, solve_weak_form
from stewartid.identification.wavelet.weak_form import SOFT_SIGN_RATES, IntervalEquations

#: Size of the likelihood-ratio test of :func:`solve_weak_form_over_rates`.
VARIATION_TEST_LEVEL = 0.01
#: Index in :data:`~stewartid.identification.wavelet.weak_form.SOFT_SIGN_RATES` of the one
#: transition rate the refit with the signs from half their window uses (the patterns cost
#: one rate, not all): 1e-4 rad/s, the rate the noisy records' fits take.
HALF_WINDOW_RATE = 1


def residual_cost(solution: WeakFormSolution) -> float:
    """Sum over channels of the log force-side noise variance (-2 profile log-likelihood per row)."""
    return float(np.sum(np.log(solution.noise_std ** 2)))


def averaged_over_rates(solve: Callable[[int], WeakFormSolution], rates: Sequence[float],
                        refit: Callable[[], WeakFormSolution] | None = None
                        ) -> tuple[WeakFormSolution, float]:
    """``solve(index)`` at every transition rate, averaged with Akaike weights exp(-n (c_k - min c) / 2).

    Mean sum_k w_k theta_k, standard error sqrt(sum_k w_k (s_k^2 + (theta_k - mean)^2)) (Burnham and
    Anderson 2002, sec. 6.3). ``refit()``: the fit at the rate :data:`HALF_WINDOW_RATE` with the
    signs from half their window, by whose distance from that rate's fit the standard errors
    widen (:func:`~stewartid.identification.sign_window.widened_by_sign_window`). Returns the averaged
    solution (rest from the best candidate, with ``rate_weights``) and the rate of greatest
    weight, rad/s.
    """
    solutions = [solve(index) for index in range(len(rates))]
    costs = np.array([residual_cost(solution) for solution in solutions])
    rows = np.array([solution.n_equations for solution in solutions], dtype=float)
    weights = np.exp(-0.5 * rows * (costs - costs.min()))
    weights /= weights.sum()

    def mixed(values: list[np.ndarray], stds: list[np.ndarray]) -> tuple[np.ndarray, np.ndarray]:
        values, stds = np.stack(values), np.stack(stds)
        mean = np.tensordot(weights, values, axes=1)
        spread = np.tensordot(weights, stds ** 2 + (values - mean) ** 2, axes=1)
        return mean, np.sqrt(spread)

    theta, theta_std = mixed([s.theta for s in solutions], [s.theta_std for s in solutions])
    coulomb, coulomb_std = mixed([s.coulomb for s in solutions],
                                 [s.coulomb_std for s in solutions])
    by_rate = {f"{rate:g}": float(w) for rate, w in zip(rates, weights, strict=True)}
    averaged = dataclasses.replace(solutions[int(np.argmin(costs))], theta=theta,
                                   theta_std=theta_std, coulomb=coulomb,
                                   coulomb_std=coulomb_std, rate_weights=by_rate)
    if refit is not None:
        with warnings.catch_warnings():  # what the data lack, the fits above have said
            warnings.simplefilter("ignore", DataWarning)
            half = refit()
        averaged = widened_by_sign_window(averaged, solutions[HALF_WINDOW_RATE], half, "coulomb")
    return averaged, float(rates[int(np.argmax(weights))])


def half_window_pick(carried: int, count: int) -> list[int]:
    """Which of an equation's ``carried`` Coulomb rows the refit with the signs from half their
    window takes: the half window's, after the ``count`` rates of the long window's, where the
    equation carries them, else the long window's at :data:`HALF_WINDOW_RATE`."""
    return [count if carried > count else HALF_WINDOW_RATE]


def half_window_rows(equations: Sequence[IntervalEquations], count: int
                     ) -> list[IntervalEquations] | None:
    """The equations with their Coulomb rows of :func:`half_window_pick` alone; None where no
    interval carries the half window's."""
    if not any(len(e.coulomb_rows) > count for e in equations):
        return None
    return [dataclasses.replace(e, coulomb_rows=e.coulomb_rows[
        half_window_pick(len(e.coulomb_rows), count)]) for e in equations]


def solve_weak_form_over_rates(equations: Sequence[IntervalEquations], n_experiments: int,
                               shared_friction: bool = True, **settings
                               ) -> tuple[WeakFormSolution, float | None]:
    """:func:`~stewartid.identification.wavelet.gls.solve_weak_form` with Coulomb rows averaged over rates.

    Levels are kept only if a likelihood-ratio test at :data:`VARIATION_TEST_LEVEL` accepts them and
    none is 3 standard errors below zero. Returns (solution, rate of greatest weight or None).
    """
    if shared_friction:  # the mean rows carry the levels
        return solve_weak_form(equations, n_experiments, True, **settings), None
    shared: dict = {}
    plain = solve_weak_form(equations, n_experiments, False, shared=shared, **settings)
    rates = SOFT_SIGN_RATES[:len(equations[0].coulomb_rows)]
    half = half_window_rows(equations, len(rates))
    refit = None if half is None else (
        lambda: solve_weak_form(half, n_experiments, False, variation=True, shared=shared,
                                **settings))
    best, best_rate = averaged_over_rates(
        lambda index: solve_weak_form(equations, n_experiments, False, rate_index=index,
                                      variation=True, shared=shared, **settings),
        rates, refit)
    rows = plain.n_equations
    # likelihood ratio of the levels, and levels a friction can have: one 3 standard errors
    # below zero says the plant's friction does not follow the structure
    gain = rows * (residual_cost(plain) - residual_cost(best))
    explains = gain > chi2_upper_quantile(len(best.coulomb), VARIATION_TEST_LEVEL)
    if explains and np.all(best.coulomb > -3.0 * best.coulomb_std):
        return best, best_rate
    return plain, None


__all__ = ["HALF_WINDOW_RATE", "VARIATION_TEST_LEVEL", "averaged_over_rates", "half_window_pick",
           "half_window_rows", "residual_cost", "solve_weak_form_over_rates"]
