"""Which Coulomb regressors Method B's rows carry: the soft sign's transition rate, the fits
at every candidate averaged by how well each explains the rows, and (every interval
constant free) whether the Coulomb levels are kept at all.

The invariant rows remove each interval's constant, but the Coulomb force is not constant
inside an interval when the pose changes its map J_j(q)^T or an idle joint (left out of the
detection) reverses: both grow with the motion's amplitude. The rows then gain the
Coulomb levels' regressors (:attr:`.weak_form.IntervalEquations.coulomb_rows`), at each
candidate transition rate of :data:`.weak_form.SOFT_SIGN_RATES`.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable, Sequence

import numpy as np
from scipy.special import chdtri

from stewartid.identification.wavelet.gls import WeakFormSolution, solve_weak_form
from stewartid.identification.wavelet.weak_form import SOFT_SIGN_RATES, IntervalEquations

#: Size of the likelihood-ratio test of :func:`solve_weak_form_over_rates`.
VARIATION_TEST_LEVEL = 0.01


def residual_cost(solution: WeakFormSolution) -> float:
    """The sum over channels of the log of the force-side noise variance: minus twice the
    profile log-likelihood of Gaussian rows, per row."""
    return float(np.sum(np.log(solution.noise_std ** 2)))


def averaged_over_rates(solve: Callable[[int], WeakFormSolution], rates: Sequence[float]
                        ) -> tuple[WeakFormSolution, float]:
    """``solve(index)`` at every transition rate, averaged over the rates with Akaike weights.

    The candidates have the same unknowns, so each one's weight is exp(-D_k / 2), normalised,
    with D_k = n (c_k - min c) its excess of minus twice the profile log-likelihood (n rows
    per channel, c = :func:`residual_cost`). Where the data tell the rates apart (a large
    Coulomb force) one candidate takes the weight; where they do not, choosing the least
    residual picks among fits that trade the Coulomb levels for Bt, and the choice's
    variance is missing from the chosen fit's standard errors (the heavy platform of
    ``docs/benchmarks.md`` at 5 N m: Bt 3-4 standard errors off on one seed in eight). The
    average carries it: mean sum_k w_k theta_k, standard error
    sqrt(sum_k w_k (s_k^2 + (theta_k - mean)^2)) (Burnham and Anderson 2002, sec. 6.3).

    Returns
    -------
    solution : WeakFormSolution
        [Mt Bt] and the Coulomb levels averaged, with their standard errors; the rest (the
        noise, hence :func:`residual_cost`) of the candidate of least residual;
        ``rate_weights`` each rate's weight.
    rate : float
        The transition rate of greatest weight (rad/s).
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
    return averaged, float(rates[int(np.argmax(weights))])


def solve_weak_form_over_rates(equations: Sequence[IntervalEquations], n_experiments: int,
                               shared_friction: bool = True, **settings
                               ) -> tuple[WeakFormSolution, float | None]:
    """:func:`solve_weak_form` with the invariant rows' Coulomb regressors at every soft-sign
    transition rate of the equations' ``coulomb_rows``, averaged over the rates
    (:func:`averaged_over_rates`); with ``shared_friction`` the solution without them.

    With every constant free (not ``shared_friction``) the levels are extra unknowns, kept
    only when a likelihood-ratio test at :data:`VARIATION_TEST_LEVEL` says they explain the
    rows (chi-square with n_types degrees of freedom; 11.3 for three levels); else the
    solution without them. Paper platform, 30 N m, reference noise, 8 seeds: the paper's
    sines gave 2.2-9.5 (keeping the levels anyway cost 35 % in the median largest error),
    the same sines at ten times their amplitude 13-118 (without the levels Mt(4,2) was
    3.5 % and 4.7 standard errors off). Levels more than 3 standard errors below zero, which
    no friction has, also leave them out: the structure does not describe the plant.

    Returns
    -------
    solution : WeakFormSolution
    rate : float or None
        The transition rate of greatest weight (rad/s, from
        :data:`.weak_form.SOFT_SIGN_RATES`); None when the levels were left out.
    """
    if shared_friction:  # the mean rows carry the levels; their benchmarks are without these
        return solve_weak_form(equations, n_experiments, True, **settings), None
    shared: dict = {}
    plain = solve_weak_form(equations, n_experiments, False, shared=shared, **settings)
    best, best_rate = averaged_over_rates(
        lambda index: solve_weak_form(equations, n_experiments, False, rate_index=index,
                                      variation=True, shared=shared, **settings),
        SOFT_SIGN_RATES[:len(equations[0].coulomb_rows)])
    rows = plain.n_equations
    # likelihood ratio of the levels (with the rate picked among the candidates), and levels
    # a friction can have: a level 3 standard errors below zero says the plant's friction
    # does not follow the structure (MuJoCo's frictionloss on the example data: -8.9)
    gain = rows * (residual_cost(plain) - residual_cost(best))
    explains = gain > chdtri(len(best.coulomb), VARIATION_TEST_LEVEL)
    if explains and np.all(best.coulomb > -3.0 * best.coulomb_std):
        return best, best_rate
    return plain, None


__all__ = ["VARIATION_TEST_LEVEL", "averaged_over_rates", "residual_cost",
           "solve_weak_form_over_rates"]
