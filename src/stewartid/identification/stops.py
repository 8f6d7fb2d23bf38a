"""Stopped legs: where a leg's rate is within its noise, its Coulomb friction follows no sign law.

A ball screw's dry friction sticks at each reversal of its leg: while the leg stands still the
friction is whatever holds it, anywhere in [-Fc, Fc], and no sign of the rate reproduces it. The
same holds wherever the measured rate is too small for its sign to be known. A fit of
Fc sign(l_dot) through such samples takes the friction of the stops for inertia and damping. So
the sign law is left out of every stop and the friction there is left free: each stop carries
Legendre polynomials in time, whose filtered signatures are projected out of the filtered rows
(one free coefficient per channel and polynomial: the friction along one leg, whatever its
course in the stop, on the scale of a filter much longer than the stop). A stop is a run of
samples whose leg rate is within :attr:`StopPolicy.band` noise levels of zero.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np
from numpy.polynomial import legendre

from stewartid.errors import IdentificationError
from stewartid.signals.differentiation import kernel_taps, savgol_coefficients, window_samples
from stewartid.signals.sign_rates import SIGN_ORDER, coulomb_sign_rates


@dataclass(frozen=True)
class StopPolicy:
    """What counts as a stop, and how much freedom its friction gets.

    Attributes
    ----------
    band : float
        A leg is stopped while |l_dot| is within this many noise levels of its sign rate (its
        sign is then not determined).
    merge : float
        Stops of one leg closer than this fraction of the filter window are one stop (the filter
        cannot tell them apart).
    terms_per_window : float
        Legendre terms of a stop: 2 (its impulse and first moment, all a filter much longer than
        the stop sees), plus this many per filter window of stop length.
    largest_share : float
        Refuse an experiment whose legs stand still for more than this share of the samples.
    """

    band: float = 3.0
    merge: float = 0.125
    terms_per_window: float = 4.0
    largest_share: float = 0.5


#: The policy the identifiers use.
STOPS = StopPolicy()


class Stop(NamedTuple):
    """One stop: ``leg`` (0-5) from sample ``start`` to ``stop`` (exclusive) with ``terms``
    Legendre polynomials."""

    leg: int
    start: int
    stop: int
    terms: int


class LegStops(NamedTuple):
    """The Coulomb sign rates of one record and the stops of its legs.

    Attributes
    ----------
    q_dot : ndarray, shape (N, 6)
        Pose rates the Coulomb signs are taken from.
    sign_window : float
        Their Savitzky-Golay window, s (:func:`~stewartid.signals.sign_rates.coulomb_sign_rates`).
    leg_rates : ndarray, shape (N, 6)
        J_lq q_dot, m/s.
    stopped : ndarray of bool, shape (N, 6)
        Samples inside a stop, per leg.
    stops : list of Stop
    """

    q_dot: np.ndarray
    sign_window: float
    leg_rates: np.ndarray
    stopped: np.ndarray
    stops: list[Stop]


def find_stops(q: np.ndarray, leg_jacobian: np.ndarray, sample_rate: float, window: float,
               pose_covariance: np.ndarray, policy: StopPolicy = STOPS) -> LegStops:
    """The legs' stops in one record.

    Parameters
    ----------
    q : ndarray, shape (N, 6)
        Pose, m and rad.
    leg_jacobian : ndarray, shape (N, 6, 6)
        J_lq at every sample.
    sample_rate : float
        Hz.
    window : float
        Filter window of the rows, s.
    pose_covariance : ndarray, shape (6, 6)
        White pose noise per sample.
    policy : StopPolicy
    """
    q_dot, sign_window = coulomb_sign_rates(q, sample_rate, window, pose_covariance)
    leg_rates = np.einsum("nlc,nc->nl", leg_jacobian, q_dot)
    taps = savgol_coefficients(window_samples(sign_window, sample_rate, SIGN_ORDER), SIGN_ORDER, 1,
                               1.0 / sample_rate)
    mean = leg_jacobian.mean(axis=0)
    noise = np.linalg.norm(taps) * np.sqrt(np.clip(
        np.einsum("ij,jk,ik->i", mean, pose_covariance, mean), 0.0, None))
    stopped, stops = leg_stop_runs(leg_rates, noise, int(policy.merge * window * sample_rate),
                                   window * sample_rate, 2, policy)
    return LegStops(q_dot, sign_window, leg_rates, stopped, stops)


def leg_stop_runs(leg_rates: np.ndarray, noise: np.ndarray, gap: int, scale: float,
                  first_terms: int, policy: StopPolicy = STOPS) -> tuple[np.ndarray, list[Stop]]:
    """Samples inside a stop (N, 6) and the stops of leg rates ``leg_rates`` (N, 6) whose noise
    levels are ``noise`` (6,), in the same unit.

    Runs at most ``gap`` samples apart are one stop; a stop of n samples carries ``first_terms``
    + ``policy.terms_per_window`` n / ``scale`` Legendre terms (``scale``: samples the rows
    resolve).
    """
    inside = np.abs(leg_rates) <= policy.band * noise
    stops, stopped = [], np.zeros_like(inside)
    for leg in range(6):
        for start, stop in _runs(inside[:, leg], gap):
            terms = first_terms + int(policy.terms_per_window * (stop - start) / scale)
            stops.append(Stop(leg, start, stop, terms))
            stopped[start:stop, leg] = True
    return stopped, stops


def _runs(mask: np.ndarray, gap: int) -> list[tuple[int, int]]:
    """[start, stop) of the runs of ``mask`` (N,), runs at most ``gap`` samples apart joined."""
    edges = np.flatnonzero(np.diff(np.r_[0, mask.astype(np.int8), 0]))
    runs: list[tuple[int, int]] = []
    for start, stop in zip(edges[::2], edges[1::2], strict=True):
        if runs and start - runs[-1][1] <= gap:
            runs[-1] = (runs[-1][0], int(stop))
        else:
            runs.append((int(start), int(stop)))
    return runs


def filtered_stop_columns(stops: list[Stop], samples: int, sample_rate: float, window: float,
                          step: int) -> np.ndarray:
    """The stops' Legendre polynomials, kernel-filtered at the rows kept (R, n).

    Rows as ``kernel_filter(x, sample_rate, window)[0][::step]`` of a record of ``samples``
    samples: row r at sample L // 2 + r step, L the kernel's length. Polynomials the kept rows do
    not see are left out.
    """
    taps = kernel_taps(sample_rate, window)[0]
    half = len(taps) // 2
    rows = len(range(0, samples - len(taps) + 1, step))
    columns = []
    for found in stops:
        first = max(0, math.ceil((found.start - 2 * half) / step))
        last = min(rows - 1, (found.stop - 1) // step)
        if last < first:
            continue
        centres = half + step * np.arange(first, last + 1)
        offsets = np.arange(found.start, found.stop)[None, :] - centres[:, None] + half
        band = np.where((offsets >= 0) & (offsets < len(taps)),
                        taps[np.clip(offsets, 0, len(taps) - 1)], 0.0)
        x = (2.0 * np.arange(found.stop - found.start) + 1.0) / (found.stop - found.start) - 1.0
        polynomials = legendre.legvander(x, found.terms - 1)
        block = np.zeros((rows, found.terms))
        block[first:last + 1] = band @ polynomials
        columns.append(block)
    return np.hstack(columns) if columns else np.zeros((rows, 0))


def check_motion(share: float, name: str, fix: str, policy: StopPolicy = STOPS) -> None:
    """Refuse experiment ``name`` when its legs stand still for a ``share`` of the samples above
    ``policy.largest_share``; ``fix``: what to do about it."""
    if share > policy.largest_share:
        raise IdentificationError(
            f"{name}: the legs stand still (rate within its noise) for {100 * share:.0f} % of "
            f"the samples, more than {100 * policy.largest_share:.0f} %: too little motion is "
            f"left for the friction law; {fix}.")


def stop_basis(found: LegStops, sample_rate: float, window: float, step: int, name: str,
               policy: StopPolicy = STOPS) -> np.ndarray:
    """Orthonormal basis (R, r) of the stops' :func:`filtered_stop_columns` in experiment ``name``.

    Raises
    ------
    IdentificationError
        When the legs stand still for more than ``policy.largest_share`` of the samples.
    """
    check_motion(float(found.stopped.mean()), name,
                 "record a faster or larger motion, or set leg_stops=False", policy)
    columns = filtered_stop_columns(found.stops, len(found.stopped), sample_rate, window, step)
    if columns.shape[1] == 0:
        return columns
    from scipy import sparse  # slow to import: only stopped legs need it

    # each column lives on a stop's filter support: a sparse Gram, then its eigenvectors (legs
    # stopping together give nearly equal columns, which the rank cut leaves out)
    local = sparse.csc_matrix(_unit_columns(columns))
    return local @ _span_coefficients((local.T @ local).toarray())


def span_basis(columns: np.ndarray) -> np.ndarray:
    """Orthonormal basis (R, r) of the span of ``columns`` (R, m), each scaled to unit length
    first; directions whose Gram eigenvalue is below :data:`RANK_CUT` of the largest are left out
    (nearly equal columns of legs stopping together, a stop's part too short for its terms)."""
    unit = _unit_columns(columns)
    return unit @ _span_coefficients(unit.T @ unit) if unit.shape[1] else unit


def _unit_columns(columns: np.ndarray) -> np.ndarray:
    """The nonzero ``columns`` (R, m), each scaled to unit length."""
    norms = np.linalg.norm(columns, axis=0)
    return columns[:, norms > 0] / norms[norms > 0]


def _span_coefficients(gram: np.ndarray) -> np.ndarray:
    """Coefficients (m, r) turning unit columns of Gram matrix ``gram`` (m, m) into an
    orthonormal basis of their span (:func:`span_basis`)."""
    values, vectors = np.linalg.eigh(gram)
    kept = values > RANK_CUT * values[-1]
    return vectors[:, kept] / np.sqrt(values[kept])


#: Smallest eigenvalue of the stops' Gram matrix, relative to the largest, kept in their basis.
RANK_CUT = 1e-10


def project_out(basis: np.ndarray, *arrays: np.ndarray) -> list[np.ndarray]:
    """Each array (R, ...) less its projection on the orthonormal ``basis`` (R, r)."""
    out = []
    for x in arrays:
        flat = x.reshape(len(x), -1)
        out.append((flat - basis @ (basis.T @ flat)).reshape(x.shape))
    return out


__all__ = ["STOPS", "LegStops", "Stop", "StopPolicy", "check_motion", "filtered_stop_columns",
           "find_stops", "leg_stop_runs", "project_out", "span_basis", "stop_basis"]
