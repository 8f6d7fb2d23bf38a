"""Imperfections of a real rig's sensor channels: delay, coloured noise, mains hum, drift.

Pure functions on sampled signals (time on axis 0, one column per channel), combined by
:func:`stewartid.simulation.sensors.measure_legs` into the simulator's sensor model.
"""

from __future__ import annotations

import math

import numpy as np
from scipy import signal

from stewartid.signals.interpolation import spline_at

#: Decay (relative amplitude) of the filter's impulse response after its warm-up: the filter
#: runs that many samples before the record so that the noise is stationary from its start.
SETTLED = 1e-10
def delay_signal(t: np.ndarray, values: np.ndarray, delay_s: float) -> np.ndarray:
    """The signal ``delay_s`` seconds later: out(t) = values(t - delay_s).

    Interpolated by :func:`~stewartid.signals.interpolation.spline_at`; a whole number of samples
    shifts the samples (to round-off). Before the first sample the signal is its first value
    (the rig at rest before the record started).

    Parameters
    ----------
    t : ndarray, shape (N,)
        Sample times (s), strictly increasing, uniform over the first and last five.
    values : ndarray, shape (N,) or (N, C)
        Sampled signal, any unit.
    delay_s : float
        Delay (s), >= 0.

    Returns
    -------
    ndarray
        Same shape and unit as ``values``.
    """
    values = np.asarray(values, dtype=float)
    if delay_s == 0:
        return values.copy()
    t = np.asarray(t, dtype=float)
    return spline_at(t, values, np.maximum(t - delay_s, t[0]))


def lowpass_sections(cutoff_hz: float, order: int, sample_rate_hz: float) -> np.ndarray:
    """Second-order sections of a digital Butterworth low-pass filter.

    Parameters
    ----------
    cutoff_hz : float
        -3 dB frequency (Hz), below the Nyquist frequency ``sample_rate_hz / 2``.
    order : int
        Filter order (roll-off 20 ``order`` dB per decade).
    sample_rate_hz : float
        Sample rate (Hz).

    Returns
    -------
    ndarray, shape (ceil(order / 2), 6)
        For :func:`scipy.signal.sosfilt`.
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
    """Stationary low-pass (coloured) Gaussian noise of a given standard deviation.

    White noise through the causal filter of :func:`lowpass_sections` (as a transducer's noise
    through an anti-aliasing filter), started :func:`warm_up_length` samples early so that it is
    stationary from the first sample, and scaled by the filter's noise gain to standard
    deviation ``std``.

    Parameters
    ----------
    rng : numpy.random.Generator
        Draws ``(warm-up + n_samples) * channels`` standard normal values.
    n_samples : int
    std : float or ndarray, shape (channels,)
        Standard deviation after filtering, per channel when an array (unit of the signal).
    cutoff_hz, order, sample_rate_hz
        As :func:`lowpass_sections`.
    channels : int

    Returns
    -------
    ndarray, shape (n_samples, channels)
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
    """A sinusoid of the mains frequency on every channel, each with its own random phase.

    Parameters
    ----------
    t : ndarray, shape (N,)
        Sample times (s).
    amplitude : float
        Peak amplitude (unit of the signal).
    frequency_hz : float
        Mains frequency (Hz), 50 or 60; below the Nyquist frequency of ``t``.
    rng : numpy.random.Generator
        Draws ``channels`` phases, uniform in [0, 2 pi).
    channels : int

    Returns
    -------
    ndarray, shape (N, channels)
        amplitude * sin(2 pi frequency_hz t + phase_c).
    """
    phases = rng.uniform(0.0, 2.0 * np.pi, size=channels)
    return amplitude * np.sin(2.0 * np.pi * frequency_hz * np.asarray(t, dtype=float)[:, None]
                              + phases)


def random_walk(n_samples: int, std: float, rng: np.random.Generator,
                channels: int = 6) -> np.ndarray:
    """A slow drift per channel: a Gaussian random walk from zero at the first sample.

    Standard deviation ``std * sqrt(k / (n_samples - 1))`` at sample k: a sensor zeroed when the
    record starts that wanders off over it.

    Parameters
    ----------
    n_samples : int
    std : float
        Standard deviation at the end of the record (unit of the signal).
    rng : numpy.random.Generator
        Draws ``(n_samples - 1) * channels`` standard normal values.
    channels : int

    Returns
    -------
    ndarray, shape (n_samples, channels)
    """
    out = np.zeros((n_samples, channels))
    if n_samples > 1:
        steps = rng.standard_normal((n_samples - 1, channels)) * (std / math.sqrt(n_samples - 1))
        out[1:] = np.cumsum(steps, axis=0)
    return out
