"""The standard errors widened by the bias of the Coulomb signs' long window.

Pose noise lengthens the window the Coulomb signs' rates are taken from
(:func:`~stewartid.signals.sign_rates.coulomb_sign_rates`). Where the motion dwells at zero rate
at a reversal and then catches up, a long window puts the zero crossing early; the Coulomb
regressor then switches early, in phase with the acceleration, and the fit takes the error
mostly from Mt. A refit with the signs' rates from the next shorter candidate window (half the
length) measures how far the window moves the estimates: the distance d between the two fits.
Estimates are unchanged; each standard error s becomes sqrt(s^2 + (k d)^2).
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from typing import Any

import numpy as np


@dataclass(frozen=True)
class SignWindowPolicy:
    """Scales k of the distance between the long and the half window's fits.

    Attributes
    ----------
    inertia : float
        On Mt: the rounding's bias falls by about a third per halving of the window, so the
        whole bias is about 3 d; 2 d leaves the error within 3 widened standard errors.
    other : float
        On Bt, the Coulomb levels and the offsets: there the half window's noisier signs move the
        fit more than the long window's bias does (docs/benchmarks.md, *Pose noise and the
        rotational inertia*).
    """

    inertia: float = 2.0
    other: float = 0.5


#: The scales the identifiers use.
SIGN_WINDOW = SignWindowPolicy()


def widened_by_sign_window(solution: Any, best: Any, refit: Any, levels: str,
                           policy: SignWindowPolicy = SIGN_WINDOW) -> Any:
    """``solution``'s standard errors widened by the distance of ``refit`` from ``best``.

    ``solution``, ``best`` and ``refit``: dataclasses with ``theta``, ``theta_std`` (6, p), whose
    first 6 columns are Mt, and a vector of shared parameters named ``levels`` (with
    ``levels + "_std"``). ``best`` is the fit of the long window that ``refit`` repeats with the
    half window's signs (the same sign shape and transition rate); ``solution`` is the reported
    fit (an average over shapes or rates whose likeliest member is ``best``).
    """
    scale = np.full(solution.theta.shape[1], policy.other)
    scale[:6] = policy.inertia
    theta_std = np.hypot(solution.theta_std, scale * (best.theta - refit.theta))
    shared_std = np.hypot(getattr(solution, f"{levels}_std"),
                          policy.other * (getattr(best, levels) - getattr(refit, levels)))
    return dataclasses.replace(solution, theta_std=theta_std, **{f"{levels}_std": shared_std})


__all__ = ["SIGN_WINDOW", "SignWindowPolicy", "widened_by_sign_window"]
