"""Method B's per-sample loops, compiled with numba (cached on disk)."""

from __future__ import annotations

import math

import numpy as np
from numba import njit


@njit(cache=True)
def soft_sign_patterns(signs: np.ndarray, noise: np.ndarray, jacobians: np.ndarray,
                       rates: np.ndarray, types: np.ndarray, out: np.ndarray) -> None:
    """Add sum_{l, a of type t} w / sqrt(w^2 + sigma^2 + r^2) J[n, l, a, :] into ``out`` (N, R, T, 6).

    ``signs`` w (N, 6, 5), ``noise`` sigma (6, 5), ``jacobians`` (N, 6, 5, 6), ``rates`` r (R,),
    ``types`` (5,): the type index of each joint axis.
    """
    for k in range(signs.shape[0]):
        for leg in range(6):
            for axis in range(5):
                w = signs[k, leg, axis]
                base = w * w + noise[leg, axis] ** 2
                t = types[axis]
                for r in range(rates.shape[0]):
                    direction = w / math.sqrt(base + rates[r] ** 2)
                    for c in range(6):
                        out[k, r, t, c] += direction * jacobians[k, leg, axis, c]
