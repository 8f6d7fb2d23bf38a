"""A few rows of the kernel filter of many signals: direct sums where the FFT of every column
would cost more (:func:`kernel_filter_rows`)."""

from __future__ import annotations

import numpy as np

from stewartid.signals.differentiation import KERNEL_EXPONENT, kernel_taps, require_window

#: Largest number of kept rows per banded product in :func:`kernel_filter_rows`.
BLOCK_ROWS = 24


def kernel_filter_rows(x: np.ndarray, sample_rate: float, window: float, step: int = 1,
                       exponent: int = KERNEL_EXPONENT, time_last: bool = False) -> np.ndarray:
    """``kernel_filter(x, ...)[0][::step]`` by direct sums, for many columns and few rows.

    Each kept row is the inner product of the kernel's taps with the samples under it, blocks of
    rows through one banded matrix product: cheaper than an FFT of every column.

    Parameters
    ----------
    x : ndarray, shape (N, ...), or (..., N) when ``time_last``
        Uniformly sampled signals, time on axis 0 (on the last axis when ``time_last``).
    sample_rate : float
        Hz.
    window : float
        Kernel support W (s).
    step : int
        Keep every ``step``-th output row.
    exponent : int
        p >= 3.
    time_last : bool
        Time on the last axis of ``x`` and of the result (no copy into time-first rows).

    Returns
    -------
    ndarray, shape (ceil((N - L + 1) / step), ...), or (..., ceil((N - L + 1) / step))
        Rows 0, step, 2 step, ... of x * h, aligned with the samples L//2, L//2 + step, ...
    """
    x = np.asarray(x, dtype=float)
    taps = kernel_taps(sample_rate, window, 0, exponent)[0]
    length = len(taps)
    samples = x.shape[-1] if time_last else len(x)
    require_window(samples, length, window)
    flat = x.reshape(-1, samples) if time_last else x.reshape(samples, -1)
    starts = np.arange(0, samples - length + 1, step)
    out = np.empty((flat.shape[0], len(starts)) if time_last else (len(starts), flat.shape[1]))
    # blocks of rows as one banded matrix product (the taps are symmetric: no flip); 24 rows
    # a block: the zeros of the band cost more in larger blocks than BLAS gains from them
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


__all__ = ["BLOCK_ROWS", "kernel_filter_rows"]
