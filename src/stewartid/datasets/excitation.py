"""What a set of experiments' motion lets an identification see: a record's sines and whether
every DOF moves on its own somewhere, measured as leg-length change dl = J_lq(q0) (q - mean q) (m).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from functools import lru_cache
from typing import NamedTuple

import numpy as np

from stewartid.datasets.dataset import Dataset
from stewartid.errors import DataError
from stewartid.model.kinematics import compute_leg_terms
from stewartid.platform import COORDINATES, Platform
from stewartid.signals.differentiation import (
    DEFAULT_ORDER,
    default_window,
    savgol_coefficients,
    window_samples,
)
from stewartid.signals.filtered_rows import convolved_rows

#: A spectral line counts when its amplitude reaches this fraction of the largest line's:
#: above the Hann window's highest sidelobe (2.7 % of its line).
LINE_FRACTION = 0.05
#: Within this many frequency bins (1 / record length) of a larger peak, a peak below
#: SIDELOBE_FRACTION of it is taken for a sidelobe (the Hann window's first sidelobes lie
#: 2.3 to 2.4 bins from their line).
SIDELOBE_BINS = 2.6
SIDELOBE_FRACTION = 0.08
#: A line needs this many periods in the record; slower content is drift or a fade-in.
MIN_LINE_PERIODS = 2.0
#: Smallest share of a DOF's velocity and acceleration left unexplained by the other DOFs',
#: relative to the best-excited DOF's (the standard errors of its column of Mt and Bt scale
#: with the inverse): below it, a DOF counts as moved only by coupling.
MIN_RELATIVE_EXCITATION = 0.01
#: Rows per experiment used by the excitation measure (an evenly strided subset).
CHECK_SAMPLES = 4000


@dataclass(frozen=True)
class SpectralLines:
    """The sines of a record, largest first.

    Attributes
    ----------
    frequencies_hz, amplitudes : ndarray, shape (L,)
        Amplitudes relative to the largest (the first is 1).
    resolution_hz : float
        1 / record length.
    largest : float
        Largest line's amplitude in the Hann-windowed spectrum, to compare records; 0 when empty.
    """

    frequencies_hz: np.ndarray
    amplitudes: np.ndarray
    resolution_hz: float
    largest: float = 0.0

    def __len__(self) -> int:
        return len(self.frequencies_hz)

    def describe(self) -> str:
        """Frequencies ascending to the resolution's decimal, e.g. ``"0.30, 0.70, 1.50 Hz"``."""
        decimals = max(0, int(np.ceil(-np.log10(self.resolution_hz))))
        return ", ".join(f"{f:.{decimals}f}" for f in np.sort(self.frequencies_hz)) + " Hz"


def neutral_jacobian(platform: Platform) -> np.ndarray:
    """J_lq(q0), shape (6, 6): leg-length change per unit motion at the neutral pose."""
    return compute_leg_terms(platform, platform.neutral_pose[None].copy())[1][0]


def dof_scales(platform: Platform) -> np.ndarray:
    """Column norms of J_lq(q0), shape (6,): leg-length change per unit motion (m/m, m/rad)."""
    return np.linalg.norm(neutral_jacobian(platform), axis=0)


def leg_space_motion(pose: np.ndarray, platform: Platform) -> np.ndarray:
    """Pose (N, 6), m, rad, as the leg-length change it causes, J_lq(q0) (q - mean q), (N, 6) m."""
    return (pose - pose.mean(axis=0)) @ neutral_jacobian(platform).T


def spectral_lines(motion: np.ndarray, sample_rate: float,
                   fraction: float = LINE_FRACTION, padding: int = 4) -> SpectralLines:
    """The sines of a multichannel record: peaks of its summed Hann-windowed spectrum.

    Mean and linear drift removed; a line lasts at least :data:`MIN_LINE_PERIODS` periods, reaches
    ``fraction`` of the largest, and is no sidelobe (:data:`SIDELOBE_BINS`, :data:`SIDELOBE_FRACTION`).

    Parameters
    ----------
    motion : ndarray, shape (N,) or (N, m)
        Channels sharing a unit, time on axis 0.
    sample_rate : float
        Hz.
    fraction : float
        Smallest relative amplitude of a line.
    padding : int
        The transform is at least this many times the record (a power of two): the default
        places the peaks on a fine grid before their parabola; 1 is four to eight times cheaper
        and places them within a few percent of a bin.
    """
    x = np.asarray(motion, dtype=float)
    x = x[:, None] if x.ndim == 1 else x
    n = len(x)
    nfft = _padded_length(n, padding)
    amplitude = np.sqrt(np.sum(np.abs(np.fft.rfft(_windowed(x), nfft, axis=0)) ** 2, axis=1))
    return _peaks(amplitude, n, nfft, sample_rate, fraction)


def channel_lines(motion: np.ndarray, sample_rate: float, fraction: float = LINE_FRACTION,
                  padding: int = 4) -> list[SpectralLines]:
    """:func:`spectral_lines` of each channel of ``motion`` (N, m) on its own, the same numbers
    from one transform of every channel (``padding`` as there)."""
    spectra, nfft = _channel_spectra(motion, padding)
    return _lines_of(spectra, len(motion), nfft, sample_rate, fraction)


def _channel_spectra(motion: np.ndarray, padding: int) -> tuple[np.ndarray, int]:
    """Each channel's Hann-windowed transform (m, nfft // 2 + 1) of ``motion`` (N, m), mean and
    drift removed, and the transform's length."""
    x = np.asarray(motion, dtype=float)
    nfft = _padded_length(len(x), padding)
    windowed = np.column_stack([_windowed(x[:, [k]]) for k in range(x.shape[1])])
    # each channel's transform on contiguous samples (time last): the same numbers
    return np.fft.rfft(np.ascontiguousarray(windowed.T), nfft, axis=1), nfft


def _lines_of(spectra: np.ndarray, n: int, nfft: int, sample_rate: float,
              fraction: float) -> list[SpectralLines]:
    """:func:`channel_lines` from the channels' transforms (:func:`_channel_spectra`)."""
    return [_peaks(np.sqrt(np.abs(spectrum) ** 2), n, nfft, sample_rate, fraction)
            for spectrum in spectra]


def _padded_length(n: int, padding: int = 4) -> int:
    """Transform length of a record of ``n`` samples: a power of two of at least ``padding`` n
    (4: peak frequencies to an eighth of a bin)."""
    return 1 << int(np.ceil(np.log2(padding * n)))


def _windowed(x: np.ndarray) -> np.ndarray:
    """Channels ``x`` (N, m) less their mean and linear drift, times a Hann window."""
    n = len(x)
    ramp = np.linspace(-1.0, 1.0, n)   # symmetric: orthogonal to the constant
    x = x - x.mean(axis=0)
    x = x - np.outer(ramp, (ramp @ x) / max(float(ramp @ ramp), 1e-300))
    return x * _hann(n)[:, None]


@lru_cache(maxsize=4)
def _hann(n: int) -> np.ndarray:
    """``np.hanning(n)``, read-only: every channel of a record's check takes the same window."""
    window = np.hanning(n)
    window.flags.writeable = False
    return window


def running_maximum(x: np.ndarray, reach: int) -> np.ndarray:
    """Largest of ``x`` (N,) >= 0 within ``reach`` samples of each sample, zero beyond the ends.

    Van Herk and Gil-Werman's two passes over blocks of the window's length: O(N) for any reach,
    without :mod:`scipy.ndimage` (slow to import) on the command line's path.
    """
    width = 2 * reach + 1
    n = len(x)
    padded = np.zeros(n + 2 * reach + (-(n + 2 * reach)) % width)
    padded[reach:reach + n] = x
    blocks = padded.reshape(-1, width)
    ahead = np.maximum.accumulate(blocks, axis=1).ravel()
    behind = np.maximum.accumulate(blocks[:, ::-1], axis=1)[:, ::-1].ravel()
    # the window [i, i + width) of padded: its tail in one block, its head in the next
    return np.maximum(behind[:n], ahead[width - 1:width - 1 + n])


def _peaks(amplitude: np.ndarray, n: int, nfft: int, sample_rate: float,
           fraction: float) -> SpectralLines:
    """The lines of an amplitude spectrum (``nfft // 2 + 1`` bins) of ``n`` samples."""
    resolution = sample_rate / n
    empty = SpectralLines(np.empty(0), np.empty(0), resolution)
    frequencies = np.arange(len(amplitude)) * sample_rate / nfft
    amplitude[frequencies < MIN_LINE_PERIODS * resolution] = 0.0
    if not np.any(amplitude > 0):
        return empty
    # a maximum beside the blanked low band is that band's edge, not a line (and its log
    # parabola through a zero neighbour would place an absurd height)
    peaks = np.flatnonzero((amplitude[1:-1] > amplitude[:-2])
                           & (amplitude[1:-1] >= amplitude[2:]) & (amplitude[:-2] > 0)) + 1
    if not len(peaks):
        return empty
    largest = amplitude[peaks].max()
    peaks = peaks[amplitude[peaks] >= fraction * largest]
    # a sidelobe: a larger peak within reach; the largest peak within reach of every grid
    # point in one pass (a noisy spectrum has thousands of maxima)
    reach_bins = int(np.floor(SIDELOBE_BINS * resolution / (sample_rate / nfft) + 1e-9))
    heights_at = np.zeros_like(amplitude)
    heights_at[peaks] = amplitude[peaks]
    nearby = running_maximum(heights_at, reach_bins)
    peaks = peaks[~(SIDELOBE_FRACTION * nearby[peaks] > amplitude[peaks])]
    peaks = peaks[np.argsort(amplitude[peaks])[::-1]]
    # a parabola through the log amplitudes of the peak and its neighbours: the Hann main
    # lobe is nearly Gaussian, so this places the line well inside the padded grid step
    below, at, above = (np.log(np.maximum(amplitude[peaks + k], np.finfo(float).tiny))
                        for k in (-1, 0, 1))
    curvature = below - 2 * at + above
    # at a local maximum the curvature is negative, or zero on a plateau (then no shift)
    # the vertex of a parabola through a maximum and its neighbours lies within half a step
    shift = np.clip(0.5 * (below - above) / np.minimum(curvature, -np.finfo(float).tiny),
                    -0.5, 0.5)
    heights = np.exp(at - 0.25 * (below - above) * shift)
    return SpectralLines((peaks + shift) * sample_rate / nfft, heights / heights.max(),
                         resolution, float(heights.max()))


class MotionRows(NamedTuple):
    """A record's evenly strided rows and the pose's rates there: what the checks of an
    experiment set read (:func:`motion_rows`).

    Attributes
    ----------
    rows : ndarray, shape (n,)
        Sample indices, at most :data:`CHECK_SAMPLES`.
    velocity, acceleration : ndarray, shape (n, 6)
        Savitzky-Golay rates of the pose there (m/s, rad/s; m/s², rad/s²).
    """

    rows: np.ndarray
    velocity: np.ndarray
    acceleration: np.ndarray


def motion_rows(dataset: Dataset, platform: Platform) -> MotionRows | None:
    """The record's :class:`MotionRows`, computed once per record and platform; None for a
    record without a spectral line (no motion to differentiate).

    The pose channels' unpadded transforms give the leg-space motion's fastest line (the
    transform is linear: J_lq(q0) times the pose's), which sets the differentiation window, and,
    kept with the record, the pose lines :func:`excitation_lines` counts.
    """
    jacobian = neutral_jacobian(platform)
    return dataset.derived(("motion rows", jacobian.tobytes()),
                           lambda record: _motion_rows(record, jacobian))


def _motion_rows(dataset: Dataset, jacobian: np.ndarray) -> MotionRows | None:
    spectra, nfft = _channel_spectra(dataset.pose, COUNTING_PADDING)
    _pose_lines(dataset, LINE_THRESHOLD, COUNTING_PADDING, (spectra, nfft))
    # the fastest line sets the differentiation window, which needs it only roughly
    amplitude = np.sqrt(np.sum(np.abs(jacobian @ spectra) ** 2, axis=0))
    lines = _peaks(amplitude, len(dataset), nfft, dataset.sample_rate, LINE_FRACTION)
    if not len(lines):
        return None
    window = min(default_window(float(np.max(lines.frequencies_hz))), dataset.duration / 4)
    taps = window_samples(window, dataset.sample_rate)
    stride = max(1, int(np.ceil((len(dataset) - 2 * (taps // 2)) / CHECK_SAMPLES)))
    # the Savitzky-Golay derivatives at the kept rows only, by direct sums; kept row k is the
    # centre of samples k stride ... k stride + taps - 1
    centred = dataset.pose - dataset.pose.mean(axis=0)
    velocity, acceleration = (convolved_rows(centred, savgol_coefficients(
        taps, DEFAULT_ORDER, k, 1.0 / dataset.sample_rate), stride) for k in (1, 2))
    rows = np.arange(len(velocity)) * stride + (taps - 1) // 2
    return MotionRows(rows, velocity, acceleration)


def excitation_per_dof(datasets: Sequence[Dataset], platform: Platform) -> np.ndarray:
    """How well each DOF is excited on its own, shape (6,) in [0, 1].

    The twelve scaled velocity and acceleration regressors are orthogonalised greedily (pivoted
    Gram-Schmidt); a DOF's measure is the smaller unexplained norm of its two. Standard errors of
    column k of Mt and Bt scale with its inverse.
    """
    scales = dof_scales(platform)
    # strided, scaled [q_dot, q_ddot] of every experiment, (n, 12)
    found = [motion_rows(d, platform) for d in datasets]
    phi = np.concatenate([np.concatenate([m.velocity * scales, m.acceleration * scales], axis=1)
                          if m is not None else np.zeros((0, 12)) for m in found])
    independent = np.zeros(12)
    norms = np.linalg.norm(phi, axis=0)
    for kind in (slice(0, 6), slice(6, 12)):
        if np.max(norms[kind], initial=0.0) > 0:
            phi[:, kind] /= np.max(norms[kind])
    # on the Gram matrix (pivoted Cholesky): each step's diagonal is the remaining columns'
    # squared norms after projecting out those picked, to round-off of the largest norm's
    # square (far below the MIN_RELATIVE_EXCITATION squared this decides on)
    gram = phi.T @ phi
    remaining = list(range(12))
    while remaining:
        sizes = np.sqrt(np.clip(np.diag(gram)[remaining], 0.0, None))
        pick = remaining.pop(int(np.argmax(sizes)))
        independent[pick] = np.max(sizes)
        if not remaining or independent[pick] == 0:
            break
        gram -= np.outer(gram[:, pick], gram[pick]) / gram[pick, pick]
    return np.minimum(independent[:6], independent[6:])


def check_excitation(datasets: Sequence[Dataset], platform: Platform) -> None:
    """Refuse a set of experiments that leaves a DOF (nearly) unexcited.

    Raises
    ------
    DataError
        Naming the DOF, its motion, its measure against :data:`MIN_RELATIVE_EXCITATION`, the fix.
    """
    measure = excitation_per_dof(datasets, platform)
    weak = [k for k in range(6) if measure[k] < MIN_RELATIVE_EXCITATION]
    if not weak:
        return
    worst = min(weak, key=lambda k: measure[k])
    names = ", ".join(COORDINATES[k] for k in weak)
    name = COORDINATES[worst]
    motion = max(float(np.max(np.abs(d.pose[:, worst] - d.pose[:, worst].mean())))
                 for d in datasets)
    detail = f"{name} never moves" if motion == 0 else (
        f"largest {name} motion {motion * 1e3:.3g} {'mm' if worst < 3 else 'mrad'}; the part of "
        f"its velocity and acceleration the other DOFs do not explain is "
        f"{100 * measure[worst]:.2g} % of the best-excited DOF's, below "
        f"{100 * MIN_RELATIVE_EXCITATION:.3g} %")
    verb, columns = ("moves", "its column") if len(weak) == 1 else ("move", "their columns")
    raise DataError(f"no experiment {verb} {names} enough to identify {columns} of Mt and Bt "
                    f"({detail}); add an experiment exciting {names}, e.g. from "
                    "`stewartid design`.")


#: In :func:`excitation_lines`, a spectral line of a DOF's motion counts when it is at least
#: this fraction of the DOF's largest line (over all experiments).
LINE_THRESHOLD = 0.1

#: The transform padding (:func:`spectral_lines`) of the lines :func:`excitation_lines` only
#: counts: the unpadded transform, several times cheaper, places them well enough for that.
COUNTING_PADDING = 1

#: Lines closer than this many frequency resolutions (1 / record length) are one line.
LINE_MERGE_BINS = 3.0


def excitation_lines(datasets: Sequence[Dataset], threshold: float = LINE_THRESHOLD,
                     padding: int = 4) -> tuple[tuple[float, ...], ...]:
    """Distinct excitation frequencies (Hz, ascending) of each DOF over all experiments.

    A line counts when its position-spectrum amplitude is at least ``threshold`` of the DOF's
    largest; lines within :data:`LINE_MERGE_BINS` resolutions are one. ``padding`` as
    :func:`spectral_lines`: 1 to count the lines, the default to place them.
    """
    found = []
    for dof in range(6):
        # a line below the threshold of its own record's largest is below the threshold of
        # the DOF's largest: the records need report no more
        records = [_pose_lines(d, threshold, padding)[dof] for d in datasets]
        largest = max((r.largest for r in records), default=0.0)
        lines: list[float] = []
        for record in records:
            if largest <= 0 or not len(record):
                continue
            strong = record.amplitudes * record.largest >= threshold * largest
            for frequency in np.sort(record.frequencies_hz[strong]):
                if all(abs(frequency - g) > LINE_MERGE_BINS * record.resolution_hz
                       for g in lines):
                    lines.append(float(frequency))
        found.append(tuple(sorted(lines)))
    return tuple(found)


def _pose_lines(dataset: Dataset, threshold: float, padding: int,
                transformed: tuple[np.ndarray, int] | None = None) -> list[SpectralLines]:
    """Each pose coordinate's lines of one record, computed once per record; ``transformed``:
    the pose's transforms at that padding and their length (:func:`_channel_spectra`), if at
    hand."""
    def lines(d: Dataset) -> list[SpectralLines]:
        if transformed is None:
            return channel_lines(d.pose, d.sample_rate, fraction=threshold, padding=padding)
        spectra, nfft = transformed
        return _lines_of(spectra, len(d), nfft, d.sample_rate, threshold)

    return dataset.derived(("pose lines", threshold, padding), lines)


__all__ = ["CHECK_SAMPLES", "COUNTING_PADDING", "LINE_FRACTION", "LINE_MERGE_BINS",
           "LINE_THRESHOLD", "MIN_RELATIVE_EXCITATION", "MotionRows", "SpectralLines",
           "channel_lines", "check_excitation", "dof_scales", "excitation_lines",
           "excitation_per_dof", "leg_space_motion", "motion_rows", "neutral_jacobian",
           "spectral_lines"]
