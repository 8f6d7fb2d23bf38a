"""Noise-aware differentiation of measured motion (Savitzky & Golay 1964; modulating kernels)
and excitation-frequency estimation.
"""

from __future__ import annotations

import math
import weakref
from collections.abc import Sequence
from typing import Any

import numpy as np

from stewartid.arrays import median as array_median
from stewartid.errors import ConfigError, DataError
from stewartid.signals.brent import minimize_bounded

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
    """Odd number of samples spanning ``window`` s, at least order + 2 (or + 3)."""
    n = int(round(window * sample_rate))
    n = max(n, order + 2)
    return n if n % 2 else n + 1


def differentiate(x: np.ndarray, sample_rate: float, window: float,
                  order: int = DEFAULT_ORDER, derivatives: Sequence[int] = (0, 1, 2)
                  ) -> tuple[np.ndarray, ...]:
    """Smoothed signal and its first two time derivatives by Savitzky-Golay filtering.

    The first and last half-window come from the end polynomials (noisier; :func:`trim` drops them).

    Parameters
    ----------
    x : ndarray, shape (N,) or (N, m)
        Uniformly sampled, time on axis 0.
    sample_rate : float
        Hz.
    window : float
        s.
    order : int
        Polynomial order (>= 3 for an acceleration).
    derivatives : sequence of int
        Which of 0 (smoothed), 1, 2 to return, in that order (units x, x/s, x/s^2).

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
    delta = 1.0 / sample_rate
    half = n // 2
    taps = [savgol_coefficients(n, order, deriv, delta) for deriv in derivatives]
    # the interior by FFT convolution (one transform of x for the three filters), the two
    # edge half-windows by the end polynomials (scipy's savgol_filter(mode="interp"))
    # the mean is filtered apart (a constant's response is its value times the taps' sum):
    # the FFT's round-off then scales with the motion, not with the absolute position
    offset = x.mean(axis=0)
    interior = convolve_valid(x - offset, taps)
    out = []
    for deriv, kernel, y_interior in zip(derivatives, taps, interior, strict=True):
        y = np.empty_like(x)
        y[half:len(x) - half] = y_interior + offset * np.sum(kernel)
        y[:half] = _end_polynomial(x[:n], order, deriv, delta, np.arange(half))
        y[len(x) - half:] = _end_polynomial(x[-n:], order, deriv, delta,
                                            np.arange(n - half, n))
        out.append(y)
    return tuple(out)


def savgol_coefficients(n: int, order: int, deriv: int = 0, delta: float = 1.0) -> np.ndarray:
    """Convolution taps (n,) of the Savitzky-Golay estimate of the ``deriv``-th derivative (1/s^deriv).

    As ``scipy.signal.savgol_coeffs(n, order, deriv, delta, use="conv")`` without importing
    scipy.signal, exact for long windows (offsets scaled to [-1, 1]).
    """
    # offsets scaled to [-1, 1]: the raw Vandermonde matrix's condition number is about (n/2)^order
    half = max(n // 2, 1)
    offsets = np.arange(n // 2, n // 2 - n, -1, dtype=float) / half
    vandermonde = offsets ** np.arange(order + 1).reshape(-1, 1)
    target = np.zeros(order + 1)
    target[deriv] = math.factorial(deriv) / (delta * half) ** deriv
    return np.linalg.lstsq(vandermonde, target, rcond=None)[0]


def _end_polynomial(segment: np.ndarray, order: int, deriv: int, delta: float,
                    positions: np.ndarray) -> np.ndarray:
    """``deriv``-th derivative of the least-squares polynomial of ``segment`` at ``positions``."""
    flat = segment.reshape(len(segment), -1)
    coefficients = np.polyfit(np.arange(len(segment)), flat, order)
    for k in range(deriv):
        coefficients = coefficients[:-1] * np.arange(order - k, 0, -1)[:, None]
    values = np.polyval(coefficients, positions.reshape(-1, 1)) / delta ** deriv
    return values.reshape((len(positions),) + segment.shape[1:])


def convolve_valid(x: np.ndarray, kernels: Sequence[np.ndarray],
                   block_bytes: int = 1 << 26) -> list[np.ndarray]:
    """Convolve ``x`` (N, ...) with each kernel (L,) along axis 0, "valid" part (N - L + 1, ...).

    Overlap-save FFT: one transform of ``x`` serves every kernel; blocks of about ``block_bytes``
    bound the scratch memory. As ``np.convolve(..., mode="valid")``.
    """
    x = np.asarray(x, dtype=float)
    length = len(kernels[0])
    tail = x.shape[1:]
    flat = x.reshape(len(x), -1)
    columns = flat.shape[1]
    n_out = len(x) - length + 1
    nfft = max(1024, 1 << int(math.ceil(math.log2(8 * length))))
    step = nfft - length + 1
    spectra = [np.fft.rfft(k, nfft) for k in kernels]
    outputs = [np.empty((n_out, columns)) for _ in kernels]
    per_group = max(1, block_bytes // (8 * nfft * max(columns, 1)))
    for start in range(0, n_out, per_group * step):
        stop = min(n_out, start + per_group * step)
        blocks = -(-(stop - start) // step)
        segment = flat[start:stop + length - 1]
        # time on the last axis: every transform reads and writes contiguous samples
        padded = np.zeros((columns, (blocks - 1) * step + nfft))
        padded[:, :len(segment)] = segment.T
        windows = np.lib.stride_tricks.sliding_window_view(padded, nfft, axis=1)[:, ::step]
        transformed = np.fft.rfft(windows, axis=-1)  # (columns, blocks, nfft // 2 + 1)
        for spectrum, out in zip(spectra, outputs, strict=True):
            y = np.fft.irfft(transformed * spectrum, nfft, axis=-1)[..., length - 1:]
            out[start:stop] = y.reshape(columns, -1)[:, :stop - start].T
    return [out.reshape((n_out,) + tail) for out in outputs]


def savgol_gain(frequency_hz: float, sample_rate: float, window: float,
                order: int = DEFAULT_ORDER, deriv: int = 0) -> float:
    """Gain of the Savitzky-Golay ``deriv``-th derivative of a sine: the symmetric filter gives exactly
    gain * d^k/dt^k sin(w t), so dividing harmonic coefficients by it removes its bias.
    """
    n = window_samples(window, sample_rate, order)
    coefficients = savgol_coefficients(n, order, deriv, 1.0 / sample_rate)[::-1]
    w = 2 * np.pi * frequency_hz
    offsets = (np.arange(n) - n // 2) / sample_rate
    response = np.sum(coefficients * np.exp(1j * w * offsets))
    return float(np.real(response / (1j * w) ** deriv))


#: Exponent p of the smoothing kernel h(tau) ~ (1 - (2 tau / W)^2)^p of :func:`kernel_filter`.
KERNEL_EXPONENT = 6


def kernel_filter(x: np.ndarray, sample_rate: float, window: float, derivatives: int = 0,
                  exponent: int = KERNEL_EXPONENT) -> list[np.ndarray]:
    """Convolve ``x`` (N, ...) with a smooth compact kernel h and, optionally, its derivatives.

    h(tau) = c (1 - (2 tau / W)^2)^p on |tau| < W/2, unit integral: its first p - 1 derivatives vanish
    at the ends, so d/dt (x * h) = x * h' exactly (modulating functions). ``window`` W in s,
    ``derivatives`` in {0, 1, 2}, ``exponent`` p >= 3. Returns [x * h, x * h', x * h''] (x, x/s, x/s^2),
    (N - L + 1, ...), aligned with samples L//2 ... N - 1 - L//2 of x.
    """
    x = np.asarray(x, dtype=float)
    taps = kernel_taps(sample_rate, window, derivatives, exponent)
    require_window(len(x), len(taps[0]), window)
    # the mean filtered apart, as in differentiate
    offset = x.mean(axis=0)
    return [y + offset * np.sum(k)
            for y, k in zip(convolve_valid(x - offset, taps), taps, strict=True)]


def require_window(samples: int, taps: int, window: float) -> None:
    """Refuse a record of ``samples`` shorter than a kernel of ``taps`` (``window`` s).

    Raises
    ------
    DataError
    """
    if taps > samples:
        raise DataError(f"record of {samples} samples is shorter than the filter window "
                        f"({taps} samples = {window:.3g} s); record longer or shorten "
                        "the window.")


def kernel_taps(sample_rate: float, window: float, derivatives: int = 0,
                exponent: int = KERNEL_EXPONENT) -> list[np.ndarray]:
    """Taps (L,), L odd, of :func:`kernel_filter`: h, h' (per s), h'' (per s^2) sampled and scaled.

    White noise of variance s^2 leaves the filter with variance s^2 sum(taps^2).
    """
    n = window_samples(window, sample_rate, 2 * exponent)
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
    return [k / norm / sample_rate for k in kernels[:derivatives + 1]]


def trim(window: float, sample_rate: float, order: int = DEFAULT_ORDER) -> int:
    """Samples to drop at each end of a differentiated record (half a window)."""
    return window_samples(window, sample_rate, order) // 2


def estimate_frequency(x: np.ndarray, sample_rate: float, refine: bool = True) -> float:
    """Frequency (Hz) of the dominant sine in ``x`` (N,) or (N, m).

    The largest peak of the Hann-windowed, zero-padded spectrum of the most varying channel
    (against its scale less white noise), refined by a sine fit; ``refine=False``: the plain
    peak, within half a bin. Computed once for a read-only array (a record's columns): every
    method asks for it; a piece of a record may take the record's (:func:`share_frequency`).

    Raises
    ------
    DataError
        When no channel moves.
    """
    if isinstance(x, np.ndarray) and not x.flags.writeable:
        whole = _whole(x)
        if whole is not x:
            return estimate_frequency(whole, sample_rate, refine)
        kind = "dominant" if refine else "peak"
        value = _cached(x, sample_rate, kind)
        if value is None:
            value, fastest, peak = _estimate_frequency(x, sample_rate, refine)
            _store(x, sample_rate, kind, value)
            if fastest is not None:  # for acceleration_frequency, from the same spectrum
                _store(x, sample_rate, "fastest", fastest)
                _store(x, sample_rate, "peak", peak)  # its coarse grid is the plain peak's
        return value
    return _estimate_frequency(x, sample_rate, refine)[0]


def share_frequency(piece: np.ndarray, whole: np.ndarray) -> None:
    """Make :func:`estimate_frequency` and :func:`acceleration_frequency` of the read-only ``piece``
    (rows of ``whole``, (n, m)) answer ``whole``'s (N, m), while ``piece`` lives.

    A piece cut from a record (a validation fold) moves at the record's excitation, but may hold
    too few periods of its slowest line for that to be found in it alone.
    """
    if piece.flags.writeable or whole.flags.writeable:
        raise ValueError("share_frequency takes read-only arrays (a record's columns).")
    key = id(piece)
    _WHOLES[key] = (weakref.ref(piece, lambda _, key=key: _WHOLES.pop(key, None)), whole)


def _whole(x: np.ndarray) -> np.ndarray:
    """The record ``x`` was cut from (:func:`share_frequency`), else ``x``."""
    whole = _WHOLES.get(id(x))
    return whole[1] if whole is not None and whole[0]() is x else x


#: Spread, relative to the most moving channel's, below which a channel holds only round-off.
ROUND_OFF_SPREAD = 1e-9

#: Frequencies of read-only arrays, by identity, sample rate and kind, while the array lives.
_FREQUENCIES: dict[tuple[int, float, str], tuple[weakref.ref, Any]] = {}

#: Records whose frequency a piece takes (:func:`share_frequency`), by the piece's identity.
_WHOLES: dict[int, tuple[weakref.ref, np.ndarray]] = {}


def _cached(x: np.ndarray, sample_rate: float, kind: str) -> Any:
    known = _FREQUENCIES.get((id(x), float(sample_rate), kind))
    return None if known is None or known[0]() is not x else known[1]


def _store(x: np.ndarray, sample_rate: float, kind: str, value: Any) -> None:
    key = (id(x), float(sample_rate), kind)
    _FREQUENCIES[key] = (weakref.ref(x, lambda _, key=key: _FREQUENCIES.pop(key, None)), value)


def _estimate_frequency(x: np.ndarray, sample_rate: float, refine: bool
                        ) -> tuple[float, tuple[np.ndarray, float] | None, float]:
    """The dominant frequency; refined, the start of :func:`acceleration_frequency`'s
    refinement (the dominant channel (N,) and its line of largest acceleration, Hz), else None;
    the plain peak (``refine=False``'s frequency)."""
    centered, spectrum, nfft, channel, median, peak = _channel_spectra(x, sample_rate, refine)
    frequency = (int(np.argmax(spectrum)) + 1) * sample_rate / nfft
    if not refine:
        return frequency, None, frequency
    column = centered[:, channel]
    fastest = (_fastest_line(spectrum, median) + 1) * sample_rate / nfft
    # a copy: the view would keep every channel alive in the record's cache
    return _refine_frequency(column, sample_rate, frequency), (column.copy(), fastest), peak


def _channel_spectra(x: np.ndarray, sample_rate: float, refine: bool
                     ) -> tuple[np.ndarray, np.ndarray, int, int, float, float]:
    """Centred channels (N, m); the spectrum of the channel of the dominant line relative to its
    scale (nfft // 2; bin k at (k + 1) sample_rate / nfft); nfft; that channel; its median bin's
    power on the same scale (white noise's level); the dominant line's frequency on the coarse
    grid (Hz; ``refine=False``'s grid)."""
    x = np.asarray(x, dtype=float)
    x = x[:, None] if x.ndim == 1 else x
    centered = x - x.mean(axis=0)
    spread = centered.std(axis=0)
    if not np.any(spread > 0):
        raise DataError("the motion is constant; no excitation frequency can be found.")
    n = len(x)
    nfft = 1 << int(np.ceil(np.log2(8 * n if refine else n)))
    # each channel's transform on contiguous samples (time last): faster, the same numbers
    hann = np.hanning(n)
    windowed = np.ascontiguousarray((centered * hann[:, None]).T)
    # a first spectrum on an eighth of the refined points (at least the record's): it gives each
    # channel's white-noise level and rules out channels whose peak cannot be the largest
    coarse_points = nfft // 8 if refine else nfft
    coarse = np.abs(np.fft.rfft(windowed, coarse_points, axis=1))
    # compare channels by spectral peak relative to the channel's own scale: units differ; a
    # channel that moves only by round-off (a still DOF of a noise-free record) has no line.
    # The scale leaves out white noise (the same power in every bin: the median bin's, the lines
    # holding few), so that noise does not demote a small channel's line; a channel whose
    # motion is below its noise has no line either
    median = array_median(coarse[:, 1:] ** 2, axis=1)
    noise = median / (math.log(2) * np.sum(hann ** 2))
    scale = np.sqrt(np.maximum(spread ** 2 - noise, 0.0))
    moving = (spread > ROUND_OFF_SPREAD * spread.max()) & (scale ** 2 > noise)
    if not moving.any():
        moving, scale = spread > ROUND_OFF_SPREAD * spread.max(), spread
    scale = np.where(moving, scale, np.inf)
    on_coarse = coarse[:, 1:] / scale[:, None]
    best = _dominant(on_coarse)
    peak = (int(np.argmax(on_coarse[best])) + 1) * sample_rate / coarse_points
    channels, relative = np.arange(len(scale)), on_coarse
    if refine:
        channels = _peak_channels(coarse / scale[:, None], n)
        if len(channels) > 2:  # the winner alone transformed whole (two cost what they save)
            channels = channels[_fine_winner(windowed[channels], coarse[channels] / scale[
                channels, None], scale[channels], nfft)]
        relative = np.abs(np.fft.rfft(windowed[channels], nfft, axis=1)[:, 1:])
        relative /= scale[channels, None]
        best = _dominant(relative)
    channel = int(channels[best])
    return (centered, relative[best], nfft, channel, float(median[channel] / scale[channel] ** 2),
            peak)


def _dominant(relative: np.ndarray) -> int:
    """The row of ``relative`` (channels' spectra) holding the largest value, of equal ones the
    lowest frequency and then the first row."""
    peaks = np.argmax(relative, axis=1)
    values = relative[np.arange(len(peaks)), peaks]
    top = np.flatnonzero(values == values.max())
    return int(top[np.argmin(peaks[top])])


#: Lines below this fraction of the dominant one's amplitude (harmonics, coupling) do not set
#: :func:`acceleration_frequency`.
LINE_FLOOR = 0.05
#: Power, in median bins, a line must exceed (white noise's largest bin of a record is about 16).
LINE_NOISE_POWER = 50.0


def acceleration_frequency(x: np.ndarray, sample_rate: float) -> float:
    """Frequency (Hz) of the line of largest acceleration (amplitude times f^2) in ``x`` (N,) or
    (N, m).

    In the channel of :func:`estimate_frequency`'s dominant line, among the spectral peaks of at
    least :data:`LINE_FLOOR` of its amplitude and above white noise; refined by a sine fit. A
    record of one sine gives its frequency; three sines of falling amplitude, the fastest. A piece
    of a record takes the record's (:func:`share_frequency`).

    Raises
    ------
    DataError
        When no channel moves.
    """
    if not (isinstance(x, np.ndarray) and not x.flags.writeable):
        column, fastest = _estimate_frequency(x, sample_rate, True)[1]
        return _refine_frequency(column, sample_rate, fastest)
    x = _whole(x)
    value = _cached(x, sample_rate, "acceleration")
    if value is None:
        start = _cached(x, sample_rate, "fastest") or _estimate_frequency(x, sample_rate, True)[1]
        column, fastest = start
        value = _refine_frequency(column, sample_rate, fastest)
        _store(x, sample_rate, "acceleration", value)
        _FREQUENCIES.pop((id(x), float(sample_rate), "fastest"), None)  # the column's memory
    return value


def _fastest_line(spectrum: np.ndarray, median: float) -> int:
    """Bin of the line of largest acceleration of ``spectrum`` (its channel's, relative to its
    scale) among its peaks of :data:`LINE_FLOOR` of the largest or more, above ``median``
    (white noise's bin) by :data:`LINE_NOISE_POWER`."""
    inner = spectrum[1:-1]
    peaks = np.flatnonzero((inner > spectrum[:-2]) & (inner >= spectrum[2:])) + 1
    peaks = np.append(peaks, int(np.argmax(spectrum)))  # the dominant line, even at an end
    lines = peaks[(spectrum[peaks] >= LINE_FLOOR * spectrum.max())
                  & (spectrum[peaks] ** 2 > LINE_NOISE_POWER * median)]
    if not len(lines):
        lines = peaks[-1:]
    return int(lines[np.argmax(spectrum[lines] * (lines + 1.0) ** 2)])


def _peak_channels(amplitude: np.ndarray, n: int) -> np.ndarray:
    """The channels (ascending) whose largest spectral peak on an eight times finer grid can
    reach the largest channel's; the others need no finer transform.

    ``amplitude`` (m, M/2 + 1): each channel's |spectrum| over its scale, on M points (a power of
    two, at least the record's ``n`` samples). A real trigonometric polynomial T of degree d, at
    most A in size and A at its maximum, is at least A cos(d h) a step h away (van der Corput
    and Schaake 1935: T'^2 + d^2 T^2 <= d^2 A^2). Centred on the record's middle, a channel's
    spectrum is one in half the frequency, of degree n - 1, so its peak is at most the coarse
    grid's largest value over cos((n - 1) pi / (2 M)); every coarse value is one of the fine
    spectrum's (every eighth bin; above zero, a lower bound of its peak).
    """
    m, coarse = len(amplitude), 2 * (amplitude.shape[1] - 1)
    if m == 1 or (n - 1) * np.pi / (2 * coarse) >= np.pi / 2:
        return np.arange(m)
    reach = amplitude.max(axis=1) / np.cos((n - 1) * np.pi / (2 * coarse))
    floor = amplitude[:, 1:].max(axis=1).max()
    # round-off of the two transforms (relative 1e-13 at most) kept well inside the margin
    return np.flatnonzero(reach * (1 + 1e-9) >= floor * (1 - 1e-9))


def _fine_winner(windowed: np.ndarray, amplitude: np.ndarray, scale: np.ndarray, nfft: int
                 ) -> slice:
    """The channel (as a slice of one row) of ``windowed`` (m, n) whose spectrum on ``nfft``
    points over its ``scale`` holds the largest peak (of equal ones the lowest bin, then the first
    row), as :func:`_dominant` would pick from every channel's whole spectrum.

    ``amplitude`` (m, M/2 + 1): each channel's coarse spectrum over its scale on M points. By
    :func:`_peak_channels`' bound, a peak that can be the largest lies within half a coarse bin of
    a coarse value of at least the largest coarse value times cos((n - 1) pi / (2 M)): only the
    fine bins about those, of every channel, are evaluated (:func:`_zoom_spectrum`), unless
    they span most of the spectrum.
    """
    n = windowed.shape[1]
    coarse = 2 * (amplitude.shape[1] - 1)
    step, half = nfft // coarse, nfft // 2
    floor = amplitude[:, 1:].max() * np.cos((n - 1) * np.pi / (2 * coarse)) * (1 - 1e-9)
    near = np.flatnonzero(np.any(amplitude * (1 + 1e-9) >= floor, axis=0))
    first = max(1, step * int(near[0]) - step // 2)
    last = min(half, step * int(near[-1]) + step // 2)
    if last - first < n:
        spectra = np.abs(_zoom_spectrum(windowed, nfft, first, last - first + 1))
    else:
        spectra = np.abs(np.fft.rfft(windowed, nfft, axis=1)[:, 1:])
    row = _dominant(spectra / scale[:, None])
    return slice(row, row + 1)


def _zoom_spectrum(x: np.ndarray, nfft: int, first: int, count: int) -> np.ndarray:
    """Bins ``first`` .. ``first + count - 1`` (..., count) of the ``nfft``-point transform of
    each row of ``x`` (..., n) (zero-padded), sum_t x[t] exp(-2 pi i j t / nfft), by Bluestein's
    chirp transform: transforms of about n + count points instead of ``nfft``."""
    n = x.shape[-1]
    size = 1 << int(math.ceil(math.log2(n + count - 1)))
    k = np.arange(max(n, count), dtype=np.int64)
    # exp(-i pi k^2 / nfft), k^2 reduced modulo 2 nfft in integers: phases exact for any k;
    # the signal's also carries the shift to the band, exp(-2 pi i first k / nfft)
    chirp = np.exp(-1j * np.pi * ((k * k) % (2 * nfft)) / nfft)
    shifted = np.exp(-1j * np.pi * ((k[:n] * (k[:n] + 2 * first)) % (2 * nfft)) / nfft)
    kernel = np.zeros(size, dtype=complex)
    kernel[:count] = chirp[:count].conj()
    kernel[size - n + 1:] = chirp[1:n][::-1].conj()
    transformed = np.fft.fft(x * shifted, size) * np.fft.fft(kernel)
    return np.fft.ifft(transformed)[..., :count] * chirp[:count]


def _refine_frequency(x: np.ndarray, sample_rate: float, frequency: float) -> float:
    """Frequency near ``frequency`` of the least-squares fit of [sin, cos, 1, t] to ``x``."""
    t = np.arange(len(x)) / sample_rate
    trend = np.linalg.qr(np.column_stack([np.ones_like(t), t]))[0].T  # (2, N) orthonormal
    target = x
    for _ in range(2):  # x less its constant and trend, twice
        target = target - (trend @ target) @ trend
    energy = float(target @ target)

    n = len(x)
    block = max(1, math.isqrt(n))
    within, starts = np.arange(block) / sample_rate, np.arange(0, n, block) / sample_rate

    def cost(f: float) -> float:
        # e^(i w t) at every sample as (block start) x (offset in block): two short sets of
        # sines and cosines instead of one per sample
        turn = np.outer(np.exp(2j * np.pi * f * starts), np.exp(2j * np.pi * f * within))
        wave = turn.ravel()[:n]
        columns = np.vstack([wave.imag, wave.real])
        # the residual's energy, from the sine's and cosine's products only: the columns less
        # their projection on the trend have the Gram matrix columns columns^T - p p^T
        fit = columns @ target
        projection = columns @ trend.T
        gram = columns @ columns.T - projection @ projection.T
        return energy - float(fit @ np.linalg.solve(gram, fit))

    bin_width = sample_rate / n
    return minimize_bounded(cost, max(frequency - bin_width, 1e-6 * frequency),
                            frequency + bin_width, 1e-9 * frequency)


__all__ = ["DEFAULT_ORDER", "DEFAULT_WINDOW_PERIODS", "LINE_FLOOR", "LINE_NOISE_POWER",
           "acceleration_frequency", "convolve_valid", "default_window",
           "differentiate", "estimate_frequency", "kernel_filter", "kernel_taps",
           "savgol_coefficients", "savgol_gain", "share_frequency", "trim", "window_samples"]
