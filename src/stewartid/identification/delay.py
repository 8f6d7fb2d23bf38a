"""Delay of the force channels relative to the motion, fitted jointly with Mt, Bt in weak form.

A delay tau biases Bt by tau w^2 Mt at one frequency; two or more per DOF separate it from damping.
Shinbrot (1957), modulating functions; Khalil and Dombre (2002), ch. 12.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from stewartid.datasets.alignment import align_forces
from stewartid.datasets.dataset import Dataset
from stewartid.datasets.excitation import COUNTING_PADDING, excitation_lines
from stewartid.errors import ConfigError, IdentificationError
from stewartid.identification.least_squares import (
    coulomb_regressors,
    leg_coulomb_regressor,
    uses_leg_coulomb,
)
from stewartid.identification.preparation import generalized_force_sensitivity, prepare_experiment
from stewartid.model.linearization import nominal_matrices
from stewartid.parallel import inheriting_workers, run_in_order
from stewartid.platform import COORDINATES, Platform
from stewartid.signals.differentiation import (
    DEFAULT_ORDER,
    differentiate,
    estimate_frequency,
    kernel_filter,
)

#: Kernel support of the weak form, in periods of the highest excitation line.
WINDOW_PERIODS = 0.45

#: Rate (rad/s) below which a joint's Coulomb sign is attenuated (as the least squares).
COULOMB_SMOOTHING = 1e-4

#: Smallest standard error of the estimate (s): on noise-free logs without a delay the model's
#: own approximation (the friction law, the linearisation's remainder) passes for one, which
#: the noise's standard error alone would call significant (docs/benchmarks.md, "The force
#: delay's floor").
MODEL_FLOOR_S = 30e-6


@dataclass(frozen=True)
class DelayEstimate:
    """The estimated delay of the force channels relative to the motion.

    Attributes
    ----------
    seconds : float
        Delay, s; positive when the forces are logged late.
    std_error, first_pass : float
        Its standard error (the noise's, :data:`MODEL_FLOOR_S` at least) and the first-pass
        estimate before alignment, s.
    lines_hz : tuple of tuple of float
        Excitation lines per DOF, Hz.
    window_s : float
        Kernel support of the weak form, s.
    own_std_error : float or None
        The noise's standard error alone (before the floor), s.
    """

    seconds: float
    std_error: float
    first_pass: float
    lines_hz: tuple[tuple[float, ...], ...]
    window_s: float
    own_std_error: float | None = None

    def to_dict(self, applied: bool = True) -> dict[str, Any]:
        """The ``"delay"`` entry of ``result.json``."""
        return {"seconds": self.seconds, "std_error": self.std_error, "applied": applied,
                "source": "estimated", "own_std_error": self.own_std_error,
                "first_pass_seconds": self.first_pass,
                "window_s": self.window_s,
                "lines_hz": {c: list(f) for c, f in zip(COORDINATES, self.lines_hz, strict=True)}}

    def describe(self) -> str:
        """One terminal line: the delay in ms with its standard error."""
        return (f"force delay {self.seconds * 1e3:.3f} ms (standard error "
                f"{self.std_error * 1e3:.3f} ms), estimated from "
                f"{min(len(f) for f in self.lines_hz)} or more lines per DOF")


def delay_bias_per_ms(platform: Platform | np.ndarray, frequencies_hz: Sequence[float],
                      stiffness: np.ndarray | None = None) -> np.ndarray:
    """Bias of 1 ms of delay on the Bt diagonal under single sines: tau (w_i^2 Mt(i, i) + K(i, i)).

    Parameters
    ----------
    platform : Platform or ndarray, shape (6, 6)
        Nominal Mt at the neutral pose, or an identified Mt.
    frequencies_hz : sequence of 6 float
    stiffness : ndarray, shape (6, 6), optional
        K = dy/dq; without it the inertial term alone.

    Returns
    -------
    ndarray, shape (6,)
        N s/m and N m s/rad per ms.
    """
    M = nominal_matrices(platform)[0] if isinstance(platform, Platform) else np.asarray(platform)
    w = 2 * np.pi * np.asarray(frequencies_hz, dtype=float)
    K = np.zeros((6, 6)) if stiffness is None else np.asarray(stiffness)
    return 1e-3 * (w ** 2 * np.diag(M) + np.diag(K))


def single_frequency_dofs(lines: Sequence[Sequence[float]]) -> list[int]:
    """The DOFs (0-5) whose excitation lines are fewer than two: where a force delay and
    damping cannot be told apart."""
    return [k for k, f in enumerate(lines) if len(f) < 2]


def delay_identifiable(datasets: Sequence[Dataset]) -> bool:
    """Whether the experiments tell a force delay from damping: two or more excitation lines
    in every DOF (what :func:`estimate_delay` requires)."""
    return not single_frequency_dofs(excitation_lines(datasets, padding=COUNTING_PADDING))


def single_frequency_bias(datasets: Sequence[Dataset], platform: Platform,
                          lines: tuple[tuple[float, ...], ...] | None = None
                          ) -> dict[str, Any] | None:
    """Where a force delay cannot be told from damping, and what it would do to Bt.

    Returns None when every DOF moves at two or more frequencies, else ``{"dofs", "frequencies_hz",
    "bt_diagonal_per_ms"}``. ``lines``: the excitation lines per DOF, if already found.
    """
    lines = excitation_lines(datasets, padding=COUNTING_PADDING) if lines is None else lines
    single = single_frequency_dofs(lines)
    if not single:
        return None
    frequencies = []
    for k, found in enumerate(lines):
        if len(found) < 2:  # its one line, or none: a still DOF
            frequencies.append(found[0] if found else np.nan)
            continue
        most = max(datasets, key=lambda d: float(np.ptp(d.pose[:, k])))
        frequencies.append(estimate_frequency(most.pose[:, k], most.sample_rate))
    reference = datasets[0]
    bias = delay_bias_per_ms(platform, frequencies, generalized_force_sensitivity(
        platform, reference.pose, reference.forces))
    return {"dofs": [COORDINATES[k] for k in single], "frequencies_hz": frequencies,
            "bt_diagonal_per_ms": bias.tolist()}


def describe_bias(found: dict[str, Any]) -> str:
    """The bias of :func:`single_frequency_bias` in words."""
    return ", ".join(f"Bt({k + 1},{k + 1}) {b:+.4g}"
                     for k, b in enumerate(found["bt_diagonal_per_ms"]) if np.isfinite(b)) \
        + " per ms"


def check_delay_identifiable(datasets: Sequence[Dataset], platform: Platform
                             ) -> tuple[tuple[float, ...], ...]:
    """The excitation lines per DOF, when every DOF holds two or more.

    Raises
    ------
    IdentificationError
        Naming the single-frequency DOFs and the Bt bias per ms.
    """
    lines = excitation_lines(datasets)
    found = single_frequency_bias(datasets, platform, lines)
    if found is None:
        return lines
    named = ", ".join(f"{name} ({found['frequencies_hz'][COORDINATES.index(name)]:.3g} Hz)"
                      for name in found["dofs"])
    raise IdentificationError(
        f"the force delay cannot be estimated: {named} moved at one frequency only, where a "
        f"delay and damping cannot be told apart (each ms of delay the forces lag adds "
        f"tau (w^2 Mt + K) to Bt: {describe_bias(found)}); excite every DOF at two or more "
        "frequencies (stewartid design), or give a known delay (--delay SECONDS).")


def _filtered_rows(dataset: Dataset, platform: Platform, window: float
                   ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Kernel-filtered rows: q_ddot, q_dot, y (N', 6), shared (N', s + 1, 6) = the Coulomb terms
    (3 joint types, and the legs' for an electric actuator) and -y_dot."""
    # the model's departure from its linearisation subtracted, as the methods do: on equally
    # spaced lines its products fall on the lines and pass for a delay
    experiment = prepare_experiment(dataset, platform, gravity=True, joints=True, remainder=True)
    rate = experiment.sample_rate
    # the Coulomb signs need rates at every sample; they only decide signs
    _, q_dot_sign, _ = differentiate(experiment.q, rate, window / 4, DEFAULT_ORDER)
    coulomb = coulomb_regressors(experiment.joint_jacobians, q_dot_sign, COULOMB_SMOOTHING)
    if uses_leg_coulomb(None, platform):  # a ball screw's friction would pass for a delay
        coulomb = np.concatenate([coulomb, leg_coulomb_regressor(
            experiment.leg_jacobian, q_dot_sign, COULOMB_SMOOTHING)], axis=1)
    y = experiment.generalized_force
    filtered = kernel_filter(np.concatenate([y, coulomb.reshape(len(y), -1)], axis=1), rate,
                             window, derivatives=1)
    _, q_dot, q_ddot = kernel_filter(experiment.q, rate, window, derivatives=2)
    shared = np.concatenate([filtered[0][:, 6:].reshape(len(q_dot), -1, 6),
                             -filtered[1][:, None, :6]], axis=1)
    return q_ddot, q_dot, filtered[0][:, :6], shared


def shared_least_squares(phi: np.ndarray, y: np.ndarray, shared: np.ndarray,
                         groups: np.ndarray, lags: int) -> tuple[np.ndarray, np.ndarray]:
    """Shared coefficients c of y = theta phi + sum_s c_s S_s, with robust standard errors.

    theta partialled out (Frisch-Waugh); channels weighted by residual variance; sandwich covariance
    with a Newey-West long-run covariance, experiments (``groups``) independent. Returns c, std (s,).

    Raises
    ------
    IdentificationError
        When the shared terms are not independent of the per-channel regressors.
    """
    basis, _ = np.linalg.qr(phi)
    y_partial = y - basis @ (basis.T @ y)
    s_partial = shared - np.einsum("kp,psi->ksi", basis, np.einsum("kp,ksi->psi", basis, shared))
    gram = np.einsum("ksi,kti->ist", s_partial, s_partial)
    rhs = np.einsum("ksi,ki->is", s_partial, y_partial)
    weights = 1.0 / np.maximum(np.mean(y_partial ** 2, axis=0), np.finfo(float).tiny)
    for _ in range(2):
        A = np.einsum("i,ist->st", weights, gram)
        scale = np.sqrt(np.diag(A))
        if not np.all(scale > 0) or np.linalg.cond(A / np.outer(scale, scale)) > 1e10:
            raise IdentificationError("the delay and Coulomb terms are not independent of "
                                      "the inertial and viscous ones in these experiments; "
                                      "excite every DOF at two or more frequencies.")
        c = np.linalg.solve(A, np.einsum("i,is->s", weights, rhs))
        residual = y_partial - np.einsum("ksi,s->ki", s_partial, c)
        weights = 1.0 / np.maximum(np.mean(residual ** 2, axis=0), np.finfo(float).tiny)
    scores = np.einsum("i,ksi,ki->ks", weights, s_partial, residual)
    omega = np.zeros((len(c), len(c)))
    for group in np.unique(groups):
        g = scores[groups == group]
        omega += g.T @ g
        for lag in range(1, min(lags, len(g) - 1) + 1):
            cross = g[lag:].T @ g[:-lag]
            omega += (1.0 - lag / (lags + 1.0)) * (cross + cross.T)
    A_inv = np.linalg.inv(A)
    covariance = A_inv @ omega @ A_inv
    return c, np.sqrt(np.clip(np.diag(covariance), 0.0, None))


def _experiment_rows(work: tuple, e: int) -> tuple[np.ndarray, ...]:
    """Experiment ``e``'s kernel-filtered rows, every ``decimate``-th (``work``: the experiments,
    the platform, the window and ``decimate``): one task of :func:`fit_delay`."""
    datasets, platform, window, decimate = work
    return tuple(np.ascontiguousarray(a[::decimate])
                 for a in _filtered_rows(datasets[e], platform, window))


def fit_delay(datasets: Sequence[Dataset], platform: Platform, window: float,
              decimate: int = 1, jobs: int | None = 1) -> tuple[float, float]:
    """One weak-form least-squares fit of the delay (first order in tau); returns delay, std_error
    in s. ``jobs``: worker processes filtering the experiments side by side (None: every core;
    :func:`~stewartid.parallel.inheriting_workers`)."""
    n_exp = len(datasets)
    phis, ys, shared, groups = [], [], [], []
    rows = run_in_order(_experiment_rows, range(n_exp), inheriting_workers(jobs, n_exp),
                        shared=(list(datasets), platform, window, decimate))
    for e, (q_ddot, q_dot, y, terms) in enumerate(rows):
        offsets = np.zeros((len(y), n_exp))
        offsets[:, e] = 1.0
        phis.append(np.concatenate([q_ddot, q_dot, offsets], axis=1))
        ys.append(y)
        shared.append(terms)
        groups.append(np.full(len(y), e))
    # the filtered noise is correlated over 2 windows (the kernel's autocorrelation support)
    lags = int(np.ceil(2 * window * min(d.sample_rate for d in datasets) / decimate))
    c, std = shared_least_squares(np.concatenate(phis), np.concatenate(ys),
                                  np.concatenate(shared), np.concatenate(groups), lags)
    return float(c[-1]), float(std[-1])


def estimate_delay(datasets: Sequence[Dataset], platform: Platform, window: float | None = None,
                   iterations: int = 1, jobs: int | None = 1) -> DelayEstimate:
    """Estimate the delay of the force channels relative to the motion, with its standard error.

    Parameters
    ----------
    datasets : sequence of Dataset
        Logged with one acquisition chain (one delay for all).
    platform : Platform
    window : float, optional
        Kernel support, s; default :data:`WINDOW_PERIODS` periods of the highest line.
    iterations : int
        Refits on the aligned experiments (0 keeps the first pass).
    jobs : int or None
        Worker processes filtering the experiments side by side (None: every core); the
        estimate does not depend on it.

    Raises
    ------
    IdentificationError
        A DOF moved at a single frequency, or the regression is rank deficient.
    ConfigError
        A non-positive window or a negative number of iterations.
    """
    if iterations < 0 or int(iterations) != iterations:
        raise ConfigError(f"The 'iterations' parameter of estimate_delay must be an int in "
                          f"the range [0, inf). Got {iterations!r} instead.")
    datasets = list(datasets)
    lines = check_delay_identifiable(datasets, platform)
    if window is None:
        window = WINDOW_PERIODS / max(f[-1] for f in lines)
    elif not (window > 0 and np.isfinite(window)):
        raise ConfigError(f"The 'window' parameter of estimate_delay must be a positive "
                          f"number of seconds. Got {window!r} instead.")
    decimate = max(1, int(window * min(d.sample_rate for d in datasets) / 20))
    delay, std = fit_delay(datasets, platform, window, decimate, jobs)
    first = delay
    for _ in range(int(iterations)):
        step, std = fit_delay(align_forces(datasets, delay), platform, window, decimate, jobs)
        delay += step
    return DelayEstimate(seconds=delay, std_error=float(np.hypot(std, MODEL_FLOOR_S)),
                         own_std_error=std, first_pass=first, lines_hz=lines,
                         window_s=float(window))


#: ``delay`` value of :func:`apply_delay` (and ``identify --delay``) that estimates it first.
AUTO = "auto"

#: Largest given delay, in periods of the motion's dominant line: a force channel a quarter
#: period late is 90 degrees out of phase with the motion, where filters and buses delay by ms.
GIVEN_DELAY_PERIODS = 0.25


def check_given_delay(datasets: Sequence[Dataset], seconds: float) -> None:
    """Refuse a given delay of :data:`GIVEN_DELAY_PERIODS` or more of the period of the motion's
    dominant line (the fastest of the records' :func:`estimate_frequency`, which every method
    reads too): most often milliseconds written as seconds.

    Raises
    ------
    ConfigError
        Naming the delay, the line and its period, and the unit.
    """
    if seconds == 0:
        return
    dominant = max(estimate_frequency(d.pose, d.sample_rate) for d in datasets)
    if abs(seconds) < GIVEN_DELAY_PERIODS / dominant:
        return
    raise ConfigError(
        f"a force delay of {seconds:g} s is {100 * abs(seconds) * dominant:.3g} % of the period "
        f"of the motion's dominant line ({dominant:.3g} Hz, {1 / dominant:.3g} s): forces that "
        f"far off are out of phase with the motion, where a force channel lags by milliseconds; "
        f"give the delay in seconds, under {GIVEN_DELAY_PERIODS / dominant:.3g} s here (--delay "
        "0.002 for 2 ms).")


def parse_delay(value: str | float | None) -> str | float | None:
    """A delay setting: None, :data:`AUTO`, or a finite number of seconds (also as text).

    Raises
    ------
    ConfigError
        Anything else.
    """
    if value is None or value == AUTO:
        return value
    try:
        seconds = float(value)
    except (TypeError, ValueError):
        seconds = float("nan")
    if not np.isfinite(seconds):
        raise ConfigError(f"--delay must be a number of seconds (0.002 for 2 ms, negative when "
                          f"the forces lead the motion) or 'auto'; got {value!r}.")
    return seconds


def apply_delay(datasets: Sequence[Dataset], platform: Platform, delay: str | float | None,
                jobs: int | None = 1) -> tuple[list[Dataset], dict[str, Any] | None]:
    """The experiments with their forces aligned with the motion, and the ``"delay"`` result entry.

    ``delay``: seconds (positive when forces are logged late), :data:`AUTO` to estimate it, or None
    to return the data as logged (entry None); ``jobs`` as :func:`estimate_delay`.

    Raises
    ------
    ConfigError
        A delay that is neither a number nor 'auto', one longer than the records, or one of a
        quarter period of the motion or more (:func:`check_given_delay`).
    IdentificationError
        'auto' where the delay cannot be estimated.
    """
    delay = parse_delay(delay)
    datasets = list(datasets)
    if delay is None:
        return datasets, None
    if delay == AUTO:
        estimate = estimate_delay(datasets, platform, jobs=jobs)
        return align_forces(datasets, estimate.seconds), estimate.to_dict(applied=True)
    check_given_delay(datasets, float(delay))
    entry = {"seconds": float(delay), "std_error": None, "applied": True, "source": "given"}
    return align_forces(datasets, float(delay)), entry


__all__ = ["AUTO", "GIVEN_DELAY_PERIODS", "DelayEstimate", "apply_delay",
           "check_delay_identifiable", "check_given_delay", "delay_bias_per_ms",
           "delay_identifiable", "describe_bias", "estimate_delay", "fit_delay", "parse_delay",
           "shared_least_squares", "single_frequency_bias", "single_frequency_dofs"]
