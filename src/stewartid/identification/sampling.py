"""Whether a result is limited by its log's sampling rather than by its noise.

Residual-based standard errors miss what the sampling leaves (integration step,
differentiation at the log's rate). The log is fitted again at half its rate; when the
standard errors grow faster than noise makes them (:data:`RATIO_LIMIT`) or the estimate moves
more than noise can (:data:`SHIFT_LIMIT`), it is also fitted at a third and a quarter of its
rate, and each entry's largest change is added to its standard error in quadrature.
"""

from __future__ import annotations

import dataclasses
import warnings
from collections.abc import Callable, Sequence
from typing import Any

import numpy as np

from stewartid.datasets.dataset import MIN_SAMPLES, Dataset
from stewartid.errors import StewartidError
from stewartid.identification.result import IdentificationResult

#: Thinning factors: the first decides whether the others are fitted.
FACTORS = (2, 3, 4)

#: Median ratio of the standard errors at half the rate to those at the full rate above which
#: the residual counts as the sampling's (noise: about sqrt(2); a sampling error of order p:
#: 2**p).
RATIO_LIMIT = 2.5

#: Largest change of a diagonal entry at half the rate, in its half-rate standard errors,
#: that noise explains.
SHIFT_LIMIT = 10.0


def thinned(dataset: Dataset, factor: int) -> Dataset:
    """Every ``factor``-th sample of an experiment, from the first.

    Parameters
    ----------
    dataset : Dataset
        N samples at rate fs.
    factor : int
        Thinning factor k >= 1.

    Returns
    -------
    Dataset
        ceil(N / k) samples at fs / k, same name.
    """
    rows = slice(0, None, factor)
    return Dataset(dataset.t[rows], dataset.pose[rows], dataset.lengths[rows],
                   dataset.forces[rows], dataset.name)


def _diagonals(result: IdentificationResult) -> tuple[np.ndarray, np.ndarray]:
    """The diagonals of Mt and Bt and their standard errors, shape (12,) each."""
    return (np.concatenate([np.diag(result.M), np.diag(result.B)]),
            np.concatenate([np.diag(result.std_errors_M), np.diag(result.std_errors_B)]))


def _compare(result: IdentificationResult, half: IdentificationResult) -> tuple[float, float]:
    """Median over the diagonals of the half-rate standard error over the full-rate one,
    and the largest change of a diagonal entry in its half-rate standard errors."""
    (value, std), (other, other_std) = _diagonals(result), _diagonals(half)
    usable = np.isfinite(std) & np.isfinite(other_std) & (std > 0) & (other_std > 0)
    if not usable.any():
        return float("nan"), float("nan")
    return (float(np.median(other_std[usable] / std[usable])),
            float(np.max(np.abs(value - other)[usable] / other_std[usable])))


def _fit_quietly(fit: Callable[[list[Dataset]], IdentificationResult],
                 datasets: Sequence[Dataset], factor: int
                 ) -> IdentificationResult | str:
    """The fit of the thinned log, or why it failed (one line)."""
    if min(len(d) for d in datasets) // factor < MIN_SAMPLES:
        return f"fewer than {MIN_SAMPLES} samples at 1/{factor} of the rate"
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the full-rate fit has warned about these data
        try:
            return fit([thinned(d, factor) for d in datasets])
        except StewartidError as error:
            return str(error).splitlines()[0]


def thinned_fits(fit: Callable[[list[Dataset]], IdentificationResult],
                 datasets: Sequence[Dataset], result: IdentificationResult
                 ) -> tuple[dict[str, Any], list[IdentificationResult]]:
    """Whether ``result`` is limited by the sampling, and the thinned fits that say by how much.

    Parameters
    ----------
    fit, datasets, result
        As :func:`check_sampling`.

    Returns
    -------
    summary : dict
        ``limited``, ``std_ratio``, ``shift``, ``factors`` (or ``reason``), as
        :func:`check_sampling` reports them.
    fits : list of IdentificationResult
        The fits at 1/2, 1/3, 1/4 of the rate that succeeded when limited; else empty.
    """
    half = _fit_quietly(fit, datasets, FACTORS[0])
    if isinstance(half, str):
        return {"limited": False, "reason": half}, []
    ratio, shift = _compare(result, half)
    summary = {"std_ratio": ratio, "shift": shift}
    if not (ratio > RATIO_LIMIT or shift > SHIFT_LIMIT):
        return {"limited": False, **summary, "factors": [FACTORS[0]]}, []
    fits = {FACTORS[0]: half}
    for factor in FACTORS[1:]:
        other = _fit_quietly(fit, datasets, factor)
        if not isinstance(other, str):
            fits[factor] = other
    return {"limited": True, **summary, "factors": sorted(fits)}, list(fits.values())


def check_sampling(fit: Callable[[list[Dataset]], IdentificationResult],
                   datasets: Sequence[Dataset], result: IdentificationResult
                   ) -> IdentificationResult:
    """The result, its standard errors widened where the log's sampling limits it.

    Parameters
    ----------
    fit : callable
        Fits a list of experiments with the method's settings and returns its result.
    datasets : sequence of Dataset
        The experiments ``result`` was fitted on.
    result : IdentificationResult
        The full-rate fit.

    Returns
    -------
    IdentificationResult
        ``result`` with ``diagnostics["sampling"]``: ``std_ratio`` (the median ratio over
        the diagonals of the half-rate standard errors to these), ``shift`` (the largest
        change of a diagonal entry at half the rate, in its half-rate standard errors),
        ``limited`` (either above its limit, :data:`RATIO_LIMIT`, :data:`SHIFT_LIMIT`),
        ``factors`` fitted, and when limited ``spread_M``/``spread_B`` (6, 6) (each
        entry's largest change over the thinned fits, added to its standard error in
        quadrature); ``reason`` instead when the half-rate fit was not possible.
    """
    summary, fits = thinned_fits(fit, datasets, result)
    if fits:
        spread_M = np.nan_to_num(np.max([np.abs(result.M - f.M) for f in fits], axis=0))
        spread_B = np.nan_to_num(np.max([np.abs(result.B - f.B) for f in fits], axis=0))
        summary = {**summary, "spread_M": spread_M, "spread_B": spread_B}
        result = dataclasses.replace(result,
                                     std_errors_M=np.hypot(result.std_errors_M, spread_M),
                                     std_errors_B=np.hypot(result.std_errors_B, spread_B))
    return dataclasses.replace(result, diagnostics={**result.diagnostics, "sampling": summary})


__all__ = ["FACTORS", "RATIO_LIMIT", "SHIFT_LIMIT", "check_sampling", "thinned",
           "thinned_fits"]
