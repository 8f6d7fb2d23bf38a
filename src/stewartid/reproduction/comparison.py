"""A reproduction's identification results, as its tables, figures and report use them
(rebuildable from ``results.json``)."""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from stewartid.files import to_jsonable
from stewartid.identification.result import IdentificationResult
from stewartid.reference.published import (
    PAPER_ENTRIES,
    EntryKey,
    PublishedEntry,
    PublishedResults,
    relative_error_percent,
)
from stewartid.reports.methods import paper_letter, report_order


@dataclass(frozen=True)
class MethodRun:
    """One method applied to the experiments at one Coulomb level.

    Attributes
    ----------
    method : str
        Registered method name.
    coulomb : float
        Coulomb friction of the simulated plant per joint axis (N m).
    result : IdentificationResult
        ``M``, ``B`` (paper frame, SI), standard errors (NaN where none), settings, diagnostics.
    seconds : float
        Wall time (s).
    """

    method: str
    coulomb: float
    result: IdentificationResult
    seconds: float = 0.0

    @property
    def diagnostics(self) -> dict[str, Any]:
        """JSON-able ``diagnostics`` for ``results.json``: condition number, RMS residual per equation,
        settings and the method's own (``details``)."""
        result = self.result
        return {"condition_number": float(result.condition_number),
                "residual_rms": np.asarray(result.residual_rms, dtype=float).tolist(),
                "settings": to_jsonable(result.settings),
                "details": to_jsonable(result.diagnostics)}

    def matrix(self, name: str) -> np.ndarray:
        """The identified ``M`` or ``B``, shape (6, 6)."""
        return self.result.M if name == "M" else self.result.B

    def value(self, key: EntryKey) -> float:
        """Identified value of one entry."""
        matrix, row, col = key
        return float(self.matrix(matrix)[row, col])

    def std_error(self, key: EntryKey) -> float:
        """Standard error of one entry; NaN when the method gives none."""
        matrix, row, col = key
        std = self.result.std_errors_M if matrix == "M" else self.result.std_errors_B
        return float(np.asarray(std)[row, col])


@dataclass(frozen=True)
class ComparisonResults:
    """All identifications of a comparison run, with the nominal truth and the paper's values.

    Attributes
    ----------
    runs : tuple of MethodRun
    nominal_M, nominal_B : ndarray, shape (6, 6)
        The simulated plant at neutral.
    published : PublishedResults
    settings : dict
        What was run (levels, durations, frequency, seed, ...), JSON-able.
    """

    runs: tuple[MethodRun, ...]
    nominal_M: np.ndarray
    nominal_B: np.ndarray
    published: PublishedResults
    settings: dict[str, Any] = field(default_factory=dict)

    @property
    def methods(self) -> tuple[str, ...]:
        """Methods present, in report order."""
        return report_order(run.method for run in self.runs)

    @property
    def coulomb_levels(self) -> tuple[float, ...]:
        """Coulomb levels present, ascending (N·m)."""
        return tuple(sorted({run.coulomb for run in self.runs}))

    def run(self, method: str, coulomb: float) -> MethodRun | None:
        """The run of ``method`` at ``coulomb`` N·m, or None."""
        for run in self.runs:
            if run.method == method and math.isclose(run.coulomb, coulomb):
                return run
        return None

    def nominal(self, key: EntryKey) -> float:
        """Nominal value of one entry (computed from our plant's description)."""
        matrix, row, col = key
        return float((self.nominal_M if matrix == "M" else self.nominal_B)[row, col])

    def eps(self, run: MethodRun, key: EntryKey) -> float:
        """ε (%) of one identified entry against nominal (NaN at a zero nominal)."""
        return relative_error_percent(run.value(key), self.nominal(key))

    def eps_all(self, run: MethodRun, entries: tuple[EntryKey, ...] = PAPER_ENTRIES
                ) -> dict[EntryKey, float]:
        """ε (%) of every entry in ``entries``."""
        return {key: self.eps(run, key) for key in entries}

    def worst(self, run: MethodRun, matrix: str | None = None) -> tuple[EntryKey, float]:
        """The entry with the largest ε (%) among the paper's 20 (or one matrix's 10)."""
        keys = [k for k in PAPER_ENTRIES if matrix is None or k[0] == matrix]
        errors = self.eps_all(run, tuple(keys))
        key = max(errors, key=errors.__getitem__)
        return key, errors[key]

    def published_entry(self, method: str, coulomb: float, key: EntryKey
                        ) -> PublishedEntry | None:
        """The paper's value for the same method, level and entry, if it reports one."""
        letter = paper_letter(method)
        return None if letter is None else self.published.entry(letter, coulomb, key)

    def published_worst(self, method: str, coulomb: float, matrix: str | None = None
                        ) -> tuple[EntryKey, float] | None:
        """The paper's largest printed ε (%) for a method and level, or None if not reported."""
        found = {}
        for key in PAPER_ENTRIES:
            if matrix is not None and key[0] != matrix:
                continue
            entry = self.published_entry(method, coulomb, key)
            if entry is None:
                return None
            found[key] = entry.eps
        key = max(found, key=found.__getitem__)
        return key, found[key]


__all__ = ["ComparisonResults", "MethodRun"]
