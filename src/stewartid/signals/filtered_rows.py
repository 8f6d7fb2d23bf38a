"""A few rows of the kernel filter of many signals, by direct sums where FFTs would cost more."""

from __future__ import annotations

import numpy as np

from stewartid.signals.differentiation import KERNEL_EXPONENT, kernel_taps, require_window

#: Largest number of kept rows per banded product in :func:`kernel_filter_rows`.
BLOCK_ROWS = 24


def kernel_filter_rows(x: np.ndarray, sample_rate: float, window: float, step: int = 1,
                       exponent: int = KERNEL_EXPONENT, time_last: bool = False,
                       derivative: int = 0) -> np.ndarray:
    """``kernel_filter(x, ..., derivatives=derivative)[derivative][::step]`` by direct sums, for
    many columns and few rows.

    Blocks of kept rows go through one banded matrix product. ``x`` (N, ...), or (..., N) with time
    on the last axis of input and result when ``time_last``; ``window`` W in s, ``exponent`` p >= 3;
    ``derivative`` 0, 1 or 2: rows of x * h, x * h' or x * h'' (x, x/s, x/s^2).
    Rows are aligned with samples L//2, L//2 + step, ...
    """
    x = np.asarray(x, dtype=float)
    kernel = kernel_taps(sample_rate, window, derivative, exponent)[derivative]
    samples = x.shape[-1] if time_last else len(x)
    require_window(samples, len(kernel), window)
    if not derivative:
        return convolved_rows(x, kernel, step, time_last)
    # the mean filtered apart, as in kernel_filter: a derivative's round-off then scales with
    # the motion, not with the position (metres of heave under millimetres of motion)
    offset = x.mean(axis=-1, keepdims=True) if time_last else x.mean(axis=0)
    return convolved_rows(x - offset, kernel, step, time_last) + offset * np.sum(kernel)


def convolved_rows(x: np.ndarray, kernel: np.ndarray, step: int = 1,
                   time_last: bool = False) -> np.ndarray:
    """``np.convolve(x, kernel, "valid")[::step]`` along time, by direct sums: kept row k at
    samples k step ... k step + L - 1 of ``x`` (N, ...), or (..., N) with time on the last axis
    of input and result when ``time_last``; ``kernel`` (L,) with L <= N."""
    taps = np.asarray(kernel, dtype=float)[::-1]
    length = len(taps)
    samples = x.shape[-1] if time_last else len(x)
    flat = x.reshape(-1, samples) if time_last else x.reshape(samples, -1)
    starts = np.arange(0, samples - length + 1, step)
    out = np.empty((flat.shape[0], len(starts)) if time_last else (len(starts), flat.shape[1]))
    # blocks of rows as one banded matrix product; 24 rows a block: the zeros of the band cost
    # more in larger blocks than BLAS gains from them
    block = max(1, min(len(starts), length // step, BLOCK_ROWS))
    span = (block - 1) * step + length
    band = np.zeros((block, span))
    for k in range(block):
        band[k, k * step:k * step + length] = taps
    for first in range(0, len(starts), block):
        rows = min(block, len(starts) - first)
        start = starts[first]
        stop = start + (rows - 1) * step + length
        if time_last:
            out[:, first:first + rows] = flat[:, start:stop] @ band[:rows, :stop - start].T
        else:
            out[first:first + rows] = band[:rows, :stop - start] @ flat[start:stop]
    if time_last:
        return out.reshape(x.shape[:-1] + (len(starts),))
    return out.reshape((len(out),) + x.shape[1:])


__all__ = ["BLOCK_ROWS", "convolved_rows", "kernel_filter_rows"]
