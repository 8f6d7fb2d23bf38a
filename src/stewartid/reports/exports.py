"""Identified matrices for control work: CSV tables and one MATLAB ``.mat`` file."""

from __future__ import annotations

import csv
import io
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from stewartid.files import write_bytes_atomic, write_text_atomic
from stewartid.identification.result import IdentificationResult
from stewartid.model.joints import FRICTION_TYPES
from stewartid.platform import COORDINATES


@dataclass(frozen=True)
class ExportedModel:
    """What is exported of one method.

    Attributes
    ----------
    name : str
        Registered method name (file prefix).
    result : IdentificationResult
        With ``validation`` set when validated.
    coulomb, coulomb_std : ndarray, shape (3,)
        Coulomb level per joint type and standard error (N m), NaN where not estimated.
    """

    name: str
    result: IdentificationResult
    coulomb: np.ndarray
    coulomb_std: np.ndarray


def matrix_csv(matrix: np.ndarray) -> str:
    """A 6x6 matrix as CSV, coordinate names on both axes, full precision."""
    buffer = io.StringIO()
    writer = csv.writer(buffer, lineterminator="\n")
    writer.writerow(["", *COORDINATES])
    for name, row in zip(COORDINATES, np.asarray(matrix, dtype=float), strict=True):
        writer.writerow([name, *(repr(float(v)) for v in row)])
    return buffer.getvalue()


def read_matrix_csv(path: str | Path) -> np.ndarray:
    """Inverse of :func:`matrix_csv`."""
    rows = list(csv.reader(Path(path).read_text().splitlines()))
    return np.array([[float(v) for v in row[1:]] for row in rows[1:]])


def write_exports(models: Sequence[ExportedModel], directory: str | Path,
                  trusted: str) -> list[Path]:
    """Write every model's CSV files, then ``identification.mat``; returns their paths.

    CSV: ``<method>_M.csv``, ``_B``, ``_std_errors_M``, ``_std_errors_B``, coordinate names as
    header and first column, SI units. MAT (MATLAB 5): one struct per method (``-`` as ``_``) with
    ``M``, ``B``, ``std_errors_M``, ``std_errors_B`` (6x6), held-out ``vaf_percent`` and ``nrmse``
    (1x6), ``coulomb_levels``, ``coulomb_std_errors`` (1x3, N m, NaN if not estimated); plus
    ``coordinates``, ``friction_types`` and ``trusted`` (the registered name of the trusted method)."""
    from scipy.io import savemat

    directory = Path(directory)
    paths = []
    document: dict[str, object] = {"coordinates": np.array(COORDINATES, dtype=object),
                                   "friction_types": np.array(FRICTION_TYPES, dtype=object),
                                   "trusted": trusted}
    for model in models:
        result = model.result
        matrices = {"M": result.M, "B": result.B, "std_errors_M": result.std_errors_M,
                    "std_errors_B": result.std_errors_B}
        for key, matrix in matrices.items():
            paths.append(write_text_atomic(directory / f"{model.name}_{key}.csv",
                                           matrix_csv(matrix)))
        validation = result.validation or {}
        document[model.name.replace("-", "_")] = {
            **{key: np.asarray(matrix, dtype=float) for key, matrix in matrices.items()},
            "vaf_percent": np.asarray(validation.get("vaf_percent", [np.nan] * 6), dtype=float),
            "nrmse": np.asarray(validation.get("nrmse", [np.nan] * 6), dtype=float),
            "coulomb_levels": np.asarray(model.coulomb, dtype=float),
            "coulomb_std_errors": np.asarray(model.coulomb_std, dtype=float)}
    buffer = io.BytesIO()
    savemat(buffer, document, oned_as="row")
    paths.append(write_bytes_atomic(directory / "identification.mat", buffer.getvalue()))
    return paths


__all__ = ["ExportedModel", "matrix_csv", "read_matrix_csv", "write_exports"]
