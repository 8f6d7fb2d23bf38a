"""Standard errors calibrated by the disagreement of symmetric pairs, against the chi
distribution of honest and of understated errors."""

from __future__ import annotations

import numpy as np
import pytest

from stewartid.identification.pairs import (
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
    """Over many draws of 15 honest pairs the Birge ratio sqrt(mean z^2) is a chi_15 /
    sqrt(15) variable, mean 0.983; understated errors scale it (and the robust scale, median
    |z| / 0.6745, the same way). With ``clip`` the ratio climbs from the robust scale to
    include errors understated everywhere, and its factor recovers the same (mean within 6 %;
    clipping at 3 ratios cuts 0.3 % of an honest normal's mass)."""
    rng = np.random.default_rng(3)
    sigma = 0.2
    ratios, clipped = [], []
    for _ in range(400):
        estimate = _estimates(rng, sigma)
        std = np.full((6, 6), sigma / understated)
        scores = symmetric_pair_scores(estimate, std)
        found = pair_calibration(scores)
        ratios.append((found["birge_ratio"], found["scale"]))
        clipped.append(pair_calibration(scores, clip=True)["factor"])
    ratios = np.array(ratios)
    spread = ratios.std(axis=0) / np.sqrt(len(ratios))
    # E chi_15 / sqrt(15) = 0.9834; the sample median of 15 is unbiased to a few per cent
    assert np.mean(ratios[:, 0]) == pytest.approx(0.9834 * understated, abs=6 * spread[0])
    assert np.mean(ratios[:, 1]) == pytest.approx(understated, abs=6 * spread[1] + 0.05 * understated)
    assert np.mean(clipped) == pytest.approx(max(0.9834 * understated, 1.0), rel=0.06)


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
    assert found["M"]["factor"] > 3
    assert np.diag(std_M) == pytest.approx(np.diag(small) * found["M"]["factor"])
    assert np.all(std_M >= small * found["M"]["factor"])
    assert pair_calibration(np.array([]))["factor"] == 1.0


def test_a_pair_still_apart_after_the_factor_gets_half_its_difference():
    """One coupling biased by 100 errors among 14 honest pairs: the factor (about
    100 / sqrt(15) = 26) leaves that pair about 3.8 combined errors apart, so both members
    get half their difference."""
    rng = np.random.default_rng(8)
    sigma = 0.1
    M = _estimates(rng, sigma)
    M[0, 4] += 100 * sigma * np.sqrt(2)
    std_M, std_B = np.full((6, 6), sigma), np.full((6, 6), sigma)
    found = calibrate_by_pairs(M, M.copy(), std_M, std_B)
    factor = found["M"]["factor"]
    assert 20 < factor < 30
    half = abs(M[0, 4] - M[4, 0]) / 2
    assert std_M[0, 4] == std_M[4, 0] == pytest.approx(half)
    assert np.max(np.delete(std_M.ravel(), [4, 24])) == pytest.approx(sigma * factor)


def test_clipping_leaves_a_few_far_pairs_to_themselves():
    """Two couplings biased by 50 errors among 13 honest pairs: the plain factor is about
    50 sqrt(2 / 15) = 18 and inflates every error; with ``clip`` (a fit immune to the
    friction law, whose model error sits in a few equations) the two pairs are left out and
    the factor stays within the chi_13 / sqrt(13) spread of honest pairs (below 1.6 with
    probability 0.998), the two members of each biased pair then taking their own
    disagreement (:func:`select_symmetric_pairs`)."""
    rng = np.random.default_rng(11)
    sigma = 0.1
    M = _estimates(rng, sigma)
    M[0, 4] += 50 * sigma * np.sqrt(2)
    M[1, 3] -= 50 * sigma * np.sqrt(2)
    scores = symmetric_pair_scores(M, np.full((6, 6), sigma))
    plain, clipped = pair_calibration(scores), pair_calibration(scores, clip=True)
    assert 14 < plain["factor"] < 22 and plain["outliers"] == 0
    assert clipped["outliers"] == 2 and clipped["factor"] < 1.6
    assert clipped["birge_ratio"] == plain["birge_ratio"]

