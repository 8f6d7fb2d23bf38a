"""What the identification report found: one :class:`MethodReport` per method and the
:class:`IdentificationReport` that holds them with the verdict and the files written."""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from stewartid.assessment.validation import FRICTION_TYPES, ValidationResult, coulomb_estimate
from stewartid.assessment.verdict import Verdict
from stewartid.errors import StewartidError
from stewartid.identification.consistency import ConsistentEstimate
from stewartid.identification.result import IdentificationResult


@dataclass(frozen=True)
class MethodReport:
    """One method applied to the experiments, with everything the report says about it.

    Attributes
    ----------
    name, display_name, color : str
        From the registry.
    result : IdentificationResult or None
        The reported result (the consistent one with ``consistent=True``), with
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
        Fit and validation time.
    error : str or None
        Why the method could not be applied.
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
class IdentificationReport:
    """What :func:`~stewartid.reports.identification.report.write_identification_report`
    found and wrote.

    Attributes
    ----------
    runs : list of MethodReport
    verdict : Verdict
        Which method to trust and why (:mod:`stewartid.assessment.verdict`).
    directory : Path
    files : list of Path
    """

    runs: list[MethodReport]
    verdict: Verdict
    directory: Path
    files: list[Path] = field(default_factory=list)

    @property
    def trusted(self) -> str:
        """Name of the method the report trusts (the only one for a single method)."""
        return self.verdict.trusted

    @property
    def result(self) -> IdentificationResult:
        """The trusted method's result (with ``validation``)."""
        return next(run.result for run in self.runs if run.name == self.trusted)


__all__ = ["IdentificationReport", "MethodReport"]
