"""Identified physical model at any pose: Mt(q) = A(q) (S^T p + o), Bt(q) likewise, each entry's
standard error sqrt(a^T C a) with a = A(q) S^T its row (delta method).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from stewartid.errors import IdentificationError
from stewartid.model import matrix_regressors
from stewartid.physical.estimator import (
    PhysicalResult,
    _full_model,
    _payload_model,
    matrix_std_errors,
)
from stewartid.platform import Platform


@dataclass(frozen=True)
class ParameterMap:
    """How a result's parameters enter the standard regressor columns.

    Attributes
    ----------
    names : tuple of str
        In covariance order.
    values : ndarray, shape (p,)
    selection : ndarray, shape (p, N_STANDARD)
        Identity rows S.
    offset : ndarray, shape (N_STANDARD,)
        Known standard parameters o (zero in full mode).
    """

    names: tuple[str, ...]
    values: np.ndarray
    selection: np.ndarray
    offset: np.ndarray

    @property
    def standard(self) -> np.ndarray:
        """S^T p + o, shape (N_STANDARD,)."""
        return self.selection.T @ self.values + self.offset


def parameter_map(platform: Platform, result: PhysicalResult) -> ParameterMap:
    """:class:`ParameterMap` of ``result`` on the platform it was fitted with.

    Raises
    ------
    IdentificationError
        Parameters not those of this platform's model or mode.
    """
    payload = result.diagnostics.get("mode") == "payload"
    names, _, selection, _, offset = (_payload_model(platform) if payload
                                      else _full_model(platform))
    if tuple(names) != tuple(result.parameters):
        raise IdentificationError("the physical result's parameters are not those of platform "
                                  f"'{platform.name}'; give the platform it was fitted with.")
    values = np.array([result.parameters[name] for name in names], dtype=float)
    return ParameterMap(tuple(names), values, selection, offset)


@dataclass(frozen=True)
class PoseMatrices:
    """Mt and Bt of the physical model at several poses.

    Attributes
    ----------
    M, B, std_errors_M, std_errors_B : ndarray, shape (n, 6, 6)
    """

    M: np.ndarray
    B: np.ndarray
    std_errors_M: np.ndarray
    std_errors_B: np.ndarray


def matrices_at(platform: Platform, result: PhysicalResult, covariance: np.ndarray,
                poses: np.ndarray, mapping: ParameterMap | None = None) -> PoseMatrices:
    """Mt(q), Bt(q) of ``result`` at absolute ``poses`` (n, 6) with standard errors, from the
    parameters' ``covariance`` (p, p); ``mapping`` is :func:`parameter_map` when at hand.
    """
    mapping = mapping or parameter_map(platform, result)
    covariance = np.asarray(covariance, dtype=float)
    if covariance.shape != (len(mapping.names),) * 2:
        raise IdentificationError(f"covariance of shape {covariance.shape} for "
                                  f"{len(mapping.names)} parameters.")
    out: list[list[np.ndarray]] = [[], [], [], []]
    for pose in np.atleast_2d(np.asarray(poses, dtype=float)):
        for k, A in enumerate((matrix_regressors.inertia_regressor(platform, pose),
                               matrix_regressors.viscous_regressor(platform, pose))):
            out[k].append(A @ mapping.standard)
        for k, std in enumerate(matrix_std_errors(platform, mapping.selection, covariance,
                                                  pose)):
            out[k + 2].append(std)
    return PoseMatrices(*(np.array(x) for x in out))


__all__ = ["ParameterMap", "PoseMatrices", "matrices_at", "parameter_map"]
