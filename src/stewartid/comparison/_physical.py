"""The physical model beside the compared methods: fitted on all experiments (not ranked by
the verdict), validated by its full nonlinear model on held-out segments, and its Mt, Bt
across the poses the data cover."""

from __future__ import annotations

import dataclasses
import time
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from stewartid.comparison._records import PhysicalSection, Workspace
from stewartid.comparison._runs import held_out_for
from stewartid.datasets.dataset import Dataset
from stewartid.errors import StewartidError
from stewartid.model.linearization import nominal_matrices
from stewartid.physical.estimator import PhysicalIdentifier, PhysicalResult
from stewartid.physical.prediction import matrices_at, parameter_map
from stewartid.physical.validation import (
    cross_validate_physical,
    validate_physical_on_records,
)
from stewartid.platform import Platform
from stewartid.validation.heldout import (
    Segment,
    ValidationResult,
    record_segments,
    validation_entry,
)

#: Poses per swept coordinate in :func:`workspace`.
WORKSPACE_POINTS = 11
#: Off-diagonal entries of Mt and of Bt shown beside the diagonal (the largest).
SHOWN_COUPLINGS = 2
#: Share of the parameters fixed at the file's values above which a comparison that does not
#: require the physical model leaves it out (the section's ``note`` says why).
MOST_FIXED = 0.5


@dataclass(frozen=True)
class PhysicalRequest:
    """What a comparison asks of the physical model.

    Attributes
    ----------
    payload : bool
        Payload mode (``identify --payload``).
    consistent : bool
        The physically consistent fit (``identify --model physical --consistent``).
    required : bool
        ``identify --model physical``: a model that cannot be applied is an error. Otherwise
        (``identify --method all --report``) the section's ``note`` says why it is not shown.
    settings : dict
        Further estimator settings (e.g. ``{"gravity": False}``).
    """

    payload: bool = False
    consistent: bool = False
    required: bool = False
    settings: Mapping[str, Any] = dataclasses.field(default_factory=dict)


def largest_couplings(matrix: np.ndarray, count: int = SHOWN_COUPLINGS
                      ) -> list[tuple[int, int]]:
    """The off-diagonal entries (i < j) of a (6, 6) matrix largest relative to
    sqrt(|m_ii m_jj|): the couplings worth showing beside the diagonal.

    Returns
    -------
    list of (int, int)
        At most ``count`` index pairs, largest first, each above 1e-6 of its scale.
    """
    d = np.sqrt(np.abs(np.diag(matrix)))
    scale = np.outer(d, d)
    relative = np.abs(matrix) / np.where(scale > 0, scale, np.inf)
    pairs = sorted(((i, j) for i in range(6) for j in range(i + 1, 6)),
                   key=lambda e: -relative[e])
    return [e for e in pairs[:count] if relative[e] > 1e-6]


def workspace(platform: Platform, result: PhysicalResult, covariance: np.ndarray,
              datasets: Sequence[Dataset], points: int = WORKSPACE_POINTS) -> Workspace:
    """Mt and Bt of ``result`` (with standard errors) and of ``platform`` with each
    coordinate swept over its measured range, the others at their mean.

    Parameters
    ----------
    platform : Platform
        The description the result was fitted with (its own Mt, Bt are the nominal curves).
    result : PhysicalResult
    covariance : ndarray, shape (p, p)
        Of the result's parameters.
    datasets : sequence of Dataset
        The experiments whose poses set the range.
    points : int
        Poses per coordinate.

    Returns
    -------
    Workspace
    """
    poses = np.concatenate([d.pose for d in datasets])
    centre = poses.mean(axis=0)
    grid = np.linspace(poses.min(axis=0), poses.max(axis=0), points).T
    mapping = parameter_map(platform, result)
    identified, nominal = [], []
    for dof in range(6):
        swept = np.tile(centre, (points, 1))
        swept[:, dof] = grid[dof]
        identified.append(matrices_at(platform, result, covariance, swept, mapping))
        nominal.append([nominal_matrices(platform, q) for q in swept])
    at_centre = matrices_at(platform, result, covariance, centre[None], mapping)
    nominal_array = np.array(nominal)  # (6, P, 2, 6, 6)
    return Workspace(centre, grid, identified, at_centre, nominal_array[:, :, 0],
                     nominal_array[:, :, 1],
                     {"M": largest_couplings(at_centre.M[0]),
                      "B": largest_couplings(at_centre.B[0])})


def fit_physical(datasets: Sequence[Dataset], platform: Platform, request: PhysicalRequest,
                 folds: int, segments: dict[tuple[bool, bool], list[Segment]],
                 records: Sequence[Dataset] = (),
                 record_cache: dict[tuple[bool, bool], list[Segment]] | None = None
                 ) -> PhysicalSection:
    """Fit the physical model on all experiments, validate it on held-out segments (and on
    ``records``) and compute its Mt, Bt across the workspace.

    Parameters
    ----------
    datasets, platform, folds
        As :func:`~stewartid.comparison.compare_methods`.
    request : PhysicalRequest
    segments, record_cache : dict
        Held-out segments and validation-record segments by (``gravity``, ``remainder``)
        setting, shared with the compared methods (filled on first use).
    records : sequence of Dataset
        Validation records (``identify --validate``).

    Returns
    -------
    PhysicalSection
        With ``note`` instead of a result when the model cannot be applied or, unless
        ``request.required``, the data fix more than ``MOST_FIXED`` of its parameters.

    Raises
    ------
    StewartidError
        With ``request.required``, when the model cannot be applied.
    """
    section = physical_fit(datasets, platform, request, records, record_cache)
    if section.result is None:
        return section
    start = time.perf_counter()
    found = physical_folds(datasets, platform, request, folds, segments)
    return with_physical_folds(section, found, request, time.perf_counter() - start)


def _options(request: PhysicalRequest) -> dict[str, Any]:
    return {**request.settings, "payload": request.payload, "consistent": request.consistent}


def _terms(request: PhysicalRequest) -> tuple[bool, bool]:
    """The model terms its held-out segments are prepared with: the full model predicts the
    nonlinear terms itself."""
    return bool(_options(request).get("gravity", True)), False


def physical_fit(datasets: Sequence[Dataset], platform: Platform, request: PhysicalRequest,
                 records: Sequence[Dataset] = (),
                 record_cache: dict[tuple[bool, bool], list[Segment]] | None = None
                 ) -> PhysicalSection:
    """The physical model's full fit, its prediction of ``records`` and its matrices across the
    workspace, not yet validated on held-out segments (:func:`physical_folds`,
    :func:`with_physical_folds`); arguments and errors as :func:`fit_physical`."""
    start = time.perf_counter()
    try:
        estimator = PhysicalIdentifier(**_options(request)).fit(list(datasets), platform)
        fixed, count = estimator.fixed_, len(estimator.parameters_)
        if not request.required and len(fixed) > MOST_FIXED * count:
            return PhysicalSection(seconds=time.perf_counter() - start, note=(
                f"The physical model is not shown: these data fix {len(fixed)} of its {count} "
                "parameters at the platform file's values (not identifiable from them); "
                "`identify --model physical` fits and names the rest."))
        terms = _terms(request)
        external = None
        if records:
            cache = {} if record_cache is None else record_cache
            if terms not in cache:
                cache[terms] = record_segments(records, platform, *terms)
            external = validate_physical_on_records(estimator.result_, records,
                                                    cache[terms], platform)
        curves = workspace(platform, estimator.result_, estimator.covariance_, datasets)
    except StewartidError as exc:
        if request.required:
            raise
        return PhysicalSection(seconds=time.perf_counter() - start,
                               note=f"The physical model is not shown: {exc}")
    return PhysicalSection(estimator.result_, estimator.covariance_, curves, None, external,
                           time.perf_counter() - start)


def physical_folds(datasets: Sequence[Dataset], platform: Platform, request: PhysicalRequest,
                   folds: int, segments: dict[tuple[bool, bool], list[Segment]]
                   ) -> ValidationResult | StewartidError:
    """The physical model refitted without each time segment, scored on the held-out segments;
    or the error that stopped the fits (arguments as :func:`fit_physical`)."""
    try:
        held_out = held_out_for(segments, _terms(request), datasets, platform, folds)
        # the fold fits predict: their standard errors (the sampling check's refits) are
        # never read
        quick = {**_options(request), "sampling_check": False}
        return cross_validate_physical(lambda: PhysicalIdentifier(**quick), datasets, platform,
                                       folds, held_out)
    except StewartidError as exc:
        return exc


def with_physical_folds(section: PhysicalSection, folds: ValidationResult | StewartidError,
                        request: PhysicalRequest, seconds: float = 0.0) -> PhysicalSection:
    """The full fit's section (:func:`physical_fit`) validated by its folds
    (:func:`physical_folds`, which took ``seconds``): the full fit's note first, then the
    folds' error (raised with ``request.required``)."""
    if section.result is None:
        return section
    if isinstance(folds, StewartidError):
        if request.required:
            raise folds
        return PhysicalSection(seconds=section.seconds + seconds,
                               note=f"The physical model is not shown: {folds}")
    result = dataclasses.replace(section.result,
                                 validation=validation_entry(folds, section.records))
    return dataclasses.replace(section, result=result, validation=folds,
                               seconds=section.seconds + seconds)


__all__ = ["MOST_FIXED", "SHOWN_COUPLINGS", "WORKSPACE_POINTS", "PhysicalRequest",
           "fit_physical", "largest_couplings", "physical_fit", "physical_folds",
           "with_physical_folds", "workspace"]
