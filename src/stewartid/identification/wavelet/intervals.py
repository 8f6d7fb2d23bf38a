"""Constant-direction intervals: time spans in which no joint reverses.

Inside one each joint's Coulomb friction is nearly constant (Zhang 2020, Section 3).
"""

from __future__ import annotations

from typing import TYPE_CHECKING, NamedTuple

import numpy as np

from stewartid.errors import ConfigError, DataError
from stewartid.model.joints import JOINT_AXES
from stewartid.model.kinematics import joint_axis_rates, joint_rate_jacobians
from stewartid.model.kinematics import leg_jacobian as leg_jacobian_at
from stewartid.platform import Platform

if TYPE_CHECKING:
    from stewartid.signals.wavelets import MotherWavelet

#: Names of the 36 joint rates returned by :func:`joint_rates`: 30 rotational axes
#: (leg-major, axes as JOINT_AXES) followed by the 6 actuators.
JOINT_RATE_NAMES = tuple(
    [f"leg{leg + 1}_{axis}" for leg in range(6) for axis in JOINT_AXES]
    + [f"actuator{leg + 1}" for leg in range(6)]
)


def joint_rates(platform: Platform, q: np.ndarray, q_dot: np.ndarray,
                joint_jacobians: np.ndarray | None = None,
                leg_jacobian: np.ndarray | None = None) -> np.ndarray:
    """Rates (N, 36) of the 30 rotational joint axes (rad/s) and 6 actuators (m/s), :data:`JOINT_RATE_NAMES`.

    ``q`` and ``q_dot`` (N, 6); Jacobians (N, 6, 5, 6) and (N, 6, 6) are computed unless given.
    """
    q = np.atleast_2d(np.asarray(q, dtype=float))
    q_dot = np.atleast_2d(np.asarray(q_dot, dtype=float))
    if q.shape != q_dot.shape or q.shape[1:] != (6,):
        raise DataError(f"q and q_dot must both have shape (N, 6); got {q.shape} and "
                        f"{q_dot.shape}.")
    if joint_jacobians is None:
        joint_jacobians = joint_rate_jacobians(platform, q)
    if leg_jacobian is None:
        leg_jacobian = leg_jacobian_at(platform, q)
    rates = np.empty((len(q), 36))
    joint_axis_rates(joint_jacobians, q_dot, out=rates[:, :30])
    np.einsum("nlj,nj->nl", leg_jacobian, q_dot, out=rates[:, 30:])
    return rates


def active_joints(rates: np.ndarray, ignore_below: float = 0.0) -> np.ndarray:
    """Mask (J,) of joints whose rate RMS reaches ``ignore_below`` times the largest of their kind."""
    if not 0.0 <= ignore_below < 1.0:
        raise ConfigError(
            f"ignore_below must be a fraction in [0, 1); got {ignore_below!r}."
        )
    rms = np.sqrt(np.mean(np.square(rates), axis=0))
    groups = [slice(0, 30), slice(30, 36)] if rates.shape[1] == 36 else [slice(None)]
    mask = np.ones(rates.shape[1], dtype=bool)
    for g in groups:
        top = rms[g].max() if rms[g].size else 0.0
        mask[g] = rms[g] > ignore_below * top if top > 0 else False
    return mask


def constant_direction_intervals(t: np.ndarray, rates: np.ndarray, margin: float = 0.02,
                                 min_duration: float = 0.0, ignore_below: float = 0.0,
                                 hysteresis: np.ndarray | float = 0.0) -> np.ndarray:
    """Time intervals [start, stop] (M, 2), s, in which every active joint rate keeps its sign.

    Parameters
    ----------
    t : ndarray, shape (N,)
        s, strictly increasing.
    rates : ndarray, shape (N, J)
        Only signs matter.
    margin : float
        Cut from both ends of every interval, s (a lagging friction reversal stays outside).
    min_duration : float
        Shorter intervals, after the margins, are dropped; s.
    ignore_below : float
        As :func:`active_joints`.
    hysteresis : float or ndarray, shape (J,)
        A direction is known only while |rate| exceeds it; joints never above it are left out.
    """
    t = np.asarray(t, dtype=float)
    rates = np.asarray(rates, dtype=float)
    if rates.ndim == 1:
        rates = rates[:, None]
    if rates.shape[0] != t.shape[0] or t.ndim != 1:
        raise DataError(f"rates must have one row per sample: t has {t.shape}, rates "
                        f"{rates.shape}.")
    if margin < 0 or min_duration < 0:
        raise ConfigError(
            f"margin and min_duration must be >= 0 s; got {margin!r} and {min_duration!r}."
        )
    mask = active_joints(rates, ignore_below)
    threshold = np.broadcast_to(np.asarray(hysteresis, dtype=float), (rates.shape[1],))
    if np.any(threshold < 0):
        raise ConfigError("hysteresis thresholds must be >= 0.")
    # an inactive joint is never confirmed (whole columns compared: selecting them costs more)
    confirmed = np.abs(rates) > np.where(mask, threshold, np.inf)
    positive = rates > 0
    kept = confirmed.any(axis=0)
    if not kept.all():
        confirmed, positive = (np.compress(kept, a, axis=1) for a in (confirmed, positive))
    n, m = confirmed.shape
    if m == 0 or n < 2:
        return np.empty((0, 2))
    # last sample (up to each one) at which each joint's direction was confirmed; a confirmed
    # rate is beyond a threshold >= 0, so its sign is that direction
    last = np.where(confirmed, np.arange(n)[:, None], -1)
    np.maximum.accumulate(last, axis=0, out=last)
    # every direction is known from the last joint's first confirmation on
    first = int(np.max(np.argmax(confirmed, axis=0)))
    known = last[first:]
    state = np.take(positive.ravel(), known * m + np.arange(m))
    changed = state[1:] != state[:-1]
    reversal = np.flatnonzero(changed.any(axis=1))
    starts = np.concatenate([[first], first + 1 + reversal])
    # end where the reversing joints last confirmed their old direction
    stops = np.append(np.where(changed[reversal], known[reversal], n).min(axis=1), n - 1)
    usable = stops > starts
    out = np.column_stack([t[starts[usable]] + margin, t[stops[usable]] - margin])
    duration = out[:, 1] - out[:, 0]
    return out[(duration > 0) & (duration >= min_duration)]


class IntervalCheck(NamedTuple):
    """Result of :func:`check_intervals`.

    Attributes
    ----------
    ok : bool
        At least ``min_count`` intervals of ``min_duration``.
    count : int
    longest : float
        s, 0 if none.
    coverage : float
        Fraction of the record covered.
    message : str
        What was found and what to change.
    """

    ok: bool
    count: int
    longest: float
    coverage: float
    message: str


def check_intervals(t: np.ndarray, rates: np.ndarray, min_duration: float,
                    min_count: int = 1, margin: float = 0.02,
                    ignore_below: float = 0.0) -> IntervalCheck:
    """Does a trajectory yield constant-direction intervals long enough for identification?"""
    t = np.asarray(t, dtype=float)
    all_intervals = constant_direction_intervals(t, rates, margin, 0.0, ignore_below)
    lengths = all_intervals[:, 1] - all_intervals[:, 0] if len(all_intervals) else np.zeros(0)
    good = lengths >= min_duration
    count = int(good.sum())
    longest = float(lengths.max()) if lengths.size else 0.0
    span = t[-1] - t[0] if len(t) > 1 else 0.0
    coverage = float(lengths[good].sum() / span) if span > 0 else 0.0
    ok = count >= min_count
    if ok:
        message = (f"{count} constant-direction intervals of at least {min_duration:.3g} s "
                   f"(longest {longest:.3g} s, {100 * coverage:.0f} % of the record).")
    else:
        message = (f"only {count} constant-direction interval(s) of at least "
                   f"{min_duration:.3g} s (longest {longest:.3g} s) where {min_count} are "
                   "needed: excite with a slower sine of one frequency in all joints, a "
                   "smaller wavelet scale, a smaller margin, or ignore idle joints "
                   "(ignore_below).")
    return IntervalCheck(ok, count, longest, coverage, message)


def wavelet_points(intervals: np.ndarray, wavelet: MotherWavelet,
                   scale_fractions: tuple[float, ...], shifts_per_scale: int,
                   ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(a, b) points whose wavelet support lies inside an interval.

    ``scale_fractions``: supports as fractions of the interval, in (0, 1]. Returns scales, shifts (K,), s,
    and the interval index of each.
    """
    scales, shifts, owner = [], [], []
    for m, (start, stop) in enumerate(intervals):
        length = stop - start
        for fraction in scale_fractions:
            a = fraction * length / (2.0 * wavelet.half_width)
            free = length - 2.0 * a * wavelet.half_width
            count = shifts_per_scale if free > 1e-9 * length else 1
            b = start + a * wavelet.half_width + np.linspace(0.0, max(free, 0.0), count)
            scales.append(np.full(count, a))
            shifts.append(b)
            owner.append(np.full(count, m))
    if not scales:
        return np.zeros(0), np.zeros(0), np.zeros(0, dtype=int)
    return np.concatenate(scales), np.concatenate(shifts), np.concatenate(owner)


__all__ = ["JOINT_RATE_NAMES", "IntervalCheck", "active_joints", "check_intervals",
           "constant_direction_intervals", "joint_rates", "wavelet_points"]
