"""Time alignment of late force channels with the motion: f(t) = f_logged(t + delay) by cubic
spline, samples beyond the record dropped (delay from
:func:`stewartid.identification.delay.estimate_delay`).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from stewartid.datasets.dataset import MIN_SAMPLES, Dataset
from stewartid.errors import ConfigError, DataError
from stewartid.signals.interpolation import spline_at


def shift_forces(dataset: Dataset, delay: float) -> Dataset:
    """The experiment with its forces moved ``delay`` s earlier (positive: forces late; 0 returns
    ``dataset``), keeping samples with t_k + delay inside the record.

    Raises
    ------
    ConfigError
        Non-finite delay, or fewer than :data:`~stewartid.datasets.dataset.MIN_SAMPLES` samples left.
    """
    delay = float(delay)
    if not np.isfinite(delay):
        raise ConfigError(f"the force delay must be a finite number of seconds; got {delay}.")
    if delay == 0.0:
        return dataset
    t = dataset.t
    period = dataset.duration / (len(t) - 1)
    # a tolerance of 1e-6 sample periods keeps the sample that a whole-period shift lands on
    tolerance = 1e-6 * period
    keep = (t + delay >= t[0] - tolerance) & (t + delay <= t[-1] + tolerance)
    if np.count_nonzero(keep) < MIN_SAMPLES:
        raise ConfigError(f"{dataset.name}: a force delay of {delay * 1e3:.4g} ms leaves "
                          f"{np.count_nonzero(keep)} of {len(t)} samples (at least "
                          f"{MIN_SAMPLES} needed); the delay is given in seconds "
                          "(--delay 0.002 for 2 ms).")
    # the kept samples are one run (t rises): the motion's terms are the record's rows
    kept = np.flatnonzero(keep)
    shifts = delay / period
    if abs(shifts - round(shifts)) < 1e-6:
        forces = dataset.forces[kept + int(round(shifts))]
    else:
        forces = spline_at(t, dataset.forces, np.clip(t[kept] + delay, t[0], t[-1]))
    return dataset.part(slice(int(kept[0]), int(kept[-1]) + 1), forces=forces)


def align_forces(datasets: Sequence[Dataset], delay: float) -> list[Dataset]:
    """:func:`shift_forces` of every experiment with one delay (one acquisition chain).

    Raises
    ------
    ConfigError
        As :func:`shift_forces`.
    DataError
        No experiments.
    """
    if not datasets:
        raise DataError("no experiments given to align; pass one or more data sets.")
    return [shift_forces(d, delay) for d in datasets]


__all__ = ["align_forces", "shift_forces"]
