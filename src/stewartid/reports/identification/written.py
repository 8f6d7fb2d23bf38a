"""A comparison and the files its identification report was written to."""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

from stewartid.comparison import Comparison, MethodFit, PhysicalSection
from stewartid.identification.result import IdentificationResult
from stewartid.verdict.rule import Verdict


@dataclass(frozen=True)
class IdentificationReport:
    """A comparison and the files its report was written to.

    Attributes
    ----------
    comparison : Comparison
    directory : Path
    files : list of Path
    """

    comparison: Comparison
    directory: Path
    files: list[Path] = field(default_factory=list)

    @property
    def runs(self) -> tuple[MethodFit, ...]:
        """Every method's fit, the consensus of close methods last when the verdict built it."""
        return self.comparison.runs

    @property
    def verdict(self) -> Verdict:
        """Which method to trust, and why."""
        return self.comparison.verdict

    @property
    def physical(self) -> PhysicalSection | None:
        """The physical model beside the compared methods, when asked for."""
        return self.comparison.physical

    @property
    def physical_primary(self) -> bool:
        """The physical model was asked for alone: ``result.json`` holds its result."""
        return self.comparison.physical_primary

    @property
    def trusted(self) -> str:
        """Name of the method the report trusts."""
        return self.comparison.trusted

    @property
    def result(self) -> IdentificationResult:
        """The trusted method's result."""
        return self.comparison.trusted_result

    @property
    def main_result(self) -> IdentificationResult:
        """What ``result.json`` holds (``Comparison.result``)."""
        return self.comparison.result


__all__ = ["IdentificationReport"]
