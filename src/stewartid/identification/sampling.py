"""Whether a result is limited by its log's sampling rather than by its noise.

Refit at 1/2 (then 1/3, 1/4) of the rate; each entry's largest change adds to its standard error.
"""

from __future__ import annotations

import dataclasses
import warnings
from collections.abc import Callable, Sequence
from typing import Any

import numpy as np

from stewartid.arrays import median
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


#: Samples per period of the fastest excitation from which the refits are skipped: with the
#: model floor (:func:`~stewartid.identification.result.with_model_floor`) they change no
#: coverage there (docs/benchmarks.md, "Sampling check").
SAMPLES_PER_PERIOD = 400

#: Share of the pose's variance below the fastest excitation frequency (:func:`fastest_frequency`).
VARIANCE_SHARE = 0.999


def fastest_frequency(dataset: Dataset) -> float:
    """Frequency (Hz) below which :data:`VARIANCE_SHARE` of the legs' length variance lies (all six
    together: one unit, and the sensor noise's share is negligible); once per record."""
    def compute(record: Dataset) -> float:
        centered = record.lengths - record.lengths.mean(axis=0)
        power = np.sum(np.abs(np.fft.rfft(centered, axis=0)) ** 2, axis=1)
        power[0] = 0.0
        if not power.sum() > 0:
            return 0.0
        share = np.cumsum(power) / power.sum()
        return float(np.argmax(share >= VARIANCE_SHARE) * record.sample_rate / len(record))

    return dataset.derived(("fastest frequency",), compute)


def samples_per_period(datasets: Sequence[Dataset]) -> float:
    """The fewest samples per period of the fastest excitation (:func:`fastest_frequency`) of the
    experiments; 0 when a record does not move (nothing to tell by)."""
    return min(d.sample_rate / f if (f := fastest_frequency(d)) > 0 else 0.0
               for d in datasets)


def thinned(dataset: Dataset, factor: int) -> Dataset:
    """Every ``factor``-th sample of an experiment, from the first (same name, rate / factor);
    one copy per record, which every method's check shares."""
    return dataset.derived(("thinned", factor),
                           lambda record: record.part(slice(0, None, factor)))


def _diagonals(result: IdentificationResult) -> tuple[np.ndarray, np.ndarray]:
    return (np.concatenate([np.diag(result.M), np.diag(result.B)]),
            np.concatenate([np.diag(result.std_errors_M), np.diag(result.std_errors_B)]))


def _compare(result: IdentificationResult, half: IdentificationResult) -> tuple[float, float]:
    """Median half-rate / full-rate standard error over the diagonals, and the largest shift in them."""
    (value, std), (other, other_std) = _diagonals(result), _diagonals(half)
    usable = np.isfinite(std) & np.isfinite(other_std) & (std > 0) & (other_std > 0)
    if not usable.any():
        return float("nan"), float("nan")
    return (median(other_std[usable] / std[usable]),
            float(np.max(np.abs(value - other)[usable] / other_std[usable])))


def _fit_quietly(fit: Callable[[list[Dataset]], IdentificationResult],
                 datasets: Sequence[Dataset], factor: int
                 ) -> IdentificationResult | str:
    """The fit of the thinned log, or why it failed."""
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
    """The sampling summary of :func:`check_sampling` and the thinned fits that succeeded when limited.

    No refit where every experiment has :data:`SAMPLES_PER_PERIOD` samples per period of its fastest
    excitation.
    """
    margin = samples_per_period(datasets)
    if margin >= SAMPLES_PER_PERIOD:
        return {"limited": False, "samples_per_period": margin,
                "reason": f"{margin:.0f} samples per period of the fastest excitation: no refit "
                          f"below {SAMPLES_PER_PERIOD}"}, []
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

    ``fit`` fits a list of experiments with the method's settings. Adds ``diagnostics["sampling"]``:
    ``std_ratio``, ``shift``, ``limited`` (above :data:`RATIO_LIMIT` or :data:`SHIFT_LIMIT`), ``factors``,
    ``spread_M``/``spread_B`` when limited, or ``reason`` (and ``samples_per_period`` where the
    rate leaves a wide margin).
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


__all__ = ["FACTORS", "RATIO_LIMIT", "SAMPLES_PER_PERIOD", "SHIFT_LIMIT", "VARIANCE_SHARE",
           "check_sampling", "fastest_frequency", "samples_per_period", "thinned", "thinned_fits"]
