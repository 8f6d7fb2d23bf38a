"""Wavelet transform at chosen (a, b) against closed forms, the integration-by-parts
identities, and PyWavelets as an independent implementation."""

from __future__ import annotations

import math

import numpy as np
import pytest

from stewartid.errors import ConfigError
from stewartid.signals.wavelets import (
    MexicanHat,
    PolynomialWavelet,
    make_wavelet,
    transform_matrix,
    wavelet_transform,
)

DT = 1e-3
T = np.arange(0.0, 20.0, DT)
SCALES = np.array([0.3, 0.7, 1.2])
SHIFTS = np.array([6.0, 9.3, 11.1])


def test_mexican_hat_of_polynomials_matches_closed_form():
    # W t^2 = a^2 * int x^2 (1 - x^2) exp(-x^2/2) dx = -2 sqrt(2 pi) a^2, W t^3 = 3 b * that
    hat = MexicanHat(truncation=10.0)
    k = -2.0 * math.sqrt(2.0 * math.pi)
    np.testing.assert_allclose(wavelet_transform(T ** 2, T, SCALES, SHIFTS, hat),
                               k * SCALES ** 2, rtol=1e-6)
    np.testing.assert_allclose(wavelet_transform(T ** 3, T, SCALES, SHIFTS, hat),
                               3 * SHIFTS * k * SCALES ** 2, rtol=1e-6)
    # vanishing moments of order 0 and 1
    np.testing.assert_allclose(wavelet_transform(np.c_[np.ones_like(T), T], T, SCALES,
                                                 SHIFTS, hat), 0.0, atol=1e-9)


def test_mexican_hat_of_sine_and_gaussian_matches_closed_form():
    hat = MexicanHat(truncation=10.0)
    w = 2 * np.pi * 0.6
    u = SCALES * w
    expected = np.sin(w * SHIFTS) * math.sqrt(2 * math.pi) * u ** 2 * np.exp(-u ** 2 / 2)
    # quadrature error, relative: every expected entry is >= 1.5e-3, so rtol governs (measured
    # 2.4e-9 at the smallest) and atol, 1e-12 << 1e-7 x 1.5e-3, is only a floor
    np.testing.assert_allclose(wavelet_transform(np.sin(w * T), T, SCALES, SHIFTS, hat),
                               expected, rtol=1e-7, atol=1e-12)
    # Gaussian centred on the wavelet: int exp(-a^2 x^2 / 2 s^2)(1 - x^2) exp(-x^2/2) dx
    s, c = 0.5, 10.0
    gauss = np.exp(-((T - c) ** 2) / (2 * s ** 2))
    p = 1.0 + SCALES ** 2 / s ** 2
    closed = np.sqrt(2 * np.pi / p) * (1.0 - 1.0 / p)
    got = wavelet_transform(gauss, T, SCALES, np.full(3, c), hat)
    np.testing.assert_allclose(got, closed, rtol=1e-7)


@pytest.mark.parametrize("order", [5, 8, 12])
def test_polynomial_wavelet_moments_and_closed_form(order):
    wavelet = PolynomialWavelet(order)
    a = SCALES / 1.0
    np.testing.assert_allclose(wavelet_transform(np.c_[np.ones_like(T), T - 7.0], T, a,
                                                 SHIFTS, wavelet), 0.0, atol=1e-8)
    # W t^2 = a^2 int x^2 g'' dx = 2 a^2 int g dx, int (1-x^2)^p = sqrt(pi) G(p+1)/G(p+3/2)
    g0 = float(wavelet(np.array(0.0), -2))
    integral = g0 * math.sqrt(math.pi) * math.gamma(order + 1) / math.gamma(order + 1.5)
    np.testing.assert_allclose(wavelet_transform(T ** 2, T, a, SHIFTS, wavelet),
                               2 * a ** 2 * integral, rtol=1e-6)
    x = np.linspace(-1, 1, 200001)
    assert np.trapezoid(wavelet(x) ** 2, x) == pytest.approx(1.0, rel=1e-8)


@pytest.mark.parametrize("wavelet", [PolynomialWavelet(8), MexicanHat(8.0)])
def test_integration_by_parts_identities(wavelet):
    w = 2 * np.pi * 0.45
    f = np.sin(w * T) + 0.2 * np.cos(2.3 * w * T)
    df = w * np.cos(w * T) - 0.46 * w * np.sin(2.3 * w * T)
    ddf = -w ** 2 * np.sin(w * T) - 0.2 * (2.3 * w) ** 2 * np.cos(2.3 * w * T)
    F = -np.cos(w * T) / w + 0.2 * np.sin(2.3 * w * T) / (2.3 * w)
    a = SCALES if wavelet.compact else SCALES / 4

    def W(signal, d=0):
        return wavelet_transform(signal, T, a, SHIFTS, wavelet, d)

    # quadrature error, relative: every compared entry is >= 0.011 (rtol x 0.011 = 1.1e-8), so
    # rtol governs on any CPU and atol is only a floor; measured 2.3e-10 at worst (absolute)
    np.testing.assert_allclose(W(df), -W(f, 1) / a, rtol=1e-6, atol=1e-9)
    np.testing.assert_allclose(W(ddf), W(f, 2) / a ** 2, rtol=1e-6, atol=1e-9)
    np.testing.assert_allclose(W(F), -a * W(f, -1), rtol=1e-6, atol=1e-9)


@pytest.mark.parametrize("wavelet", [PolynomialWavelet(6), MexicanHat()])
def test_analytic_derivatives_match_finite_differences(wavelet):
    x = np.linspace(-0.9, 0.9, 41) * wavelet.half_width * 0.8
    h = 1e-5
    for d in (-2, -1, 0, 1):
        numeric = (wavelet(x + h, d) - wavelet(x - h, d)) / (2 * h)
        np.testing.assert_allclose(numeric, wavelet(x, d + 1), rtol=1e-6, atol=1e-6)


def test_mexican_hat_agrees_with_pywavelets():
    pywt = pytest.importorskip("pywt")
    scales_samples = np.array([60.0, 150.0, 400.0])
    t = T[:10000]
    f = np.cos(2 * np.pi * 0.7 * t) + 0.5 * np.sin(2 * np.pi * 1.9 * t)
    coef, _ = pywt.cwt(f, scales_samples, "mexh", sampling_period=DT)
    n = np.array([4000, 5000, 6123])
    # pywt differences an integrated wavelet, which centres coefficient n half a sample early
    ours = np.array([wavelet_transform(f, t, scales_samples * DT, np.full(3, t[k] - DT / 2),
                                       "mexican_hat") for k in n]).T
    # pywt's 'mexh' is 2/(sqrt(3) pi^(1/4)) (1 - x^2) exp(-x^2/2), normalised by 1/sqrt(s)
    # with s in samples, while ours is (1/a) with a in seconds: coef = c sqrt(s) W
    c = 2 / (math.sqrt(3) * math.pi ** 0.25)
    np.testing.assert_allclose(coef[:, n], c * np.sqrt(scales_samples)[:, None] * ours,
                               rtol=2e-4)


def test_transform_matrix_is_sparse_inside_support():
    wavelet = PolynomialWavelet(8)
    m = transform_matrix(T, np.array([0.5]), np.array([3.0]), wavelet)
    cols = m.indices
    assert T[cols].min() >= 2.5 - 1e-12 and T[cols].max() <= 3.5 + 1e-12
    assert m.shape == (1, len(T))


def test_bad_wavelet_settings_are_refused():
    with pytest.raises(ConfigError, match="unknown wavelet 'morlet'"):
        make_wavelet("morlet")
    with pytest.raises(ConfigError, match="'order' parameter of PolynomialWavelet"):
        PolynomialWavelet(3)
    with pytest.raises(ConfigError, match="'truncation' parameter of MexicanHat"):
        MexicanHat(1.0)
    with pytest.raises(ConfigError, match="derivative order"):
        PolynomialWavelet()(np.zeros(3), 3)
    with pytest.raises(ConfigError, match="positive"):
        transform_matrix(T, np.array([-1.0]), np.array([1.0]), MexicanHat())
    assert make_wavelet({"name": "polynomial", "order": 7}).order == 7
