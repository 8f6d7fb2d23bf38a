"""Cramér-Rao bounds on Mt and Bt: the best any unbiased estimator can do with a motion.

I = sum_t C_t^-1 (x) x_t x_t^T, C_t = J_lq^T diag(sigma^2) J_lq, x_t = [q_ddot, q_dot], constants
per record or interval profiled out (Kay 1993, "Estimation Theory", ch. 3).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from stewartid.errors import ConfigError
from stewartid.identification.wavelet.intervals import constant_direction_intervals, joint_rates
from stewartid.model.kinematics import leg_jacobian
from stewartid.platform import Platform
from stewartid.reference.published import PAPER_ENTRIES

#: Nuisance structures of :func:`information_bound`.
FRICTION_KNOWLEDGE = ("known", "immune")


@dataclass(frozen=True)
class InformationBound:
    """Cramér-Rao lower bound on the covariance of [Mt Bt].

    Attributes
    ----------
    covariance : ndarray, shape (72, 72)
        Of row-major [Mt Bt] (6, 12): index 12 i + j.
    friction : str
        ``"known"`` or ``"immune"``.
    n_constants : int
        Nuisance constants per channel.
    """

    covariance: np.ndarray
    friction: str
    n_constants: int

    @property
    def std(self) -> np.ndarray:
        """Lower bound on the standard error of [Mt Bt]; shape (6, 12)."""
        return np.sqrt(np.diag(self.covariance)).reshape(6, 12)

    def paper_covariance(self) -> np.ndarray:
        """Covariance of the paper's 20 entries (:data:`PAPER_ENTRIES` order); (20, 20)."""
        index = [12 * i + (j if m == "M" else 6 + j) for m, i, j in PAPER_ENTRIES]
        return self.covariance[np.ix_(index, index)]


def _profiled_information(q_dot: np.ndarray, q_ddot: np.ndarray, precision: np.ndarray,
                          labels: np.ndarray) -> tuple[np.ndarray, int]:
    """(72, 72) information with one constant per label >= 0 profiled out (-1: unused), and the count."""
    keep = labels >= 0
    x = np.hstack([q_ddot, q_dot])[keep]                                # (n, 12)
    p, lab = precision[keep], labels[keep]
    # theta block: I[a i, b j] = sum_t P_ab x_i x_j
    full = np.einsum("nab,ni,nj->aibj", p, x, x, optimize=True).reshape(72, 72)
    groups = np.unique(lab)
    for g in groups:
        sel = lab == g
        a = p[sel].sum(axis=0)                                          # (6, 6)
        cross = np.einsum("nab,ni->abi", p[sel], x[sel]).reshape(6, 72)  # d c_a, theta_bi
        full -= cross.T @ np.linalg.solve(a, cross)
    return full, len(groups)


def information_bound(platform: Platform, motions: Sequence[tuple[np.ndarray, ...]],
                      force_noise: float | np.ndarray, friction: str = "immune",
                      margin: float = 0.0, ignore_below: float = 0.01) -> InformationBound:
    """Cramér-Rao bound on [Mt Bt] for true motions and white leg-force noise.

    Parameters
    ----------
    platform : Platform
    motions : sequence of (t, q, q_dot, q_ddot)
        True motion of every record; (N,) s and (N, 6) m, rad and derivatives.
    force_noise : float or ndarray, shape (6,)
        Leg-force noise standard deviation, N.
    friction : {"immune", "known"}
        One constant per interval (Coulomb-invariant) or per record.
    margin : float
        Cut from both ends of every interval, s.
    ignore_below : float
        Joints slower than this fraction of the fastest of their kind do not split intervals.
    """
    if friction not in FRICTION_KNOWLEDGE:
        raise ConfigError(f"friction must be one of {', '.join(FRICTION_KNOWLEDGE)}; "
                          f"got {friction!r}.")
    sigma = np.broadcast_to(np.asarray(force_noise, dtype=float), (6,))
    if not np.all(np.isfinite(sigma) & (sigma > 0)):
        raise ConfigError(f"force_noise must be finite and > 0 (N); got {force_noise!r}.")
    information = np.zeros((72, 72))
    n_constants = 0
    for t, q, q_dot, q_ddot in motions:
        jacobian = leg_jacobian(platform, q)                           # (N, 6 legs, 6)
        # C_t^-1 = (J^T S J)^-1 = J^-1 S^-1 J^-T
        inverse = np.linalg.inv(jacobian)
        precision = np.einsum("nal,l,nbl->nab", inverse, sigma ** -2.0, inverse)
        labels = np.zeros(len(t), dtype=int)
        if friction == "immune":
            rates = joint_rates(platform, q, q_dot, leg_jacobian=jacobian)
            found = constant_direction_intervals(t, rates, margin=margin,
                                                 ignore_below=ignore_below)
            labels[:] = -1
            for k, (start, stop) in enumerate(found):
                labels[(t > start) & (t < stop)] = k
        part, count = _profiled_information(q_dot, q_ddot, precision, labels)
        information += part
        n_constants += count
    return InformationBound(covariance=np.linalg.inv(information), friction=friction,
                            n_constants=n_constants)


__all__ = ["FRICTION_KNOWLEDGE", "InformationBound", "information_bound"]
