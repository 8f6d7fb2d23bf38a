"""Method B on windows that span joint reversals: the Coulomb structure integrated.

Mt <phi'', q> - Bt <phi', q> + sum_types F_type <phi, W_type> = <phi, y>.
"""

from __future__ import annotations

from collections.abc import Sequence
from functools import partial
from typing import NamedTuple

import numpy as np
from numpy.polynomial import legendre

from stewartid.identification.preparation import Experiment
from stewartid.identification.solvers import check_rank, regressor_names
from stewartid.identification.stops import STOPS, Stop, StopPolicy, leg_stop_runs, span_basis
from stewartid.identification.wavelet.detection import Detection
from stewartid.identification.wavelet.gls import (
    N_THETA,
    InvariantFit,
    WeakFormSolution,
    fit_jointly,
    local_terms,
    standard_errors,
)
from stewartid.identification.wavelet.rate_selection import (
    Run,
    averaged_over_rates,
    half_window_pick,
    solved_over_rates,
)
from stewartid.identification.wavelet.variance_components import row_noise
from stewartid.identification.wavelet.weak_form import (
    SOFT_SIGN_RATES,
    IntervalEquations,
    PatternsBySamples,
    coulomb_patterns,
    inside,
    noise_gram,
    project_patterns,
    stack_equations,
    test_family,
)


class WindowEquations(NamedTuple):
    """``rows`` (mean row unused) and ``coulomb`` <phi_k, W_type> (n_rates, K, n_types, 6) of one
    window; ``stops`` (6, K, r): an orthonormal basis of the span of <phi_k, J_lq[l, i] P_j>,
    the Legendre terms P_j of the legs' stops inside it (channel i), each a free force along
    leg l."""

    rows: IntervalEquations
    coulomb: np.ndarray
    stops: np.ndarray | None = None


def window_stops(found: Detection, sample_rate: float, policy: StopPolicy = STOPS
                 ) -> list[Stop]:
    """The legs' stops of one experiment as Method B sees them.

    As least squares' (:func:`~stewartid.identification.stops.find_stops`) on Method B's own
    Coulomb sign rates: a leg is stopped while its rate is within ``policy.band`` noise levels;
    the differentiation window takes the place of the filter window. Two free terms or more per
    stop take up the sign law's own impulse and moment there.
    """
    window = found.info["differentiation_window"] * sample_rate
    return leg_stop_runs(found.leg_sign_rates, found.leg_sign_rate_noise,
                         int(policy.merge * window), window, 2, policy)[1]


#: Largest share of a window's rows (6 K) its stops' free terms may take, on average over
#: the experiment (:func:`stop_window_length`).
STOP_ROW_SHARE = 0.5


def stop_window_length(stops: Sequence[Stop], duration: float, size: int, longest: float
                       ) -> float:
    """Window length (s), at most ``longest``, whose stops' terms take on average at most
    :data:`STOP_ROW_SHARE` of its 6 ``size`` rows, over a record of ``duration`` s."""
    terms = sum(stop.terms for stop in stops)
    if terms == 0:
        return longest
    return min(longest, STOP_ROW_SHARE * 6 * size * duration / terms)


def _stop_columns(stops: Sequence[Stop], sel: slice, phi: np.ndarray,
                  leg_jacobian: np.ndarray) -> np.ndarray | None:
    """An orthonormal basis (6, K, r) of the span of <phi_k, J_lq[l, i] P_j> of the stops'
    parts inside the window ``sel`` (:func:`~stewartid.identification.stops.span_basis`); None
    without any."""
    columns = []
    for found in stops:
        if found.stop <= sel.start or found.start >= sel.stop:
            continue
        start, stop = max(found.start, sel.start), min(found.stop, sel.stop)
        x = (2.0 * np.arange(stop - start) + 1.0) / (stop - start) - 1.0
        polynomials = legendre.legvander(x, found.terms - 1)                # (n, terms)
        local = phi[:, start - sel.start:stop - sel.start]                   # (K, n)
        legs = leg_jacobian[start:stop, found.leg]                           # (n, 6)
        products = (legs[:, :, None] * polynomials[:, None, :]).reshape(len(legs), -1)
        columns.append((local @ products).reshape(len(local), 6, -1).transpose(1, 0, 2))
    if not columns:
        return None
    columns = np.concatenate(columns, axis=2)
    return span_basis(columns.reshape(-1, columns.shape[2])).reshape(*columns.shape[:2], -1)


def window_bounds(t: np.ndarray, length: float) -> np.ndarray:
    """[start, stop] (s) of consecutive windows about ``length`` s long covering ``t``."""
    span = float(t[-1] - t[0])
    count = max(1, int(round(span / length)))
    edges = t[0] + span * np.arange(count + 1) / count
    return np.column_stack([edges[:-1], edges[1:]])


def window_equations(experiment: Experiment, found: Detection, order: int, size: int,
                     index: int, uniform: bool, length: float,
                     patterns: np.ndarray | PatternsBySamples | None = None,
                     stops: Sequence[Stop] | None = None) -> list[WindowEquations]:
    """The equations of every window of one experiment.

    ``order``, ``size``: bump exponent and K; ``length``: window, s; ``patterns``:
    :func:`coulomb_patterns` of the experiment at every soft-sign rate, or its rows on demand
    (:class:`~stewartid.identification.wavelet.weak_form.PatternsBySamples`; computed when not
    given);
    ``stops``: the legs' stops (:func:`window_stops`), whose friction each window leaves free.
    """
    t, q, y = experiment.t, experiment.q, experiment.generalized_force
    if patterns is None:
        patterns = coulomb_patterns(found, experiment.joint_jacobians, uniform)
    h = float(t[1] - t[0])
    out = []
    for start, stop in window_bounds(t, length):
        sel = inside(t, start, stop)
        if sel.stop - sel.start < 4 * (size + 1):
            continue
        (phi0, phi1, phi2), bump = test_family(t[sel], start, stop, order, size, h)
        qc = q[sel] - q[sel].mean(axis=0)
        rows = IntervalEquations(
            regressors=np.hstack([phi2 @ qc, -(phi1 @ qc)]), targets=phi0 @ y[sel],
            mean_regressors=np.zeros(12), mean_target=np.zeros(6), weight=0.0,
            coulomb=np.zeros((patterns.shape[2], 6)), experiment=int(index),
            noise_gram=noise_gram((phi0, phi1, phi2), bump))
        out.append(WindowEquations(rows, project_patterns(phi0, patterns[sel]),
                                   None if not stops else _stop_columns(
                                       stops, sel, phi0, experiment.leg_jacobian)))
    return out


def _designs(regressors: np.ndarray, coulomb: np.ndarray) -> list[np.ndarray]:
    n, k_rows = regressors.shape[:2]
    designs = []
    for i in range(6):
        design = np.zeros((n, k_rows, N_THETA + coulomb.shape[2]))
        design[:, :, 12 * i:12 * i + 12] = regressors
        design[:, :, N_THETA:] = coulomb[:, :, :, i]
        designs.append(design)
    return designs


def solve_windows(equations: Sequence[WindowEquations], iterations: int = 3,
                  max_condition: float = 1e8, pose_covariance: np.ndarray | None = None,
                  force_sensitivity: np.ndarray | None = None,
                  force_variance: np.ndarray | None = None, rate_index: int = 0
                  ) -> WeakFormSolution:
    """[Mt Bt] and Coulomb levels from window equations by iterated generalized least squares.

    Parameters as :func:`~stewartid.identification.wavelet.gls.solve_weak_form`. ``offsets`` are NaN
    and ``constant_scatter`` zero.
    """
    stacked = stack_equations([e.rows for e in equations], pose_covariance, force_sensitivity,
                              force_variance)
    coulomb = np.stack([e.coulomb[rate_index] for e in equations])    # (n, K, types, 6)
    n, k_rows = stacked.regressors.shape[:2]
    flat = stacked.regressors.reshape(-1, 12)
    condition = check_rank(flat.T @ flat, regressor_names("q_ddot", "q_dot"), max_condition)
    designs = _designs(stacked.regressors, coulomb)
    targets = [stacked.targets[:, :, i] for i in range(6)]
    # start: ordinary least squares over all channels at once
    stacked_design = np.concatenate([d.reshape(-1, d.shape[-1]) for d in designs])
    z = np.linalg.lstsq(stacked_design, np.concatenate([t.ravel() for t in targets]),
                        rcond=None)[0]
    local = None
    if any(e.stops is not None for e in equations):
        local = [np.zeros((6, k_rows, 0)) if e.stops is None else e.stops for e in equations]
    fitted = targets
    for _ in range(max(1, iterations)):
        noise = row_noise(stacked, designs, fitted, z,
                          0 if local is None else sum(c.shape[2] for c in local) / 6)
        start = InvariantFit(theta=z[:N_THETA].reshape(6, 12), noise=noise,
                             pose_share=np.zeros(6))
        fit = fit_jointly(stacked, designs, targets, start, None, 1, local)
        z = fit.z
        if local is not None:  # the stops' friction as fitted, for the rows' noise
            own = local_terms(local, fit.local_z)
            fitted = [targets[i] - own[i] for i in range(6)]
    std = standard_errors(designs, targets, fit, local)
    return WeakFormSolution(
        theta=z[:N_THETA].reshape(6, 12), theta_std=std[:N_THETA].reshape(6, 12),
        coulomb=z[N_THETA:], coulomb_std=std[N_THETA:],
        offsets=np.full((int(stacked.owner.max()) + 1, 6), np.nan),
        noise_std=np.sqrt(noise.mean(axis=0)), pose_noise_share=np.zeros(6),
        constant_scatter=np.zeros(6), condition_number=condition,
        n_equations=int(n * k_rows))


def solve_windows_over_rates(equations: Sequence[WindowEquations],
                             rates: Sequence[float] = SOFT_SIGN_RATES, run: Run | None = None,
                             **settings) -> tuple[WeakFormSolution, float]:
    """:func:`solve_windows` averaged over transition rates, and the rate of greatest weight.

    Where windows carry Coulomb rows from the signs of half their window after the ``rates``'
    (:func:`~stewartid.identification.wavelet.friction_models.patterns_with_half_window`), the
    standard errors widen by that refit's distance (:func:`averaged_over_rates`). ``run`` as
    :func:`~stewartid.identification.wavelet.rate_selection.solved_over_rates`.
    """
    count = len(rates)
    refit = None
    if any(len(e.coulomb) > count for e in equations):
        refit = partial(solve_windows, [e._replace(coulomb=e.coulomb[half_window_pick(
            len(e.coulomb), count)]) for e in equations], **settings)
    # each fit given its rate's Coulomb rows alone: a worker receives what it solves
    fits = [partial(solve_windows, [e._replace(coulomb=e.coulomb[k:k + 1]) for e in equations],
                    **settings) for k in range(count)]
    solutions, half = solved_over_rates(fits, refit, run)
    return averaged_over_rates(solutions, rates, half)


__all__ = ["SOFT_SIGN_RATES", "STOP_ROW_SHARE", "WindowEquations", "coulomb_patterns",
           "solve_windows", "solve_windows_over_rates", "window_bounds", "window_equations",
           "stop_window_length", "window_stops"]
