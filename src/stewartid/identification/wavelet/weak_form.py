"""Weak-form equations on constant-direction intervals: the default rows of Method B.

Mt <phi'', q> - Bt <phi', q> + c_m <phi, 1> = <phi, y>: no signal is differentiated
(Zhang 2020; Bortz, Messenger, Dukic, WENDy 2023; Shinbrot 1957).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from functools import lru_cache
from typing import NamedTuple

import numpy as np
from numpy.polynomial import polynomial

from stewartid.identification.preparation import Experiment
from stewartid.identification.wavelet.detection import Detection
from stewartid.model.joints import JOINT_TYPES
from stewartid.model.kinematics import joint_type_forces


@lru_cache(maxsize=32)
def _family_coefficients(order: int, size: int) -> tuple[np.ndarray, ...]:
    """Power-series coefficients (degree + 1, size + 1) of g, g', g'', g''' for (1 - x^2)^order x^k."""
    bump = polynomial.polypow([1.0, 0.0, -1.0], order)
    columns = [bump] + [np.r_[np.zeros(k), bump] for k in range(size)]
    degree = 2 * order + size + 1
    out = []
    for derivative in range(4):
        block = np.zeros((degree, size + 1))
        for j, c in enumerate(columns):
            d = polynomial.polyder(c, derivative) if derivative else c
            block[:len(d), j] = d
        out.append(block)
    return tuple(out)


#: Samples per span from which the rectangle rule on the samples integrates the test functions
#: (polynomials of degree 2 order + size + 1) to well below the rows' noise. A shorter span is
#: integrated against the samples' local Lagrange interpolant of :data:`STENCIL` samples (degree
#: one less), by Gauss-Legendre quadrature of :data:`GAUSS_POINTS` nodes between consecutive
#: samples.
RESOLVED_SAMPLES = 400
STENCIL = 6
GAUSS_POINTS = 6


def _interpolated_family(t: np.ndarray, start: float, stop: float, order: int, size: int,
                         h: float) -> tuple[np.ndarray, ...]:
    """Quadrature weights (n, size + 1) of g, g', g'', g''' on the samples ``t``: their
    integrals over [start, stop] against the samples' interpolant (:data:`RESOLVED_SAMPLES`)."""
    half, centre = 0.5 * (stop - start), 0.5 * (start + stop)
    edges = np.r_[start, t, stop]
    nodes, weights = np.polynomial.legendre.leggauss(GAUSS_POINTS)
    width = np.diff(edges)[:, None]
    points = edges[:-1, None] + 0.5 * width * (nodes + 1)              # (segments, nodes)
    # one interpolant per segment, on the samples about it
    first = np.clip(np.arange(len(t) + 1) - STENCIL // 2, 0, len(t) - STENCIL)
    u = (points - t[first, None]) / h
    stencil = np.arange(STENCIL)
    lagrange = np.stack([np.prod([(u - i) / (j - i) for i in stencil if i != j], axis=0)
                         for j in stencil], axis=-1)               # (segments, nodes, STENCIL)
    coefficients = _family_coefficients(order, size)
    vander = polynomial.polyvander((points.ravel() - centre) / half, coefficients[0].shape[0] - 1)
    values = np.hstack([vander @ c / half ** d for d, c in enumerate(coefficients)])
    values = values.reshape(*points.shape, -1) * (0.5 * width * weights)[:, :, None]
    parts = np.einsum("sgj,sgc->sjc", lagrange, values)             # (segments, STENCIL, 4 (K+1))
    out = np.zeros((len(t), parts.shape[-1]))
    np.add.at(out, first[:, None] + stencil, parts)
    return tuple(np.split(out, 4, axis=1))


def test_family(t: np.ndarray, start: float, stop: float, order: int, size: int, h: float
                ) -> tuple[tuple[np.ndarray, ...], tuple[np.ndarray, ...]]:
    """The test functions of one span as quadrature weights on its samples ``t``: sampled and
    scaled by ``h`` (the rectangle rule), or, on fewer than :data:`RESOLVED_SAMPLES` samples,
    integrated against their interpolant (:func:`_interpolated_family`).

    phi_k = d/dt [(1 - x^2)^p x^k], x = (t - c) / L, orthonormalised; the mean row is the bump
    orthogonalised against them. Returns (phi, phi', phi'') (size, n) and (g, g', g'') (n,).
    """
    half, centre = 0.5 * (stop - start), 0.5 * (start + stop)
    if len(t) < RESOLVED_SAMPLES:
        g0, g1, g2, g3 = _interpolated_family(t, start, stop, order, size, h)
    else:
        x = (t - centre) / half
        vander = polynomial.polyvander(x, _family_coefficients(order, size)[0].shape[0] - 1)
        g0, g1, g2, g3 = (vander @ c * (h / half ** d)
                          for d, c in enumerate(_family_coefficients(order, size)))
    phi0, phi1, phi2 = g1[:, 1:].T, g2[:, 1:].T, g3[:, 1:].T
    u, s, _ = np.linalg.svd(phi0, full_matrices=False)
    transform = (u / s).T  # orthonormal rows
    phi0, phi1, phi2 = transform @ phi0, transform @ phi1, transform @ phi2
    bump0, bump1, bump2 = g0[:, 0], g1[:, 0], g2[:, 0]
    projection = phi0 @ bump0
    bump0, bump1, bump2 = bump0 - projection @ phi0, bump1 - projection @ phi1, \
        bump2 - projection @ phi2
    norm = np.linalg.norm(bump0)
    return (phi0, phi1, phi2), (bump0 / norm, bump1 / norm, bump2 / norm)


@dataclass(frozen=True)
class IntervalEquations:
    """Weak-form equations of one constant-direction interval.

    Attributes
    ----------
    regressors : ndarray, shape (K, 12)
        Invariant rows [<phi_k'', q>, -<phi_k', q>].
    targets : ndarray, shape (K, 6)
        <phi_k, y>, N s, N m s.
    mean_regressors : ndarray, shape (12,)
    mean_target : ndarray, shape (6,)
    weight : float
        <g, 1>, s^(1/2).
    coulomb : ndarray, shape (n_types, 6) or (1, 6)
        <g, W_type> with the interval's joint directions.
    coulomb_rows : ndarray, shape (n_rates, K, n_types, 6) or None
        <phi_k, W_type(t)> per soft-sign rate (free constants only).
    experiment : int
    noise_gram : ndarray, shape (3, 3, K + 1, K + 1)
        <phi^(a), phi^(b)> of the invariant rows then the mean row.
    """

    regressors: np.ndarray
    targets: np.ndarray
    mean_regressors: np.ndarray
    mean_target: np.ndarray
    weight: float
    coulomb: np.ndarray
    experiment: int
    noise_gram: np.ndarray
    coulomb_rows: np.ndarray | None = None


def interval_equations(t: np.ndarray, q: np.ndarray, y: np.ndarray,
                       joint_jacobians: np.ndarray | None,
                       joint_rates: np.ndarray,
                       rate_noise: np.ndarray, interval: Sequence[float], order: int, size: int,
                       experiment: int = 0, uniform: bool = False,
                       patterns: np.ndarray | PatternsBySamples | None = None
                       ) -> IntervalEquations | None:
    """Weak-form equations of one interval; None when it holds fewer than 4 (K + 1) samples.

    Parameters
    ----------
    t : ndarray, shape (N,)
        s, uniform.
    q, y : ndarray, shape (N, 6)
        Pose (m, rad) and generalized force (N, N m).
    joint_jacobians : ndarray, shape (N, 6, 5, 6) or None
        None: no friction structure.
    joint_rates : ndarray, shape (N, 6, 5)
        Smoothed, rad/s; their mean gives the directions.
    rate_noise : ndarray, shape (6, 5)
        rad/s; a direction weighs |mean| / noise within it.
    interval : (start, stop)
        s.
    order : int
        p of (1 - x^2)^p, >= 3.
    size : int
        K invariant test functions.
    experiment : int
    uniform : bool
        One Coulomb level for every joint axis.
    patterns : ndarray, shape (N, n_rates, n_types, 6), or PatternsBySamples, optional
        :func:`coulomb_patterns` (or its rows on demand), for ``coulomb_rows``.
    """
    start, stop = float(interval[0]), float(interval[1])
    sel = inside(t, start, stop)
    if sel.stop - sel.start < 4 * (size + 1):
        return None
    (phi0, phi1, phi2), (bump0, bump1, bump2) = test_family(t[sel], start, stop, order, size,
                                                            float(t[1] - t[0]))
    # removing the mean keeps the offset's rounding from being amplified
    qc = q[sel] - q[sel].mean(axis=0)
    ys = y[sel]
    mean_rate = joint_rates[sel].mean(axis=0)
    direction = mean_rate / np.sqrt(mean_rate ** 2 + rate_noise ** 2)
    n_types = (1 if uniform else len(JOINT_TYPES)) if patterns is None else patterns.shape[2]
    if joint_jacobians is None:
        coulomb = np.zeros((n_types, 6))
    else:
        coulomb = np.einsum("n,ntc->tc", bump0, _by_type(
            np.einsum("la,nlac->nac", direction, joint_jacobians[sel]), uniform))
    # the invariant rows see the joints' soft signs at every sample (an idle joint, left out
    # of the detection, may reverse inside the interval) and the pose's change
    rows = None if patterns is None else project_patterns(phi0, patterns[sel])
    gram = noise_gram((phi0, phi1, phi2), (bump0, bump1, bump2))
    return IntervalEquations(
        regressors=np.hstack([phi2 @ qc, -(phi1 @ qc)]), targets=phi0 @ ys,
        mean_regressors=np.r_[bump2 @ qc, -(bump1 @ qc)], mean_target=bump0 @ ys,
        weight=float(bump0.sum()), coulomb=coulomb, experiment=int(experiment),
        noise_gram=gram, coulomb_rows=rows)


#: Samples per block of :func:`coulomb_patterns`: its per-sample temporaries stay small.
PATTERN_BLOCK = 2048
#: Candidate transition rates r (rad/s) of the Coulomb soft sign (:func:`coulomb_patterns`).
#: No rate between 0 and 1e-4, where one would fit the sampling error of an exact sign.
SOFT_SIGN_RATES = (0.0, 1e-4, 3e-4, 1e-3, 3e-3)


def coulomb_patterns(found: Detection, joint_jacobians: np.ndarray, uniform: bool,
                     rates: Sequence[float] = SOFT_SIGN_RATES,
                     leg_jacobian: np.ndarray | None = None,
                     also: Sequence[tuple[Detection, Sequence[float]]] = ()) -> np.ndarray:
    """W_type(t) (N, n_rates, n_types, 6): generalized force of a unit Coulomb torque on each axis of a type.

    Soft sign w / sqrt(w^2 + sigma^2 + r^2) of ``found.sign_rates`` at every transition rate r of
    ``rates``, rad/s. Samples lead, so that an interval's rows are one contiguous slice. With
    ``leg_jacobian`` J_lq (N, 6, 6), a last type: a unit force along every leg (a ball screw's
    friction), J_lq^T soft-sign(l_dot) with the same r in m/s. ``also``: further signs (of the
    same samples) and their rates, whose patterns follow along the rate axis (one pass over the
    Jacobians for all).
    """
    groups = (tuple(range(5)),) if uniform else tuple(JOINT_TYPES.values())
    sets = [(signs, np.asarray(set_rates, dtype=float))
            for signs, set_rates in ((found, rates), *also)]
    count = sum(len(set_rates) for _, set_rates in sets)
    n_samples = len(found.sign_rates)
    out = np.empty((n_samples, count, len(groups) + (leg_jacobian is not None), 6))
    squares = [(signs.sign_rate_noise ** 2, set_rates[:, None, None] ** 2)
               for signs, set_rates in sets]
    # one block's temporaries, reused: w^2 + sigma^2, then the soft signs (n, R, 6, 5)
    level = np.empty((min(n_samples, PATTERN_BLOCK), 6, 5))
    direction = np.empty((len(level), count, 6, 5))
    for start in range(0, n_samples, PATTERN_BLOCK):
        block = slice(start, start + PATTERN_BLOCK)
        first = 0
        for (signs, set_rates), (noise, squared_rates) in zip(sets, squares, strict=True):
            w = signs.sign_rates[block]
            n = len(w)
            np.multiply(w, w, out=level[:n])
            level[:n] += noise
            soft = np.add(level[:n, None], squared_rates,
                          out=direction[:n, first:first + len(set_rates)])
            np.sqrt(soft, out=soft)
            np.divide(w[:, None], soft, out=soft)
            first += len(set_rates)
        joint_type_forces(direction[:n], joint_jacobians[block], groups,
                          out=out[block, :, :len(groups)])
    if leg_jacobian is not None:
        first = 0
        for signs, set_rates in sets:
            legs = signs.leg_sign_rates[:, None]                                  # (N, 1, 6)
            soft = legs ** 2 + signs.leg_sign_rate_noise ** 2 + set_rates[:, None] ** 2
            np.sqrt(soft, out=soft)
            np.divide(legs, soft, out=soft)                                       # (N, R, 6)
            out[:, first:first + len(set_rates), -1] = soft @ leg_jacobian
            first += len(set_rates)
    return out


@dataclass(frozen=True)
class PatternsBySamples:
    """:func:`coulomb_patterns` of one experiment, computed for the samples a slice asks for:
    ``patterns[rows]`` gives the numbers of the whole (N, n_rates, n_types, 6) array's rows, which
    is never held (an experiment's windows each take theirs, one at a time)."""

    found: Detection
    joint_jacobians: np.ndarray
    uniform: bool
    rates: Sequence[float] = SOFT_SIGN_RATES
    leg_jacobian: np.ndarray | None = None
    also: tuple[tuple[Detection, Sequence[float]], ...] = ()

    @property
    def shape(self) -> tuple[int, int, int, int]:
        """The whole array's shape."""
        types = (1 if self.uniform else len(JOINT_TYPES)) + (self.leg_jacobian is not None)
        rates = len(self.rates) + sum(len(rates) for _, rates in self.also)
        return len(self.joint_jacobians), rates, types, 6

    def __getitem__(self, rows: slice) -> np.ndarray:
        def part(signs: Detection) -> Detection:
            legs = signs.leg_sign_rates
            return signs._replace(sign_rates=signs.sign_rates[rows],
                                  leg_sign_rates=None if legs is None else legs[rows])

        return coulomb_patterns(part(self.found), self.joint_jacobians[rows], self.uniform,
                                self.rates, leg_jacobian=(None if self.leg_jacobian is None
                                              else self.leg_jacobian[rows]),
                                also=tuple((part(signs), rates) for signs, rates in self.also))


def _by_type(pattern: np.ndarray, uniform: bool) -> np.ndarray:
    """Per-axis pattern (n, 5, 6) summed per joint type: (n, n_types, 6), or (n, 1, 6) if ``uniform``."""
    by_type = np.stack([pattern[:, axes[0]:axes[-1] + 1].sum(axis=1)
                        for axes in JOINT_TYPES.values()], axis=1)
    return by_type.sum(axis=1, keepdims=True) if uniform else by_type


def inside(t: np.ndarray, start: float, stop: float) -> slice:
    """The samples of ``t`` (uniform, increasing) strictly between ``start`` and ``stop``, as a slice."""
    return slice(int(np.searchsorted(t, start, side="right")),
                 int(np.searchsorted(t, stop, side="left")))


def project_patterns(phi: np.ndarray, patterns: np.ndarray) -> np.ndarray:
    """<phi_k, W> (n_rates, K, n_types, 6) of test functions ``phi`` (K, n) and patterns W
    (n, n_rates, n_types, 6)."""
    rows = phi @ patterns.reshape(len(patterns), -1)
    return rows.reshape(len(phi), *patterns.shape[1:]).transpose(1, 0, 2, 3)


def noise_gram(phi: Sequence[np.ndarray], bump: Sequence[np.ndarray]) -> np.ndarray:
    """<phi^(a), phi^(b)> (3, 3, K + 1, K + 1), a, b = 0, 1, 2, of the invariant rows ``phi`` (K, n)
    then the mean row ``bump`` (n,)."""
    family = np.concatenate([np.vstack([p, g]) for p, g in zip(phi, bump, strict=True)])
    rows = len(family) // 3
    return (family @ family.T).reshape(3, rows, 3, rows).transpose(0, 2, 1, 3)


def experiment_equations(experiment: Experiment, found: Detection, order: int, size: int,
                         index: int, friction: str,
                         patterns: np.ndarray | PatternsBySamples | None = None
                         ) -> list[IntervalEquations]:
    """The weak-form equations of every usable interval of one experiment.

    ``friction``: "free" (no structure in the mean rows), "shared" or "uniform" (one level);
    ``patterns``: :func:`coulomb_patterns` (not uniform) of the invariant rows' Coulomb regressors
    ("free" only; computed when not given).
    """
    jacobians = experiment.joint_jacobians
    uniform, free = friction == "uniform", friction == "free"
    if free and patterns is None:
        patterns = coulomb_patterns(found, jacobians, uniform)
    elif not free:
        patterns = None
    equations = (interval_equations(experiment.t, experiment.q, experiment.generalized_force,
                                    None if free else jacobians,
                                    found.joint_rates, found.rate_noise, interval,
                                    order, size, index, uniform=uniform, patterns=patterns)
                 for interval in found.intervals)
    return [rows for rows in equations if rows is not None]


class StackedEquations(NamedTuple):
    """The equations of n intervals as arrays, with the noise levels of their experiments.

    Attributes
    ----------
    regressors : ndarray, shape (n, K, 12)
    targets : ndarray, shape (n, K, 6)
    mean_regressors : ndarray, shape (n, 12)
    mean_targets : ndarray, shape (n, 6)
    weights : ndarray, shape (n,)
        <g, 1>, s^(1/2).
    coulomb : ndarray, shape (n, n_types, 6)
    coulomb_rows : ndarray, shape (n, K, n_types, 6)
    owner : ndarray of int, shape (n,)
        Experiment of every interval.
    gram : ndarray, shape (n, 3, 3, K + 1, K + 1)
    sigma, sensitivity : ndarray, shape (n, 6, 6)
        Pose noise per sample and K = dy/dq (zero when not given).
    white : ndarray, shape (n, 6)
        Generalized-force white noise variance (zero when not given).
    """

    regressors: np.ndarray
    targets: np.ndarray
    mean_regressors: np.ndarray
    mean_targets: np.ndarray
    weights: np.ndarray
    coulomb: np.ndarray
    coulomb_rows: np.ndarray
    owner: np.ndarray
    gram: np.ndarray
    sigma: np.ndarray
    sensitivity: np.ndarray
    white: np.ndarray


def stack_equations(equations: Sequence[IntervalEquations],
                    pose_covariance: np.ndarray | None = None,
                    force_sensitivity: np.ndarray | None = None,
                    force_variance: np.ndarray | None = None, rate_index: int = 0
                    ) -> StackedEquations:
    """Every interval's equations as arrays, with its experiment's noise levels (None: zero)."""
    owner = np.array([e.experiment for e in equations])
    return StackedEquations(
        regressors=np.stack([e.regressors for e in equations]),
        targets=np.stack([e.targets for e in equations]),
        mean_regressors=np.stack([e.mean_regressors for e in equations]),
        mean_targets=np.stack([e.mean_target for e in equations]),
        weights=np.array([e.weight for e in equations]),
        coulomb=np.stack([e.coulomb for e in equations]),
        coulomb_rows=np.stack([np.zeros((len(e.targets), *e.coulomb.shape))
                               if e.coulomb_rows is None else e.coulomb_rows[rate_index]
                               for e in equations]), owner=owner,
        gram=np.stack([e.noise_gram for e in equations]),
        sigma=_per_interval(pose_covariance, owner, (6, 6)),
        sensitivity=_per_interval(force_sensitivity, owner, (6, 6)),
        white=_per_interval(force_variance, owner, (6,)))


def _per_interval(values: np.ndarray | None, owner: np.ndarray, shape: tuple[int, ...]
                  ) -> np.ndarray:
    """Per-experiment ``values`` at every interval; zeros for None."""
    if values is None:
        return np.zeros((len(owner), *shape))
    return np.asarray(values, dtype=float)[owner]


__all__ = ["SOFT_SIGN_RATES", "IntervalEquations", "PatternsBySamples", "StackedEquations",
           "coulomb_patterns", "experiment_equations", "inside", "interval_equations",
           "noise_gram", "project_patterns", "stack_equations", "test_family"]
