"""Constant-direction intervals of one measured experiment: the interval step of Method B.

Smoothed joint rates are cut where an active joint reverses beyond its noise band.
"""

from __future__ import annotations

import warnings
from collections.abc import Sequence
from typing import NamedTuple

import numpy as np

from stewartid.arrays import median
from stewartid.errors import DataWarning, IdentificationError
from stewartid.identification.preparation import Experiment
from stewartid.identification.wavelet.intervals import constant_direction_intervals, joint_rates
from stewartid.identification.wavelet.noise import NoiseModel, joint_rate_noise
from stewartid.model.kinematics import joint_axis_rates
from stewartid.platform import COORDINATES
from stewartid.signals.differentiation import (
    acceleration_frequency,
    default_window,
    estimate_frequency,
)
from stewartid.signals.sign_rates import (
    SIGN_NOISE,
    SIGN_ORDER,
    coulomb_sign_rates,
    sign_rates,
)


class Detection(NamedTuple):
    """Constant-direction intervals of one experiment and what their detection measured.

    Attributes
    ----------
    intervals : ndarray, shape (M, 2)
        Usable [start, stop], s.
    info : dict
        Counts, lengths, window, pose-noise covariance, force white-noise variance.
    joint_rates, sign_rates : ndarray, shape (N, 6, 5)
        Smoothed joint-axis rates, and those the Coulomb signs use, rad/s.
    rate_noise, sign_rate_noise : ndarray, shape (6, 5)
        Their noise levels, rad/s.
    q_dot, q_ddot : ndarray, shape (N, 6)
        Savitzky-Golay derivatives of the pose.
    leg_sign_rates : ndarray, shape (N, 6)
        The leg-length rates the Coulomb signs along the legs use, m/s.
    leg_sign_rate_noise : ndarray, shape (6,)
        Their noise levels, m/s.
    sign_window : float
        The Savitzky-Golay window of the signs' rates, s.
    mean_jacobian : ndarray, shape (36, 6), or None
        :func:`~stewartid.identification.wavelet.noise.mean_rate_jacobian` of the experiment.
    """

    intervals: np.ndarray
    info: dict
    joint_rates: np.ndarray
    rate_noise: np.ndarray
    q_dot: np.ndarray
    q_ddot: np.ndarray
    sign_rates: np.ndarray
    sign_rate_noise: np.ndarray
    leg_sign_rates: np.ndarray
    leg_sign_rate_noise: np.ndarray
    sign_window: float = float("nan")
    mean_jacobian: np.ndarray | None = None


#: Largest noise of the Coulomb signs' rates relative to their RMS
#: (:func:`~stewartid.signals.sign_rates.coulomb_sign_rates`), the other methods' rule: a lower
#: limit takes the signs from longer windows, whose rounded reversals bias Mt.
SIGN_NOISE_LIMIT = SIGN_NOISE
#: Joints whose rate RMS is below this multiple of its noise level count as idle.
IDLE_NOISE_RATIO = 2.0
#: A DOF moved by the experiments that gave intervals less than this fraction of its largest
#: motion in any experiment has lost its excitation.
COVERAGE_FRACTION = 0.1


def raise_no_interval(infos: Sequence[dict]) -> None:
    """Raise for data without a usable interval, naming the longest found and the need."""
    longest = max(info["longest_interval"] for info in infos)
    needed = min(info["shortest_usable"] for info in infos)
    raise IdentificationError(
        f"no constant-direction interval long enough for the smallest wavelet scale "
        f"in any experiment (longest {longest:.3g} s, at least {needed:.3g} s needed); "
        "use friction='coulomb' (windows across reversals) or '--method ls', excite with "
        "a slower single-frequency sine ('stewartid design'), or lower 'margin' or "
        "'min_support_samples'.")


def check_coverage(names: Sequence[str], motion: np.ndarray, counts: Sequence[int]) -> None:
    """Warn for every experiment without a usable interval; raise if they alone moved a DOF.

    ``motion`` (n_experiments, 6): RMS of each pose coordinate, m, rad; ``counts``: usable intervals.
    """
    counts = np.asarray(counts)
    for name, count in zip(names, counts, strict=True):
        if count == 0:
            warnings.warn(f"{name}: no usable constant-direction interval (joint rates within "
                          f"their noise, or reversals too close together); it adds nothing "
                          f"to Method B", DataWarning, stacklevel=3)
    largest = motion.max(axis=0)
    kept = motion[counts > 0].max(axis=0) if np.any(counts > 0) else np.zeros(6)
    lost = [c for c, k, top in zip(COORDINATES, kept, largest, strict=True)
            if top > 0 and k < COVERAGE_FRACTION * top]
    if lost:
        raise IdentificationError(
            f"DOF {', '.join(lost)} lost its excitation: the experiments that move it most "
            f"({', '.join(n for n, c in zip(names, counts, strict=True) if c == 0)}) gave no "
            f"usable constant-direction interval; check their joint-rate noise in the "
            f"diagnostics, or lower hysteresis / margin")


#: Share of every moving pose channel's variance one sine must explain for an experiment to
#: count as the paper's protocol (one sine per experiment).
SINGLE_SINE_SHARE = 0.9


def sine_share(lengths: np.ndarray, sample_rate: float, frequency: float) -> float:
    """Share in [0, 1] of the leg-length variance (N, 6) one sine at ``frequency`` (Hz, the
    motion's dominant one) explains over the record's later half.

    The later half: a fade-in from rest is no second frequency, yet on a short record (2 s of
    fade in 5 s) it leaves 15 % of the whole record's variance to any one sine.
    """
    lengths = lengths[len(lengths) // 2:]
    t = np.arange(len(lengths)) / sample_rate
    basis = np.column_stack([np.sin(2 * np.pi * frequency * t),
                             np.cos(2 * np.pi * frequency * t), np.ones_like(t), t - t.mean()])
    centered = lengths - lengths.mean(axis=0)
    residual = centered - basis @ np.linalg.lstsq(basis, centered, rcond=None)[0]
    power = np.mean(centered ** 2, axis=0)
    moving = power > 1e-2 * power.max()
    return float(1.0 - np.sum(np.mean(residual ** 2, axis=0)[moving]) / np.sum(power[moving]))


def excitation_scales(experiment: Experiment, window: float | None, margin: float | None,
                      margin_periods: float) -> tuple[float, float]:
    """The Savitzky-Golay window and the interval margin of one experiment, s.

    None for either: the window from the pose's line of largest acceleration
    (:func:`~stewartid.signals.differentiation.acceleration_frequency`: it caps the window of the
    Coulomb signs' rates, whose rounding of the reversals biases Mt), the margin ``margin_periods``
    periods of its dominant line.
    """
    if window is None:
        fastest = acceleration_frequency(experiment.q, experiment.sample_rate)
        duration = float(experiment.t[-1] - experiment.t[0])
        if default_window(fastest) > duration:
            raise IdentificationError(
                f"{experiment.name}: the record lasts {duration:.3g} s, shorter than the "
                f"differentiation window ({default_window(fastest):.3g} s) its motion's "
                f"frequency ({fastest:.3g} Hz found) sets: record a longer experiment, or give "
                "differentiation_window and margin (s).")
        window = default_window(fastest)
    if margin is None:
        margin = margin_periods / estimate_frequency(experiment.q, experiment.sample_rate)
    return window, margin


def detect_intervals(experiment: Experiment, noise: NoiseModel, *, margin: float,
                     hysteresis: float, ignore_below: float, min_interval: float | None,
                     min_support_samples: int, smallest: float) -> Detection:
    """Usable constant-direction intervals of one experiment.

    Parameters
    ----------
    experiment : Experiment
        With its joint-axis Jacobians.
    noise : NoiseModel
    margin : float
        Cut from both ends of every interval, s.
    hysteresis : float
        Noise multiples inside which a direction is unknown.
    ignore_below : float
        Joints slower than this fraction of the fastest of their kind are left out.
    min_interval : float or None
        Shortest usable interval, s; None: half the median.
    min_support_samples : int
        Fewest samples the smallest test function may cover.
    smallest : float
        Smallest support as a fraction of an interval.
    """
    t, period, rate_noise = experiment.t, experiment.period, noise.rate_noise
    rates = joint_rates(experiment.platform, experiment.q, noise.q_dot,
                        experiment.joint_jacobians, experiment.leg_jacobian)
    # a joint whose rate is no larger than its noise has no direction to keep; an infinite
    # threshold leaves it out (its rates still give the friction pattern)
    idle = np.sqrt(np.mean(np.square(rates), axis=0)) < IDLE_NOISE_RATIO * rate_noise
    found = constant_direction_intervals(t, rates, margin=margin, ignore_below=ignore_below,
                                         hysteresis=np.where(idle, np.inf,
                                                             hysteresis * rate_noise))
    lengths = found[:, 1] - found[:, 0]
    shortest = (min_interval if min_interval is not None
                else 0.5 * median(lengths) if len(lengths) else 0.0)
    needed = min_support_samples * period / smallest
    intervals = found[lengths >= max(shortest, needed)]
    info = {"name": experiment.name, "intervals_found": int(len(found)),
            "longest_interval": float(lengths.max()) if len(lengths) else 0.0,
            "shortest_usable": float(max(shortest, needed)),
            "intervals": intervals, "differentiation_window": float(noise.window),
            "noise_covariance": noise.pose_covariance,
            "force_noise_variance": noise.force_variance}
    # a floor keeps the direction weights of noise-free data finite
    return Detection(intervals=intervals, info=info,
                     joint_rates=rates[:, :30].reshape(len(t), 6, 5),
                     rate_noise=np.maximum(rate_noise[:30].reshape(6, 5), 1e-12),
                     q_dot=noise.q_dot, q_ddot=noise.q_ddot, mean_jacobian=noise.mean_jacobian,
                     **sign_rate_fields(experiment, noise.window, noise.pose_covariance,
                                        mean_jacobian=noise.mean_jacobian))


def sign_rate_fields(experiment: Experiment, window: float, pose_covariance: np.ndarray,
                     mean_jacobian: np.ndarray | None = None, chosen: float | None = None
                     ) -> dict:
    """The Coulomb signs' rates, their noise levels and window, as :class:`Detection` fields,
    for the kernel ``window`` (s) and the pose noise (6, 6); ``mean_jacobian`` as
    :func:`~stewartid.identification.wavelet.noise.joint_rate_noise`; ``chosen``: the signs'
    window (s) if already chosen (:func:`~stewartid.signals.sign_rates.sign_rates` then)."""
    if chosen is None:
        q_dot, window = coulomb_sign_rates(experiment.q, experiment.sample_rate, window,
                                           pose_covariance, SIGN_NOISE_LIMIT)
    else:
        q_dot, window = sign_rates(experiment.q, experiment.sample_rate, chosen), chosen
    jacobians = experiment.joint_jacobians
    level = joint_rate_noise(pose_covariance, experiment.sample_rate, window, jacobians,
                             experiment.leg_jacobian, SIGN_ORDER, mean_jacobian)
    return {"sign_rates": joint_axis_rates(jacobians, q_dot),
            "sign_rate_noise": np.maximum(level[:30].reshape(6, 5), 1e-12),
            "leg_sign_rates": (experiment.leg_jacobian @ q_dot[:, :, None])[:, :, 0],
            "leg_sign_rate_noise": np.maximum(level[30:], 1e-12), "sign_window": window}


__all__ = ["SINGLE_SINE_SHARE", "Detection", "check_coverage", "detect_intervals",
           "excitation_scales", "raise_no_interval", "sign_rate_fields", "sine_share"]
