"""Standard errors calibrated by the disagreement of symmetric pairs, against the chi
distribution of honest and of understated errors."""

from __future__ import annotations

import numpy as np
import pytest

from stewartid.identification.solvers import (
    calibrate_by_pairs,
    pair_calibration,
    symmetric_pair_scores,
)


def _estimates(rng, sigma, n=6):
    truth = rng.normal(size=(n, n))
    truth = truth + truth.T
    return truth + sigma * rng.normal(size=(n, n))


def test_scores_are_the_pair_differences_over_their_combined_errors():
    matrix = np.array([[1.0, 2.0], [5.0, 1.0]])
    std = np.array([[1.0, 3.0], [4.0, 1.0]])
    assert symmetric_pair_scores(matrix, std) == pytest.approx([3.0 / 5.0])


@pytest.mark.parametrize("understated", [1.0, 4.0])
def test_the_factor_recovers_how_far_errors_are_understated(understated):
    """Over many draws of 15 honest pairs the Birge ratio sqrt(mean z^2) is a chi_15 / sqrt(15)
    variable: mean near 1, standard deviation 1/sqrt(30); understated errors scale it."""
    rng = np.random.default_rng(3)
    sigma = 0.2
    ratios = []
    for _ in range(400):
        estimate = _estimates(rng, sigma)
        std = np.full((6, 6), sigma / understated)
        ratios.append(pair_calibration(symmetric_pair_scores(estimate, std))["birge_ratio"])
    spread = understated / np.sqrt(30) / np.sqrt(len(ratios))
    assert np.mean(ratios) == pytest.approx(understated, abs=6 * spread + 0.02 * understated)


def test_honest_errors_are_never_shrunk_and_understated_ones_are_raised():
    rng = np.random.default_rng(5)
    M, B = _estimates(rng, 0.1), _estimates(rng, 0.1)
    honest = np.full((6, 6), 10.0)       # far larger than the scatter
    std_M, std_B = honest.copy(), honest.copy()
    found = calibrate_by_pairs(M, B, std_M, std_B)
    assert found["M"]["factor"] == 1.0 and np.array_equal(std_M, honest)
    small = np.full((6, 6), 0.01)
    std_M, std_B = small.copy(), small.copy()
    found = calibrate_by_pairs(M, B, std_M, std_B)
    assert found["M"]["factor"] > 3 and std_M == pytest.approx(small * found["M"]["factor"])
    assert pair_calibration(np.array([]))["factor"] == 1.0
