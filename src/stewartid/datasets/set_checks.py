"""The checks a set of experiments passes before any fit: no experiment twice, every DOF
excited, and force channels numbered as the legs they measure.
"""

from __future__ import annotations

import itertools
from collections.abc import Sequence
from functools import lru_cache

import numpy as np

from stewartid.datasets.dataset import Dataset
from stewartid.datasets.distinct import check_distinct_experiments
from stewartid.datasets.excitation import check_excitation, motion_rows
from stewartid.errors import DataError
from stewartid.model.kinematics import compute_leg_terms
from stewartid.model.linearization import nominal_matrices
from stewartid.platform import Platform

#: A renumbering of the force channels is named when it raises their correlation with the
#: leg forces the platform's model predicts by this much (summed over the six channels, mean
#: over the experiments). On a correct log the logged numbering is the best, or ties with the
#: renumberings a symmetric motion cannot tell from it.
CHANNEL_ORDER_GAIN = 0.5
#: ... and when the renumbered channels follow their legs at least this well (mean correlation).
CHANNEL_ORDER_FIT = 0.3

#: Numberings whose scores differ by less than this tie (the correlations' noise).
CHANNEL_TIE = 0.05
#: Rows per experiment the correlations take (an evenly strided subset of the excitation
#: check's): a correlation's noise is then a few hundredths.
CHANNEL_ROWS = 1000

#: Every numbering of six channels (channel k holds leg NUMBERINGS[n, k]), the logged one first.
NUMBERINGS = np.array(list(itertools.permutations(range(6))))


def force_channel_correlation(dataset: Dataset, platform: Platform) -> np.ndarray | None:
    """Correlation (6, 6) of logged force channel i with the force of leg j that the nominal
    model predicts from the motion, J_lq(q)^-T (Mt q'' + Bt q' + G(q)) (and an electric leg's
    screw friction, ``[actuator] coulomb`` times the sign of its rate), over the record's
    :func:`~stewartid.datasets.excitation.motion_rows` (means removed: the mean load and
    Coulomb friction's mean do not enter; gravity's share moving between the legs as the
    platform tilts does, which slow motion is dominated by); None for a record without motion.
    A channel or leg that does not vary correlates 0. Computed once per record and platform.
    """
    return dataset.derived(("force channel correlation", platform),
                           lambda record: _correlation(record, platform))


@lru_cache(maxsize=4)
def _nominal(platform: Platform) -> tuple[np.ndarray, np.ndarray]:
    return nominal_matrices(platform)


def _correlation(dataset: Dataset, platform: Platform) -> np.ndarray | None:
    found = motion_rows(dataset, platform)
    if found is None:
        return None
    M, B = _nominal(platform)
    every = slice(None, None, max(1, -(-len(found.rows) // CHANNEL_ROWS)))
    rows, velocity, acceleration = found.rows[every], found.velocity[every], found.acceleration[every]
    # the pose-only leg terms of the static balance check: no mass matrix, no compiled kernel
    gravity, jacobian, _, _ = compute_leg_terms(platform, np.ascontiguousarray(dataset.pose[rows]))
    generalized = acceleration @ M.T + velocity @ B.T + gravity
    predicted = np.linalg.solve(np.transpose(jacobian, (0, 2, 1)), generalized[..., None])[..., 0]
    if platform.actuator.kind == "electric":
        # a ball screw's Coulomb friction along its leg: most of an electric leg's varying force
        predicted += platform.actuator.coulomb * np.sign((jacobian @ velocity[..., None])[..., 0])
    logged = dataset.forces[rows]
    logged, predicted = logged - logged.mean(axis=0), predicted - predicted.mean(axis=0)
    norms = np.outer(np.linalg.norm(logged, axis=0), np.linalg.norm(predicted, axis=0))
    products = logged.T @ predicted
    return np.divide(products, norms, out=np.zeros((6, 6)), where=norms > 0)


def numbering_scores(datasets: Sequence[Dataset], platform: Platform) -> np.ndarray | None:
    """Every numbering of the channels (as :data:`NUMBERINGS`, the logged one first) scored by
    its channels' summed :func:`force_channel_correlation` with their legs, mean over the
    experiments; None where no experiment moves."""
    found = [r for r in (force_channel_correlation(d, platform) for d in datasets)
             if r is not None]
    if not found:
        return None
    return sum(r[np.arange(6), NUMBERINGS].sum(axis=1) for r in found) / len(found)


def check_force_channels(datasets: Sequence[Dataset], platform: Platform) -> None:
    """Refuse force channels numbered differently from the legs: the numbering of the channels
    whose varying parts follow the predicted leg forces best (:func:`numbering_scores`) against
    the logged one.

    Raises
    ------
    DataError
        Naming the channels, the legs they follow and the ``--columns`` mapping.
    """
    scores = numbering_scores(datasets, platform)
    if scores is None:
        return
    if scores.max() - scores[0] < CHANNEL_ORDER_GAIN or scores.max() < 6 * CHANNEL_ORDER_FIT:
        return
    # numberings a symmetric motion cannot tell apart tie: the one that moves fewest channels
    near = np.flatnonzero(scores >= scores.max() - CHANNEL_TIE)
    best = int(near[np.argmin((NUMBERINGS[near] != np.arange(6)).sum(axis=1))])
    legs = NUMBERINGS[best]
    # an electric actuator's log holds motor currents i1..i6, read as forces
    column, kind = ("i", "current") if platform.actuator.kind == "electric" else ("f", "force")
    moved = [k for k in range(6) if legs[k] != k]
    follows = ", ".join(f"{column}{k + 1} follows leg {legs[k] + 1}" for k in moved)
    mapping = ",".join(f"{column}{legs[k] + 1}={column}{k + 1}" for k in moved)
    raise DataError(
        f"the {kind} channels are numbered differently from the legs: {follows} (mean "
        f"correlation with the leg forces platform '{platform.name}' predicts from the motion "
        f"{scores[best] / 6:.2f} renumbered, {scores[0] / 6:.2f} as logged); map them with "
        f"--columns {mapping} (docs/conventions.md numbers the legs).")


def check_experiment_set(datasets: Sequence[Dataset], platform: Platform) -> None:
    """Checks before any fit: no experiment twice
    (:func:`~stewartid.datasets.distinct.check_distinct_experiments`), every DOF excited
    (:func:`~stewartid.datasets.excitation.check_excitation`), the force channels numbered as
    the legs (:func:`check_force_channels`).

    Raises
    ------
    DataError
    """
    check_distinct_experiments(datasets, [d.name for d in datasets])
    check_excitation(datasets, platform)
    check_force_channels(datasets, platform)


__all__ = ["CHANNEL_ORDER_FIT", "CHANNEL_ORDER_GAIN", "CHANNEL_ROWS", "CHANNEL_TIE", "NUMBERINGS",
           "check_experiment_set", "check_force_channels", "force_channel_correlation",
           "numbering_scores"]
