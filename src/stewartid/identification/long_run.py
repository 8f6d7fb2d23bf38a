"""Sandwich covariances A^-1 B A^-1 of estimates from correlated residuals."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np


def with_variances(covariance: np.ndarray, variances: np.ndarray) -> np.ndarray:
    """``covariance`` with its variances replaced by ``variances``, correlations kept."""
    own = np.sqrt(np.clip(np.diag(covariance), 0.0, None))
    target = np.sqrt(np.clip(variances, 0.0, None))
    factor = np.where(own > 0, target / np.where(own > 0, own, 1.0), 1.0)
    out = covariance * np.outer(factor, factor)
    return out + np.diag(np.where(own > 0, 0.0, target ** 2))


def with_larger_variances(covariance: np.ndarray, other: np.ndarray) -> np.ndarray:
    """``covariance`` with each variance raised to ``other``'s where larger, correlations kept."""
    return with_variances(covariance, np.maximum(np.diag(covariance), np.diag(other)))


def long_run_covariance(scores: np.ndarray, segments: Sequence[tuple[int, int]],
                        stride: int = 1, psd: bool = True) -> np.ndarray:
    """Covariance B (n, n) of the sum of score vectors ``scores`` (K, n), lags within records.

    Autocovariances summed uniformly over lags below each record's correlation length; ``segments``:
    (rows, correlation length) per record; ``stride``: outer products every stride-th row, times stride;
    ``psd``: clip negative eigenvalues (:func:`nearest_psd`).
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
    """B = Cov(sum_k s_k), s_k = sum_c w_c X_kc e_kc, for a known filtered noise e; (n, n).

    Cov(e_k, e_j) = S rho(|k - j|) within a record, 0 across; ``noises``: per record (S (c, c), rho (L,)).
    """
    Z = X * weights[None, :, None]
    B = np.zeros((X.shape[2],) * 2)
    start = 0
    for (rows, _), (S, rho) in zip(segments, noises, strict=True):
        part = Z[start:start + rows]
        start += rows
        B += np.einsum("kcp,cd,kdq->pq", part, S, _smeared(part, rho[:rows]), optimize=True)
    return B


def _smeared(part: np.ndarray, near: np.ndarray) -> np.ndarray:
    """sum_j rho(|k - j|) part_j (K, ...) with ``near`` rho(0), rho(1), ... (at most K lags):
    a symmetric convolution along the rows, zero outside, a few lags long (numpy: scipy.ndimage
    costs more to import than this to run)."""
    smeared = near[0] * part
    for lag in range(1, len(near)):
        smeared[lag:] += near[lag] * part[:-lag]
        smeared[:-lag] += near[lag] * part[lag:]
    return smeared


def nearest_psd(matrix: np.ndarray) -> np.ndarray:
    """A symmetric matrix with its negative eigenvalues set to zero."""
    values, vectors = np.linalg.eigh(matrix)
    return (vectors * np.clip(values, 0.0, None)) @ vectors.T


def score_sandwich(inverse: np.ndarray, scores: np.ndarray,
                   segments: Sequence[tuple[int, int]], basis: np.ndarray | None = None,
                   psd: bool | str = True) -> np.ndarray:
    """A^-1 B A^-1 (m, m), B the :func:`long_run_covariance` of the rows' scores.

    ``basis`` (n, m) maps solved unknowns to the scores'. ``psd``: clip B, or ``"variances"`` to take
    the clipped correlations and the unclipped variances.
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
    """A^-1 B A^-1 with the records as independent clusters.

    B = R / (R - 1) sum_r (summed scores - ``expected``)(...)^T: sees model error correlated with the
    motion over a whole record.
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
