"""What a result's standard errors predict about its accuracy over a set of entries of Mt
and Bt, alone or conditioned on other methods' estimates of the same data."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from stewartid.identification.quantiles import normal_cdf
from stewartid.identification.result import IdentificationResult
from stewartid.reference.published import PAPER_ENTRIES, EntryKey


def entry_estimate(result: IdentificationResult, matrix: str, i: int, j: int
                   ) -> tuple[float, float]:
    """Estimate and standard error of entry (i, j) of ``matrix`` ("M" or "B")."""
    if matrix == "M":
        return float(result.M[i, j]), float(result.std_errors_M[i, j])
    return float(result.B[i, j]), float(result.std_errors_B[i, j])


def entry_relative_std(result: IdentificationResult,
                       entries: Sequence[EntryKey] = PAPER_ENTRIES) -> np.ndarray:
    """Relative standard error of each of ``entries`` (fractions), in their order; infinite
    for a zero estimate."""
    out = []
    for key in entries:
        value, std = entry_estimate(result, *key)
        out.append(std / abs(value) if value != 0 else np.inf)
    values = np.array(out, dtype=float)
    return np.where(np.isnan(values), np.inf, values)


def relative_std(result: IdentificationResult) -> float:
    """Median relative standard error of the diagonals of Mt and Bt (a fraction)."""
    values = np.concatenate([np.diag(result.std_errors_M) / np.abs(np.diag(result.M)),
                             np.diag(result.std_errors_B) / np.abs(np.diag(result.B))])
    return float(np.nanmedian(values))


def expected_worst_error(relative_std: np.ndarray, mean: np.ndarray | None = None) -> float:
    """Expected largest |error| of independent Gaussian errors N(mean_k, s_k^2).

    E[max_k |e_k|] = integral over x > 0 of 1 - prod_k P(|e_k| <= x), where
    P(|e_k| <= x) = Phi((x - m_k) / s_k) - Phi((-x - m_k) / s_k) (a step at |m_k| for
    s_k = 0), on a grid of 4000 steps up to the largest |m_k| + 8 s_k (the tail beyond holds
    less than 1e-14 of it).

    Parameters
    ----------
    relative_std : ndarray, shape (K,)
        Standard errors (any unit; non-finite ones make the result infinite).
    mean : ndarray, shape (K,), optional
        The errors' means, in the same unit (zero by default).

    Returns
    -------
    float
        In the unit of ``relative_std``.
    """
    s = np.asarray(relative_std, dtype=float)
    m = np.zeros_like(s) if mean is None else np.abs(np.asarray(mean, dtype=float))
    if not (np.all(np.isfinite(s)) and np.all(np.isfinite(m))):
        return float("inf")
    keep = (s > 0) | (m > 0)
    s, m = s[keep], m[keep]
    if s.size == 0:
        return 0.0
    x = np.linspace(0.0, float(np.max(m + 8.0 * s)), 4001)[:, None]
    scale = np.where(s > 0, s, 1.0)
    within = np.where(s > 0, normal_cdf((x - m) / scale) - normal_cdf((-x - m) / scale), x >= m)
    return float(np.trapezoid(1.0 - np.prod(within, axis=1), x[:, 0]))


def symmetric_members(result: IdentificationResult, matrix: str, i: int, j: int
                      ) -> list[tuple[float, float]]:
    """The distinct estimates (value, standard error) of entry (i, j) of ``matrix`` and of its
    symmetric partner (j, i): one where they are the same (a diagonal entry, a fit that
    estimates one parameter for both, or keeps one member of the pair), none without a
    finite value and a positive, finite standard error."""
    found: list[tuple[float, float]] = []
    for a, b in ((i, j), (j, i)):
        value, std = entry_estimate(result, matrix, a, b)
        if np.isfinite(value) and np.isfinite(std) and std > 0 and (value, std) not in found:
            found.append((value, std))
    return found


def pooled(estimates: Sequence[tuple[float, float]]) -> tuple[float, float]:
    """Inverse-variance mean of independent estimates (value, standard error) and its
    variance."""
    weights = np.array([std ** -2.0 for _, std in estimates])
    variance = 1.0 / float(weights.sum())
    return variance * float(weights @ np.array([value for value, _ in estimates])), variance


def error_posterior(result: IdentificationResult, others: Sequence[IdentificationResult],
                    entries: Sequence[EntryKey] = PAPER_ENTRIES
                    ) -> tuple[np.ndarray, np.ndarray]:
    """This result's error on each of ``entries``, given other estimates of the same
    quantities: the Gaussian posterior of its error conditioned on them.

    Entry (i, j) is estimated by every other fit (its members (i, j) and (j, i) pooled) and by
    this result's own partner (j, i) where that differs. With independent, unbiased Gaussian
    errors at their standard errors, the error e given the differences d is Gaussian with mean
    c' V^-1 d and variance s^2 - c' V^-1 c (c = Cov(e, d) = s^2 1, V = Cov(d) =
    s^2 1 1' + diag(s_p^2)).

    Returns
    -------
    mean, std : ndarray, shape (len(entries),)
        The error's posterior mean and standard deviation relative to the estimate
        (fractions); (0, :func:`entry_relative_std`) where nothing else estimates the entry.
    """
    std = entry_relative_std(result, entries)
    mean = np.zeros_like(std)
    for k, (matrix, i, j) in enumerate(entries):
        value, own = entry_estimate(result, matrix, i, j)
        if not (value != 0 and np.isfinite(value) and np.isfinite(own) and own > 0):
            continue
        estimates = []
        for other in others:
            found = symmetric_members(other, matrix, i, j)
            if found:
                centre, variance = pooled(found)
                estimates.append((centre, np.sqrt(variance)))
        estimates += [(v, s) for v, s in symmetric_members(result, matrix, i, j)
                      if (v, s) != (value, own)]
        if not estimates:
            continue
        with_d = np.full(len(estimates), own ** 2)
        of_d = own ** 2 + np.diag(np.array([s for _, s in estimates]) ** 2)
        weights = np.linalg.pinv(of_d, hermitian=True) @ with_d
        differences = value - np.array([v for v, _ in estimates])
        mean[k] = float(weights @ differences) / abs(value)
        std[k] = np.sqrt(max(own ** 2 - float(with_d @ weights), 0.0)) / abs(value)
    return mean, std


def predicted_worst_error(result: IdentificationResult) -> float:
    """The largest relative error over the paper's 20 entries that the result's own standard
    errors predict (:func:`expected_worst_error` of :func:`entry_relative_std`, a fraction)."""
    return expected_worst_error(entry_relative_std(result))


__all__ = ["entry_estimate", "entry_relative_std", "error_posterior",
           "expected_worst_error", "pooled", "predicted_worst_error",
           "relative_std", "symmetric_members"]
