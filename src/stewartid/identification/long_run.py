"""Covariance of an estimate from correlated residuals: sandwiches A^-1 B A^-1 whose B is the
long-run covariance of the rows' scores or their sum per record, and the more cautious of two.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import scipy.ndimage


def with_variances(covariance: np.ndarray, variances: np.ndarray) -> np.ndarray:
    """``covariance`` with its variances replaced by ``variances``, its correlations kept.

    A variance of zero takes its new value with no correlation.

    Parameters
    ----------
    covariance : ndarray, shape (n, n)
    variances : ndarray, shape (n,)
        Nonnegative.

    Returns
    -------
    ndarray, shape (n, n)
    """
    own = np.sqrt(np.clip(np.diag(covariance), 0.0, None))
    target = np.sqrt(np.clip(variances, 0.0, None))
    factor = np.where(own > 0, target / np.where(own > 0, own, 1.0), 1.0)
    out = covariance * np.outer(factor, factor)
    return out + np.diag(np.where(own > 0, 0.0, target ** 2))


def with_larger_variances(covariance: np.ndarray, other: np.ndarray) -> np.ndarray:
    """``covariance`` with each variance raised to ``other``'s where larger, correlations kept.

    Parameters
    ----------
    covariance, other : ndarray, shape (n, n)

    Returns
    -------
    ndarray, shape (n, n)
    """
    return with_variances(covariance, np.maximum(np.diag(covariance), np.diag(other)))


def long_run_covariance(scores: np.ndarray, segments: Sequence[tuple[int, int]],
                        stride: int = 1, psd: bool = True) -> np.ndarray:
    """Covariance of the sum of a series of score vectors, for a sandwich A^-1 B A^-1.

    The scores' autocovariances summed with uniform weights over every lag below each record's
    correlation length (filtered white noise is correlated over the filter's support only), no
    lag crossing two records.

    Parameters
    ----------
    scores : ndarray, shape (K, n)
        Per row, the gradient of its weighted squared residual in the unknowns.
    segments : sequence of (int, int)
        Rows of each record (summing to K) and its correlation length L (rows): rows L or
        more apart are uncorrelated.
    stride : int
        Take the outer products at every ``stride``-th row only, times ``stride`` (cheaper for
        slowly varying scores).
    psd : bool
        Set the negative eigenvalues to zero (:func:`nearest_psd`); else the symmetrized sum,
        whose diagonal stays unbiased.

    Returns
    -------
    ndarray, shape (n, n)
    """
    B = np.zeros((scores.shape[1],) * 2)
    start = 0
    for rows, length in segments:
        part = scores[start:start + rows]
        start += rows
        reach = int(min(max(length - 1, 0), rows - 1))
        cumulative = np.concatenate([np.zeros((1, part.shape[1])), np.cumsum(part, axis=0)])
        k = np.arange(0, rows, stride)
        window = (cumulative[np.minimum(k + reach + 1, rows)]
                  - cumulative[np.maximum(k - reach, 0)])
        B += (part[k].T @ window) * (rows / len(k))
    B = 0.5 * (B + B.T)
    return nearest_psd(B) if psd else B


def filtered_noise_covariance(X: np.ndarray, weights: np.ndarray,
                              segments: Sequence[tuple[int, int]],
                              noises: Sequence[tuple[np.ndarray, np.ndarray]]) -> np.ndarray:
    """B = Cov(sum_k s_k) for scores s_k = sum_c w_c X_kc e_kc whose e is a known filtered noise.

    Cov(e_k, e_j) = S rho(|k - j|) over the rows of one record and 0 across records. It
    estimates nothing from the residual, so it does not scatter between realisations.

    Parameters
    ----------
    X : ndarray, shape (K, c, n)
    weights : ndarray, shape (c,)
    segments : sequence of (int, int)
        Rows of each record (summing to K); the second item is not used.
    noises : sequence of (ndarray, ndarray)
        Per record, S (c, c) and rho (L,): the filter's autocorrelation at lags of 0, 1, ...
        rows (rho[0] the filtered noise's variance per unit S).

    Returns
    -------
    ndarray, shape (n, n)
    """
    Z = X * weights[None, :, None]
    B = np.zeros((X.shape[2],) * 2)
    start = 0
    for (rows, _), (S, rho) in zip(segments, noises, strict=True):
        part = Z[start:start + rows]
        start += rows
        # sum_j rho(|k - j|) Z_j: one symmetric convolution along the rows, zero outside
        near = rho[:rows]
        taps = np.concatenate([near[:0:-1], near])
        smeared = scipy.ndimage.convolve1d(part, taps, axis=0, mode="constant")
        B += np.einsum("kcp,cd,kdq->pq", part, S, smeared, optimize=True)
    return B


def nearest_psd(matrix: np.ndarray) -> np.ndarray:
    """A symmetric matrix with its negative eigenvalues set to zero.

    Clipping raises the diagonal of a long-run sum whose value is a small remainder of large
    autocovariances of either sign.
    """
    values, vectors = np.linalg.eigh(matrix)
    return (vectors * np.clip(values, 0.0, None)) @ vectors.T


def score_sandwich(inverse: np.ndarray, scores: np.ndarray,
                   segments: Sequence[tuple[int, int]], basis: np.ndarray | None = None,
                   psd: bool | str = True) -> np.ndarray:
    """The covariance A^-1 B A^-1 of an estimate, B the :func:`long_run_covariance` of its rows' scores.

    The outer products are taken a sixteenth of the shortest correlation length apart.

    Parameters
    ----------
    inverse : ndarray, shape (m, m)
        A^-1, in the unknowns the estimate is solved for.
    scores : ndarray, shape (K, n)
        Per row, the gradient of its weighted squared residual (n = m, or in the unknowns
        ``basis`` maps from).
    segments : sequence of (int, int)
        Rows of each record and its correlation length (rows).
    basis : ndarray, shape (n, m), optional
        Maps the solved unknowns to the scores' (B becomes basis^T B basis).
    psd : bool or "variances"
        B with its negative eigenvalues set to zero, or not; ``"variances"``: the correlations
        of the clipped B and the variances of the unclipped one (the clipped where negative).

    Returns
    -------
    ndarray, shape (m, m)
    """
    stride = max(1, min(length for _, length in segments) // 16)
    raw = long_run_covariance(scores, segments, stride, psd=False)
    B = nearest_psd(raw) if psd else raw
    if basis is not None:
        B = basis.T @ B @ basis
    covariance = inverse @ B @ inverse
    if psd != "variances":
        return covariance
    if basis is not None:
        raw = basis.T @ raw @ basis
    # a variance whose estimate came out negative has nothing better than the clipped
    unbiased = np.diag(inverse @ raw @ inverse)
    return with_variances(covariance, np.where(unbiased > 0, unbiased, np.diag(covariance)))


def record_sandwich(inverse: np.ndarray, scores: np.ndarray,
                    segments: Sequence[tuple[int, int]], expected: np.ndarray | None = None
                    ) -> np.ndarray:
    """The covariance A^-1 B A^-1 with the records as independent clusters.

    B is the sum over the R records of the outer product of their summed scores (less each
    record's expected sum), times R / (R - 1). It sees model error correlated with the motion
    over a whole record, which short-lag autocovariances do not.

    Parameters
    ----------
    inverse : ndarray, shape (m, m)
    scores : ndarray, shape (K, m)
    segments : sequence of (int, int)
        Rows of each record (summing to K) and its correlation length (unused here).
    expected : ndarray, shape (R, m), optional
        Each record's expected summed score under noise alone (its errors-in-variables
        correction); by default the total shared out by rows.

    Returns
    -------
    ndarray, shape (m, m)
    """
    rows = np.array([n for n, _ in segments])
    ends = np.cumsum([0, *rows])
    sums = np.add.reduceat(scores, ends[:-1], axis=0)
    # less what noise alone gives each record, which a corrected estimate leaves nonzero
    if expected is None:
        expected = np.outer(rows / rows.sum(), sums.sum(axis=0))
    sums = sums - expected
    records = len(sums)
    B = sums.T @ sums * records / max(records - 1, 1)
    return inverse @ B @ inverse


__all__ = ["filtered_noise_covariance", "long_run_covariance", "nearest_psd", "record_sandwich",
           "score_sandwich", "with_larger_variances", "with_variances"]
