"""The result of an identification: matrices, standard errors, settings, diagnostics, its
JSON file (``result.json``), and the comparison table in the layout of the paper (Zhang 2020,
Tables 3-6).
"""

from __future__ import annotations

import json
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from stewartid.files import to_jsonable, write_json_atomic
from stewartid.reference.published import (
    PAPER_ENTRIES,
    EntryKey,
    entry_label,
    relative_error_percent,
)


@dataclass(frozen=True)
class IdentificationResult:
    """Identified inertial and viscous matrices with their uncertainty.

    Attributes
    ----------
    M : ndarray, shape (6, 6)
        Inertial matrix Mt, paper frame (kg, kg m, kg m^2 blocks).
    B : ndarray, shape (6, 6)
        Viscous matrix Bt (N s/m, N s, N m s blocks).
    std_errors_M, std_errors_B : ndarray, shape (6, 6)
        Standard errors of every entry, from the residuals.
    condition_number : float
        Of the (column-equilibrated) regression solved.
    residual_rms : ndarray, shape (6,)
        RMS residual per equation (N, N m, or the units of the transformed equations).
    method : str
        ``"fourier"``, ``"wavelet"``, ``"ls"``.
    settings : dict
        Every setting of the identifier.
    diagnostics : dict
        Method-specific: intervals, (a, b) points, frequencies, Coulomb levels, ...
    validation : dict, optional
        Held-out prediction scores, ``{"vaf_percent": [6], "nrmse": [6], "folds": N}``
        (:mod:`stewartid.validation.heldout`); None when not validated.
    delay : dict, optional
        The delay of the force channels relative to the motion the data were aligned by,
        ``{"seconds", "std_error", "applied", "source": "given" | "estimated", ...}``
        (:mod:`stewartid.identification.delay`); None when the data were used as logged.
    verdict : dict, optional
        With several methods compared, which to trust and why,
        ``{"trusted", "ranking", "uncertain_entries", "reasons", ...}``
        (:meth:`stewartid.verdict.rule.Verdict.to_dict`); None otherwise.

    ``to_dict`` also writes ``consistency``, the symmetry and definiteness of M and B
    (:func:`~stewartid.identification.consistency.consistency_metrics`).
    """

    M: np.ndarray
    B: np.ndarray
    std_errors_M: np.ndarray
    std_errors_B: np.ndarray
    condition_number: float
    residual_rms: np.ndarray
    method: str
    settings: dict[str, Any] = field(default_factory=dict)
    diagnostics: dict[str, Any] = field(default_factory=dict)
    validation: dict[str, Any] | None = None
    delay: dict[str, Any] | None = None
    verdict: dict[str, Any] | None = None

    def to_dict(self) -> dict[str, Any]:
        """A JSON-ready dict; non-finite numbers are None (see :mod:`stewartid.files`)."""
        from stewartid.identification.consistency import consistency_metrics

        document = {
            "M": self.M, "B": self.B,
            "std_errors_M": self.std_errors_M, "std_errors_B": self.std_errors_B,
            "condition_number": float(self.condition_number),
            "residual_rms": self.residual_rms,
            "method": self.method, "settings": self.settings, "diagnostics": self.diagnostics,
            "consistency": consistency_metrics(self.M, self.B),
        }
        if self.validation is not None:
            document["validation"] = self.validation
        if self.delay is not None:
            document["delay"] = self.delay
        if self.verdict is not None:
            document["verdict"] = self.verdict
        return to_jsonable(document)

    def to_json(self, path: str | Path) -> Path:
        """Write the result as JSON, atomically; returns the path."""
        return write_json_atomic(path, self.to_dict())

    @classmethod
    def from_dict(cls, document: dict[str, Any]) -> IdentificationResult:
        """Inverse of :meth:`to_dict`."""
        def array(key: str, shape: tuple[int, ...]) -> np.ndarray:
            value = document.get(key)
            if value is None:
                return np.full(shape, np.nan)
            return np.asarray(value, dtype=float).reshape(shape)

        condition = document.get("condition_number", np.nan)
        return cls(M=array("M", (6, 6)), B=array("B", (6, 6)),
                   std_errors_M=array("std_errors_M", (6, 6)),
                   std_errors_B=array("std_errors_B", (6, 6)),
                   condition_number=float(condition if condition is not None else np.nan),
                   residual_rms=array("residual_rms", (6,)),
                   method=str(document.get("method", "unknown")),
                   settings=dict(document.get("settings", {})),
                   diagnostics=dict(document.get("diagnostics", {})),
                   validation=document.get("validation"), delay=document.get("delay"),
                   verdict=document.get("verdict"))

    @classmethod
    def from_json(cls, path: str | Path) -> IdentificationResult:
        """Read a result written by :meth:`to_json`."""
        return cls.from_dict(json.loads(Path(path).read_text()))

    def comparison_table(self, M_nominal: np.ndarray, B_nominal: np.ndarray):
        """Identified versus nominal values, in the layout of the paper's tables.

        Parameters
        ----------
        M_nominal, B_nominal : ndarray, shape (6, 6)

        Returns
        -------
        pandas.DataFrame
            One row per entry of :data:`~stewartid.reference.published.PAPER_ENTRIES`,
            columns ``entry`` ("Mt(1,1)"), ``matrix``, ``i``, ``j`` (1-based, as printed),
            ``identified``, ``std_error``, ``nominal``, ``error_percent`` (the paper's ε,
            :func:`~stewartid.reference.published.relative_error_percent`; NaN where the
            nominal value is zero).
        """
        return comparison_table(self.M, self.B, M_nominal, B_nominal,
                                self.std_errors_M, self.std_errors_B)


def comparison_rows(M: np.ndarray, B: np.ndarray, M_nominal: np.ndarray,
                    B_nominal: np.ndarray, std_M: np.ndarray | None = None,
                    std_B: np.ndarray | None = None,
                    entries: Sequence[EntryKey] = PAPER_ENTRIES) -> list[dict[str, Any]]:
    """The rows of :func:`comparison_table` as dicts, without pandas, for ``entries`` (the
    paper's 20 by default)."""
    identified = {"M": np.asarray(M), "B": np.asarray(B)}
    nominal = {"M": np.asarray(M_nominal, dtype=float), "B": np.asarray(B_nominal, dtype=float)}
    std = {"M": std_M if std_M is not None else np.full((6, 6), np.nan),
           "B": std_B if std_B is not None else np.full((6, 6), np.nan)}
    rows = []
    for key in entries:
        matrix, row, col = key
        value = float(identified[matrix][row, col])
        ref = float(nominal[matrix][row, col])
        rows.append({
            "entry": entry_label(key), "matrix": matrix, "i": row + 1, "j": col + 1,
            "identified": value, "std_error": float(std[matrix][row, col]),
            "nominal": ref, "error_percent": relative_error_percent(value, ref),
        })
    return rows


def comparison_table(M: np.ndarray, B: np.ndarray, M_nominal: np.ndarray,
                     B_nominal: np.ndarray, std_M: np.ndarray | None = None,
                     std_B: np.ndarray | None = None):
    """Table of the paper's 20 entries; see :meth:`IdentificationResult.comparison_table`."""
    import pandas as pd

    return pd.DataFrame(comparison_rows(M, B, M_nominal, B_nominal, std_M, std_B))


def max_error_percent(M: np.ndarray, B: np.ndarray, M_nominal: np.ndarray,
                      B_nominal: np.ndarray) -> float:
    """Largest epsilon (%) over the 20 entries of the paper's tables."""
    return float(comparison_table(M, B, M_nominal, B_nominal)["error_percent"].max())


__all__ = ["IdentificationResult", "comparison_rows", "comparison_table", "max_error_percent"]
