"""Identified matrices for control work: CSV tables and one MATLAB ``.mat`` file.

CSV: one file per matrix, ``<method>_M.csv``, ``<method>_B.csv``, ``<method>_std_errors_M.csv``,
``<method>_std_errors_B.csv``; a header row and a first column with the coordinate names
(x, y, z, rx, ry, rz), SI units (Mt: kg, kg m, kg m^2; Bt: N s/m, N s, N m s), full precision.

MAT (``identification.mat``, MATLAB 5 format, :func:`scipy.io.savemat`): one struct per
method (its name with ``-`` as ``_``) with fields ``M``, ``B``, ``std_errors_M``,
``std_errors_B`` (6x6), ``vaf_percent`` and ``nrmse`` (1x6, held out), ``coulomb_levels`` and
``coulomb_std_errors`` (1x3, N m; NaN where the method does not estimate friction),
plus ``coordinates``, ``friction_types`` and ``trusted`` (the method the report trusts).
"""

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
        With ``validation`` set when it was validated.
    coulomb : ndarray, shape (3,)
        Coulomb level per joint type (N m), NaN where not estimated.
    coulomb_std : ndarray, shape (3,)
        Their standard errors (N m).
    """

    name: str
    result: IdentificationResult
    coulomb: np.ndarray
    coulomb_std: np.ndarray


def matrix_csv(matrix: np.ndarray) -> str:
    """A 6x6 matrix as CSV text with coordinate names on both axes, full precision."""
    buffer = io.StringIO()
    writer = csv.writer(buffer, lineterminator="\n")
    writer.writerow(["", *COORDINATES])
    for name, row in zip(COORDINATES, np.asarray(matrix, dtype=float), strict=True):
        writer.writerow([name, *(repr(float(v)) for v in row)])
    return buffer.getvalue()


def read_matrix_csv(path: str | Path) -> np.ndarray:
    """Inverse of :func:`matrix_csv`: the 6x6 matrix of a file written by it."""
    rows = list(csv.reader(Path(path).read_text().splitlines()))
    return np.array([[float(v) for v in row[1:]] for row in rows[1:]])


def write_exports(models: Sequence[ExportedModel], directory: str | Path,
                  trusted: str) -> list[Path]:
    """Write the CSV files and ``identification.mat`` of every model.

    Parameters
    ----------
    models : sequence of ExportedModel
    directory : str or Path
    trusted : str
        Registered name of the trusted method, stored as ``trusted``.

    Returns
    -------
    list of Path
        The CSV files, then the MAT file.
    """
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
