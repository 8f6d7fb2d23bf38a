"""What payload mode's design aims at: the payload's mass, centre of mass and inertia about
it, each within the accuracy it is needed to.

A payload is wanted as the platform file's ``[payload]`` holds it: mass, centre of mass and
inertia about the centre of mass (:func:`~stewartid.physical.estimator.payload_section`),
not as the ten parameters about the reference point the estimator fits. Those three are
needed to different accuracies (:data:`REQUIRED_PAYLOAD_ACCURACY`): the mass is most of the
translational Mt, and a relative error of the inertia moves only the rotational block.
Judged on equal relative terms, as full mode judges the moving body's ten, the design spent
the motion on the inertia: on the paper platform with a 2 t payload the mass's predicted
standard error along the commanded motion was 0.122 %, the inertia's 0.18 %, and on a
simulator that tracked the command the worst mass of 8 seeds came out 0.20-0.25 %.

The standard errors of the three follow from the parameters' covariance to first order
(:func:`payload_jacobian` of
:func:`~stewartid.model.regressor.about_centre_of_mass`).

The search holds each of the three within its accuracy in :data:`ACCURACY_COVERAGE` of
runs (:func:`held_share`; the centre of mass's error as a distance in three directions,
:func:`distance_quantile`) and, within that, sharpens every one of the ten parameters
(:func:`payload_objective`). Minimising the largest share of accuracy alone left a flat
direction the search wandered along: on the paper platform with a 2 t payload it reached
0.385 of the accuracy (the centre of mass) with the ten's worst relative standard error at
0.67 of the all-DOFs multisine's; held within the accuracy in 95 % of runs and sharpened,
0.38 and 0.49.
"""

from __future__ import annotations

import math
from collections.abc import Mapping

import numpy as np
from scipy import special

from stewartid.errors import ConfigError
from stewartid.model import regressor as reg

#: Accuracy each payload quantity is needed to by default (``design --accuracy`` sets
#: others): the mass relative to itself, the centre of mass as a distance (m; its standard
#: error along its least certain direction in :func:`payload_criterion`), every entry of
#: the inertia about the centre of mass relative to the mean of its diagonal. The design
#: holds one run's error within it in :data:`ACCURACY_COVERAGE` of runs (:func:`held_share`).
REQUIRED_PAYLOAD_ACCURACY = {"mass": 0.002, "com": 0.002, "inertia": 0.02}
#: Share of runs whose error payload mode's design holds within the required accuracy
#: (:func:`held_share`).
ACCURACY_COVERAGE = 0.95


def payload_jacobian(parameters: np.ndarray) -> np.ndarray:
    """Derivative of (mass, centre of mass, inertia about it) by the body parameters.

    Parameters
    ----------
    parameters : ndarray, shape (10,)
        m (kg), first moment h (kg m), inertia about the reference point (kg m^2), in the
        order of :data:`~stewartid.model.regressor.BODY_PARAMETERS`.

    Returns
    -------
    ndarray, shape (10, 10)
        Rows: m, c_x, c_y, c_z, I_xx, I_yy, I_zz, I_xy, I_xz, I_yz (about the centre of
        mass); columns: the parameters.
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
    """Predicted standard errors of the payload's quantities, each in the unit its accuracy
    is needed in (:data:`REQUIRED_PAYLOAD_ACCURACY`).

    Parameters
    ----------
    names : tuple of str
        The estimator's parameters in payload mode (``payload.m``, ...).
    nominal : ndarray, shape (p,)
        Their values (the payload expected).
    covariance : ndarray, shape (p, p)
        Their covariance; a parameter the estimator fixes has NaN rows and columns, and
        counts as known.

    Returns
    -------
    dict
        ``mass``: relative to the mass; ``com``: the centre of mass's standard error along
        its least certain direction (m); ``inertia``: the largest of the inertia's six
        entries about the centre of mass relative to the mean of its diagonal;
        ``com_distance``: the distance from the true centre of mass within which a run's
        lies in :data:`ACCURACY_COVERAGE` of runs (m, :func:`distance_quantile`).
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
    """The largest ratio of a payload quantity's standard error to the accuracy it is needed
    to (``accuracy``, default :data:`REQUIRED_PAYLOAD_ACCURACY`), and the quantity (below 1
    every one is expected within its accuracy at one standard error)."""
    accuracy = REQUIRED_PAYLOAD_ACCURACY if accuracy is None else accuracy
    ratios = {k: std_errors[k] / accuracy[k] for k in REQUIRED_PAYLOAD_ACCURACY}
    worst = max(ratios, key=ratios.__getitem__)
    return ratios[worst], worst


def distance_quantile(variances: np.ndarray, coverage: float) -> float:
    """The distance a Gaussian error with these variances along its principal directions
    stays within in ``coverage`` of draws, by Satterthwaite's scaled chi-square (the sum of
    weighted chi-squares matched in mean and variance; within 1 % of a Monte Carlo for the
    centres of mass here).

    Parameters
    ----------
    variances : ndarray, shape (k,)
        Variances along the principal directions (m^2), >= 0.
    coverage : float
        In (0, 1).

    Returns
    -------
    float
        m; 0 if every variance is 0.
    """
    variances = np.asarray(variances, dtype=float)
    total, squares = variances.sum(), (variances ** 2).sum()
    if squares <= 0:
        return 0.0
    return float(math.sqrt(squares / total * special.chdtri(total ** 2 / squares,
                                                              1 - coverage)))


def held_share(std_errors: Mapping[str, float],
               accuracy: Mapping[str, float] | None = None) -> tuple[float, str]:
    """The largest ratio of a payload quantity's error in :data:`ACCURACY_COVERAGE` of runs
    to the accuracy it is needed to, and the quantity: at most 1, every one is within its
    accuracy in that share of runs. The mass and each inertia entry are one number (1.96
    standard errors); the centre of mass's error is a distance in three directions
    (``com_distance``): 2 standard errors of the least certain one, as a first version
    held it, left the largest distance of 8 runs at 1.5-2.1 mm of 2."""
    accuracy = REQUIRED_PAYLOAD_ACCURACY if accuracy is None else accuracy
    z = math.sqrt(special.chdtri(1, 1 - ACCURACY_COVERAGE))
    shares = {"mass": z * std_errors["mass"] / accuracy["mass"],
              "com": std_errors["com_distance"] / accuracy["com"],
              "inertia": z * std_errors["inertia"] / accuracy["inertia"]}
    worst = max(shares, key=shares.__getitem__)
    return shares[worst], worst


def payload_objective(worst_relative_std: float, std_errors: Mapping[str, float],
                      accuracy: Mapping[str, float] | None = None) -> float:
    """What payload mode's search minimises: the ten parameters' worst relative standard
    error, times :func:`held_share` ^10 where that exceeds 1: a constraint the search may
    cross only to where a few percent beyond it would halve the worst error."""
    return worst_relative_std * max(1.0, held_share(std_errors, accuracy)[0]) ** 10


def parse_accuracy(text: str) -> dict[str, float]:
    """The ``design --accuracy`` value ``MASS,COM,INERTIA`` (%, mm, %) as
    :data:`REQUIRED_PAYLOAD_ACCURACY` holds it (fractions and metres).

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
