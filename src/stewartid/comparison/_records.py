"""What a comparison found: one :class:`MethodFit` per method and the physical model's
:class:`PhysicalSection`."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from stewartid.errors import StewartidError
from stewartid.identification.consistency import ConsistentEstimate
from stewartid.identification.result import IdentificationResult
from stewartid.physical.estimator import PhysicalResult
from stewartid.physical.prediction import PoseMatrices
from stewartid.validation.heldout import (
    FRICTION_TYPES,
    CrossValidation,
    ValidationResult,
    coulomb_estimate,
)


@dataclass(frozen=True)
class MethodFit:
    """One method fitted to the experiments and validated on held-out data.

    Attributes
    ----------
    name, display_name, color : str
        From the registry.
    result : IdentificationResult or None
        The result the verdict judges (the consistent one with ``consistent=True``), with
        ``validation`` set; None if the method could not be applied.
    unconstrained : IdentificationResult or None
        The method's own estimate.
    validation : ValidationResult or None
        Held-out scores of ``result``'s fold models.
    validation_unconstrained : ValidationResult or None
        Of the unconstrained fold models, when ``result`` is the consistent one.
    in_sample : ValidationResult or None
        The full fit on the same segments (residuals over time).
    projection : ConsistentEstimate or None
    records : ValidationResult or None
        The full fit's prediction of the validation records (``identify --validate``).
    seconds : float
        Fit and validation time (s).
    error : str or None
        Why the method could not be applied.
    exception : StewartidError or None
        The error itself, raised again when no method could be applied.
    cross_validation : CrossValidation or None
        The fold fits ``validation`` scores (a consensus of close methods is built from them).
    estimator : BaseIdentifier or None
        The fitted estimator (None for the consensus of close methods, built from results).
    """

    name: str
    display_name: str
    color: str
    result: IdentificationResult | None = None
    unconstrained: IdentificationResult | None = None
    validation: ValidationResult | None = None
    validation_unconstrained: ValidationResult | None = None
    in_sample: ValidationResult | None = None
    projection: ConsistentEstimate | None = None
    records: ValidationResult | None = None
    seconds: float = 0.0
    error: str | None = None
    exception: StewartidError | None = field(default=None, repr=False, compare=False)
    cross_validation: CrossValidation | None = field(default=None, repr=False, compare=False)
    estimator: Any = field(default=None, repr=False, compare=False)

    @property
    def coulomb(self) -> tuple[np.ndarray, np.ndarray]:
        """Coulomb level and standard error per joint type (N m), shape (3,) each, NaN where
        not estimated."""
        if self.result is None:
            nan = np.full(len(FRICTION_TYPES), np.nan)
            return nan, nan
        return coulomb_estimate(self.result)

    @property
    def evidence(self) -> ValidationResult | None:
        """What the verdict judges the prediction by: the validation records when given,
        else the held-out segments."""
        return self.records if self.records is not None else self.validation


@dataclass(frozen=True)
class Workspace:
    """Mt and Bt of the physical model and of the platform description across the poses the
    data cover: each coordinate swept from its smallest to its largest measured value, the
    others at their mean.

    Attributes
    ----------
    centre : ndarray, shape (6,)
        The mean measured pose (m, rad).
    grid : ndarray, shape (6, P)
        The swept values of each coordinate (m, rad).
    identified : list of PoseMatrices
        Per swept coordinate, at its P poses, with standard errors.
    at_centre : PoseMatrices
        At the mean pose (one pose).
    nominal_M, nominal_B : ndarray, shape (6, P, 6, 6)
        Of the platform description at the same poses.
    couplings : dict of str to list of (int, int)
        The largest off-diagonal entries of ``"M"`` and ``"B"`` (relative to their
        diagonals, at the mean pose), shown beside the diagonal.
    """

    centre: np.ndarray
    grid: np.ndarray
    identified: list[PoseMatrices]
    at_centre: PoseMatrices
    nominal_M: np.ndarray
    nominal_B: np.ndarray
    couplings: dict[str, list[tuple[int, int]]]


@dataclass(frozen=True)
class PhysicalSection:
    """The physical model beside the compared methods (not ranked by the verdict).

    Attributes
    ----------
    result : PhysicalResult or None
        Fitted on all experiments, with ``validation`` set; None when not shown.
    covariance : ndarray, shape (p, p) or None
        Of its parameters (``PhysicalIdentifier.covariance_``).
    workspace : Workspace or None
    validation : ValidationResult or None
        Held-out prediction by the full model (:mod:`stewartid.physical.validation`).
    records : ValidationResult or None
        Its prediction of the validation records (``identify --validate``).
    seconds : float
        Time of the fit, validation and workspace curves (s).
    note : str or None
        Why the model is not shown (it cannot be applied, or the data fix most of its
        parameters).
    """

    result: PhysicalResult | None = None
    covariance: np.ndarray | None = None
    workspace: Workspace | None = None
    validation: ValidationResult | None = None
    records: ValidationResult | None = None
    seconds: float = 0.0
    note: str | None = None


__all__ = ["MethodFit", "PhysicalSection", "Workspace"]
