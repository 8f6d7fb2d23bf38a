"""Data preparation shared by every identifier.

Jacobians, gravity and y = J_lq^T f_a - G(q) at every measured pose, computed once (Zhang 2020, Eq. 5).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence
from dataclasses import dataclass, field
from functools import cached_property
from pathlib import Path
from typing import Any

import numpy as np

from stewartid.datasets.dataset import Dataset, read_datasets
from stewartid.errors import ConfigError, DataError
from stewartid.model.kinematics import compute_leg_terms, joint_rate_jacobians
from stewartid.model.linearization import linearisation_remainder
from stewartid.platform import Platform, load_platform
from stewartid.signals.differentiation import (
    default_window,
    differentiate,
    estimate_frequency,
    window_samples,
)
from stewartid.signals.interpolation import hermite_uniform


@dataclass(frozen=True)
class Experiment:
    """One experiment prepared for identification.

    Attributes
    ----------
    name : str
    t : ndarray, shape (N,)
        s, uniform.
    q : ndarray, shape (N, 6)
        m, rad.
    generalized_force : ndarray, shape (N, 6)
        y = J_lq^T f_a - G(q), N, N m (G omitted when gravity is off).
    leg_jacobian : ndarray, shape (N, 6, 6)
    gravity : ndarray, shape (N, 6)
        G(q), N, N m, subtracted or not.
    force_sensitivity : ndarray, shape (6, 6)
        K = dy/dq at the mean pose and forces.
    sample_rate : float
        Hz.
    platform : Platform
    joint_jacobians : ndarray, shape (N, 6, 5, 6)
        Joint-axis rates per unit q_dot; computed on first use.
    """

    name: str
    t: np.ndarray
    q: np.ndarray
    generalized_force: np.ndarray
    leg_jacobian: np.ndarray
    gravity: np.ndarray
    force_sensitivity: np.ndarray
    sample_rate: float
    platform: Platform = field(repr=False)

    @cached_property
    def joint_jacobians(self) -> np.ndarray:
        """Joint-axis rate Jacobians, shape (N, 6, 5, 6)."""
        return joint_rate_jacobians(self.platform, self.q)

    @property
    def period(self) -> float:
        """Sample period (s)."""
        return 1.0 / self.sample_rate

    def __len__(self) -> int:
        return len(self.t)


def resolve_platform(platform: Platform | str | Path) -> Platform:
    """A Platform from a Platform, ``"paper"`` or a TOML path."""
    if isinstance(platform, Platform):
        return platform
    if isinstance(platform, str | Path):
        return load_platform(platform)
    raise ConfigError(f"platform must be a Platform, 'paper' or a TOML path; got "
                      f"{type(platform).__name__}.")


def resolve_datasets(datasets: Any, platform: Platform) -> list[Dataset]:
    """Datasets from a Dataset, a path, or a sequence of either."""
    if isinstance(datasets, Dataset | str | Path):
        datasets = [datasets]
    datasets = list(datasets)
    if not datasets:
        raise DataError("no experiments given; pass one or more data sets.")
    out: list[Dataset] = []
    for d in datasets:
        if isinstance(d, Dataset):
            out.append(d)
        elif isinstance(d, str | Path):
            out.extend(read_datasets([d], platform))
        else:
            raise ConfigError(f"expected Dataset objects or file paths; got "
                                      f"{type(d).__name__}.")
    return out


def generalized_force_sensitivity(platform: Platform, q: np.ndarray, forces: np.ndarray,
                                  gravity: bool = True, step: float = 1e-6) -> np.ndarray:
    """K = d(J_lq^T f - G(q)) / dq (6, 6) at the mean pose and leg forces, by central differences.

    Maps pose noise into the generalized force; ``gravity`` as :func:`prepare`'s.
    """
    q0, f0 = q.mean(axis=0), forces.mean(axis=0)
    poses = np.repeat(q0[None], 12, axis=0)
    for j in range(6):
        poses[2 * j, j] += step
        poses[2 * j + 1, j] -= step
    terms = compute_leg_terms(platform, poses)
    y = np.einsum("nji,j->ni", terms.leg_jacobian, f0)
    if gravity:
        y = y - terms.gravity
    return ((y[0::2] - y[1::2]) / (2 * step)).T


def prepare_experiment(dataset: Dataset, platform: Platform, gravity: bool = True,
                       joints: bool = False, remainder: bool = False) -> Experiment:
    """Every model term of one experiment, each computed once per record, at every measured pose.

    The terms are kept with the record (:meth:`~stewartid.datasets.dataset.Dataset.derived`), so
    that every method fitted to it shares them; the joint-axis Jacobians, the largest, are not.
    G(q) and J_lq, which every setting shares, are the rows of its record's for a part of one
    (:meth:`~stewartid.datasets.dataset.Dataset.pointwise`).

    Parameters
    ----------
    dataset : Dataset
    platform : Platform
    gravity : bool
        Subtract G(q) (else the legs' gravity stiffness biases Mt).
    joints : bool
        Compute the joint-axis Jacobians now rather than on first use.
    remainder : bool
        Subtract the model's departure from its linearisation (:func:`model_remainder`).
    """
    fresh: dict[str, np.ndarray] = {}   # the joint-axis Jacobians of a first leg-terms pass
    shared = dataset.derived(("prepared", platform, gravity, remainder),
                             lambda record: _prepared(record, platform, gravity, remainder,
                                                      joints, fresh))
    experiment = dataclasses.replace(shared)   # its own slot for the joint-axis Jacobians
    if joints:
        experiment.__dict__["joint_jacobians"] = fresh.get("joint_jacobians")
        if experiment.__dict__["joint_jacobians"] is None:
            experiment.__dict__["joint_jacobians"] = joint_rate_jacobians(platform, dataset.pose)
    return experiment


def _pose_terms(dataset: Dataset, platform: Platform, joints: bool,
                fresh: dict[str, np.ndarray]) -> tuple[np.ndarray, np.ndarray]:
    """G(q) (N, 6) and J_lq (N, 6, 6) of a record; with ``joints``, the joint-axis Jacobians of
    the same pass into ``fresh`` when the pass is made."""
    def compute(record: Dataset) -> tuple[np.ndarray, np.ndarray]:
        G, J, _, joint_jacobians = compute_leg_terms(platform, np.ascontiguousarray(record.pose),
                                                     joints and record is dataset)
        if joints and record is dataset:
            fresh["joint_jacobians"] = joint_jacobians
        return G, J

    return dataset.pointwise(("pose terms", platform), compute)


def _prepared(dataset: Dataset, platform: Platform, gravity: bool, remainder: bool,
              joints: bool, fresh: dict[str, np.ndarray]) -> Experiment:
    """The terms of one setting; with ``joints``, the joint-axis Jacobians into ``fresh`` when
    computed in the same pass as G and J."""
    G, J = _pose_terms(dataset, platform, joints, fresh)
    y = np.einsum("nji,nj->ni", J, dataset.forces)
    if gravity:
        y = y - G
    if remainder:
        y = y - model_remainder(platform, dataset.pose, dataset.sample_rate)
    return Experiment(
        name=dataset.name, t=dataset.t, q=dataset.pose, generalized_force=y, leg_jacobian=J,
        gravity=G, force_sensitivity=generalized_force_sensitivity(
            platform, dataset.pose, dataset.forces, gravity),
        sample_rate=dataset.sample_rate, platform=platform)


def model_remainder(platform: Platform, q: np.ndarray, sample_rate: float) -> np.ndarray:
    """The model's departure from its linearisation along a measured motion q (N, 6), (N, 6).

    Evaluated every :data:`REMAINDER_STEPS`-th of the Savitzky-Golay window, Hermite-interpolated.
    """
    # the window needs the frequency only roughly: the spectrum's peak without refinement
    window = default_window(estimate_frequency(q, sample_rate, refine=False)) / REMAINDER_FRACTION
    q_s, q_dot, q_ddot = differentiate(q, sample_rate, window, REMAINDER_ORDER)
    n = len(q_s)
    step = max(1, window_samples(window, sample_rate, REMAINDER_ORDER) // REMAINDER_STEPS)
    knots = np.arange(0, n, step)
    if len(knots) < 5:
        return linearisation_remainder(platform, q_s, q_dot, q_ddot)
    values = linearisation_remainder(platform, q_s[knots], q_dot[knots], q_ddot[knots])
    covered = knots[-1] + 1
    out = np.empty((n, 6))
    out[:covered] = hermite_uniform(values, step, covered)
    if covered < n:   # the samples after the last knot, fewer than a step: evaluated
        tail = slice(covered, n)
        out[tail] = linearisation_remainder(platform, q_s[tail], q_dot[tail], q_ddot[tail])
    return out


#: Savitzky-Golay order and window (a fraction of a fifth of the dominant period) of
#: :func:`model_remainder`, and its model evaluations per window.
REMAINDER_ORDER, REMAINDER_FRACTION, REMAINDER_STEPS = 5, 2, 8


def prepare(datasets: Sequence[Dataset], platform: Platform, gravity: bool = True,
            joints: bool = False, remainder: bool = False) -> list[Experiment]:
    """:func:`prepare_experiment` of every data set."""
    return [prepare_experiment(d, platform, gravity, joints, remainder) for d in datasets]


__all__ = ["Experiment", "generalized_force_sensitivity", "model_remainder",
           "prepare", "prepare_experiment", "resolve_datasets", "resolve_platform"]
