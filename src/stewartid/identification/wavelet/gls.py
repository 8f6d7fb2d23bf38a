"""Generalized least squares for the weak-form equations, with pose noise propagated.

Rows of channel i have covariance s_i I + Q, Q_rs = sum_ab (c_a Sigma c_b) <phi_r^(a), phi_s^(b)>;
the noise bias is removed (Bortz, Messenger, Dukic, WENDy 2023; Söderström 2007).
"""

from __future__ import annotations

import warnings
from collections.abc import Sequence
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

from stewartid.errors import DataWarning, IdentificationError
from stewartid.identification.solvers import check_rank, regressor_names
from stewartid.identification.wavelet.variance_components import (
    chi2_excess,
    compensate,
    excess_variance,
    pose_coefficients,
    pose_covariance,
    row_noise,
)
from stewartid.identification.wavelet.weak_form import (
    IntervalEquations,
    StackedEquations,
    stack_equations,
)
from stewartid.platform import COORDINATES

#: Unknowns of [Mt Bt].
N_THETA = 72


@dataclass(frozen=True)
class WeakFormSolution:
    """Solution of :func:`solve_weak_form`.

    Attributes
    ----------
    theta, theta_std : ndarray, shape (6, 12)
        [Mt Bt] and standard errors.
    coulomb, coulomb_std : ndarray, shape (n_types,)
        Per joint type, N m; NaN without shared friction.
    offsets : ndarray, shape (n_experiments, 6)
        N, N m; NaN without shared friction.
    noise_std : ndarray, shape (6,)
        Force-side noise per row, sqrt(s_i).
    pose_noise_share : ndarray, shape (6,)
        Share of the invariant rows' residual power the pose noise explains.
    constant_scatter : ndarray, shape (6,)
        tau, the interval constants' spread around the friction structure, N, N m.
    condition_number : float
    n_equations : int
        Rows per channel.
    rate_weights : dict of str to float, optional
        Weight per soft-sign rate averaged over; None for a single fit.
    level_sensitivity : ndarray, shape (n_rates, 6, 12, n_types), optional
        The fit with free interval constants and no Coulomb levels (:func:`solve_weak_form`'s
        plain fit, on equations that carry Coulomb rows): d theta / d c, how [Mt Bt] moves per
        N m of each joint type's Coulomb torque its invariant rows leave out, at each
        soft-sign rate of their rows; else None.
    """

    theta: np.ndarray
    theta_std: np.ndarray
    coulomb: np.ndarray
    coulomb_std: np.ndarray
    offsets: np.ndarray
    noise_std: np.ndarray
    pose_noise_share: np.ndarray
    constant_scatter: np.ndarray
    condition_number: float
    n_equations: int
    rate_weights: dict[str, float] | None = None
    level_sensitivity: np.ndarray | None = None


def _weighted_normal(design: np.ndarray, weights: np.ndarray, target: np.ndarray
                     ) -> tuple[np.ndarray, np.ndarray]:
    """sum_n D_n^T W_n D_n and sum_n D_n^T W_n t_n, as two matrix products."""
    weighted = weights @ design                                         # (n, R, u)
    flat = design.reshape(-1, design.shape[-1])
    return (flat.T @ weighted.reshape(flat.shape),
            weighted.reshape(flat.shape).T @ target.ravel())


def channel_systems(stacked: StackedEquations, n_experiments: int, shared_friction: bool,
                    variation: bool = False) -> tuple[list[np.ndarray], list[np.ndarray]]:
    """Design (n, R, u) and targets (n, R) of each of the 6 channels over all u unknowns.

    Unknowns: [Mt Bt] row-major, then (shared friction) per-experiment offsets, then Coulomb levels
    (shared friction or ``variation``, which gives them to the invariant rows too).
    """
    x, y, owner = stacked.regressors, stacked.targets, stacked.owner
    n, k_rows = x.shape[:2]
    n_types = stacked.coulomb.shape[1]
    offsets = 6 * n_experiments if shared_friction else 0
    levels = n_types if shared_friction or variation else 0
    n_unknowns = N_THETA + offsets + levels
    rows = k_rows + 1 if shared_friction else k_rows
    designs, targets = [], []
    for i in range(6):
        design = np.zeros((n, rows, n_unknowns))
        design[:, :k_rows, 12 * i:12 * i + 12] = x
        if variation:
            design[:, :k_rows, N_THETA + offsets:] = stacked.coulomb_rows[:, :, :, i]
        target = y[:, :, i]
        if shared_friction:
            design[:, k_rows, 12 * i:12 * i + 12] = stacked.mean_regressors
            design[np.arange(n), k_rows, N_THETA + 6 * owner + i] = stacked.weights
            design[:, k_rows, N_THETA + offsets:] = stacked.coulomb[:, :, i]
            target = np.concatenate([target, stacked.mean_targets[:, i:i + 1]], axis=1)
        designs.append(design)
        targets.append(target)
    return designs, targets


def channel_covariance(stacked: StackedEquations, gram: np.ndarray, noise: np.ndarray,
                       i: int, theta_i: np.ndarray, scatter: float | None) -> np.ndarray:
    """Covariance (n, R, R) of channel i's rows: force noise, pose noise at theta_i, constants' scatter."""
    rows = gram.shape[-1]
    v = noise[:, None, None] * np.eye(rows) + pose_covariance(
        gram, stacked.sigma, pose_coefficients(stacked.sensitivity[:, i], theta_i))
    if scatter is not None:
        v[:, -1, -1] += (scatter * stacked.weights) ** 2
    return v


class InvariantFit(NamedTuple):
    """theta (6, 12), force-side noise variance (n, 6) and pose-noise share (6,) of the invariant rows."""

    theta: np.ndarray
    noise: np.ndarray
    pose_share: np.ndarray


def fit_invariant_rows(stacked: StackedEquations, iterations: int) -> InvariantFit:
    """Each channel from the invariant rows alone, reweighted ``iterations`` times."""
    x, y = stacked.regressors, stacked.targets
    n, k_rows = x.shape[:2]
    sigma, sensitivity, white = stacked.sigma, stacked.sensitivity, stacked.white
    # contiguous once: every channel's products below reshape it (a slice would be copied)
    gram = np.ascontiguousarray(stacked.gram[..., :k_rows, :k_rows])
    theta = np.linalg.lstsq(x.reshape(-1, 12), y.reshape(-1, 6), rcond=None)[0].T
    # floor: noise-free data must not give infinite weights
    floor = 1e-24 * np.maximum(np.mean(y.reshape(-1, 6) ** 2, axis=0), 1e-300)
    noise = np.zeros((n, 6))
    pose_share = np.zeros(6)
    for i in range(6):
        for _ in range(max(1, iterations)):
            q_inv = pose_covariance(gram, sigma, pose_coefficients(sensitivity[:, i], theta[i]))
            residual = y[:, :, i] - x @ theta[i]
            power, pose = float(np.sum(residual ** 2)), float(np.trace(q_inv, 0, 1, 2).sum())
            excess = excess_variance(white[:, i, None, None] * np.eye(k_rows) + q_inv,
                                     residual, residual.size - 12)
            noise[:, i] = np.maximum(white[:, i] + excess, floor[i])
            pose_share[i] = min(pose / max(power, 1e-300), 1.0)
            w = np.linalg.inv(noise[:, i, None, None] * np.eye(k_rows) + q_inv)
            normal, rhs, _ = compensate(*_weighted_normal(x, w, y[:, :, i]), w, gram, sigma,
                                        sensitivity[:, i])
            theta[i] = np.linalg.solve(normal, rhs)
    return InvariantFit(theta=theta, noise=noise, pose_share=pose_share)


def constant_scatter(stacked: StackedEquations, designs: Sequence[np.ndarray],
                     invariant: InvariantFit) -> np.ndarray:
    """tau (6,), N, N m: the interval constants' scatter around the friction structure (invariant fit)."""
    theta, n = invariant.theta, len(stacked.owner)
    gram = stacked.gram
    variance = np.stack([channel_covariance(stacked, gram, invariant.noise[:, i], i, theta[i],
                                            0.0)[:, -1, -1]
                         for i in range(6)], axis=1)                  # (n, 6), tau = 0
    base = stacked.mean_targets - stacked.mean_regressors @ theta.T
    nuisance_design = np.stack([d[:, -1, N_THETA:] for d in designs], axis=1)  # (n,6,u)
    n_nuisance = nuisance_design.shape[-1]
    scaled = nuisance_design / np.sqrt(variance)[:, :, None]
    fitted = np.linalg.lstsq(scaled.reshape(-1, n_nuisance),
                             (base / np.sqrt(variance)).ravel(), rcond=None)[0]
    mean_residual = base - nuisance_design @ fitted
    # tau^2 per channel with sum_k r_k^2 / (v_k + tau^2 w_k^2) = dof, weighted because the
    # intervals' noise variances v differ widely
    dof = n - n_nuisance / 6
    weight = stacked.weights
    return np.sqrt([chi2_excess(variance[:, i] / weight ** 2,
                                (mean_residual[:, i] / weight) ** 2, dof)
                    for i in range(6)])


class JointFit(NamedTuple):
    """Result of :func:`fit_jointly`.

    Attributes
    ----------
    z : ndarray, shape (u,)
    normal : ndarray, shape (u, u)
        Compensated normal matrix of the last pass.
    scale : ndarray, shape (u,)
        Its column equilibration.
    weights : list of ndarray, shape (n, R, R)
    uncorrected : ndarray of bool, shape (6,)
        Channels left without the errors-in-variables correction.
    local_z : list of ndarray, shape (m,), or None
        Each equation's own unknowns (``local`` of :func:`fit_jointly`).
    """

    z: np.ndarray
    normal: np.ndarray
    scale: np.ndarray
    weights: list[np.ndarray]
    uncorrected: np.ndarray
    local_z: list[np.ndarray] | None = None


def _size_groups(local: Sequence[np.ndarray]) -> list[tuple[int, np.ndarray]]:
    """The equations (indices, ascending) with as many own unknowns m > 0 in their columns
    ``local`` (6, R, m), for each m in ascending order."""
    sizes = np.array([columns.shape[2] for columns in local])
    return [(int(size), np.flatnonzero(sizes == size)) for size in np.unique(sizes[sizes > 0])]


def _eliminate_local(local: Sequence[np.ndarray], designs: Sequence[np.ndarray],
                     targets: Sequence[np.ndarray], weights: Sequence[np.ndarray],
                     carried: Sequence[np.ndarray], n_unknowns: int
                     ) -> tuple[np.ndarray, np.ndarray, list[tuple[np.ndarray, ...]]]:
    """The Schur complement of the equations' own unknowns: what to subtract from the normal
    matrix (u, u) and right-hand side (u,), and per group of equations with as many own
    unknowns m (indices (g,), C^T W D (g, m, u), C^T W t (g, m, 1), (C^T W C)^-1 (g, m, m)) to
    recover them. ``designs[i]``: channel i's design on the unknowns its rows carry, whose
    indices among the ``n_unknowns`` (u) are ``carried[i]``.
    """
    runs = [_runs(indices) for indices in carried]
    groups = []
    normal, rhs = np.zeros((n_unknowns, n_unknowns)), np.zeros(n_unknowns)
    for size, group in _size_groups(local):
        columns = np.stack([local[j] for j in group])                        # (g, 6, R, m)
        inner = np.zeros((len(group), size, size))
        cross = np.zeros((len(group), size, n_unknowns))
        own = np.zeros((len(group), size, 1))
        for i in range(6):
            weighted = weights[i][group] @ columns[:, i]                      # (g, R, m)
            inner += columns[:, i].transpose(0, 2, 1) @ weighted
            flipped = weighted.transpose(0, 2, 1)
            products = flipped @ designs[i][group]                           # (g, m, carried)
            for first, last, at in runs[i]:
                cross[:, :, first:last] += products[:, :, at:at + last - first]
            own += flipped @ targets[i][group][:, :, None]
        inverse = np.linalg.inv(inner)
        # sum over the group of C^T W D' (C^T W C)^-1 C^T W [D t]: one product of the stacks
        solved = inverse @ np.concatenate([cross, own], axis=2)              # (g, m, u + 1)
        removed = cross.reshape(-1, n_unknowns).T @ solved.reshape(-1, n_unknowns + 1)
        normal += removed[:, :-1]
        rhs += removed[:, -1]
        groups.append((group, cross, own, inverse))
    return normal, rhs, groups


def _runs(indices: np.ndarray) -> list[tuple[int, int, int]]:
    """Runs of consecutive values in the ascending ``indices``: (first, last + 1, position of
    the first in ``indices``) each."""
    breaks = np.flatnonzero(np.diff(indices) != 1) + 1
    starts = np.concatenate([[0], breaks])
    stops = np.concatenate([breaks, [len(indices)]])
    return [(int(indices[a]), int(indices[b - 1]) + 1, int(a))
            for a, b in zip(starts, stops, strict=True) if b > a]


def local_terms(local: Sequence[np.ndarray], local_z: Sequence[np.ndarray]) -> np.ndarray:
    """What the equations' own unknowns ``local_z`` (m,) add to their rows through their columns
    ``local`` (6, R, m): (6, n, R), channel first. The equations with the same number of own
    unknowns are taken together, each product in their stack the one of an equation alone."""
    out = np.zeros((6, len(local), local[0].shape[1]))
    for _, group in _size_groups(local):
        products = (np.stack([local[j] for j in group])
                    @ np.stack([local_z[j] for j in group])[:, None, :, None])   # (g, 6, R, 1)
        out[:, group] = products[..., 0].transpose(1, 0, 2)
    return out


def fit_jointly(stacked: StackedEquations, designs: Sequence[np.ndarray],
                targets: Sequence[np.ndarray], invariant: InvariantFit,
                scatter: np.ndarray | None, iterations: int,
                local: Sequence[np.ndarray] | None = None) -> JointFit:
    """All channels at once, rows weighted by their inverse covariance, noise bias removed.

    ``local``: per equation, columns (6, R, m) of unknowns its rows alone carry, shared by its
    channels (a stopped leg's free friction), linearly independent (a basis of their span:
    :func:`~stewartid.identification.stops.span_basis`), eliminated by their Schur complement.
    """
    n_unknowns = designs[0].shape[-1]
    rows = designs[0].shape[1]
    gram = np.ascontiguousarray(stacked.gram[..., :rows, :rows])  # reshaped per channel
    z = np.zeros(n_unknowns)
    z[:N_THETA] = invariant.theta.ravel()
    uncorrected = np.zeros(6, dtype=bool)
    # each channel's products on the unknowns its rows carry (its own 12, the shared levels and
    # offsets): the others' columns are zero in its design
    carried = [np.flatnonzero(np.any(design, axis=(0, 1))) for design in designs]
    compact = [design[:, :, kept] for design, kept in zip(designs, carried, strict=True)]
    for _ in range(max(1, iterations) if scatter is not None else 1):
        normal = np.zeros((n_unknowns, n_unknowns))
        rhs = np.zeros(n_unknowns)
        weights = []
        for i in range(6):
            block = slice(12 * i, 12 * i + 12)
            w = np.linalg.inv(channel_covariance(stacked, gram, invariant.noise[:, i], i,
                                                 z[block], None if scatter is None
                                                 else scatter[i]))
            weights.append(w)
            part, part_rhs = _weighted_normal(compact[i], w, targets[i])
            normal[np.ix_(carried[i], carried[i])] += part
            rhs[carried[i]] += part_rhs
            normal[block, block], rhs[block], corrected = compensate(
                normal[block, block], rhs[block], w, gram, stacked.sigma,
                stacked.sensitivity[:, i])
            uncorrected[i] = not corrected
        if local is not None:
            removed, removed_rhs, parts = _eliminate_local(local, compact, targets, weights,
                                                           carried, n_unknowns)
            normal, rhs = normal - removed, rhs - removed_rhs
        scale = np.sqrt(np.abs(np.diag(normal)))
        scale = np.where(scale > 0, scale, 1.0)
        try:
            z = np.linalg.solve(normal / np.outer(scale, scale), rhs / scale) / scale
        except np.linalg.LinAlgError as exc:
            raise IdentificationError(
                "the weak-form equations do not determine every unknown (the records hold too "
                "few constant-direction intervals for the interval constants shared by "
                "friction); record longer experiments or leave the constants free "
                "(friction='free').") from exc
    local_z = None
    if local is not None:
        local_z = [np.zeros(0)] * len(local)
        for group, cross, own, inverse in parts:
            values = inverse @ (own[:, :, 0] - cross @ z)[:, :, None]           # (g, m, 1)
            for k, j in enumerate(group):
                local_z[j] = values[k, :, 0]
    return JointFit(z=z, normal=normal, scale=scale, weights=weights, uncorrected=uncorrected,
                    local_z=local_z)


def standard_errors(designs: Sequence[np.ndarray], targets: Sequence[np.ndarray],
                    fit: JointFit, local: Sequence[np.ndarray] | None = None) -> np.ndarray:
    """Standard errors (u,): the larger of the GLS one and one cluster-robust over intervals.

    ``local`` as :func:`fit_jointly`'s: each interval's own unknowns, whose scores vanish in
    their interval, count among the unknowns.
    """
    n, n_unknowns = len(designs[0]), len(fit.z)
    scores = np.zeros((n, n_unknowns))
    squares, n_rows = 0.0, 0
    if local is not None:
        n_unknowns += sum(len(z) for z in fit.local_z)
        own = local_terms(local, fit.local_z)
    for i in range(6):
        residual = targets[i] - designs[i] @ fit.z
        if local is not None:
            residual = residual - own[i]
        weighted = (fit.weights[i] @ residual[:, :, None])[:, :, 0]
        scores += (weighted[:, None, :] @ designs[i])[:, 0, :]
        squares += float(np.sum(residual * weighted))
        n_rows += residual.size
    bread = _inverse_normal(fit)
    model_cov = bread * max(squares / max(n_rows - n_unknowns, 1), 1e-300)
    g = n
    robust_cov = (g / max(g - 1, 1) * (n_rows - 1) / max(n_rows - n_unknowns, 1)
                  * bread @ (scores.T @ scores) @ bread)
    return np.sqrt(np.maximum(np.diag(model_cov), np.diag(robust_cov)))


def solve_weak_form(equations: Sequence[IntervalEquations], n_experiments: int,
                    shared_friction: bool = True, iterations: int = 5, max_condition: float = 1e8,
                    pose_covariance: np.ndarray | None = None,
                    force_sensitivity: np.ndarray | None = None,
                    force_variance: np.ndarray | None = None, rate_index: int = 0,
                    variation: bool = False, shared: dict | None = None) -> WeakFormSolution:
    """Generalized least squares for [Mt Bt] (and the friction structure), pose noise compensated.

    Parameters
    ----------
    equations : sequence of IntervalEquations
        All with the same number of invariant rows.
    n_experiments : int
    shared_friction : bool
        Use the mean rows with the friction structure; False: every interval constant free.
    iterations : int
        Reweighting passes.
    max_condition : float
    pose_covariance : ndarray, shape (n_experiments, 6, 6), optional
        White pose noise per sample; None: noise-free.
    force_sensitivity : ndarray, shape (n_experiments, 6, 6), optional
        K = dy/dq; None: zero.
    force_variance : ndarray, shape (n_experiments, 6), optional
        White generalized-force noise per sample; None: from the residuals alone.
    rate_index : int
        Soft-sign rate of the invariant rows' Coulomb regressors.
    variation : bool
        Give the invariant rows the Coulomb levels and refit on re-measured noise.
    shared : dict, optional
        Cache of the work independent of ``rate_index`` and ``variation``.
    """
    stacked = stack_equations(equations, pose_covariance, force_sensitivity, force_variance,
                              rate_index)
    n, k_rows = stacked.regressors.shape[:2]
    shared = {} if shared is None else shared
    if "invariant" not in shared:
        flat = stacked.regressors.reshape(-1, 12)
        shared["condition"] = check_rank(flat.T @ flat, regressor_names("q_ddot", "q_dot"),
                                         max_condition)
        shared["invariant"] = fit_invariant_rows(stacked, iterations)
    condition, invariant = shared["condition"], shared["invariant"]
    designs, targets = channel_systems(stacked, n_experiments, shared_friction, variation)
    scatter = constant_scatter(stacked, designs, invariant) if shared_friction else None
    fit = fit_jointly(stacked, designs, targets, invariant, scatter, iterations)
    for _ in range(VARIATION_PASSES if variation else 0):
        # the invariant fit's residuals hold the Coulomb variation the joint fit models
        invariant = invariant._replace(noise=row_noise(stacked, designs, targets, fit.z))
        fit = fit_jointly(stacked, designs, targets, invariant, scatter, iterations)
    if fit.uncorrected.any():
        names = ", ".join(c for c, u in zip(COORDINATES, fit.uncorrected, strict=True) if u)
        warnings.warn(f"pose noise too large for the errors-in-variables correction of the "
                      f"{names} equations: their rows of Mt and Bt keep the attenuation the "
                      f"noise causes (biased towards zero by its share of the regressors' "
                      f"power); longer intervals or less pose noise remove it", DataWarning,
                      stacklevel=3)
    std = standard_errors(designs, targets, fit)
    sensitivity = None
    if not (shared_friction or variation) and all(e.coulomb_rows is not None
                                                   for e in equations):
        # the rates every interval carries (some add the signs from half their window)
        rates = min(len(e.coulomb_rows) for e in equations)
        sensitivity = level_sensitivity(fit, stacked.regressors,
                                        np.stack([e.coulomb_rows[:rates] for e in equations]))
    z, n_types = fit.z, stacked.coulomb.shape[1]
    levels = N_THETA + (6 * n_experiments if shared_friction else 0)
    if shared_friction:
        offsets = z[N_THETA:levels].reshape(n_experiments, 6)
    else:
        offsets = np.full((n_experiments, 6), np.nan)
    if shared_friction or variation:
        coulomb, coulomb_std = z[levels:], std[levels:]
    else:
        coulomb = coulomb_std = np.full(n_types, np.nan)
    return WeakFormSolution(
        theta=z[:N_THETA].reshape(6, 12), theta_std=std[:N_THETA].reshape(6, 12),
        coulomb=coulomb, coulomb_std=coulomb_std, offsets=offsets,
        noise_std=np.sqrt(invariant.noise.mean(axis=0)), pose_noise_share=invariant.pose_share,
        constant_scatter=np.zeros(6) if scatter is None else scatter,
        condition_number=condition, n_equations=int(n * k_rows),
        level_sensitivity=sensitivity)


def level_sensitivity(fit: JointFit, regressors: np.ndarray, coulomb_rows: np.ndarray
                      ) -> np.ndarray:
    """d theta / d c (n_rates, 6, 12, n_types) of a fit of [Mt Bt] alone on invariant rows
    ``regressors`` (n, K, 12) whose Coulomb rows ``coulomb_rows`` (n, n_rates, K, n_types, 6) it
    leaves out: (X^T W X)^-1 X^T W R per channel, its weights and normal matrix.

    A constant Coulomb torque on a joint gives a generalized force that follows the pose inside
    an interval, which a free constant per interval does not absorb: c times this is the bias
    it puts on the fit.
    """
    n_rates, n_types = coulomb_rows.shape[1], coulomb_rows.shape[3]
    cross = np.zeros((n_rates, N_THETA, n_types))
    for i in range(6):
        weighted = fit.weights[i] @ regressors                                   # (n, K, 12)
        cross[:, 12 * i:12 * i + 12] = np.einsum("nkr,nqkt->qrt", weighted,
                                                 coulomb_rows[..., i])
    return (_inverse_normal(fit) @ cross).reshape(n_rates, 6, 12, n_types)


def _inverse_normal(fit: JointFit) -> np.ndarray:
    """(X^T W X)^-1 of ``fit``, through its equilibrated normal matrix, which is well
    conditioned (checked before the fit): an inverse."""
    outer = np.outer(fit.scale, fit.scale)
    return np.linalg.inv(fit.normal / outer) / outer


#: Passes of :func:`solve_weak_form` with the noise re-measured from the joint fit.
VARIATION_PASSES = 2


__all__ = ["VARIATION_PASSES", "InvariantFit", "JointFit", "WeakFormSolution",
           "channel_covariance", "channel_systems", "constant_scatter",
           "fit_invariant_rows", "fit_jointly", "level_sensitivity", "local_terms",
           "solve_weak_form", "standard_errors"]
