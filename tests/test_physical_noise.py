"""Errors in variables of the physical model: the pose noise's share of the normal equations
against a Monte Carlo of the filtered regression on noisy copies of one record, and the
Coulomb signs' window against the record's noise."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from stewartid.identification.physical_noise import regressor_noise
from stewartid.identification.physical_regression import (
    SAVGOL_FRACTION,
    SAVGOL_ORDER,
    filtered_regression,
)
from stewartid.identification.preparation import prepare
from stewartid.identification.wavelet.noise import white_noise_covariance
from stewartid.model import regressor as reg
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
