"""Held-out prediction of the physical model by its full nonlinear model (J_lq^T f = Y p with
gravity, Coulomb friction and offsets), scored as :mod:`stewartid.validation.heldout` does.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Any

import numpy as np

from stewartid.datasets.dataset import Dataset
from stewartid.errors import DataError
from stewartid.identification.preparation import prepare
from stewartid.physical.estimator import PhysicalResult
from stewartid.physical.prediction import parameter_map
from stewartid.physical.regression import filtered_regression
from stewartid.platform import Platform
from stewartid.signals.differentiation import DEFAULT_ORDER
from stewartid.validation.heldout import (
    DEFAULT_FOLDS,
    Segment,
    ValidationResult,
    cross_validate,
    excitation_window,
    fold_bounds,
    score,
    time_piece,
)


def predict_physical(segment: Segment, dataset: Dataset, platform: Platform,
                     result: PhysicalResult, window: float,
                     standard: np.ndarray | None = None) -> np.ndarray:
    """Physical model's prediction (n, 6) of ``segment.force`` (N, N m).

    ``dataset`` is the record filtered with kernel support ``window`` (s); ``standard`` is
    :attr:`~stewartid.physical.prediction.ParameterMap.standard` when at hand.
    """
    settings = result.settings
    experiments = prepare([dataset], platform, gravity=False)
    data = filtered_regression(experiments, platform, window,
                               settings.get("order", DEFAULT_ORDER), 1,
                               settings.get("gravity", True),
                               settings.get("coulomb_smoothing", 1e-4))
    if data.y.shape != segment.force.shape:
        raise DataError(f"{segment.name}: the filtered record has {len(data.y)} samples, the "
                        f"segment {len(segment.force)}; filter both with the same kernel.")
    if standard is None:
        standard = parameter_map(platform, result).standard
    return segment.force - (data.y - data.Y @ standard)


def cross_validate_physical(create: Callable[[], Any], datasets: Sequence[Dataset],
                            platform: Platform, folds: int = DEFAULT_FOLDS,
                            segments: list[Segment] | None = None) -> ValidationResult:
    """Held-out scores of the physical model, each segment predicted by the fit without it;
    ``create`` returns a new :class:`~stewartid.physical.estimator.PhysicalIdentifier`.
    """
    gravity = bool(create().get_params().get("gravity", True))
    found = cross_validate(create, datasets, platform, folds, gravity, segments)
    windows = [excitation_window(dataset) for dataset in datasets]
    standard = [parameter_map(platform, r).standard for r in found.fold_results]
    predicted = []
    for s in found.segments:
        dataset = datasets[s.experiment]
        edges = fold_bounds(len(dataset), folds)
        predicted.append(predict_physical(s, time_piece(dataset, edges[s.fold], edges[s.fold + 1]),
                                          platform, found.fold_results[s.fold],
                                          windows[s.experiment], standard[s.fold]))
    return score(found.segments, predicted, folds)


def validate_physical_on_records(result: PhysicalResult, records: Sequence[Dataset],
                                 segments: Sequence[Segment], platform: Platform
                                 ) -> ValidationResult:
    """Scores (``folds`` = 0) of the model fitted on all experiments, on validation records'
    :func:`~stewartid.validation.heldout.record_segments`.
    """
    standard = parameter_map(platform, result).standard
    predicted = [predict_physical(s, record, platform, result, excitation_window(record),
                                  standard) for s, record in zip(segments, records, strict=True)]
    return score(segments, predicted, folds=0)


__all__ = ["cross_validate_physical", "predict_physical", "validate_physical_on_records"]
