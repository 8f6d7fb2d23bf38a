"""The result of an identification.

Matrices, standard errors, ``result.json`` and the paper's comparison table (Zhang 2020, Tables 3-6).
"""

from __future__ import annotations

import dataclasses
import json
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from stewartid.files import to_jsonable, write_json_atomic
from stewartid.model.joints import FRICTION_TYPES
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
    M, B : ndarray, shape (6, 6)
        Mt (kg, kg m, kg m^2) and Bt (N s/m, N s, N m s), paper frame.
    std_errors_M, std_errors_B : ndarray, shape (6, 6)
    condition_number : float
        Of the column-equilibrated regression.
    residual_rms : ndarray, shape (6,)
        Per equation, N, N m (or the transformed equations' units).
    method : str
    settings : dict
    diagnostics : dict
        Method-specific.
    validation : dict, optional
        Held-out scores ``{"vaf_percent", "nrmse", "folds"}``, and ``"residual_delay"``
        (``{"ms", "std_ms", "identifiable"}``) where measured.
    delay : dict, optional
        The force delay the data were aligned by (:mod:`stewartid.identification.delay`).
    verdict : dict, optional
        Which method to trust and why, when several were compared.
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

    @property
    def friction_model(self) -> str | None:
        """Method B's interval constants (``"free"``, ``"shared"``, ``"uniform"``,
        ``"coulomb"``); None for a method without them."""
        return self.diagnostics.get("friction_model")

    @property
    def coulomb(self) -> tuple[np.ndarray, np.ndarray] | None:
        """Coulomb level and standard error per joint type (N m), shape (3,) each in
        :data:`~stewartid.model.joints.FRICTION_TYPES` order, as the method estimated them
        (standard errors NaN where not given); None when it estimated none, or left its
        interval constants free."""
        levels = self.diagnostics.get("coulomb")
        if not isinstance(levels, dict) or self.friction_model == "free":
            return None
        values = np.array([levels.get(name, np.nan) for name in FRICTION_TYPES], dtype=float)
        if not np.all(np.isfinite(values)):
            return None
        std = self.diagnostics.get("coulomb_std") or {}
        return values, np.array([std.get(name, np.nan) for name in FRICTION_TYPES], dtype=float)

    @property
    def validation_coulomb(self) -> np.ndarray | None:
        """The Coulomb levels per joint type (N m, shape (3,)) a result that estimated none is
        validated with (a friction-estimating fit of the same data); None without."""
        found = self.diagnostics.get("validation_coulomb")
        if not isinstance(found, dict):
            return None
        values = np.array([found.get(name, np.nan) for name in FRICTION_TYPES], dtype=float)
        return values if np.all(np.isfinite(values)) else None

    @property
    def consensus_members(self) -> tuple[str, ...]:
        """The methods a consensus result combines (empty for any other result)."""
        return tuple(self.diagnostics.get("consensus", {}).get("members", ()))

    def to_dict(self) -> dict[str, Any]:
        """A JSON-ready dict (with ``consistency``); non-finite numbers are None."""
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
        """Identified versus nominal values, one row per paper entry, as a DataFrame.

        Columns ``entry``, ``matrix``, ``i``, ``j`` (1-based), ``identified``, ``std_error``, ``nominal``,
        ``error_percent`` (the paper's epsilon; NaN where the nominal is zero).
        """
        return comparison_table(self.M, self.B, M_nominal, B_nominal,
                                self.std_errors_M, self.std_errors_B)


def comparison_rows(M: np.ndarray, B: np.ndarray, M_nominal: np.ndarray,
                    B_nominal: np.ndarray, std_M: np.ndarray | None = None,
                    std_B: np.ndarray | None = None,
                    entries: Sequence[EntryKey] = PAPER_ENTRIES) -> list[dict[str, Any]]:
    """The rows of :func:`comparison_table` as dicts, for ``entries`` (the paper's 20 by default)."""
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


#: The linearised model's own approximation error (the remainder's derivatives and
#: interpolation, interval detection) as a share of sqrt(|A_ii A_jj|): the largest error of
#: any method on noise-free logs, measured by ``benchmarks/coverage_study.py``, is below it.
MODEL_FLOOR = 1e-3


def with_model_floor(result: IdentificationResult) -> IdentificationResult:
    """The result with every standard error at least :data:`MODEL_FLOOR` sqrt(|A_ii A_jj|).

    On noise-free or long logs the noise-based errors shrink towards zero while the model's
    approximation error does not; the floor keeps entry (i, j) of Mt and Bt covered, in the
    units of its own row and column (the diagonals set the scale of the couplings).
    """
    def floored(matrix: np.ndarray, std: np.ndarray) -> np.ndarray:
        diagonal = np.abs(np.diag(matrix))
        floor = MODEL_FLOOR * np.sqrt(np.outer(diagonal, diagonal))
        return np.where(np.isfinite(floor), np.fmax(std, floor), std)

    # the floor is an error every method shares: combining methods weighs their own errors
    own = result.diagnostics.get("own_std_errors",
                                 {"M": result.std_errors_M, "B": result.std_errors_B})
    return dataclasses.replace(result, std_errors_M=floored(result.M, result.std_errors_M),
                               std_errors_B=floored(result.B, result.std_errors_B),
                               diagnostics={**result.diagnostics, "own_std_errors": own})


def own_std_errors(result: IdentificationResult) -> tuple[np.ndarray, np.ndarray]:
    """Standard errors (M, B) of Mt and Bt without the model floor (:func:`with_model_floor`)."""
    own = result.diagnostics.get("own_std_errors")
    if own is None:
        return result.std_errors_M, result.std_errors_B
    return np.asarray(own["M"], dtype=float), np.asarray(own["B"], dtype=float)


def max_error_percent(M: np.ndarray, B: np.ndarray, M_nominal: np.ndarray,
                      B_nominal: np.ndarray) -> float:
    """Largest epsilon (%) over the 20 entries of the paper's tables."""
    return float(comparison_table(M, B, M_nominal, B_nominal)["error_percent"].max())


__all__ = ["MODEL_FLOOR", "IdentificationResult", "comparison_rows", "comparison_table",
           "max_error_percent", "own_std_errors", "with_model_floor"]
