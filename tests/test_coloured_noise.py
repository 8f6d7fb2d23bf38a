"""Coloured force noise in Method B's weak-form rows: what its white-noise estimate misses and
what the residuals' chi-square excess gives back.

Force noise through a 20 Hz low-pass filter (an anti-aliasing filter) keeps its standard
deviation but moves its power below 20 Hz: at the excitation frequencies its density is
fs / (2 B) times that of white noise of the same variance (B: the filter's noise bandwidth,
integrated here from the filter's response, 20.5 Hz; 24x at 1 kHz). The sample-to-sample
(second-difference) estimate sees almost none of it; the rows of the smooth test functions
see all of it, and the excess of their residuals over the white estimate restores it.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy import signal

from stewartid.identification.wavelet.noise import white_noise_covariance
from stewartid.identification.wavelet.variance_components import excess_variance
from stewartid.identification.wavelet.weak_form import test_family as family
from stewartid.simulation.imperfections import lowpass_noise, lowpass_sections

RATE, CUTOFF, ORDER = 1000.0, 20.0, 4
WINDOWS, SIZE = 120, 8


def in_band_inflation() -> float:
    """fs / (2 B): the low-pass noise's density at low frequencies over white noise's of the
    same variance, B = integral of |H|^2 / |H(0)|^2 over 0..fs/2 (trapezoid rule)."""
    f, h = signal.sosfreqz(lowpass_sections(CUTOFF, ORDER, RATE), worN=1 << 18, fs=RATE)
    return 0.5 * RATE / np.trapezoid(np.abs(h) ** 2, f)


@pytest.fixture(scope="module")
def rows():
    """Rows <phi_r, n> of one channel of unit-variance low-pass noise, on 1 s windows
    (WINDOWS, SIZE), and the white-noise variance estimated from the same samples."""
    noise = lowpass_noise(np.random.default_rng(7), int(WINDOWS * RATE), 1.0, CUTOFF, ORDER,
                          RATE, channels=1)[:, 0]
    t = np.arange(len(noise)) / RATE
    out = []
    for w in range(WINDOWS):
        sel = np.flatnonzero((t > w) & (t < w + 1))
        (phi0, _, _), _ = family(t[sel], float(w), float(w + 1), 6, SIZE, 1.0 / RATE)
        # unit-norm rows: white noise of unit variance gives rows of unit variance
        out.append(phi0 @ noise[sel] / np.linalg.norm(phi0, axis=1))
    white = float(white_noise_covariance(noise[:, None])[0, 0])
    return np.array(out), white


def test_rows_carry_the_in_band_density_the_white_estimate_misses(rows):
    values, white = rows
    assert in_band_inflation() == pytest.approx(24.4, rel=0.01)
    # 960 rows: the variance is known to sqrt(2 / 960) = 5 %
    assert np.mean(values ** 2) == pytest.approx(in_band_inflation(), rel=0.15)
    assert white < 0.01


def test_the_residuals_excess_restores_it(rows):
    values, white = rows
    covariance = np.broadcast_to(white * np.eye(SIZE), (WINDOWS, SIZE, SIZE))
    total = white + excess_variance(covariance, values, values.size)
    assert total == pytest.approx(in_band_inflation(), rel=0.15)
