"""Held-out prediction of the physical model by its full nonlinear model, scored as every
other method's (:mod:`stewartid.validation.heldout`).

The model predicts J_lq^T f = Y(q, q_dot, q_ddot) p at the measured poses, with gravity,
Coulomb friction and sensor offsets, the regressor filtered as the fit filters it.
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
    """The physical model's prediction of ``segment.force``, shape (n, 6) (N, N m).

    Parameters
    ----------
    segment : Segment
        The filtered record (:func:`~stewartid.validation.heldout.prepare_segment`).
    dataset : Dataset
        The record it was filtered from.
    platform : Platform
        The description the result was fitted with.
    result : PhysicalResult
    window : float
        The kernel support (s) the segment was filtered with.
    standard : ndarray, shape (N_STANDARD,), optional
        The result's :attr:`~stewartid.physical.prediction.ParameterMap.standard`, if at hand.
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
    """Held-out scores of the physical model, each time segment predicted by the fit without it.

    Parameters
    ----------
    create : callable
        Returns a new, unfitted :class:`~stewartid.physical.estimator.PhysicalIdentifier`.
    datasets : sequence of Dataset
    platform : Platform
    folds : int
    segments : list of Segment, optional
        The held-out segments (:func:`~stewartid.validation.heldout.held_out_segments`).

    Returns
    -------
    ValidationResult
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
    """Scores of the physical model fitted on all experiments on validation records
    (``segments``: :func:`~stewartid.validation.heldout.record_segments` of ``records``).

    Returns
    -------
    ValidationResult
        With ``folds`` = 0 (no refit).
    """
    standard = parameter_map(platform, result).standard
    predicted = [predict_physical(s, record, platform, result, excitation_window(record),
                                  standard) for s, record in zip(segments, records, strict=True)]
    return score(segments, predicted, folds=0)


__all__ = ["cross_validate_physical", "predict_physical", "validate_physical_on_records"]
