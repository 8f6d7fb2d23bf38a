"""An experiment given twice (one file, two spellings, or equal numbers) weighs its DOF double
and hides the one it displaced; refused before any fit.
"""

from __future__ import annotations

import hashlib
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from stewartid.errors import DataError

if TYPE_CHECKING:
    from stewartid.datasets.dataset import Dataset


def _give_once(what: str) -> DataError:
    return DataError(f"{what}: each experiment must be given once (one counted twice weighs "
                     "its DOF double and may hide another left out); drop the repeat and check "
                     "that no experiment is missing.")


def check_distinct_paths(files: Sequence[Path]) -> None:
    """Refuse a file given twice, however spelled (relative, absolute, link).

    Raises
    ------
    DataError
        Naming both spellings.
    """
    seen: dict[Path, Path] = {}
    for f in files:
        key = f.resolve()
        if key in seen:
            raise _give_once(f"{f} is given twice" if str(seen[key]) == str(f) else
                             f"{seen[key]} and {f} are the same file ({key})")
        seen[key] = f


def experiment_digest(dataset: Dataset) -> str:
    """SHA-256 of an experiment's pose and forces, whatever its times, name or format; once per
    record (reading and the checks before a fit both ask)."""
    return dataset.derived(("digest",), _digest)


def _digest(dataset: Dataset) -> str:
    digest = hashlib.sha256()
    for numbers in (dataset.pose, dataset.forces):  # hashed where they lie, without a copy
        digest.update(np.ascontiguousarray(numbers).data)
    return digest.hexdigest()


def check_distinct_experiments(datasets: Sequence[Dataset], labels: Sequence[str]) -> None:
    """Refuse two experiments with identical pose and forces; ``labels`` name them.

    Raises
    ------
    DataError
        Naming both.
    """
    seen: dict[str, str] = {}
    for dataset, label in zip(datasets, labels, strict=True):
        digest = experiment_digest(dataset)
        if digest in seen:
            raise _give_once(f"{seen[digest]} and {label} hold the same experiment "
                             "(identical pose and forces)")
        seen[digest] = label


__all__ = ["check_distinct_experiments", "check_distinct_paths", "experiment_digest"]
