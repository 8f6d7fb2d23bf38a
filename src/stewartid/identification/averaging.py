"""Records sampled well above what the identification needs, averaged down to a lower rate before
any method sees them (:meth:`~stewartid.datasets.dataset.Dataset.averaged`), on request: a 2 kHz
log then costs about a 1 kHz log's time and memory (docs/benchmarks.md, "Averaged fast logs",
for where the estimates stay within noise of the full rate's and where they do not)."""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

from stewartid.datasets.dataset import MIN_SAMPLES, Dataset
from stewartid.errors import ConfigError
from stewartid.identification.sampling import SAMPLES_PER_PERIOD, samples_per_period


@dataclass(frozen=True)
class AveragingPolicy:
    """Thresholds of the averaging rule (:func:`averaging_factor`).

    Attributes
    ----------
    floor_hz : float
        Lowest rate (Hz) the averaging may bring a record to.
    samples_per_period : float
        Fewest samples per period of the fastest excitation
        (:func:`~stewartid.identification.sampling.fastest_frequency`) to keep: the sampling
        check's margin, above which it finds no record sampling-limited.
    """

    floor_hz: float = 1000.0
    samples_per_period: float = SAMPLES_PER_PERIOD

    def __post_init__(self) -> None:
        for name in ("floor_hz", "samples_per_period"):
            value = getattr(self, name)
            if not (isinstance(value, int | float) and value > 0):  # inf: never average
                raise ConfigError(f"The {name!r} parameter of AveragingPolicy must be a float in "
                                  f"the range (0, inf]. Got {value!r} instead.")


#: The rule ``identify --average`` applies.
DEFAULT_AVERAGING = AveragingPolicy()

#: Relative slack of the rule's ratios: a rate read from rounded time stamps (1999.99999 Hz)
#: counts as the whole multiple of the floor it stands for.
RATIO_SLACK = 1e-6


def averaging_factor(datasets: Sequence[Dataset], policy: AveragingPolicy = DEFAULT_AVERAGING
                     ) -> int:
    """Samples k to average: the largest whole number that keeps every record's rate / k at or
    above ``policy.floor_hz``, its samples per period of the fastest excitation / k at or above
    ``policy.samples_per_period``, and at least
    :data:`~stewartid.datasets.dataset.MIN_SAMPLES` samples; 1 (as logged) where none does, or
    where a record does not move."""
    margin = samples_per_period(datasets)
    ratios = [margin / policy.samples_per_period,
              *(d.sample_rate / policy.floor_hz for d in datasets),
              *(len(d) / MIN_SAMPLES for d in datasets)]
    return max(1, math.floor(min(ratios) * (1.0 + RATIO_SLACK)))


@dataclass(frozen=True)
class Averaging:
    """Records averaged by :func:`average_experiments`, and the decision.

    Attributes
    ----------
    experiments : list of Dataset
    entry : dict or None
        ``diagnostics["averaging"]`` of ``result.json``: ``averaged_samples`` (1: as logged),
        ``sample_rate_hz`` and ``rate_hz`` (the lowest record's, logged and fitted),
        ``samples_per_period`` (fitted), ``reason``; None when no averaging was asked.
    """

    experiments: list[Dataset]
    entry: dict[str, Any] | None


def describe_averaging(entry: dict[str, Any]) -> str:
    """One terminal line of an :attr:`Averaging.entry`: the rates and why."""
    if entry["averaged_samples"] == 1:
        return f"every sample used: {entry['reason']}"
    return (f"averaged {entry['averaged_samples']} samples into one: "
            f"{entry['sample_rate_hz']:.6g} Hz -> {entry['rate_hz']:.6g} Hz, "
            f"{entry['samples_per_period']:.0f} samples per period of the fastest excitation")


def average_experiments(datasets: Sequence[Dataset],
                        policy: AveragingPolicy | None = DEFAULT_AVERAGING) -> Averaging:
    """The records averaged over :func:`averaging_factor` samples (every one alike); as logged,
    without an entry, for ``policy`` None."""
    datasets = list(datasets)
    if policy is None:
        return Averaging(datasets, None)
    rate = min(d.sample_rate for d in datasets)
    margin = samples_per_period(datasets)
    samples = averaging_factor(datasets, policy)
    reason = (f"the most samples that keep {policy.floor_hz:.6g} Hz and "
                  f"{policy.samples_per_period:.0f} samples per period of the fastest "
                  "excitation" if samples > 1 else
                  f"{rate:.6g} Hz and {margin:.0f} samples per period of the fastest "
                  "excitation leave nothing to average above "
                  f"{policy.floor_hz:.6g} Hz and {policy.samples_per_period:.0f}")
    entry = {"averaged_samples": samples, "sample_rate_hz": rate, "rate_hz": rate / samples,
             "samples_per_period": margin / samples, "reason": reason}
    if samples == 1:
        return Averaging(datasets, entry)
    return Averaging([d.averaged(samples) for d in datasets], entry)


__all__ = ["DEFAULT_AVERAGING", "RATIO_SLACK", "Averaging", "AveragingPolicy",
           "average_experiments", "averaging_factor", "describe_averaging"]
