"""Imperfections of a rig's sensor channels (delay, coloured noise, mains hum, drift) on sampled signals."""

from __future__ import annotations

import math

import numpy as np
from scipy import signal

from stewartid.signals.interpolation import spline_at

#: Decay (relative amplitude) of the filter's impulse response after its warm-up: the filter
#: runs that many samples before the record so that the noise is stationary from its start.
SETTLED = 1e-10
def delay_signal(t: np.ndarray, values: np.ndarray, delay_s: float) -> np.ndarray:
    """The signal ``delay_s`` (>= 0) seconds later, out(t) = values(t - delay_s), same shape and unit.

    By :func:`~stewartid.signals.interpolation.spline_at` (exact for whole samples); before the first
    sample the signal holds its first value (the rig at rest).
    """
    values = np.asarray(values, dtype=float)
    if delay_s == 0:
        return values.copy()
    t = np.asarray(t, dtype=float)
    return spline_at(t, values, np.maximum(t - delay_s, t[0]))


def lowpass_sections(cutoff_hz: float, order: int, sample_rate_hz: float) -> np.ndarray:
    """Second-order sections (ceil(order / 2), 6) of a digital Butterworth low-pass, for
    :func:`scipy.signal.sosfilt`; ``cutoff_hz`` (-3 dB) below ``sample_rate_hz / 2``.
    """
    return signal.butter(int(order), cutoff_hz, btype="low", fs=sample_rate_hz, output="sos")


def warm_up_length(sections: np.ndarray) -> int:
    """Samples after which the filter's impulse response has decayed to :data:`SETTLED`."""
    _, poles, _ = signal.sos2zpk(sections)
    radius = float(np.max(np.abs(poles))) if len(poles) else 0.0
    if radius <= 0.0:
        return 1
    return int(math.ceil(math.log(SETTLED) / math.log(radius))) + 1


def lowpass_noise(rng: np.random.Generator, n_samples: int, std: float | np.ndarray,
                  cutoff_hz: float, order: int, sample_rate_hz: float,
                  channels: int = 6) -> np.ndarray:
    """Stationary low-pass Gaussian noise (n_samples, channels) of standard deviation ``std`` after filtering.

    White noise through :func:`lowpass_sections` (a transducer behind an anti-aliasing filter),
    started :func:`warm_up_length` samples early and scaled by the filter's noise gain.
    """
    sections = lowpass_sections(cutoff_hz, order, sample_rate_hz)
    warm_up = warm_up_length(sections)
    impulse = np.zeros(warm_up)
    impulse[0] = 1.0
    gain = math.sqrt(float(np.sum(signal.sosfilt(sections, impulse) ** 2)))
    white = rng.standard_normal((warm_up + n_samples, channels))
    return np.asarray(std) / gain * signal.sosfilt(sections, white, axis=0)[warm_up:]


def mains_hum(t: np.ndarray, amplitude: float, frequency_hz: float, rng: np.random.Generator,
              channels: int = 6) -> np.ndarray:
    """amplitude * sin(2 pi frequency_hz t + phase_c), (N, channels), a random phase per channel."""
    phases = rng.uniform(0.0, 2.0 * np.pi, size=channels)
    return amplitude * np.sin(2.0 * np.pi * frequency_hz * np.asarray(t, dtype=float)[:, None]
                              + phases)


def random_walk(n_samples: int, std: float, rng: np.random.Generator,
                channels: int = 6) -> np.ndarray:
    """A drift per channel (n_samples, channels): a Gaussian random walk from zero, standard deviation
    ``std * sqrt(k / (n_samples - 1))`` at sample k (a sensor zeroed at the start).
    """
    out = np.zeros((n_samples, channels))
    if n_samples > 1:
        steps = rng.standard_normal((n_samples - 1, channels)) * (std / math.sqrt(n_samples - 1))
        out[1:] = np.cumsum(steps, axis=0)
    return out
