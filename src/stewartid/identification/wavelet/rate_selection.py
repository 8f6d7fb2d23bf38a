"""Which Coulomb regressors Method B's rows carry: the soft sign's transition rate, chosen
by the fit's residual, and (every interval constant free) whether the Coulomb levels are
kept at all.

The invariant rows remove each interval's constant, but the Coulomb force is not constant
inside an interval when the pose changes its map J_j(q)^T or an idle joint (left out of the
detection) reverses: both grow with the motion's amplitude. The rows then gain the
Coulomb levels' regressors (:attr:`.weak_form.IntervalEquations.coulomb_rows`), at each
candidate transition rate of :data:`.weak_form.SOFT_SIGN_RATES`.
"""

from __future__ import annotations

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


def best_over_rates(solve: Callable[[int], WeakFormSolution], rates: Sequence[float]
                    ) -> tuple[WeakFormSolution, float]:
    """``solve(index)`` at every transition rate; the solution of least
    :func:`residual_cost` and its rate (rad/s)."""
    best, best_rate = None, 0.0
    for index, rate in enumerate(rates):
        solution = solve(index)
        if best is None or residual_cost(solution) < residual_cost(best):
            best, best_rate = solution, float(rate)
    return best, best_rate


def solve_weak_form_over_rates(equations: Sequence[IntervalEquations], n_experiments: int,
                               shared_friction: bool = True, **settings
                               ) -> tuple[WeakFormSolution, float | None]:
    """:func:`solve_weak_form` with the invariant rows' Coulomb regressors at every soft-sign
    transition rate of the equations' ``coulomb_rows``, and the solution whose weighted
    residual is smallest (:func:`residual_cost`); with ``shared_friction`` the solution
    without them.

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
        The chosen transition rate (rad/s, from :data:`.weak_form.SOFT_SIGN_RATES`); None
        when the levels were left out.
    """
    if shared_friction:  # the mean rows carry the levels; their benchmarks are without these
        return solve_weak_form(equations, n_experiments, True, **settings), None
    shared: dict = {}
    plain = solve_weak_form(equations, n_experiments, False, shared=shared, **settings)
    best, best_rate = best_over_rates(
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


__all__ = ["VARIATION_TEST_LEVEL", "best_over_rates", "residual_cost",
           "solve_weak_form_over_rates"]
