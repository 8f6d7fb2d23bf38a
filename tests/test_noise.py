"""Sensor noise: every method's errors against the standard errors it predicts.

The independent simulator's example data set (tests/data/example_c10, truth in truth.json)
with 20 um of white noise on the measured leg lengths (the pose is the forward kinematics of
the noisy lengths, as on a real hexapod) and 0.5 % force noise, over three seeds. The
predicted standard errors must be of the order of the actual errors (ratio RMS over the 20
entries of the paper's tables and the seeds within [0.2, 5]); the noise-induced error is the
difference from the same method's noise-free estimate (Method A's Coulomb bias is a bias,
which no standard error predicts, so Method A is checked on that one only). Method B's
default margin (0.015 periods) is compared with a 0.1 s one under noise (see
docs/benchmarks.md).

The fast test runs Methods A and least squares on one seed at a quarter of the sample rate:
their noise-induced errors lie within three reported standard errors for most entries.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benchmarks"))
from noise_study import study  # noqa: E402

SEEDS = (0, 1, 2)


@pytest.fixture(scope="module")
def rows():
    # every other sample (500 Hz): the same physics at half the cost; the sampling check
    # flags none of these records (test_sampling.py, the contract test) and would add a fit
    # at half the rate to each
    return study(seeds=SEEDS, length_noise=20e-6, force_noise=0.005, stride=2,
                 sampling_check=False)


def _rms(values):
    values = np.concatenate(values)
    return float(np.sqrt(np.mean(values ** 2)))


def test_noise_induced_errors_within_three_standard_errors():
    rows = study(methods=("fourier", "ls"), seeds=(0,), length_noise=20e-6, force_noise=0.005,
                 stride=4)
    for method in ("fourier", "ls"):
        (noisy,) = [r for r in rows if r["method"] == method and r["noise"] == "noisy"]
        within = np.mean(noisy["noise_ratios"] <= 3.0)
        assert within >= 0.8, f"{method}: only {within:.0%} of the 20 entries within 3 SE"
        # ... and the standard errors are not so pessimistic that the check is vacuous
        assert _rms([noisy["noise_ratios"]]) >= 0.2, method


def _noisy(rows, method):
    out = [r for r in rows if r["method"] == method and r["noise"] == "noisy"]
    assert len(out) == len(SEEDS)
    return out


@pytest.mark.slow
@pytest.mark.parametrize("method", ["fourier", "ls", "wavelet"])
def test_standard_errors_predict_the_noise_induced_error(rows, method):
    ratio = _rms([r["noise_ratios"] for r in _noisy(rows, method)])
    assert 0.2 <= ratio <= 5.0, f"{method}: RMS |noise-induced error| / SE = {ratio:.3g}"


@pytest.mark.slow
@pytest.mark.parametrize("method", ["ls", "wavelet"])
def test_standard_errors_predict_the_error_against_truth(rows, method):
    ratio = _rms([r["ratios"] for r in _noisy(rows, method)])
    assert 0.2 <= ratio <= 5.0, f"{method}: RMS |error| / SE = {ratio:.3g}"


@pytest.mark.slow
def test_wavelet_noise_free_within_one_percent_and_short_margin_less_noise_sensitive(rows):
    clean = [r for r in rows if r["method"] == "wavelet" and r["noise"] == "none"]
    assert clean[0]["max_error_percent"] <= 1.0
    largest = {method: max(r["max_error_percent"] for r in _noisy(rows, method))
               for method in ("wavelet_free", "wavelet_m01")}
    assert all(np.isfinite(value) for value in largest.values())
    # with the free interval constants, the default margin (0.015 periods, 0.019 s here)
    # keeps longer intervals than 0.1 s, so noise moves its estimate less
    assert largest["wavelet_free"] < largest["wavelet_m01"], largest


@pytest.mark.slow
def test_method_b_under_reference_noise_is_accurate_and_calibrated():
    """Default Method B on the independent example with the reference sensor noise (20 um on
    the leg lengths, pose by forward kinematics, 0.5 % force noise): the inertia diagonal
    within 0.75 %, the inertia couplings within 15 %, and |error| within three reported
    standard errors for at least 19 of the 20 entries of the paper's tables (this seed at
    500 Hz: 0.31 %, 7.0 %, 20/20; over 8 seeds at 1 kHz: Mt diagonal <= 0.37 %, couplings
    <= 9.4 %, 100 % of the entries within 3 SE). Before the pose noise was weighted and its
    bias removed the Mt diagonal reached 1.0 %, the couplings 19 %."""
    (row,) = [r for r in study(methods=("wavelet",), seeds=(1,), length_noise=20e-6,
                               force_noise=0.005, stride=2) if r["noise"] == "noisy"]
    assert np.max(row["errors"][:6]) <= 0.75, row["errors"][:6]
    assert np.max(row["errors"][6:10]) <= 15.0, row["errors"][6:10]
    assert np.sum(row["ratios"] <= 3.0) >= 19, row["ratios"]
    # the standard errors are not so wide that the check says nothing
    assert np.median(row["ratios"]) >= 0.1
