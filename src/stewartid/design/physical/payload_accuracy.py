"""Payload mode's design target: mass, centre of mass and inertia about it as ``[payload]`` holds
them, each within its required accuracy, standard errors by first order (:func:`payload_jacobian`).
"""

from __future__ import annotations

import math
from collections.abc import Mapping

import numpy as np
from scipy import special

from stewartid.errors import ConfigError
from stewartid.model import regressor as reg

#: Accuracy each payload quantity is needed to by default (``design --accuracy`` sets
#: others): the mass relative to itself, the centre of mass as a distance (m), every entry of
#: the inertia about the centre of mass relative to the mean of its diagonal.
REQUIRED_PAYLOAD_ACCURACY = {"mass": 0.002, "com": 0.002, "inertia": 0.02}
#: Share of runs whose error payload mode's design holds within the required accuracy
#: (:func:`held_share`).
ACCURACY_COVERAGE = 0.95


def payload_jacobian(parameters: np.ndarray) -> np.ndarray:
    """Derivative (10, 10) of (m, c_x, c_y, c_z, I about the com in
    :data:`~stewartid.model.regressor.BODY_PARAMETERS` order) by the ten body ``parameters``.
    """
    m, h = parameters[0], parameters[1:4]
    J = np.zeros((10, 10))
    J[0, 0] = 1.0
    J[1:4, 0] = -h / m**2
    J[1:4, 1:4] = np.eye(3) / m
    J[4:10, 4:10] = np.eye(6)
    shift = h @ h * np.eye(3) - np.outer(h, h)  # times 1/m
    for row, (i, j) in enumerate(reg.INERTIA_ENTRIES):
        J[4 + row, 0] = shift[i, j] / m**2
        for k in range(3):
            # d(h.h delta_ij - h_i h_j)/dh_k = 2 h_k delta_ij - delta_ik h_j - h_i delta_jk
            d = 2 * h[k] * (i == j) - (i == k) * h[j] - h[i] * (j == k)
            J[4 + row, 1 + k] = -d / m
    return J


def payload_std_errors(names: tuple[str, ...], nominal: np.ndarray, covariance: np.ndarray
                       ) -> dict[str, float]:
    """Standard errors of the payload's quantities in :data:`REQUIRED_PAYLOAD_ACCURACY` units.

    ``names``, ``nominal`` (p,) and ``covariance`` (p, p) are the payload-mode parameters'; NaN rows
    of a fixed parameter count as known.

    Returns
    -------
    dict
        ``mass`` relative; ``com`` along its least certain direction (m); ``inertia`` largest entry
        over the diagonal's mean; ``com_distance`` (m, :func:`distance_quantile`).
    """
    index = [names.index(f"payload.{n}") for n in reg.BODY_PARAMETERS]
    values = np.asarray(nominal, dtype=float)[index]
    block = np.nan_to_num(np.asarray(covariance, dtype=float)[np.ix_(index, index)])
    J = payload_jacobian(values)
    C = J @ block @ J.T
    m, _, inertia = reg.about_centre_of_mass(values)
    axes = np.clip(np.linalg.eigvalsh(C[1:4, 1:4]), 0.0, None)
    return {"mass": float(np.sqrt(max(C[0, 0], 0.0)) / m),
            "com": float(np.sqrt(axes[-1])),
            "com_distance": distance_quantile(axes, ACCURACY_COVERAGE),
            "inertia": float(np.sqrt(np.clip(np.diag(C)[4:], 0.0, None)).max()
                             / np.mean(np.abs(inertia[:3])))}


def payload_criterion(std_errors: Mapping[str, float],
                      accuracy: Mapping[str, float] | None = None) -> tuple[float, str]:
    """Largest ratio of a payload quantity's standard error to its accuracy, and the quantity."""
    accuracy = REQUIRED_PAYLOAD_ACCURACY if accuracy is None else accuracy
    ratios = {k: std_errors[k] / accuracy[k] for k in REQUIRED_PAYLOAD_ACCURACY}
    worst = max(ratios, key=ratios.__getitem__)
    return ratios[worst], worst


def distance_quantile(variances: np.ndarray, coverage: float) -> float:
    """Distance (m) a Gaussian error with principal ``variances`` (k,), m^2, stays within in
    ``coverage`` of draws, by Satterthwaite's scaled chi-square; 0 when all are 0.
    """
    variances = np.asarray(variances, dtype=float)
    total, squares = variances.sum(), (variances ** 2).sum()
    if squares <= 0:
        return 0.0
    return float(math.sqrt(squares / total * special.chdtri(total ** 2 / squares,
                                                              1 - coverage)))


def held_share(std_errors: Mapping[str, float],
               accuracy: Mapping[str, float] | None = None) -> tuple[float, str]:
    """Largest ratio of a payload quantity's error in :data:`ACCURACY_COVERAGE` of runs to its
    accuracy, and the quantity (the com's as a 3-D distance).
    """
    accuracy = REQUIRED_PAYLOAD_ACCURACY if accuracy is None else accuracy
    z = math.sqrt(special.chdtri(1, 1 - ACCURACY_COVERAGE))
    shares = {"mass": z * std_errors["mass"] / accuracy["mass"],
              "com": std_errors["com_distance"] / accuracy["com"],
              "inertia": z * std_errors["inertia"] / accuracy["inertia"]}
    worst = max(shares, key=shares.__getitem__)
    return shares[worst], worst


def payload_objective(worst_relative_std: float, std_errors: Mapping[str, float],
                      accuracy: Mapping[str, float] | None = None) -> float:
    """Payload search objective: the worst relative standard error times :func:`held_share` ^10
    where that exceeds 1.
    """
    return worst_relative_std * max(1.0, held_share(std_errors, accuracy)[0]) ** 10


def parse_accuracy(text: str) -> dict[str, float]:
    """``design --accuracy`` ``MASS,COM,INERTIA`` (%, mm, %) as fractions and metres.

    Raises
    ------
    ConfigError
        Not three positive numbers.
    """
    parts = text.split(",")
    try:
        values = [float(v) for v in parts]
    except ValueError:
        values = []
    if len(values) != 3 or not all(math.isfinite(v) and v > 0 for v in values):
        raise ConfigError(f"--accuracy must be three positive numbers MASS,COM,INERTIA (%, mm, "
                          f"%), e.g. 0.2,2,2; got {text!r}.")
    return {"mass": values[0] / 100, "com": values[1] / 1000, "inertia": values[2] / 100}


__all__ = ["ACCURACY_COVERAGE", "REQUIRED_PAYLOAD_ACCURACY", "distance_quantile", "held_share",
           "parse_accuracy", "payload_criterion", "payload_jacobian", "payload_objective",
           "payload_std_errors"]
