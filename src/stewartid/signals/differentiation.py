"""Noise-aware differentiation of measured motion, and excitation-frequency estimation.

Velocities and accelerations come from a Savitzky-Golay filter: a polynomial of order
``order`` fitted by least squares in a sliding window of ``window`` seconds, differentiated
analytically (Savitzky & Golay 1964, doi:10.1021/ac60214a047).

Choice of window and order. For a sine of frequency f the filter returns the derivative
scaled by a gain H_d(f) that tends to 1 as the window shrinks, while the white-noise gain grows
like window^-(d + 1/2). With order 5 and a window of 0.2 periods of the highest excitation
frequency (the default, :func:`default_window`), the relative amplitude error at f is
1e-6 for the velocity and 2e-4 for the acceleration, and at 1 kHz and 0.5 Hz the noise on the
acceleration is about 29 (1/s^2) times the position noise per sample, which averages out over
whole periods. Shorter windows trade noise for bias; ``window`` is a setting of every
identifier that differentiates.

The first and last half-window are fitted by the end polynomials (``mode="interp"``); they
are noisier, so identifiers drop them (:func:`trim`).
"""

from __future__ import annotations

import numpy as np
from scipy.signal import savgol_filter

from stewartid.errors import ConfigError, DataError

#: Default polynomial order of the Savitzky-Golay differentiator.
DEFAULT_ORDER = 5
#: Default window, in periods of the highest excitation frequency.
DEFAULT_WINDOW_PERIODS = 0.2


def default_window(frequency_hz: float, periods: float = DEFAULT_WINDOW_PERIODS) -> float:
    """Savitzky-Golay window (s): ``periods`` periods of ``frequency_hz``."""
    if not (frequency_hz > 0 and np.isfinite(frequency_hz)):
        raise ConfigError(f"excitation frequency must be positive and finite; got "
                          f"{frequency_hz!r} Hz.")
    return periods / frequency_hz


def window_samples(window: float, sample_rate: float, order: int = DEFAULT_ORDER) -> int:
    """Odd number of samples spanning ``window`` seconds, at least order + 2 (or + 3)."""
    n = int(round(window * sample_rate))
    n = max(n, order + 2)
    return n if n % 2 else n + 1


def differentiate(x: np.ndarray, sample_rate: float, window: float,
                  order: int = DEFAULT_ORDER) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Smoothed signal and its first two time derivatives by Savitzky-Golay filtering.

    Parameters
    ----------
    x : ndarray, shape (N,) or (N, m)
        Uniformly sampled signal(s), time on axis 0.
    sample_rate : float
        Hz.
    window : float
        Window length (s); see the module docstring for the choice.
    order : int
        Polynomial order (>= 3 for an acceleration).

    Returns
    -------
    x_smooth, x_dot, x_ddot : ndarray, shape of ``x``
        Units of x, x/s, x/s^2.

    Raises
    ------
    DataError
        When the record is shorter than the window.
    """
    x = np.asarray(x, dtype=float)
    if order < 3:
        raise ConfigError(f"The 'order' parameter of the differentiator must be an int >= 3. "
                          f"Got {order!r} instead.")
    n = window_samples(window, sample_rate, order)
    if n > len(x):
        raise DataError(f"record of {len(x)} samples is shorter than the differentiation "
                        f"window ({n} samples = {window:.3g} s); record longer or shorten "
                        "the window.")
    from scipy.signal import oaconvolve, savgol_coeffs

    delta = 1.0 / sample_rate
    half = n // 2
    out = []
    for deriv in (0, 1, 2):
        # interior by FFT convolution (long windows), the two edge half-windows by the end
        # polynomials of scipy's savgol_filter(mode="interp")
        taps = savgol_coeffs(n, order, deriv=deriv, delta=delta, use="conv")
        taps = taps.reshape((n,) + (1,) * (x.ndim - 1))
        y = oaconvolve(x, taps, mode="same", axes=0)
        head = savgol_filter(x[:n], n, order, deriv=deriv, delta=delta, axis=0, mode="interp")
        tail = savgol_filter(x[-n:], n, order, deriv=deriv, delta=delta, axis=0, mode="interp")
        y[:half] = head[:half]
        y[len(x) - half:] = tail[n - half:]
        out.append(y)
    return out[0], out[1], out[2]


def savgol_gain(frequency_hz: float, sample_rate: float, window: float,
                order: int = DEFAULT_ORDER, deriv: int = 0) -> float:
    """Gain of the Savitzky-Golay estimate of the ``deriv``-th derivative of a sine.

    The filter is symmetric, so for x = sin(w t) its derivative estimate is exactly
    gain * d^k/dt^k sin(w t) (no phase error); dividing harmonic coefficients by this gain
    removes the filter's amplitude bias at that frequency.
    """
    from scipy.signal import savgol_coeffs

    n = window_samples(window, sample_rate, order)
    coefficients = savgol_coeffs(n, order, deriv=deriv, delta=1.0 / sample_rate, use="dot")
    w = 2 * np.pi * frequency_hz
    offsets = (np.arange(n) - n // 2) / sample_rate
    response = np.sum(coefficients * np.exp(1j * w * offsets))
    return float(np.real(response / (1j * w) ** deriv))


#: Exponent p of the smoothing kernel h(tau) ~ (1 - (2 tau / W)^2)^p of :func:`kernel_filter`.
KERNEL_EXPONENT = 6


def kernel_filter(x: np.ndarray, sample_rate: float, window: float, derivatives: int = 0,
                  exponent: int = KERNEL_EXPONENT) -> list[np.ndarray]:
    """Convolve with a smooth compact kernel h and, optionally, its derivatives.

    (x * h)(t) = integral x(t - tau) h(tau) dtau with h(tau) = c (1 - (2 tau / W)^2)^p on
    |tau| < W/2 (unit integral). Because h and its first p - 1 derivatives vanish at the ends,
    d/dt (x * h) = x * h' and d^2/dt^2 (x * h) = x * h'' exactly: filtering a linear
    equation of motion with h gives an equation in filtered signals whose velocity and
    acceleration come from the measured positions without numerical differentiation, and in
    which every other term (forces, Coulomb signs) is filtered identically, so the filter
    introduces no bias (the modulating-function idea).

    Parameters
    ----------
    x : ndarray, shape (N, ...)
        Uniformly sampled signals, time on axis 0.
    sample_rate : float
        Hz.
    window : float
        Kernel support W (s).
    derivatives : {0, 1, 2}
        Also return x * h' (units x/s) and x * h'' (x/s^2).
    exponent : int
        p >= 3.

    Returns
    -------
    list of ndarray, each of shape (N - L + 1, ...)
        [x * h, (x * h'), (x * h'')], aligned with the samples L//2 ... N - 1 - L//2 of x
        (L = kernel samples, odd).
    """
    from scipy.signal import oaconvolve

    x = np.asarray(x, dtype=float)
    n = window_samples(window, sample_rate, 2 * exponent)
    if n > len(x):
        raise DataError(f"record of {len(x)} samples is shorter than the filter window "
                        f"({n} samples = {window:.3g} s); record longer or shorten the window.")
    half = (n - 1) / 2 / sample_rate + 0.5 / sample_rate
    tau = (np.arange(n) - (n - 1) / 2) / sample_rate
    u = tau / half
    base = 1.0 - u ** 2
    p = exponent
    kernels = [base ** p,
               p * base ** (p - 1) * (-2 * u / half),
               (p * (p - 1) * base ** (p - 2) * (2 * u / half) ** 2
                + p * base ** (p - 1) * (-2 / half ** 2))]
    norm = np.sum(kernels[0]) / sample_rate
    shape = (n,) + (1,) * (x.ndim - 1)
    return [oaconvolve(x, (k / norm / sample_rate).reshape(shape), mode="valid", axes=0)
            for k in kernels[:derivatives + 1]]


def trim(window: float, sample_rate: float, order: int = DEFAULT_ORDER) -> int:
    """Samples to drop at each end of a differentiated record (half a window)."""
    return window_samples(window, sample_rate, order) // 2


def estimate_frequency(x: np.ndarray, sample_rate: float) -> float:
    """Frequency (Hz) of the dominant sine in ``x``.

    The largest peak of the Hann-windowed, zero-padded spectrum of the channel with the largest
    relative variation, refined by fitting a sine by nonlinear least squares around it (the
    refinement is what makes whole-period windows exact enough for Method A).

    Parameters
    ----------
    x : ndarray, shape (N,) or (N, m)
    sample_rate : float
        Hz.

    Returns
    -------
    float
        Hz.

    Raises
    ------
    DataError
        When no channel moves.
    """
    x = np.asarray(x, dtype=float)
    x = x[:, None] if x.ndim == 1 else x
    centered = x - x.mean(axis=0)
    spread = centered.std(axis=0)
    if not np.any(spread > 0):
        raise DataError("the motion is constant; no excitation frequency can be found.")
    n = len(x)
    nfft = 1 << int(np.ceil(np.log2(8 * n)))
    spectra = np.abs(np.fft.rfft(centered * np.hanning(n)[:, None], nfft, axis=0))
    # compare channels by spectral peak relative to the channel's own scale: units differ
    relative = spectra[1:] / np.where(spread > 0, spread, np.inf)
    k, channel = np.unravel_index(np.argmax(relative), relative.shape)
    frequency = (k + 1) * sample_rate / nfft
    return _refine_frequency(centered[:, channel], sample_rate, frequency)


def _refine_frequency(x: np.ndarray, sample_rate: float, frequency: float) -> float:
    from scipy.optimize import minimize_scalar

    t = np.arange(len(x)) / sample_rate
    design_constant = np.ones_like(t)

    def cost(f: float) -> float:
        A = np.column_stack([np.sin(2 * np.pi * f * t), np.cos(2 * np.pi * f * t),
                             design_constant, t])
        coef, *_ = np.linalg.lstsq(A, x, rcond=None)
        return float(np.sum((x - A @ coef) ** 2))

    bin_width = sample_rate / len(x)
    result = minimize_scalar(cost, bounds=(max(frequency - bin_width, 1e-6 * frequency),
                                           frequency + bin_width),
                             method="bounded", options={"xatol": 1e-9 * frequency})
    return float(result.x)


__all__ = ["DEFAULT_ORDER", "DEFAULT_WINDOW_PERIODS", "default_window", "differentiate",
           "estimate_frequency", "kernel_filter", "savgol_gain", "trim", "window_samples"]
