"""Weighted least squares of physical parameters, the ones the data cannot tell fixed at known
values: the solver of :mod:`stewartid.identification.physical`.

Channels (forces and moments, in different units) are weighted by their residual variance
(feasible generalized least squares); the standard errors allow for the residual's
autocorrelation (filtered signals) as
:func:`~stewartid.identification.solvers.solve_least_squares` with ``autocorrelated`` does.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from stewartid.identification.solvers import integrated_autocorrelation

#: Weighted column norm, relative to the largest, below which a parameter counts as not
#: excited (round-off of a column that is zero in exact arithmetic).
DEAD_COLUMN = 1e-10


@dataclass(frozen=True)
class Solution:
    """Weighted least squares with unidentifiable parameters fixed (:func:`solve_parameters`).

    Attributes
    ----------
    values : ndarray, shape (p,)
        Every parameter: estimated, or fixed at its nominal value.
    covariance : ndarray, shape (p, p)
        Zero in the rows and columns of the fixed ones.
    fixed : dict of str to str
        Fixed parameters and why.
    condition_number : float
        Of the column-equilibrated, channel-weighted regression of the estimated ones.
    singular_values : ndarray
        Its singular values (relative to the largest), every parameter included.
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
    """Equilibrated weighted least squares from the per-channel Gram matrices ``gram``
    (6, p, p) and ``cross`` (6, p) = X_c^T y_c, the parameters outside ``free`` held at
    ``fixed_values``: the estimates of the free ones, the inverse of their normal matrix (in
    the original units), the singular values of the scaled regression relative to the
    largest and its right singular vectors (rows)."""
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
                     max_relative_error: float = 0.3) -> Solution:
    """Weighted least squares for y = X theta with residual-autocorrelation-consistent
    standard errors, fixing at ``nominal`` what the data cannot tell.

    Channels are weighted by their residual variance from a first, RMS-weighted pass
    (feasible generalized least squares). A parameter is fixed when the column-equilibrated
    regression's condition number exceeds ``max_condition`` (the one weighing most in the
    weakest direction, repeatedly) or, for a parameter whose value is positive by nature,
    when its standard error exceeds ``max_relative_error`` of its size (the larger of its
    estimate and its scale).

    Parameters
    ----------
    X : ndarray, shape (K, 6, p)
    y : ndarray, shape (K, 6)
    names : list of str
    nominal : ndarray, shape (p,)
        The values a fixed parameter keeps (the platform file's).
    scales : ndarray, shape (p,), optional
        The size of each parameter positive by nature (a mass, an inertia: the moving
        body's, for a payload's), zero for the others, which no relative error applies to.
    max_condition, max_relative_error : float

    Returns
    -------
    Solution
    """
    p = X.shape[2]
    scales = np.zeros(p) if scales is None else np.asarray(scales, dtype=float)
    scale_y = np.sqrt(np.mean(y ** 2, axis=0))
    weights = 1.0 / np.where(scale_y > 0, scale_y, 1.0) ** 2
    by_channel = np.ascontiguousarray(X.transpose(1, 0, 2))  # (6, K, p): BLAS products
    gram = np.swapaxes(by_channel, 1, 2) @ by_channel
    cross = np.einsum("ckp,kc->cp", by_channel, y, optimize=True)
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
        sigma = np.sqrt(np.sum(residual ** 2, axis=0) / len(y))
        weights = 1.0 / np.maximum(sigma, 1e-12 * scale_y) ** 2
    covariance = np.zeros((p, p))
    covariance[np.ix_(free, free)] = inverse * variance
    return Solution(values, covariance, fixed, condition, singular_all,
                    np.sqrt(np.mean(residual ** 2, axis=0)), len(y))


__all__ = ["DEAD_COLUMN", "Solution", "solve_parameters"]
