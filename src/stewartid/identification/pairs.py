"""Symmetric pairs: the two estimates of each off-diagonal entry of Mt and Bt.

They come from different equations: their difference tests and calibrates the standard errors.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from stewartid.arrays import median


def symmetric_pair_scores(matrix: np.ndarray, std: np.ndarray) -> np.ndarray:
    """|a_ij - a_ji| / sqrt(s_ij^2 + s_ji^2) of every off-diagonal pair (i < j), row-major."""
    upper = np.triu_indices(matrix.shape[0], 1)
    spread = np.hypot(std[upper], std.T[upper])
    return np.abs(matrix[upper] - matrix.T[upper]) / np.maximum(spread, 1e-300)


#: A symmetric pair whose members still differ by more than this many combined standard
#: errors after the common factor carries a model error of its own.
PAIR_DISAGREEMENT = 3.0


#: Median of |z| for a standard normal z: the robust scale of honest pair scores.
HALF_NORMAL_MEDIAN = 0.6744897501960817


def pair_calibration(scores: np.ndarray, clip: bool = False) -> dict[str, Any]:
    """How far the symmetric pairs' scatter exceeds their standard errors.

    The factor is the Birge ratio sqrt(mean z^2), at least 1; with ``clip`` it is taken over the pairs
    within :data:`PAIR_DISAGREEMENT` times it. Returns ``{"pairs", "birge_ratio", "scale", "largest",
    "outliers", "factor"}``.
    """
    scores = np.asarray(scores, dtype=float)
    scores = scores[np.isfinite(scores)]
    if scores.size == 0:
        nan = float("nan")
        return {"pairs": 0, "birge_ratio": nan, "scale": nan, "largest": nan, "outliers": 0,
                "factor": 1.0}
    ratio = float(np.sqrt(np.mean(scores ** 2)))
    scale = median(scores) / HALF_NORMAL_MEDIAN
    # from the robust scale up: a few pairs far out cannot hold the ratio above them
    inside = np.zeros(scores.size, dtype=bool)
    clipped = scale if clip else ratio
    for _ in range(scores.size + 1 if clip else 0):
        now = scores <= PAIR_DISAGREEMENT * max(clipped, 1.0)
        if not now.any() or np.array_equal(now, inside):
            break
        inside = now
        clipped = float(np.sqrt(np.mean(scores[inside] ** 2)))
    return {"pairs": int(scores.size), "birge_ratio": ratio,
            "scale": scale, "largest": float(scores.max()),
            "outliers": int(np.sum(~inside)) if clip else 0,
            "factor": max(clipped, 1.0)}


def calibrate_by_pairs(M: np.ndarray, B: np.ndarray, std_M: np.ndarray,
                       std_B: np.ndarray) -> dict[str, dict[str, Any]]:
    """Calibrate the standard errors of Mt and Bt, in place, by their symmetric pairs.

    Errors times :func:`pair_calibration`'s factor; members still disagreeing beyond
    :data:`PAIR_DISAGREEMENT` get at least half their difference. Returns ``{"M": ..., "B": ...}``.
    """
    found = {}
    upper = np.triu_indices(M.shape[0], 1)
    for name, matrix, std in (("M", M, std_M), ("B", B, std_B)):
        found[name] = pair_calibration(symmetric_pair_scores(matrix, std))
        std *= found[name]["factor"]
        half = np.abs(matrix[upper] - matrix.T[upper]) / 2
        apart = half * 2 > PAIR_DISAGREEMENT * np.hypot(std[upper], std.T[upper])
        for i, j, h in zip(upper[0][apart], upper[1][apart], half[apart], strict=True):
            std[i, j], std[j, i] = max(std[i, j], h), max(std[j, i], h)
    return found


def select_symmetric_pairs(matrix: np.ndarray, std: np.ndarray,
                           preferred_rows: tuple[int, ...] = (0, 1, 2),
                           disagreement: float = PAIR_DISAGREEMENT, pool: bool = False
                           ) -> list[dict]:
    """Copy the better estimate of every off-diagonal pair (or the pooled mean) onto both entries, in place.

    The smaller standard error wins; beyond ``disagreement`` a member in ``preferred_rows`` (0-based)
    wins and its error is raised to |difference| / ``disagreement``; ``pool`` averages agreeing members
    by inverse variance. Returns per pair {"pair", "kept", "disagreement", "pooled"}, 1-based.
    """
    choice = []
    n = matrix.shape[0]
    for i in range(n):
        for j in range(i + 1, n):
            keep, drop = ((i, j), (j, i)) if std[i, j] <= std[j, i] else ((j, i), (i, j))
            difference = abs(matrix[i, j] - matrix[j, i])
            z = difference / max(float(np.hypot(std[i, j], std[j, i])), 1e-300)
            if z > disagreement and (i in preferred_rows) != (j in preferred_rows):
                keep, drop = ((i, j), (j, i)) if i in preferred_rows else ((j, i), (i, j))
            pooled = pool and z <= disagreement
            if pooled:
                w_keep, w_drop = std[keep] ** -2.0, std[drop] ** -2.0
                matrix[keep] = (w_keep * matrix[keep] + w_drop * matrix[drop]) / (w_keep + w_drop)
                std[keep] = (w_keep + w_drop) ** -0.5
            matrix[drop] = matrix[keep]
            if z > disagreement:
                std[keep] = max(std[keep], difference / disagreement)
            std[drop] = std[keep]
            choice.append({"pair": [[i + 1, j + 1], [j + 1, i + 1]],
                           "kept": [keep[0] + 1, keep[1] + 1], "disagreement": float(z),
                           "pooled": bool(pooled)})
    return choice


def combine_pairs(M: np.ndarray, B: np.ndarray, std_M: np.ndarray, std_B: np.ndarray,
                  symmetric: bool = False, pair_selection: str = "pooled", clip: bool = False
                  ) -> tuple[dict, dict]:
    """Method B's symmetric pairs, in place, and their calibration.

    Select per ``pair_selection`` ("pooled", "std_error", "none") then calibrate, or with ``symmetric``
    the inverse-variance mean. Returns (chosen, calibration) dicts keyed "M", "B".
    """
    if symmetric:
        for matrix, std in ((M, std_M), (B, std_B)):
            w = 1.0 / np.maximum(std, 1e-300) ** 2
            matrix[:] = (w * matrix + w.T * matrix.T) / (w + w.T)
            std[:] = 1.0 / np.sqrt(w + w.T)
        return {}, {}
    factors = {"M": pair_calibration(symmetric_pair_scores(M, std_M), clip),
               "B": pair_calibration(symmetric_pair_scores(B, std_B), clip)}
    raw = {"M": np.minimum(std_M, std_M.T), "B": np.minimum(std_B, std_B.T)}
    chosen = {}
    if pair_selection in ("std_error", "pooled"):
        pool = pair_selection == "pooled"
        chosen = {"M": select_symmetric_pairs(M, std_M, pool=pool),
                  "B": select_symmetric_pairs(B, std_B, pool=pool)}
    # a pair's error raised to its disagreement already holds its model error
    for name, std in (("M", std_M), ("B", std_B)):
        std[:] = np.maximum(std, factors[name]["factor"] * np.minimum(std, raw[name]))
    return chosen, factors


__all__ = ["HALF_NORMAL_MEDIAN", "PAIR_DISAGREEMENT", "calibrate_by_pairs", "combine_pairs",
           "pair_calibration", "select_symmetric_pairs", "symmetric_pair_scores"]
