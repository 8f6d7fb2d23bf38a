"""What a result's standard errors predict about its accuracy over the paper's 20 entries.

Used to choose between fits of the same data (Method B's friction model, the verdict between
methods): the one whose calibrated standard errors predict the smaller largest error.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from stewartid.identification.result import IdentificationResult
from stewartid.reference.published import PAPER_ENTRIES


def entry_estimate(result: IdentificationResult, matrix: str, i: int, j: int
                   ) -> tuple[float, float]:
    """Estimate and standard error of entry (i, j) of ``matrix`` ("M" or "B")."""
    if matrix == "M":
        return float(result.M[i, j]), float(result.std_errors_M[i, j])
    return float(result.B[i, j]), float(result.std_errors_B[i, j])


def entry_relative_std(result: IdentificationResult) -> np.ndarray:
    """Relative standard error of each of the paper's 20 entries (fractions), in the order
    of :data:`~stewartid.reference.published.PAPER_ENTRIES`; infinite for a zero estimate."""
    out = []
    for key in PAPER_ENTRIES:
        value, std = entry_estimate(result, *key)
        out.append(std / abs(value) if value != 0 else np.inf)
    values = np.array(out, dtype=float)
    return np.where(np.isnan(values), np.inf, values)


def expected_worst_error(relative_std: np.ndarray) -> float:
    """Expected largest |error| of independent Gaussian errors with these standard errors.

    E[max_k |e_k|] = integral over x > 0 of 1 - prod_k (2 Phi(x / s_k) - 1), on a grid of
    4000 steps up to 8 times the largest s_k (the tail beyond holds less than 1e-14 of it).

    Parameters
    ----------
    relative_std : ndarray, shape (K,)
        Standard errors (any unit; non-finite ones make the result infinite).

    Returns
    -------
    float
        In the unit of ``relative_std``.
    """
    from scipy.special import erf

    s = np.asarray(relative_std, dtype=float)
    if not np.all(np.isfinite(s)):
        return float("inf")
    s = s[s > 0]
    if s.size == 0:
        return 0.0
    x = np.linspace(0.0, 8.0 * s.max(), 4001)
    below = np.prod(erf(x[:, None] / (np.sqrt(2.0) * s[None, :])), axis=1)
    return float(np.trapezoid(1.0 - below, x))


#: Another method's estimate of an entry at least this many times more precise than this
#: method's measures this method's error there (their difference, to within a fifth of this
#: method's own standard error).
PRECISION_FACTOR = 5.0


def cross_checked_relative_std(result: IdentificationResult,
                               others: Sequence[IdentificationResult]
                               ) -> tuple[np.ndarray, list[int]]:
    """Relative error scale of each of the paper's 20 entries, where other fits of the same
    data measure it.

    Where another result estimates the entry (or its symmetric partner: Mt and Bt are
    symmetric) with a standard error s_o at most 1 / :data:`PRECISION_FACTOR` of this
    result's s, this result's error there is its difference d from that estimate, known to
    within s_o: the scale is sqrt(d^2 + s_o^2) (the least over such results) instead of s.
    An estimate without a positive, finite standard error measures nothing.
    A standard error widened for model error (a symmetric pair whose members disagree, a
    log limited by its sampling) covers a bias the data cannot place; a more precise fit that
    agrees shows it absent, and one that disagrees shows it present.

    Parameters
    ----------
    result : IdentificationResult
    others : sequence of IdentificationResult
        Other methods' fits of the same data.

    Returns
    -------
    relative : ndarray, shape (20,)
        Fractions, in the order of :data:`~stewartid.reference.published.PAPER_ENTRIES`
        (as :func:`entry_relative_std` where no other result is precise enough).
    measured : list of int
        Indices of the entries whose scale another result measured.
    """
    relative = entry_relative_std(result)
    measured = []
    for k, (matrix, i, j) in enumerate(PAPER_ENTRIES):
        value, std = entry_estimate(result, matrix, i, j)
        scales = [float(np.hypot(v - value, s)) for other in others
                  for v, s in {entry_estimate(other, matrix, i, j),
                               entry_estimate(other, matrix, j, i)}
                  if 0 < PRECISION_FACTOR * s <= std and np.isfinite(v)]
        if scales and value != 0:
            relative[k] = min(scales) / abs(value)
            measured.append(k)
    return relative, measured


def predicted_worst_error(result: IdentificationResult) -> float:
    """The largest relative error over the paper's 20 entries that the result's standard
    errors predict (:func:`expected_worst_error` of :func:`entry_relative_std`, a fraction)."""
    return expected_worst_error(entry_relative_std(result))


__all__ = ["PRECISION_FACTOR", "cross_checked_relative_std", "entry_estimate",
           "entry_relative_std", "expected_worst_error", "predicted_worst_error"]
