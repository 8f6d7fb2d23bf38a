"""The pose rates Coulomb friction's signs are taken from: the shortest Savitzky-Golay window the
noise allows (a window rounds off the reversal's kink; noise makes the sign chatter).
"""

from __future__ import annotations

import numpy as np

from stewartid.signals.differentiation import differentiate, savgol_coefficients, window_samples

#: Savitzky-Golay order and candidate windows (fractions of the kernel's) of the rates the
#: Coulomb signs are taken from, shortest first; the short ones keep the reversals of quiet
#: records where the motion has them.
SIGN_ORDER, SIGN_FRACTIONS = 3, (1 / 64, 1 / 32, 1 / 16, 1 / 8, 1 / 4, 1 / 2, 1)
#: Largest noise of the sign's rate relative to the rate's RMS (on the most moved DOF): a
#: sine's sign is then uncertain for about (2 / pi) x this fraction of the time.
SIGN_NOISE = 0.002


def sign_window(q: np.ndarray, sample_rate: float, window: float, pose_noise: np.ndarray,
                noise_limit: float = SIGN_NOISE, shorter: int = 0) -> float:
    """The Savitzky-Golay window (s) of the rates the Coulomb signs are taken from.

    The shortest of :data:`SIGN_FRACTIONS` of ``window`` whose rate noise, from the per-sample pose
    covariance ``pose_noise`` (6, 6), is within ``noise_limit`` of the rate's RMS; else the whole
    kernel. ``shorter``: that many candidates shorter (never below the first), the refit that
    measures the long window's rounding of the reversals.
    """
    sigma = np.diag(pose_noise)
    # the rates' RMS barely depends on the window: taken once, at an eighth of the kernel
    rms = np.sqrt(np.mean(differentiate(q, sample_rate, window / 8, SIGN_ORDER, (1,))[0] ** 2,
                          axis=0))
    for index in range(len(SIGN_FRACTIONS)):
        n = window_samples(window * SIGN_FRACTIONS[index], sample_rate, SIGN_ORDER)
        taps = savgol_coefficients(n, SIGN_ORDER, 1, 1 / sample_rate)
        noise = np.sqrt(sigma * np.sum(taps ** 2))
        if np.min(noise / np.maximum(rms, 1e-300)) <= noise_limit:
            break
    return window * SIGN_FRACTIONS[max(index - shorter, 0)]


def coulomb_sign_rates(q: np.ndarray, sample_rate: float, window: float,
                       pose_noise: np.ndarray, noise_limit: float = SIGN_NOISE,
                       shorter: int = 0) -> tuple[np.ndarray, float]:
    """The pose rates (N, 6) the Coulomb signs are taken from, and their Savitzky-Golay window
    (s, :func:`sign_window` of the arguments)."""
    chosen = sign_window(q, sample_rate, window, pose_noise, noise_limit, shorter)
    return sign_rates(q, sample_rate, chosen), chosen


def sign_rates(q: np.ndarray, sample_rate: float, sign_window: float) -> np.ndarray:
    """The pose rates (N, 6) of ``q`` (N, 6) over a Savitzky-Golay window of ``sign_window`` s,
    the Coulomb signs' order."""
    return differentiate(q, sample_rate, sign_window, SIGN_ORDER, (1,))[0]


def shorter_sign_window(window: float, sign_window: float, shorter: int = 1) -> float:
    """The candidate of ``window`` (s) ``shorter`` places shorter than ``sign_window`` (s, one of
    them), never below the first: :func:`sign_window` with ``shorter`` from its choice without,
    for a refit that need not search the candidates again."""
    index = int(np.argmin(np.abs(window * np.asarray(SIGN_FRACTIONS) - sign_window)))
    return window * SIGN_FRACTIONS[max(index - shorter, 0)]


def lengthened_by_noise(window: float, sign_window: float) -> bool:
    """Whether :func:`coulomb_sign_rates` took a window (s) longer than its shortest candidate
    of ``window`` (s): the pose noise lengthened it."""
    return sign_window > window * SIGN_FRACTIONS[0] * (1.0 + 1e-9)


__all__ = ["SIGN_FRACTIONS", "SIGN_NOISE", "SIGN_ORDER", "coulomb_sign_rates",
           "lengthened_by_noise", "shorter_sign_window", "sign_rates", "sign_window"]
