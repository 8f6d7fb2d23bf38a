"""Errors in variables of the physical model: the pose noise's share of the normal equations
against a Monte Carlo of the filtered regression on noisy copies of one record, and the
Coulomb signs' window against the record's noise."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from stewartid.identification.long_run import filtered_noise_covariance
from stewartid.identification.preparation import prepare
from stewartid.identification.wavelet.noise import white_noise_covariance
from stewartid.model import regressor as reg
from stewartid.physical.noise import regressor_noise
from stewartid.physical.regression import (
    SAVGOL_FRACTION,
    SAVGOL_ORDER,
    filtered_regression,
)
from stewartid.signals.filtered_rows import kernel_filter_rows
from stewartid.signals.sign_rates import SIGN_FRACTIONS, coulomb_sign_rates
from test_physical_model import PAYLOAD, multisine_records

#: Pose noise (m, rad) of the copies: white, independent per coordinate.
NOISE = np.array([2e-5, 2e-5, 2e-5, 1e-5, 1e-5, 1e-5])


@pytest.fixture(scope="module")
def loaded(paper):
    return paper.replace(friction__coulomb=30.0,
                         **{f"payload__{key}": value for key, value in PAYLOAD.items()})


def test_regressor_noise_matches_a_monte_carlo(loaded):
    """E[dY^T dY] of the inertial columns (m, I_xx, I_yy, I_zz, summed over channels): the
    prediction within 20 % of 24 noisy copies' mean (whose own scatter is about
    sqrt(2 / 24) = 29 % per copy-pair product, far less over the rows summed)."""
    record = multisine_records(loaded, 1.0, duration=6.0)[:1]
    clean = prepare(record, loaded, gravity=False)
    base = filtered_regression(clean, loaded, decimate=None, order=SAVGOL_ORDER)
    windows = [e["window_s"] for e in base.experiments]
    step = base.experiments[0]["row_step"]
    columns = reg.parameter_index(["m", "I_xx", "I_yy", "I_zz"])
    rng = np.random.default_rng(3)
    sums, predicted = np.zeros(len(columns)), np.zeros(len(columns))
    copies = 24
    for _ in range(copies):
        noisy = [dataclasses.replace(e, q=e.q + rng.normal(size=e.q.shape) * NOISE)
                 for e in clean]
        found = filtered_regression(noisy, loaded, windows[0], SAVGOL_ORDER, step)
        delta = (found.Y - base.Y)[:, :, columns]
        sums += np.einsum("kip,kip->p", delta, delta)
        gram = regressor_noise(noisy, windows, step, loaded, SAVGOL_FRACTION, SAVGOL_ORDER,
                               found.pose_noise)
        predicted += np.einsum("ipp->p", gram[:, columns][:, :, columns])
    assert predicted / sums == pytest.approx(np.ones(len(columns)), rel=0.2)


def test_filtered_noise_covariance_equals_the_dense_sum():
    """B = G^T Sigma G with Sigma the rows' noise covariance written out in full (the
    channels' S times rho at every pair of rows of a record, none across records), against
    the lag sums."""
    rng = np.random.default_rng(5)
    segments = [(23, 0), (2, 0), (15, 0)]  # one record shorter than the correlation
    X = rng.normal(size=(40, 3, 2))
    weights = np.array([0.5, 1.0, 2.0])
    noises = []
    for _ in segments:
        L = rng.normal(size=(3, 3))
        noises.append((L @ L.T, np.array([1.0, 0.6, 0.25, -0.1])))
    sigma = np.zeros((120, 120))
    start = 0
    for (rows, _), (S, rho) in zip(segments, noises, strict=True):
        for k in range(rows):
            for j in range(rows):
                if abs(k - j) < len(rho):
                    sigma[3 * (start + k):3 * (start + k) + 3,
                          3 * (start + j):3 * (start + j) + 3] = S * rho[abs(k - j)]
        start += rows
    G = (X * weights[None, :, None]).reshape(120, 2)
    assert np.allclose(filtered_noise_covariance(X, weights, segments, noises),
                       G.T @ sigma @ G, rtol=1e-12, atol=0.0)


def test_measured_force_noise_is_that_of_the_filtered_rows(loaded):
    """The leg forces' white noise estimated from a noisy copy of one record (6 s at 500 Hz:
    a standard error of about 2 %; 150.3-154.2 N came out), and the kernel's
    autocorrelation at row lags against the filtered rows of white noise (64 series: the
    lag products' scatter about 2 % of rho[0]; within 1.6 % came out)."""
    record = multisine_records(loaded, 1.0, duration=6.0)[0]
    noise = 150.0
    rng = np.random.default_rng(9)
    noisy = dataclasses.replace(
        record, forces=record.forces + rng.normal(0.0, noise, record.forces.shape))
    data = filtered_regression(prepare([noisy], loaded, gravity=False), loaded)
    assert np.sqrt(np.diag(data.force_noise[0])) == pytest.approx([noise] * 6, rel=0.06)
    S, rho = data.measured_force_noise()[0]
    e = data.experiments[0]
    series = rng.normal(size=(64, 6000))
    rows = np.array([kernel_filter_rows(x, e["sample_rate"], e["window_s"], e["row_step"])
                     for x in series])
    lags = len(rho) + 2
    empirical = np.array([np.mean(rows[:, :rows.shape[1] - m] * rows[:, m:])
                          for m in range(lags)])
    expected = np.concatenate([rho, np.zeros(2)])
    assert np.allclose(empirical, expected, atol=0.05 * rho[0])


def test_sign_window_follows_the_noise(loaded):
    """Noise-free poses keep the shortest window (the switches where the motion has them);
    the reference noise on the paper's small sines takes a longer one."""
    record = prepare(multisine_records(loaded, 1.0, duration=6.0)[:1], loaded, gravity=False)[0]
    window = 0.4
    _, chosen = coulomb_sign_rates(record.q, record.sample_rate, window,
                                   white_noise_covariance(record.q, record.q))
    assert chosen == pytest.approx(window * SIGN_FRACTIONS[0])
    noisy = record.q + np.random.default_rng(0).normal(size=record.q.shape) * NOISE * 3
    _, chosen = coulomb_sign_rates(noisy, record.sample_rate, window,
                                   white_noise_covariance(noisy, record.q))
    assert chosen > window * SIGN_FRACTIONS[0]
