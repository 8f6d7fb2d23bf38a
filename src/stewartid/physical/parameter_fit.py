"""Solvers of :mod:`stewartid.physical.estimator`: weighted least squares with unidentifiable
parameters fixed, and the nearest physically consistent parameters (an SDP in cvxpy;
Wensing, Kim & Slotine, IEEE RA-L 2017).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from stewartid.identification.consistency import (
    STRICT_FRACTION,
    default_solver,
    require_cvxpy,
    solve_convex,
)
from stewartid.identification.long_run import (
    filtered_noise_covariance,
    record_sandwich,
    score_sandwich,
    with_larger_variances,
)
from stewartid.identification.solvers import integrated_autocorrelation
from stewartid.model.regressor import BODY_PARAMETERS, pseudo_inertia

#: Weighted column norm, relative to the largest, below which a parameter counts as not
#: excited (round-off of a column that is zero in exact arithmetic).
DEAD_COLUMN = 1e-10


@dataclass(frozen=True)
class Solution:
    """Weighted least squares with unidentifiable parameters fixed (:func:`solve_parameters`).

    Attributes
    ----------
    values : ndarray, shape (p,)
        Estimated, or fixed at nominal.
    covariance : ndarray, shape (p, p)
        Zero in the fixed ones' rows and columns.
    fixed : dict of str to str
        Fixed parameters and why.
    condition_number : float
        Of the equilibrated, channel-weighted regression of the estimated ones.
    singular_values : ndarray
        Relative to the largest, every parameter included.
    residual_rms : ndarray, shape (6,)
    n_equations : int
    """

    values: np.ndarray
    covariance: np.ndarray
    fixed: dict[str, str]
    condition_number: float
    singular_values: np.ndarray
    residual_rms: np.ndarray
    n_equations: int


def _weighted_fit(gram, cross, weights, free, fixed_values):
    """Equilibrated weighted LS from per-channel ``gram`` (6, p, p) and ``cross`` (6, p): free
    estimates, inverse normal matrix, relative singular values and right singular vectors.
    """
    N = np.einsum("c,cpq->pq", weights, gram)
    b = np.einsum("c,cp->p", weights, cross) - N[:, ~free] @ fixed_values[~free]
    N, b = N[np.ix_(free, free)], b[free]
    scale = np.sqrt(np.diag(N))
    scale = np.where(scale > 0, scale, 1.0)
    eigenvalues, vectors = np.linalg.eigh(N / np.outer(scale, scale))
    eigenvalues = np.clip(eigenvalues[::-1], eigenvalues[-1] * 1e-300, None)
    vectors = vectors[:, ::-1]
    theta = (vectors @ ((vectors.T @ (b / scale)) / eigenvalues)) / scale
    inverse = (vectors / eigenvalues) @ vectors.T / np.outer(scale, scale)
    singular = np.sqrt(eigenvalues / eigenvalues[0])
    return theta, inverse, singular, vectors.T


def solve_parameters(X: np.ndarray, y: np.ndarray, names: list[str], nominal: np.ndarray,
                     scales: np.ndarray | None = None, max_condition: float = 1e5,
                     max_relative_error: float = 0.3, regressor_noise: np.ndarray | None = None,
                     target_noise: np.ndarray | None = None,
                     segments: list[tuple[int, int]] | None = None,
                     measured_noise: list[tuple[np.ndarray, np.ndarray]] | None = None
                     ) -> Solution:
    """Weighted least squares for y = X theta, fixing at ``nominal`` what the data cannot tell.

    Channels are weighted by their residual variance from a first RMS-weighted pass. A parameter
    is fixed when the condition number exceeds ``max_condition`` (the one weighing most in the
    weakest direction) or, if positive by nature (``scales`` > 0), when its standard error exceeds
    ``max_relative_error`` of its size.

    Parameters
    ----------
    X : ndarray, shape (K, 6, p)
    y : ndarray, shape (K, 6)
    names : list of str
    nominal, scales : ndarray, shape (p,)
    max_condition, max_relative_error : float
    regressor_noise, target_noise : ndarray, shape ([R,] 6, p, p) and ([R,] 6, p), optional
        Expected noise shares of X^T X and X^T y per channel (and record), subtracted.
    segments : list of (int, int), optional
        Per record, rows and correlation lag; given, the covariance is :func:`score_covariance`.
    measured_noise : list of (ndarray, ndarray), optional
        With ``segments``: a separately measured row noise flooring the standard errors.
    """
    p = X.shape[2]
    scales = np.zeros(p) if scales is None else np.asarray(scales, dtype=float)
    scale_y = np.sqrt(np.mean(y ** 2, axis=0))
    weights = 1.0 / np.where(scale_y > 0, scale_y, 1.0) ** 2
    by_channel = np.ascontiguousarray(X.transpose(1, 0, 2))  # (6, K, p): BLAS products
    gram = np.swapaxes(by_channel, 1, 2) @ by_channel
    cross = np.einsum("ckp,kc->cp", by_channel, y, optimize=True)
    by_record = regressor_noise is not None and regressor_noise.ndim == 4
    if regressor_noise is not None:
        gram = gram - (regressor_noise.sum(axis=0) if by_record else regressor_noise)
    if target_noise is not None:
        cross = cross - (target_noise.sum(axis=0) if target_noise.ndim == 3 else target_noise)
    # a column that is zero (relative to the forces it would explain) is not excited at all
    column = np.sqrt(np.einsum("c,cpp->p", weights, gram))
    free = column > DEAD_COLUMN * column.max()
    fixed = {names[k]: "not excited by these data: its regressor column is zero"
             for k in np.flatnonzero(~free)}
    singular_all = _weighted_fit(gram, cross, weights, free, nominal)[2]
    for _ in range(2):  # the second pass with the residual's channel weights
        while True:
            theta, inverse, s, Vt = _weighted_fit(gram, cross, weights, free, nominal)
            condition = float(1.0 / s[-1])
            index = np.flatnonzero(free)
            if condition > max_condition:
                k = index[int(np.argmax(np.abs(Vt[-1])))]
                fixed[names[k]] = (f"not identifiable from these data: condition number "
                                   f"{condition:.3g} of the scaled regression")
                free[k] = False
                continue
            values = nominal.astype(float).copy()
            values[free] = theta
            residual = y - X @ values
            sigma2 = np.sum(residual ** 2, axis=0) / max(len(y) - p / 6.0, 1.0)
            tau = np.array([integrated_autocorrelation(r) for r in residual.T])
            variance = float(np.mean(sigma2 * tau * weights))
            std = np.sqrt(np.clip(np.diag(inverse) * variance, 0.0, None))
            size = np.maximum(np.abs(theta), scales[index])
            loose = [j for j, k in enumerate(index)
                     if scales[k] > 0 and std[j] > max_relative_error * size[j]]
            if not loose:
                break
            j = max(loose, key=lambda j: std[j] / size[j])
            fixed[names[index[j]]] = (f"not identifiable from these data: standard error "
                                      f"{std[j]:.3g} against a value of {theta[j]:.4g}")
            free[index[j]] = False
        used, sigma = weights, np.sqrt(np.sum(residual ** 2, axis=0) / len(y))
        weights = 1.0 / np.maximum(sigma, 1e-12 * scale_y) ** 2
    covariance = np.zeros((p, p))
    solved = inverse * variance
    if segments is not None:
        expected = None
        if by_record:  # E[sum of a record's scores] = its sum_c w_c (t_c - N_c theta)
            target = 0.0 if target_noise is None else target_noise
            expected = np.einsum("c,rcp->rp", used,
                                 target - regressor_noise @ values)[:, free]
        solved = score_covariance(inverse, X[:, :, free], residual, used, segments, expected,
                                  measured_noise)
    covariance[np.ix_(free, free)] = solved
    return Solution(values, covariance, fixed, condition, singular_all,
                    np.sqrt(np.mean(residual ** 2, axis=0)), len(y))


@dataclass(frozen=True)
class Body:
    """A rigid body of the consistent fit: its ten standard parameters are ``mapping @ p + offset``.

    Attributes
    ----------
    name : str
    mapping : ndarray, shape (10, p)
    offset : ndarray, shape (10,)
    mass_scale : float
        kg; mass kept above ``STRICT_FRACTION`` of it, pseudo-inertia scaled by it.
    """

    name: str
    mapping: np.ndarray
    offset: np.ndarray
    mass_scale: float

    def pseudo_inertia(self, p: np.ndarray) -> np.ndarray:
        """Pseudo-inertia matrix (4, 4) at ``p``."""
        return pseudo_inertia(self.mapping @ p + self.offset)


@dataclass(frozen=True)
class ConsistentParameters:
    """Physically consistent parameters nearest an estimate (:func:`nearest_consistent`).

    Attributes
    ----------
    values : ndarray, shape (p,)
    change : ndarray, shape (p,)
        (consistent - unconstrained) / standard error; 0 when fixed.
    objective : float
        (p - p^)^T Sigma^-1 (p - p^) at the solution.
    min_eigenvalues : dict of str to float
        Smallest pseudo-inertia eigenvalue per body (kg m^2).
    solver : str
        cvxpy solver, or ``"none"`` when already consistent.
    status : str
        ``"optimal"``, ``"optimal_inaccurate"`` or ``"consistent already"``.
    """

    values: np.ndarray
    change: np.ndarray
    objective: float
    min_eigenvalues: dict[str, float]
    solver: str
    status: str


def score_covariance(inverse: np.ndarray, X: np.ndarray, residual: np.ndarray,
                     weights: np.ndarray, segments: list[tuple[int, int]],
                     expected: np.ndarray | None = None,
                     measured_noise: list[tuple[np.ndarray, np.ndarray]] | None = None
                     ) -> np.ndarray:
    """N^-1 B N^-1 (p, p), B the long-run covariance of the scores s_k = sum_c w_c X_kc r_kc.

    Each variance of B is raised to the per-record summed scores' where larger
    (:func:`~stewartid.identification.long_run.record_sandwich`), then to the measured noise floor.
    ``inverse`` is N^-1; ``segments`` give each record's rows and correlation length; ``expected``
    (R, p) each record's summed score under noise alone, taken out; ``measured_noise`` per record
    the covariance per sample and filter autocorrelation
    (:func:`~stewartid.identification.long_run.filtered_noise_covariance`).
    """
    scores = np.einsum("kcp,kc->kp", X, residual * weights, optimize=True)
    rows = np.array([n for n, _ in segments])
    if expected is None:
        expected = np.outer(rows / rows.sum(), scores.sum(axis=0))
    centred = scores - np.repeat(expected / rows[:, None], rows, axis=0)
    covariance = with_larger_variances(
        score_sandwich(inverse, centred, segments, psd="variances"),
        record_sandwich(inverse, scores, segments, expected))
    if measured_noise is None:
        return covariance
    floor = inverse @ filtered_noise_covariance(X, weights, segments, measured_noise) @ inverse
    return with_larger_variances(covariance, floor)


def nearest_consistent(values: np.ndarray, covariance: np.ndarray, bodies: list[Body],
                       nonnegative: np.ndarray, solver: str | None = None
                       ) -> ConsistentParameters:
    """Consistent parameters nearest ``values`` in the metric of ``covariance``.

        minimise (p - p^)^T Sigma^-1 (p - p^)  s.t.  J(body) >= 0,  m(body) > 0,  f >= 0

    Parameters
    ----------
    values : ndarray, shape (p,)
    covariance : ndarray, shape (p, p)
        Zero-variance parameters stay as they are.
    bodies : list of Body
    nonnegative : ndarray of bool, shape (p,)
        Friction coefficients.
    solver : str, optional
        cvxpy solver; Clarabel when installed, else SCS.

    Raises
    ------
    ConfigError
        cvxpy not installed.
    IdentificationError
        Solver fails, or no consistent parameters with the fixed ones.
    """
    require_cvxpy()  # needed whatever the estimate
    values = np.asarray(values, dtype=float)
    bounded = np.asarray(nonnegative, dtype=bool)
    minima = {body.name: float(np.linalg.eigvalsh(body.pseudo_inertia(values))[0])
              for body in bodies}
    if (all(v >= 0 for v in minima.values()) and np.all(values[bounded] >= 0)
            and all(body.mapping[0] @ values + body.offset[0]
                    >= STRICT_FRACTION * body.mass_scale for body in bodies)):
        # consistent already: the estimate is its own projection, exactly
        return ConsistentParameters(values, np.zeros(len(values)), 0.0, minima, "none",
                                    "consistent already")
    # only the parameters in a constraint are solved for; the others follow them by their
    # correlation (the minimum over them of the quadratic objective, in closed form)
    variance = np.diag(covariance)
    involved = bounded | np.any([np.any(body.mapping != 0, axis=0) for body in bodies], axis=0)
    solved = np.flatnonzero((variance > 0) & involved)
    follow = np.flatnonzero((variance > 0) & ~involved)
    std = np.sqrt(np.maximum(variance, 0.0))
    scaled = np.where(std > 0, std, 1.0)
    correlation = covariance / np.outer(scaled, scaled)
    block = correlation[np.ix_(solved, solved)]
    z_solved, status = _projection(values, std, block, solved, bodies, bounded, solver)
    change = np.zeros(len(values))
    change[solved] = z_solved
    change[follow] = correlation[np.ix_(follow, solved)] @ np.linalg.solve(block, z_solved)
    consistent = values + std * change
    return ConsistentParameters(
        consistent, change, float(z_solved @ np.linalg.solve(block, z_solved)),
        {body.name: float(np.linalg.eigvalsh(body.pseudo_inertia(consistent))[0])
         for body in bodies}, solver or default_solver(), status)


def _projection(values, std, correlation, solved, bodies, bounded, solver):
    """Changes z (standard errors) of ``solved`` minimising z^T C^-1 z under the constraints, and status."""
    cp = require_cvxpy()
    eigenvalues, vectors = np.linalg.eigh(correlation)
    eigenvalues = np.maximum(eigenvalues, eigenvalues[-1] * 1e-15)
    root = (vectors / np.sqrt(eigenvalues)) @ vectors.T  # C^(-1/2)
    D = np.zeros((len(values), len(solved)))  # p = values + D z
    D[solved, np.arange(len(solved))] = std[solved]
    z = cp.Variable(len(solved))
    units = pseudo_inertia(np.eye(len(BODY_PARAMETERS))).reshape(len(BODY_PARAMETERS), 16).T
    constraints = []
    for body in bodies:  # in units of the body's mass scale, so that tolerances are relative
        linear = units @ body.mapping @ D / body.mass_scale
        constant = units @ (body.mapping @ values + body.offset) / body.mass_scale
        J = cp.reshape(linear @ z + constant, (4, 4), order="C")
        mass = body.mapping[0] @ values + body.offset[0]
        constraints += [(J + J.T) / 2 >> 0, body.mapping[0] @ D @ z / body.mass_scale
                        >= STRICT_FRACTION - mass / body.mass_scale]
    lower = bounded[solved]
    if lower.any():
        index = solved[lower]
        constraints.append(z[np.flatnonzero(lower)] >= -values[index] / std[index])
    problem = cp.Problem(cp.Minimize(cp.sum_squares(root @ z)), constraints)
    _, status = solve_convex(problem, solver,
                             "check the parameters fixed at the platform file's values")
    return np.asarray(z.value, dtype=float), status


__all__ = ["Body", "ConsistentParameters", "DEAD_COLUMN", "Solution", "nearest_consistent",
           "score_covariance", "solve_parameters"]
