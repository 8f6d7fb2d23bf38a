"""The chi-square and normal laws the identification's tests and error predictions use.

The chi-square tail with a whole number of degrees of freedom has a closed form, solved here to
round-off, and the normal law is the standard library's, so that the identification path does not
load :mod:`scipy.special` (slow to import: every start of the command line would pay for it).
"""

from __future__ import annotations

import math
from statistics import NormalDist

import numpy as np


def chi2_tail(x: float, dof: int) -> float:
    """P(X > x) for X chi-square with ``dof`` >= 1 degrees of freedom (whole number).

    The regularised upper incomplete gamma Q(dof/2, x/2) by its recurrence in steps of one,
    Q(a + 1, y) = Q(a, y) + y^a e^-y / Gamma(a + 1), from Q(1, y) = e^-y or Q(1/2, y) =
    erfc(sqrt y).
    """
    if dof < 1 or int(dof) != dof:
        raise ValueError(f"chi2_tail takes a whole number of degrees of freedom >= 1, not {dof!r}.")
    if x <= 0.0:
        return 1.0
    y = 0.5 * x
    a = 1.0 if dof % 2 == 0 else 0.5
    tail = math.exp(-y) if a == 1.0 else math.erfc(math.sqrt(y))
    log_y = math.log(y)
    while a < 0.5 * dof:
        tail += math.exp(a * log_y - y - math.lgamma(a + 1.0))
        a += 1.0
    return min(tail, 1.0)


def chi2_upper_quantile(dof: int, level: float) -> float:
    """The point x with P(X > x) = ``level`` for X chi-square with ``dof`` degrees of freedom.

    ``dof`` a whole number >= 1, ``level`` in (0, 1); bisection on :func:`chi2_tail`, which
    falls monotonically, to the resolution of a double.
    """
    if not 0.0 < level < 1.0:
        raise ValueError(f"chi2_upper_quantile takes a level in (0, 1), not {level!r}.")
    low, high = 0.0, max(1.0, float(dof))
    while chi2_tail(high, dof) > level:
        low, high = high, 2.0 * high
    while True:
        middle = 0.5 * (low + high)
        if middle in (low, high):
            return high
        if chi2_tail(middle, dof) > level:
            low = middle
        else:
            high = middle


def normal_cdf(z: np.ndarray) -> np.ndarray:
    """P(Z <= z) for a standard normal Z, elementwise on ``z`` (any shape)."""
    z = np.asarray(z, dtype=float)
    # beyond these the double is exactly 1 or 0: only the rest costs a call of math.erfc
    out = (z >= _ONE_FROM).astype(float)
    inside = (z > _ZERO_BELOW) & (z < _ONE_FROM)
    out[inside] = 0.5 * _ERFC(-z[inside] / math.sqrt(2.0)).astype(float)
    return out


_ERFC = np.frompyfunc(math.erfc, 1, 1)

#: Phi(z) rounds to 1.0 from here (1 - Phi(8.3) = 5e-17, below half a double's epsilon) and
#: to 0.0 below the other (Phi(-38.5) = 1e-324, beneath the smallest subnormal).
_ONE_FROM = 8.3
_ZERO_BELOW = -38.5


def normal_upper_quantile(level: float) -> float:
    """The point z with P(Z > z) = ``level`` for a standard normal Z, ``level`` in (0, 1)."""
    return NormalDist().inv_cdf(1.0 - level)


__all__ = ["chi2_tail", "chi2_upper_quantile", "normal_cdf", "normal_upper_quantile"]
