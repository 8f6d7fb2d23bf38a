"""Which Coulomb regressors Method B's rows carry.

Fits over soft-sign transition rates averaged by Akaike weight, and whether the levels are kept.
"""

from __future__ import annotations

import dataclasses
import warnings
from collections.abc import Callable, Sequence
from functools import partial
from typing import Any

import numpy as np

from stewartid.errors import DataWarning
from stewartid.identification.quantiles import chi2_upper_quantile
from stewartid.identification.sign_window import widened_by_sign_window
from stewartid.identification.wavelet.gls import WeakFormSolution, solve_weak_form
from stewartid.identification.wavelet.weak_form import SOFT_SIGN_RATES, IntervalEquations

#: Runs zero-argument calls and returns their results in order (in this process or on workers).
Run = Callable[[Sequence[Callable[[], Any]]], list]

#: Size of the likelihood-ratio test of :func:`solve_weak_form_over_rates`.
VARIATION_TEST_LEVEL = 0.01
#: Index in :data:`~stewartid.identification.wavelet.weak_form.SOFT_SIGN_RATES` of the one
#: transition rate the refit with the signs from half their window uses (the patterns cost
#: one rate, not all): 1e-4 rad/s, the rate the noisy records' fits take.
HALF_WINDOW_RATE = 1


def residual_cost(solution: WeakFormSolution) -> float:
    """Sum over channels of the log force-side noise variance (-2 profile log-likelihood per row)."""
    return float(np.sum(np.log(solution.noise_std ** 2)))


def averaged_over_rates(solutions: Sequence[WeakFormSolution], rates: Sequence[float],
                        half: WeakFormSolution | None = None
                        ) -> tuple[WeakFormSolution, float]:
    """The fits ``solutions`` at every transition rate of ``rates``, averaged with Akaike
    weights exp(-n (c_k - min c) / 2).

    Mean sum_k w_k theta_k, standard error sqrt(sum_k w_k (s_k^2 + (theta_k - mean)^2)) (Burnham and
    Anderson 2002, sec. 6.3). ``half``: the fit at the rate :data:`HALF_WINDOW_RATE` with the
    signs from half their window, by whose distance from that rate's fit the standard errors
    widen (:func:`~stewartid.identification.sign_window.widened_by_sign_window`). Returns the averaged
    solution (rest from the best candidate, with ``rate_weights``) and the rate of greatest
    weight, rad/s.
    """
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
    if half is not None:
        averaged = widened_by_sign_window(averaged, solutions[HALF_WINDOW_RATE], half, "coulomb")
    return averaged, float(rates[int(np.argmax(weights))])


def solved_over_rates(fits: Sequence[Callable[[], WeakFormSolution]],
                      refit: Callable[[], WeakFormSolution] | None, run: Run | None
                      ) -> tuple[list[WeakFormSolution], WeakFormSolution | None]:
    """The ``fits`` (one per rate) and ``refit()``, side by side by ``run``
    (:meth:`~stewartid.parallel.WorkerPool.call_all`; None: one after the other), each
    picklable. The refit's warnings are left out: what the data lack, the fits at every rate
    have said."""
    calls = list(fits)
    if refit is not None:
        calls.append(partial(_without_data_warnings, refit))
    solutions = (run or in_sequence)(calls)
    return solutions[:len(fits)], (solutions[len(fits)] if refit is not None else None)


def in_sequence(calls: Sequence[Callable[[], Any]]) -> list[Any]:
    """``[call() for call in calls]``: :func:`solved_over_rates` in this process."""
    return [call() for call in calls]


def _without_data_warnings(call: Callable[[], WeakFormSolution]) -> WeakFormSolution:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DataWarning)
        return call()


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


def plain_fit(equations: Sequence[IntervalEquations], n_experiments: int, **settings
              ) -> tuple[WeakFormSolution, dict]:
    """The free interval constants' fit without Coulomb rows, and the work it shares with the
    fits at the soft-sign rates (:func:`solve_weak_form_over_rates`)."""
    shared: dict = {}
    return solve_weak_form(equations, n_experiments, False, shared=shared, **settings), shared


def solve_weak_form_over_rates(equations: Sequence[IntervalEquations], n_experiments: int,
                               shared_friction: bool = True, run: Run | None = None,
                               start: tuple[WeakFormSolution, dict] | None = None,
                               **settings) -> tuple[WeakFormSolution, float | None]:
    """:func:`~stewartid.identification.wavelet.gls.solve_weak_form` with Coulomb rows averaged over rates.

    Levels are kept only if a likelihood-ratio test at :data:`VARIATION_TEST_LEVEL` accepts them and
    none is 3 standard errors below zero. ``run`` as :func:`solved_over_rates`; ``start``:
    :func:`plain_fit` of the same equations, where it was computed already. Returns (solution,
    rate of greatest weight or None).
    """
    if shared_friction:  # the mean rows carry the levels
        return solve_weak_form(equations, n_experiments, True, **settings), None
    plain, shared = start or plain_fit(equations, n_experiments, **settings)
    rates = SOFT_SIGN_RATES[:len(equations[0].coulomb_rows)]
    half = half_window_rows(equations, len(rates))
    refit = None if half is None else partial(solve_weak_form, half, n_experiments, False,
                                              variation=True, shared=shared, **settings)
    # each fit given its rate's Coulomb rows alone: a worker receives what it solves
    fits = [partial(solve_weak_form, [dataclasses.replace(e, coulomb_rows=e.coulomb_rows[k:k + 1])
                                      for e in equations], n_experiments, False,
                    variation=True, shared=shared, **settings) for k in range(len(rates))]
    solutions, refitted = solved_over_rates(fits, refit, run)
    best, best_rate = averaged_over_rates(solutions, rates, refitted)
    rows = plain.n_equations
    # likelihood ratio of the levels, and levels a friction can have: one 3 standard errors
    # below zero says the plant's friction does not follow the structure
    gain = rows * (residual_cost(plain) - residual_cost(best))
    explains = gain > chi2_upper_quantile(len(best.coulomb), VARIATION_TEST_LEVEL)
    if explains and np.all(best.coulomb > -3.0 * best.coulomb_std):
        return best, best_rate
    return plain, None


__all__ = ["HALF_WINDOW_RATE", "VARIATION_TEST_LEVEL", "Run", "averaged_over_rates",
           "half_window_pick", "half_window_rows", "in_sequence", "plain_fit", "residual_cost",
           "solve_weak_form_over_rates", "solved_over_rates"]
