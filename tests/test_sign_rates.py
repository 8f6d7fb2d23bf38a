"""The rates Coulomb signs are taken from: a friction kink at a reversal stays where it is on a
quiet record, and noise lengthens the window."""

from __future__ import annotations

import numpy as np
import pytest

from stewartid.signals.differentiation import differentiate
from stewartid.signals.sign_rates import (
    SIGN_FRACTIONS,
    SIGN_ORDER,
    coulomb_sign_rates,
    shorter_sign_window,
    sign_window,
)

RATE = 1000.0
WINDOW = 0.4


def kinked_pose(n: int = 4001) -> tuple[np.ndarray, np.ndarray]:
    """Pose whose rate reverses at t = 0 with a jump of the acceleration (the Coulomb force
    flipping), the same in every DOF: w = a t before, b t after."""
    t = (np.arange(n) - n // 2) / RATE
    a, b = 0.02, 0.08
    rate = np.where(t < 0, a * t, b * t)
    pose = np.where(t < 0, a * t ** 2 / 2, b * t ** 2 / 2)
    return t, np.tile(pose[:, None], (1, 6)), rate


def crossing(t: np.ndarray, rate: np.ndarray) -> float:
    """Time (s) of the rate's zero crossing nearest t = 0, by linear interpolation."""
    k = np.flatnonzero(np.diff(np.sign(rate)) != 0)
    k = k[np.argmin(np.abs(t[k]))]
    return float(t[k] - rate[k] * (t[k + 1] - t[k]) / (rate[k + 1] - rate[k]))


def test_a_quiet_record_keeps_the_reversal_where_the_friction_puts_it():
    t, pose, _ = kinked_pose()
    rates, window = coulomb_sign_rates(pose, RATE, WINDOW, np.zeros((6, 6)))
    assert window == pytest.approx(WINDOW * SIGN_FRACTIONS[0])
    # the smoothing window rounds the kink off and moves the crossing by a fraction of itself
    long = differentiate(pose, RATE, WINDOW / 8, SIGN_ORDER, (1,))[0]
    shift_short = abs(crossing(t, rates[:, 0]))
    shift_long = abs(crossing(t, long[:, 0]))
    assert shift_long > 4 * shift_short
    assert shift_short < window / 4


def test_noise_lengthens_the_window_up_to_the_whole_kernel():
    t, pose, _ = kinked_pose()
    windows = []
    for sigma in (1e-7, 1e-5, 1e-3):
        _, window = coulomb_sign_rates(pose, RATE, WINDOW, sigma ** 2 * np.eye(6))
        windows.append(window)
    assert windows == sorted(windows) and windows[0] < windows[-1]
    assert windows[-1] == pytest.approx(WINDOW * SIGN_FRACTIONS[-1])


def test_the_shorter_window_from_the_choice_is_the_search_with_shorter():
    # every candidate chosen (noise from none to the whole kernel's), one and two places shorter
    _, pose, _ = kinked_pose()
    chosen = set()
    for sigma in [0.0, *np.geomspace(1e-9, 1e-2, 30)]:
        noise = sigma ** 2 * np.eye(6)
        window = sign_window(pose, RATE, WINDOW, noise)
        chosen.add(window)
        for shorter in (1, 2):
            assert shorter_sign_window(WINDOW, window, shorter) == sign_window(
                pose, RATE, WINDOW, noise, shorter=shorter)
    assert len(chosen) == len(SIGN_FRACTIONS)
