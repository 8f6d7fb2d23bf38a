"""Predicted standard errors of the physical model's parameters for a design, from the
channel-weighted regression's sandwich covariance (:func:`sandwich_covariance`).
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping
from typing import Any

import numpy as np
import scipy.signal

from stewartid.design.candidates import Design
from stewartid.design.physical.payload_accuracy import (
    REQUIRED_PAYLOAD_ACCURACY,
    payload_criterion,
    payload_std_errors,
)
from stewartid.design.pose_noise import pose_noise_scores
from stewartid.model import regressor as reg
from stewartid.physical.estimator import (
    POSITIVE_PARAMETERS,
    parameter_model,
)
from stewartid.physical.regression import leg_force_transforms
from stewartid.platform import Platform
from stewartid.signals.differentiation import default_window, estimate_frequency, kernel_taps
from stewartid.simulation.sensors import SensorNoise

#: Rate (Hz) the regressor is summed at along a commanded motion: at least ten samples per
#: period of the fastest motion of the search.
INFORMATION_RATE = 25.0


@dataclasses.dataclass(frozen=True)
class ParameterPrediction:
    """Predicted standard errors of the physical model's parameters for one design.

    Attributes
    ----------
    names : tuple of str
        Every fitted parameter, nuisance ones included.
    nominal, std_errors : ndarray, shape (p,)
        File values; standard errors with every parameter estimated.
    expected_std_errors : ndarray, shape (p,)
        Once the parameters the estimator would fix are fixed (NaN for those).
    fixed : tuple of str
        Those parameters.
    expected_covariance : ndarray, shape (p, p)
        NaN rows and columns for the fixed.
    sizes : ndarray, shape (p,)
        What a relative standard error is taken of; 0 for nuisance parameters.
    payload : bool
    accuracy : mapping of str to float
        Payload mode's required accuracies
        (:data:`~stewartid.design.physical.payload_accuracy.REQUIRED_PAYLOAD_ACCURACY`).
    """

    names: tuple[str, ...]
    nominal: np.ndarray
    std_errors: np.ndarray
    expected_std_errors: np.ndarray
    fixed: tuple[str, ...]
    expected_covariance: np.ndarray
    sizes: np.ndarray
    payload: bool
    accuracy: Mapping[str, float] = dataclasses.field(
        default_factory=lambda: dict(REQUIRED_PAYLOAD_ACCURACY))

    @property
    def judged(self) -> np.ndarray:
        """Mask of the parameters the criterion is over (the moving body's or payload's)."""
        return self.sizes > 0

    @property
    def relative_std(self) -> np.ndarray:
        """Expected standard error over each judged parameter's size (%); NaN for the others."""
        with np.errstate(divide="ignore", invalid="ignore"):
            return np.where(self.judged, 100 * self.expected_std_errors / self.sizes, np.nan)

    @property
    def worst_relative_std(self) -> float:
        """Largest relative standard error over the judged parameters (%)."""
        return float(np.nanmax(self.relative_std))

    @property
    def worst_parameter(self) -> str:
        """The judged parameter with the largest relative standard error."""
        return self.names[int(np.nanargmax(self.relative_std))]

    @property
    def payload_std_errors(self) -> dict[str, float] | None:
        """Payload mode: the payload's quantities' standard errors; else None."""
        if not self.payload:
            return None
        return payload_std_errors(self.names, self.nominal, self.expected_covariance)

    @property
    def criterion(self) -> float:
        """What the design is judged by: payload mode, the largest ratio of standard error to
        required accuracy; else the worst relative standard error (%).
        """
        if self.payload:
            return payload_criterion(self.payload_std_errors, self.accuracy)[0]
        return self.worst_relative_std

    def to_dict(self) -> dict[str, Any]:
        """Per parameter: nominal value, predicted SE and relative SE (%, None for nuisance); JSON ready."""
        relative = self.relative_std
        out = {"mode": "payload" if self.payload else "full", "criterion": self.criterion,
                "worst_relative_std_percent": self.worst_relative_std,
                "worst_parameter": self.worst_parameter, "fixed": list(self.fixed),
                "parameters": {name: {"nominal": float(self.nominal[k]),
                                      "std_error": float(self.std_errors[k]),
                                      "expected_std_error": (
                                          None if name in self.fixed
                                          else float(self.expected_std_errors[k])),
                                      "relative_std_percent": (float(relative[k])
                                                               if self.judged[k] else None)}
                               for k, name in enumerate(self.names)}}
        if self.payload:
            out["payload_std_errors"] = self.payload_std_errors
            out["required_accuracy"] = dict(self.accuracy)
        return out


def parameter_sizes(names: tuple[str, ...], nominal: np.ndarray) -> np.ndarray:
    """Size each parameter's relative standard error is taken of; 0 for those not judged.

    Mass against itself, first moments against the first-moment vector's length (at least
    mass x radius of gyration / 10), inertia entries against the diagonal's mean: frame invariant.
    """
    values = dict(zip((n.removeprefix("payload.") for n in names), nominal, strict=True))
    mass = abs(values.get("m", 0.0))
    diagonal = np.mean([abs(values.get(f"I_{a}{a}", 0.0)) for a in "xyz"])
    gyration = math.sqrt(1.5 * diagonal / mass) if mass > 0 else 0.0  # tr(I) / 2 m
    moment = math.hypot(*(values.get(f"mc_{a}", 0.0) for a in "xyz"))
    sizes = np.zeros(len(names))
    for k, name in enumerate(names):
        short = name.removeprefix("payload.")
        if short not in reg.BODY_PARAMETERS:
            continue
        if short == "m":
            sizes[k] = mass
        elif short.startswith("mc_"):
            sizes[k] = max(moment, 0.1 * mass * gyration)
        else:
            sizes[k] = diagonal
    return sizes


def force_noise_covariance(noise: SensorNoise, rows: int) -> np.ndarray:
    """Leg force noise covariance S per row, shape (rows, 6, 6), N^2."""
    sigma = np.broadcast_to(np.asarray(noise.force_noise, dtype=float), 6)
    return np.broadcast_to(np.diag(sigma ** 2), (rows, 6, 6))


def channel_weights(S: np.ndarray) -> np.ndarray:
    """Per-leg weights W, shape (6,), 1/N^2: inverse mean noise variance over the rows of ``S``."""
    return 1.0 / np.mean(np.diagonal(S, axis1=1, axis2=2), axis=0)


def sandwich_covariance(X: np.ndarray, S: np.ndarray, samples_per_row: float,
                        noise_rows: np.ndarray | None = None,
                        extra: np.ndarray | None = None) -> np.ndarray:
    """Channel-weighted least-squares covariance (p, p) of rows ``X`` (K, 6, p) with noise ``S`` (K, 6, 6):

        Cov = A^-1 B A^-1,   A = sum_k X_k^T W X_k,   B = sum_k X_k^T W S_k W X_k

    Each row stands for ``samples_per_row`` logged samples; B is taken of ``noise_rows`` when given
    (kernel-filtered rows), plus ``extra`` (:func:`~stewartid.design.pose_noise.pose_noise_scores`).
    """
    weights = channel_weights(S)
    Z = weights[None, :, None] * X  # W X
    A = np.einsum("kcp,kcq->pq", X, Z, optimize=True)
    if noise_rows is not None:
        Z = weights[None, :, None] * noise_rows
    B = np.einsum("kcp,kcd,kdq->pq", Z, S, Z, optimize=True)
    if extra is not None:
        B = B + extra
    scale = np.sqrt(np.diag(A))
    scale = np.where(scale > 0, scale, 1.0)
    inverse = np.linalg.pinv(A / np.outer(scale, scale), rcond=1e-14) / np.outer(scale, scale)
    return inverse @ B @ inverse / samples_per_row


def record_rows(design: Design, rate_hz: float = INFORMATION_RATE) -> list[int]:
    """Rows of each record in :func:`design_rows` at ``rate_hz``."""
    return [int(math.floor(r.duration * rate_hz)) + 1 for r in design.records]


def record_ends(design: Design, rate_hz: float = INFORMATION_RATE) -> np.ndarray:
    """Each record's first row in :func:`design_rows`, then the total; shape (records + 1,)."""
    return np.cumsum([0, *record_rows(design, rate_hz)])


def design_rows(platform: Platform, design: Design, rate_hz: float = INFORMATION_RATE
                ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Commanded q, q_dot, q_ddot of every record at ``rate_hz``, concatenated, each (K, 6)."""
    parts = [playable.evaluate(np.arange(rows) / rate_hz) for playable, rows
             in zip(design.playable(platform), record_rows(design, rate_hz), strict=True)]
    return tuple(np.concatenate(x) for x in zip(*parts, strict=True))


def played_states(records: list, design: Design, rate_hz: float
                  ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Motion of a design's records as the plant played them (tracking errors included),
    q, q_dot, q_ddot, each (K, 6), at ``rate_hz``.

    ``records`` are :func:`~stewartid.design.prediction.plant_records`, one per record, from 0 s.
    """
    parts = []
    for record, rows in zip(records, record_rows(design, rate_hz), strict=True):
        t = np.arange(rows) / rate_hz
        parts.append([np.stack([np.interp(t, record.t, x[:, j]) for j in range(6)], axis=1)
                      for x in (record.q, record.q_dot, record.q_ddot)])
    return tuple(np.concatenate(x) for x in zip(*parts, strict=True))


def record_kernels(design: Design, rate_hz: float, q: np.ndarray) -> list[np.ndarray]:
    """Each record's taps of the physical estimator's kernel at ``rate_hz``."""
    ends = record_ends(design, rate_hz)
    return [kernel_taps(rate_hz, default_window(estimate_frequency(q[a:b], rate_hz)))[0]
            for a, b in zip(ends[:-1], ends[1:], strict=True)]


def kernel_filtered(design: Design, rate_hz: float, q: np.ndarray, X: np.ndarray,
                    taps: list[np.ndarray] | None = None
                    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Pose ``q`` (K, 6) and regressor ``X`` (K, 6, p) filtered per record with the estimator's
    kernel, record ends dropped.

    Returns q, X and ``noise_rows`` = h * h * X (the filtered noise is correlated over the kernel).
    """
    ends = record_ends(design, rate_hz)
    poses, rows, twice = [], [], []
    taps = record_kernels(design, rate_hz, q) if taps is None else taps
    for (a, b), h in zip(zip(ends[:-1], ends[1:], strict=True), taps, strict=True):
        poses.append(scipy.signal.convolve(q[a:b], h[:, None], mode="valid"))
        rows.append(scipy.signal.convolve(X[a:b], h[:, None, None], mode="valid"))
        twice.append(scipy.signal.convolve(rows[-1], h[:, None, None], mode="same"))
    return np.concatenate(poses), np.concatenate(rows), np.concatenate(twice)


def predict_parameters(platform: Platform, design: Design, noise: SensorNoise,
                       payload: bool = False, rate_hz: float = INFORMATION_RATE,
                       max_relative_error: float = 0.3,
                       states: tuple[np.ndarray, np.ndarray, np.ndarray] | None = None,
                       rows: np.ndarray | None = None, filtered: bool = False
                       ) -> ParameterPrediction:
    """Predicted standard errors of the physical model's parameters for a design.

    Parameters
    ----------
    platform : Platform
        With the expected payload in payload mode.
    design : Design
    noise : SensorNoise
        ``force_noise`` (N); with ``filtered``, ``length_noise`` (m) too.
    payload : bool
        Judge the payload's ten parameters on the known platform; else every base parameter.
    rate_hz : float
        Rate the regressor is summed at (Hz).
    max_relative_error : float
        The estimator's: a positive parameter whose standard error exceeds this fraction of its
        size is fixed, worst first.
    states : tuple of ndarray, optional
        (q, q_dot, q_ddot) at ``rate_hz``: :func:`design_rows` or :func:`played_states`.
    rows : ndarray, shape (K, 6, N_STANDARD), optional
        Standard regressor at ``states``, when already computed.
    filtered : bool
        Filter with the estimator's kernel and add the pose noise's share; needs ``rate_hz``
        >= 100 Hz.
    """
    names, _, selection, nominal, _ = parameter_model(platform, payload)
    states = design_rows(platform, design, rate_hz) if states is None else states
    q = states[0]
    X = (reg.regressor(platform, *states) if rows is None else rows) @ selection.T
    twice = taps = None
    if filtered:
        taps = record_kernels(design, rate_hz, q)
        q, X, twice = kernel_filtered(design, rate_hz, q, X, taps)
    to_legs = leg_force_transforms(platform, q)
    X = np.einsum("kij,kjp->kip", to_legs, X, optimize=True)
    if twice is not None:
        twice = np.einsum("kij,kjp->kip", to_legs, twice, optimize=True)
    S = force_noise_covariance(noise, len(q))
    per_row = platform.sensors.sample_rate / rate_hz
    extra = np.zeros((len(names),) * 2)
    if filtered:
        extra = pose_noise_scores(
            platform, noise, rate_hz, states, record_ends(design, rate_hz),
            taps, X, to_legs, channel_weights(S), reg.standard_parameters(platform))
    # the estimator's own rule for what it fixes (PhysicalIdentifier's scales)
    positive = np.isin(reg.PARAMETERS, POSITIVE_PARAMETERS)
    size = np.maximum(np.abs(nominal), selection @ np.where(
        positive, np.abs(reg.standard_parameters(platform)), 0.0))
    fixable = selection @ positive > 0
    free = np.ones(len(names), dtype=bool)
    while True:
        covariance = np.full((len(names),) * 2, np.nan)
        covariance[np.ix_(free, free)] = sandwich_covariance(
            X[:, :, free], S, per_row, None if twice is None else twice[:, :, free],
            extra[np.ix_(free, free)])
        std = np.sqrt(np.clip(np.diag(covariance), 0.0, None))
        if free.all():
            every = std.copy()
        with np.errstate(divide="ignore", invalid="ignore"):
            ratio = np.where(free & fixable & (size > 0), std / size, 0.0)
        if not ratio.max() > max_relative_error:
            break
        free[int(np.argmax(ratio))] = False
    return ParameterPrediction(tuple(names), np.asarray(nominal, dtype=float), every, std,
                               tuple(n for n, f in zip(names, free, strict=True) if not f),
                               covariance, parameter_sizes(tuple(names), nominal), payload)


__all__ = ["INFORMATION_RATE", "ParameterPrediction", "channel_weights", "design_rows",
           "force_noise_covariance", "kernel_filtered", "parameter_sizes", "played_states",
           "predict_parameters", "record_ends", "record_kernels", "record_rows",
           "sandwich_covariance"]
