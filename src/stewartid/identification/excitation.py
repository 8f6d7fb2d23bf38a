"""The excitation lines of logged experiments: the distinct frequencies at which each DOF
moved, read from the spectra of the measured pose (whether a delay and damping can be told
apart, :mod:`stewartid.identification.delay`)."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from stewartid.datasets.dataset import Dataset

#: A spectral line of a DOF's motion counts when it is at least this fraction of the DOF's
#: largest line (over all experiments).
LINE_THRESHOLD = 0.1

#: Lines closer than this many frequency resolutions (1 / record length) are one line.
LINE_MERGE_BINS = 3.0


def spectral_lines(x: np.ndarray, sample_rate: float) -> tuple[np.ndarray, np.ndarray]:
    """Local maxima of the Hann-windowed amplitude spectrum of one signal.

    Parameters
    ----------
    x : ndarray, shape (N,)
        A position signal (m or rad), uniformly sampled.
    sample_rate : float
        Hz.

    Returns
    -------
    frequencies : ndarray, shape (L,)
        Hz, above two frequency resolutions (drift apart).
    amplitudes : ndarray, shape (L,)
        Amplitude of each peak (units of x, up to the window's gain).
    """
    n = len(x)
    t = np.arange(n)
    centered = x - np.polyval(np.polyfit(t, x, 1), t)
    nfft = 1 << int(np.ceil(np.log2(4 * n)))
    frequencies = np.fft.rfftfreq(nfft, 1.0 / sample_rate)
    spectrum = np.abs(np.fft.rfft(centered * np.hanning(n), nfft))
    peak = (spectrum[1:-1] > spectrum[:-2]) & (spectrum[1:-1] >= spectrum[2:])
    index = np.flatnonzero(peak) + 1
    index = index[frequencies[index] > 2.0 * sample_rate / n]
    return frequencies[index], spectrum[index]


def excitation_lines(datasets: Sequence[Dataset], threshold: float = LINE_THRESHOLD
                     ) -> tuple[tuple[float, ...], ...]:
    """The distinct excitation frequencies of each DOF over all experiments.

    A line counts when its amplitude is at least ``threshold`` times the DOF's largest line
    over the experiments (a position spectrum: sensor noise, white in the pose, stays far
    below it, where a velocity spectrum would raise it with frequency); lines within
    :data:`LINE_MERGE_BINS` frequency resolutions of each other are one.

    Parameters
    ----------
    datasets : sequence of Dataset
    threshold : float
        Fraction of the DOF's largest line.

    Returns
    -------
    tuple of 6 tuples of float
        Hz, ascending, per DOF of :data:`~stewartid.platform.COORDINATES`.
    """
    found = []
    for dof in range(6):
        peaks = [spectral_lines(d.pose[:, dof], d.sample_rate) + (d.duration,) for d in datasets]
        largest = max((float(a.max()) if len(a) else 0.0) for _, a, _ in peaks)
        if largest <= 0:
            found.append(())
            continue
        lines: list[float] = []
        for f, a, duration in peaks:
            for frequency in np.sort(f[a >= threshold * largest]):
                if all(abs(frequency - g) > LINE_MERGE_BINS / duration for g in lines):
                    lines.append(float(frequency))
        found.append(tuple(sorted(lines)))
    return tuple(found)


__all__ = ["LINE_MERGE_BINS", "LINE_THRESHOLD", "excitation_lines", "spectral_lines"]
