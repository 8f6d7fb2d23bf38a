"""Data preparation shared by every identifier: each experiment's model terms (Jacobians,
gravity, the generalized force y = J_lq^T f_a - G(q) and its sensitivity to the pose),
computed once at every measured pose (Zhang 2020, Eq. 5).

References
----------
Zhang, C. "A Parameter Identification Method for Stewart Manipulator Based on Wavelet
Transform." Mathematics 8(2), 257 (2020). doi:10.3390/math8020257
"""

from __future__ import annotations

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
        Time (s), uniform.
    q : ndarray, shape (N, 6)
        Measured pose (m, rad).
    generalized_force : ndarray, shape (N, 6)
        y = J_lq(q)^T f_a - G(q) (N, N m); without the gravity term when gravity subtraction
        is off.
    leg_jacobian : ndarray, shape (N, 6, 6)
        J_lq at every measured pose.
    gravity : ndarray, shape (N, 6)
        G(q) of the platform description (N, N m), whether or not it was subtracted.
    force_sensitivity : ndarray, shape (6, 6)
        K = d y / d q at the mean pose and mean leg forces
        (:func:`generalized_force_sensitivity`).
    sample_rate : float
        Hz.
    platform : Platform
        The description the terms were computed from.
    joint_jacobians : ndarray, shape (N, 6, 5, 6)
        Joint-axis rate Jacobians (rad/s per unit q_dot), axes lower 1, lower 2, upper 1,
        upper 2, revolute; computed on first use unless :func:`prepare` was asked for them.
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
        """Joint-axis rate Jacobians, shape (N, 6, 5, 6); see the class docstring."""
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
    """K = d(J_lq(q)^T f - G(q)) / dq at the mean pose and mean leg forces.

    K maps pose noise into the generalized force, for errors-in-variables corrections.

    Parameters
    ----------
    platform : Platform
    q : ndarray, shape (N, 6)
        Measured poses (m, rad).
    forces : ndarray, shape (N, 6)
        Measured leg forces (N).
    gravity : bool
        Whether G(q) is part of the generalized force (as :func:`prepare`'s ``gravity``).
    step : float
        Central-difference step (m, rad).

    Returns
    -------
    ndarray, shape (6, 6)
        K[i, j] = d y_i / d q_j (N/m, N/rad, N m/m, N m/rad).
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
    """Every model term of one experiment, each computed once, at every measured pose.

    Parameters
    ----------
    dataset : Dataset
    platform : Platform
        Platform description (geometry for J_lq; leg masses for G(q)).
    gravity : bool
        Subtract the model's pose-dependent gravity term G(q) from J_lq^T f_a (else the
        legs' gravity stiffness biases Mt).
    joints : bool
        Compute the joint-axis Jacobians now, in the same pass as J_lq and G(q), rather than
        on first use.
    remainder : bool
        Also subtract the model's departure from its linearisation (:func:`model_remainder`),
        so that the linear model holds at any amplitude.

    Returns
    -------
    Experiment
    """
    G, J, _, joint_jacobians = compute_leg_terms(platform, np.ascontiguousarray(dataset.pose), joints)
    y = np.einsum("nji,nj->ni", J, dataset.forces)
    if gravity:
        y = y - G
    if remainder:
        y = y - model_remainder(platform, dataset.pose, dataset.sample_rate)
    experiment = Experiment(
        name=dataset.name, t=dataset.t, q=dataset.pose, generalized_force=y, leg_jacobian=J,
        gravity=G, force_sensitivity=generalized_force_sensitivity(
            platform, dataset.pose, dataset.forces, gravity),
        sample_rate=dataset.sample_rate, platform=platform)
    if joints:  # the cached property's slot, as its first use would fill it
        experiment.__dict__["joint_jacobians"] = joint_jacobians
    return experiment


def model_remainder(platform: Platform, q: np.ndarray, sample_rate: float) -> np.ndarray:
    """The model's departure from its linearisation along a measured motion (N, 6).

    :func:`~stewartid.model.linearization.linearisation_remainder` at the measured pose q
    (N, 6) with Savitzky-Golay rates and accelerations (order 5 over a tenth of the dominant
    period), evaluated every :data:`REMAINDER_STEPS`-th of the window and interpolated by cubic
    Hermite polynomials (:func:`~stewartid.signals.interpolation.hermite_uniform`).
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
    """:func:`prepare_experiment` of every data set.

    Parameters
    ----------
    datasets : sequence of Dataset
    platform : Platform
    gravity, joints, remainder : bool
        As in :func:`prepare_experiment`.

    Returns
    -------
    list of Experiment
    """
    return [prepare_experiment(d, platform, gravity, joints, remainder) for d in datasets]


__all__ = ["Experiment", "generalized_force_sensitivity", "model_remainder", "prepare",
           "prepare_experiment",
           "resolve_datasets", "resolve_platform"]
