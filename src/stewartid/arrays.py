"""Array helpers for the hot paths: numpy's results without its slow imports."""

from __future__ import annotations

import numpy as np


def median(values: np.ndarray, axis: int | None = None) -> float | np.ndarray:
    """``np.median(values, axis)`` bit for bit, without its NaN check's import of numpy.ma (each
    process pays it once, worker processes included); a NaN in a slice gives NaN.

    ``axis`` None: over all elements, a float; else the medians along ``axis``, an array.
    """
    array = np.asarray(values, dtype=float)
    scalar = axis is None
    if scalar:
        array, axis = array.ravel(), 0
    count = array.shape[axis]
    half = count // 2
    middle = [half - 1, half] if count % 2 == 0 else [half]
    # the middle values averaged by np.mean, as np.median does
    out = np.mean(np.take(np.partition(array, middle, axis=axis), middle, axis=axis), axis=axis)
    out = np.where(np.isnan(array).any(axis=axis), np.nan, out)
    return float(out) if scalar else out


__all__ = ["median"]
