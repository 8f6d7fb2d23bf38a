"""The log kinds of ``benchmarks/noise_study.py``: the oracle's Savitzky-Golay window and
the excitation lines it is chosen from, against signals of known content."""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benchmarks"))
from noise_study import kind_sines, leg_length_lines, oracle_window  # noqa: E402

from stewartid.signals.differentiation import differentiate, trim  # noqa: E402

RATE = 1000.0
T = np.arange(0.0, 20.0, 1.0 / RATE)


def three_sine_lengths() -> tuple[np.ndarray, np.ndarray]:
    """Leg lengths (m) of three whole-record sines (0.3, 0.7, 1.5 Hz; amplitudes 12, 6, 3 mm
    on leg 1, half on leg 2), and their analytic acceleration (m/s^2)."""
    parts = ((12e-3, 0.3, 0.0), (6e-3, 0.7, 1.0), (3e-3, 1.5, 2.0))
    x = sum(a * np.sin(2 * np.pi * f * T + ph) for a, f, ph in parts)
    xdd = sum(-a * (2 * np.pi * f) ** 2 * np.sin(2 * np.pi * f * T + ph) for a, f, ph in parts)
    lengths = 1.5 + np.column_stack([x, 0.5 * x, np.zeros((len(T), 4))])
    return lengths, xdd


def test_excitation_lines_are_the_injected_sines():
    """Three sines with whole periods in the record: exactly their frequencies, with their
    amplitude shares (Hann window: leakage only into the neighbouring bins)."""
    lengths, _ = three_sine_lengths()
    frequencies, shares = leg_length_lines(lengths, RATE)
    np.testing.assert_allclose(frequencies, [0.3, 0.7, 1.5], atol=1e-9)
    np.testing.assert_allclose(shares, [1.0, 0.5, 0.25], rtol=1e-6)


def test_oracle_window_keeps_every_line_of_the_acceleration():
    """With the chosen window, the Savitzky-Golay acceleration of the three sines matches the
    analytic one within the tolerance, 1e-3 of the largest acceleration line (1.5 Hz; the
    gain error grows like f^6 for order 5, so the slower lines add (0.7/1.5)^6 * 2 and less:
    under 5 % more), and the window is not needlessly short: one 20 % longer misses (measured
    2.1e-3)."""
    lengths, xdd = three_sine_lengths()
    window = oracle_window(lengths, RATE)

    def error(w: float) -> float:
        _, _, acceleration = differentiate(lengths[:, 0], RATE, w)
        cut = trim(w, RATE)
        inner = slice(cut, len(T) - cut)
        # the largest line's acceleration amplitude (1.5 Hz: 3 mm * (3 pi)^2)
        return np.max(np.abs(acceleration[inner] - xdd[inner])) / (3e-3 * (3 * np.pi) ** 2)

    assert error(window) < 1.05e-3
    assert error(1.2 * window) > 1.5e-3


def test_kind_sines_reject_an_unknown_kind():
    assert len(kind_sines("three", 0)) == 3 and len(kind_sines("alldof", 2)) == 6
    with pytest.raises(ValueError, match="log kind must be one of paper, three, alldof, tenx"):
        kind_sines("five", 0)
