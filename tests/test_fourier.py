"""Method A (first-harmonic Fourier) against the linear model it assumes."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from linear_model_data import AMPLITUDES, make_experiment, random_matrices
from roundoff import EPS, convolution_bound
from stewartid.errors import ConfigError, IdentificationError
from stewartid.identification.fourier import FourierIdentifier
from stewartid.identification.harmonics import harmonic_coefficients
from stewartid.identification.result import IdentificationResult
from stewartid.reference.published import PAPER_ENTRIES
from stewartid.signals.differentiation import (
    DEFAULT_ORDER,
    acceleration_frequency,
    differentiate,
    estimate_frequency,
    kernel_filter,
    kernel_taps,
    savgol_coefficients,
    savgol_gain,
    share_frequency,
    window_samples,
)
from stewartid.signals.filtered_rows import kernel_filter_rows


@pytest.fixture(scope="module")
def truth():
    return random_matrices(np.random.default_rng(7))


def test_exact_recovery_with_constant_offsets(paper, truth):
    M, B = truth
    offset = np.array([120.0, -80.0, 900.0, 30.0, -45.0, 10.0])
    data = [make_experiment(paper, M, B, k, offset=offset) for k in range(6)]
    est = FourierIdentifier().fit(data, paper)
    assert est.M_ == pytest.approx(M, rel=1e-5, abs=1e-5 * np.abs(M).max())
    assert est.B_ == pytest.approx(B, rel=1e-5, abs=1e-5 * np.abs(B).max())
    assert est.frequencies_[0][0] == pytest.approx(1.0, rel=1e-6)
    assert est.condition_number_ < 10


def test_coulomb_square_wave_biases_bt_by_four_over_pi(paper, truth):
    """A square wave of level F in phase with the velocity of DOF k has the first harmonic
    (4/pi) F, attributed to Bt[:, k] as (4/pi) F / (w A_k); Mt is unaffected."""
    M, B = truth
    w = 2 * np.pi * 1.0
    level = np.array([50.0, -20.0, 35.0, 80.0, 15.0, -60.0])
    data = []
    for k in range(6):
        def square(t, q, qd, J, k=k):
            return np.sign(qd[:, k])[:, None] * level
        # sample rate a multiple of 4f: the switches fall between samples symmetrically
        data.append(make_experiment(paper, M, B, k, sample_rate=400.0, coulomb=square))
    est = FourierIdentifier(frequency_hz=1.0).fit(data, paper)
    predicted = B + (4 / np.pi) * level[:, None] / (w * AMPLITUDES[None, :])
    assert est.B_ == pytest.approx(predicted, rel=2e-3, abs=2e-3 * np.abs(B).max())
    assert est.M_ == pytest.approx(M, rel=1e-3, abs=1e-3 * np.abs(M).max())


#: Coulomb level per channel of the square-wave tests (N, N m).
SQUARE_LEVEL = np.array([50.0, -20.0, 35.0, 80.0, 15.0, -60.0])


def square_wave_fit(paper, M, B, with_friction: bool, periods: int = 4,
                    force_noise: float = 0.0, rng=None) -> FourierIdentifier:
    """Method A on six single-DOF sines (1 Hz, 400 Hz sampling) of the linear model, with a
    square wave of :data:`SQUARE_LEVEL` in phase with the excited DOF's velocity, and white
    leg-force noise of ``force_noise`` N."""
    data = []
    for k in range(6):
        def square(t, q, qd, J, k=k):
            return np.sign(qd[:, k])[:, None] * SQUARE_LEVEL
        exp = make_experiment(paper, M, B, k, sample_rate=400.0, periods=periods,
                              coulomb=square if with_friction else None)
        if force_noise:
            exp = dataclasses.replace(
                exp, forces=exp.forces + rng.normal(0.0, force_noise, exp.forces.shape))
        data.append(exp)
    return FourierIdentifier(frequency_hz=1.0).fit(data, paper)


def test_standard_errors_carry_the_coulomb_bias_the_third_harmonic_shows(paper, truth):
    """The bias (4/pi) F / (w A) of a square wave is what its third harmonic, (4/3pi) F,
    implies: the reported standard error of Bt[:, k] covers the bias; without friction the
    bound vanishes (no third harmonic in a linear system's force)."""
    M, B = truth
    w = 2 * np.pi * 1.0
    biased = square_wave_fit(paper, M, B, True)
    bias = (4 / np.pi) * np.abs(SQUARE_LEVEL)[:, None] / (w * AMPLITUDES[None, :])
    bound = np.asarray(biased.result_.diagnostics["friction_bias"]["bound_B"])
    # the sampled square wave's third harmonic is exact to the switching-time resolution
    assert bound == pytest.approx(bias, rel=2e-2)
    assert np.all(np.abs(biased.B_ - B) <= 1.05 * biased.std_errors_["B"])
    clean = square_wave_fit(paper, M, B, False)
    clean_bound = np.asarray(clean.result_.diagnostics["friction_bias"]["bound_B"])
    assert np.all(clean_bound <= 1e-6 * bias)


def test_stiffness_needs_two_frequencies(paper, truth):
    M, B = truth
    K = np.diag([2e4, 2e4, 5e4, 1e4, 1e4, 3e3])
    data = []
    for k in range(6):
        extra = [(k, AMPLITUDES[k] / 2, 2 * np.pi * 3.0, 0.3)]
        exp = make_experiment(paper, M, B, k, extra=extra, periods=6)
        # add the stiffness force K (q - q0) through the forces
        from stewartid.model.dynamics import ModelTerms
        terms = ModelTerms(paper, exp.pose)
        y = np.einsum("nji,nj->ni", terms.leg_jacobian, exp.forces) - terms.gravity
        y = y + (exp.pose - paper.neutral_pose) @ K.T
        forces = np.linalg.solve(np.transpose(terms.leg_jacobian, (0, 2, 1)),
                                 (y + terms.gravity)[..., None])[..., 0]
        data.append(type(exp)(t=exp.t, pose=exp.pose, lengths=exp.lengths, forces=forces,
                              name=exp.name))
    est = FourierIdentifier(frequency_hz=[1.0, 3.0], stiffness=True).fit(data, paper)
    assert est.M_ == pytest.approx(M, rel=1e-4, abs=1e-4 * np.abs(M).max())
    assert est.stiffness_ == pytest.approx(K, abs=1e-3 * np.abs(K).max())
    # fitted at one frequency, the 3 Hz line (half the amplitude, the third harmonic) is a
    # second sine, and Method A says so instead of returning the biased Mt - K / w^2
    with pytest.raises(IdentificationError, match=r"exp1: Method A needs motion at the given "
                                                  r"1 Hz only; .* 2 spectral lines .*\(1.0, 3.0 Hz\)"):
        FourierIdentifier(frequency_hz=1.0).fit(data, paper)
    with pytest.raises(ConfigError, match="single excitation frequency"):
        FourierIdentifier(frequency_hz=1.0, stiffness=True).fit(data, paper)


def test_rank_deficient_when_a_dof_is_never_excited(paper, truth):
    M, B = truth
    data = [make_experiment(paper, M, B, k) for k in range(5)]
    with pytest.raises(IdentificationError, match="DOF rz was never excited"):
        FourierIdentifier().fit(data, paper)


def test_bad_settings(paper):
    with pytest.raises(ConfigError, match="'order' parameter of FourierIdentifier"):
        FourierIdentifier(order=2).fit([], paper)
    with pytest.raises(ConfigError, match="'frequency_hz' parameter"):
        FourierIdentifier(frequency_hz=-1.0).fit([], paper)


def test_harmonic_coefficients_are_fourier_coefficients_over_whole_periods():
    t = np.arange(1000) / 500.0          # two whole periods of 1 Hz
    x = 3.0 + 2.0 * np.cos(2 * np.pi * t) - 0.5 * np.sin(2 * np.pi * t) + \
        0.7 * np.sin(2 * np.pi * 4 * t)
    c = harmonic_coefficients(x[:, None], t, [1.0])
    direct = [2 / len(t) * np.sum(x * np.cos(2 * np.pi * t)),
              2 / len(t) * np.sum(x * np.sin(2 * np.pi * t))]
    # sums of N terms of size <= max|x| (2/N of them) through a normal matrix of condition 2
    # (orthogonal columns, the constant's twice as long): <= 2 * 2 N eps max|x| of round-off
    roundoff = 4 * len(t) * np.finfo(float).eps * np.abs(x).max()
    assert c[:, 0] == pytest.approx(direct, abs=roundoff)
    assert c[:, 0] == pytest.approx([2.0, -0.5], abs=roundoff)


def test_savgol_gain_and_differentiation_of_a_sine():
    fs, f, window = 1000.0, 0.5, 0.4
    t = np.arange(4000) / fs
    w = 2 * np.pi * f
    _, v, a = differentiate(np.sin(w * t), fs, window)
    inner = slice(500, -500)
    gain_v = savgol_gain(f, fs, window, deriv=1)
    gain_a = savgol_gain(f, fs, window, deriv=2)
    # a symmetric filter scales a sine exactly: the two sides differ by round-off only (the
    # FFT convolution against the gain's direct sum), whatever the CPU
    n = window_samples(window, fs)
    bound_v, bound_a = (convolution_bound(savgol_coefficients(n, DEFAULT_ORDER, d, 1 / fs), 1.0)
                        for d in (1, 2))
    assert v[inner] == pytest.approx(gain_v * w * np.cos(w * t[inner]), abs=bound_v)
    assert a[inner] == pytest.approx(-gain_a * w ** 2 * np.sin(w * t[inner]), abs=bound_a)
    assert 0.999 < gain_a < 1.0
    # the derivatives asked for alone, in the order asked, hold the same bounds
    a_only, v_only = differentiate(np.sin(w * t), fs, window, derivatives=(2, 1))
    assert v_only[inner] == pytest.approx(gain_v * w * np.cos(w * t[inner]), abs=bound_v)
    assert a_only[inner] == pytest.approx(-gain_a * w ** 2 * np.sin(w * t[inner]), abs=bound_a)


def test_kernel_filter_derivative_identities():
    fs = 500.0
    t = np.arange(3000) / fs
    x = np.sin(2.0 * t) + 0.3 * np.cos(5.0 * t) + 0.1 * t ** 2
    xd = 2.0 * np.cos(2.0 * t) - 1.5 * np.sin(5.0 * t) + 0.2 * t
    xdd = -4.0 * np.sin(2.0 * t) - 7.5 * np.cos(5.0 * t) + 0.2
    h0, h1, h2 = kernel_filter(x, fs, 0.5, derivatives=2)
    # the discrete identities hold to the quadrature error of the sampled kernel (3.8e-12 and
    # 9.6e-10 with exact direct convolution), which no CPU changes; the FFT's round-off is
    # below log2(nfft) eps max|x| sum|h^(d)| = 11 * 2.2e-16 * 3.1 * (11.7, 209) <= 2e-12
    assert h1 == pytest.approx(kernel_filter(xd, fs, 0.5)[0], abs=1e-9)
    assert h2 == pytest.approx(kernel_filter(xdd, fs, 0.5)[0], abs=1e-7)


def test_kernel_filter_rows_are_the_filtered_rows():
    """Direct sums of the kept rows against the FFT convolution of every row: the same to
    the FFT's round-off (log2(nfft) eps sum|x| |h|), for steps that split the record's rows
    into blocks unevenly and for one block."""
    fs = 500.0
    t = np.arange(3001) / fs
    x = np.stack([np.sin(2.0 * t) + 3.0, 0.3 * np.cos(5.0 * t) + 0.1 * t ** 2], axis=1)
    x = np.stack([x, -2.0 * x], axis=2)  # (N, 2, 2): time on axis 0, any trailing shape
    every = kernel_filter(x, fs, 0.5)[0]
    bound = convolution_bound(kernel_taps(fs, 0.5)[0], np.abs(x).max())
    for step in (1, 7, 60, 1000):
        rows = kernel_filter_rows(x, fs, 0.5, step)
        assert rows.shape == every[::step].shape
        assert rows == pytest.approx(every[::step], abs=bound)
        # time on the last axis: the same rows, time last
        last = kernel_filter_rows(np.moveaxis(x, 0, -1), fs, 0.5, step, time_last=True)
        assert np.moveaxis(last, -1, 0) == pytest.approx(every[::step], abs=bound)


def test_kernel_filter_rows_of_the_derivatives_are_the_filtered_rows():
    """The rows of x * h' and x * h'' against the FFT convolution of every row, on a motion
    riding on an offset 1e5 times its size (a heave of metres under tens of micrometres): both
    filter the mean apart, so that they agree to the round-off of the motion, not of the offset
    (direct sums of the raw signal miss by 1e5 times that)."""
    fs = 500.0
    t = np.arange(3001) / fs
    motion = np.stack([np.sin(2.0 * t), 0.3 * np.cos(5.0 * t) + 0.1 * t ** 2], axis=1)
    offset = np.array([1e5, -3e5])
    x = motion + offset
    every = kernel_filter(x, fs, 0.5, derivatives=2)
    for derivative in (1, 2):
        kernel = kernel_taps(fs, 0.5, derivative)[derivative]
        # the motion's round-off, and the offset's share offset sum(h^(d)) taken from the two
        # means (a few eps of the offset apart)
        bound = (convolution_bound(kernel, np.abs(x - x.mean(axis=0)).max())
                 + 4 * EPS * np.abs(offset).max() * np.abs(kernel.sum()))
        for step in (1, 7, 1000):
            rows = kernel_filter_rows(x, fs, 0.5, step, derivative=derivative)
            assert rows == pytest.approx(every[derivative][::step], abs=bound)
            last = kernel_filter_rows(x.T, fs, 0.5, step, time_last=True, derivative=derivative)
            assert last.T == pytest.approx(every[derivative][::step], abs=bound)


def test_estimate_frequency():
    fs = 1000.0
    t = np.arange(9000) / fs
    x = np.column_stack([1e-4 * np.sin(2 * np.pi * 0.73 * t + 0.4), np.zeros_like(t)])
    assert estimate_frequency(x, fs) == pytest.approx(0.73, rel=1e-6)


@pytest.mark.parametrize("seed", range(4))
def test_estimate_frequency_finds_a_trending_sine_to_the_minimiser_tolerance(seed):
    # the refinement's least-squares fit of [sin, cos, 1, t] is exact at the true frequency of
    # a sine on a linear drift; Brent stops within sqrt(eps) ~ 1.5e-8 relative of it. Records
    # of 1 or 2 kHz, whole and broken periods
    rng = np.random.default_rng(seed)
    fs = float(rng.choice([1000.0, 2000.0]))
    t = np.arange(int(rng.integers(5000, 40001))) / fs
    frequency = rng.uniform(0.2, 8.0)
    x = (rng.uniform(1e-3, 1) * np.sin(2 * np.pi * frequency * t + rng.uniform(0, 6))
         + rng.uniform(-1e-2, 1e-2) * t + rng.uniform(-1, 1))
    assert estimate_frequency(x, fs) == pytest.approx(frequency, rel=1e-7)


def three_sines(t: np.ndarray, amplitude: float) -> np.ndarray:
    """A DOF's record of three sines of falling amplitude: 0.6, 0.3 and 0.15 of ``amplitude``
    at 0.3, 0.7 and 1.5 Hz."""
    return sum(share * amplitude * np.sin(2 * np.pi * hz * t + phase)
               for hz, share, phase in ((0.3, 0.6, 0.0), (0.7, 0.3, 1.0), (1.5, 0.15, 2.0)))


def test_estimate_frequency_ignores_channels_that_hold_only_round_off():
    # a noise-free heave record of three sines: the still DOFs carry the forward kinematics'
    # round-off (spreads of 1e-17), whose one clean line stands out against its own scale more
    # than the heave's largest line against the heave's; the other lines pull the refined
    # frequency by under 1 % on 20 s
    fs = 1000.0
    t = np.arange(20000) / fs
    heave = three_sines(t, 1e-2)
    still = 1e-17 * np.sin(2 * np.pi * 7.1 * t)
    x = np.column_stack([still, still, heave, still, still, still])
    assert estimate_frequency(x, fs) == pytest.approx(0.3, rel=1e-2)


def test_estimate_frequency_is_not_moved_by_white_noise():
    # a roll record of three sines beside a lateral DOF moved by coupling, mostly at the fastest
    # line: that line stands out against the lateral scale more than the roll's largest line
    # against the roll's. White noise adds to the lateral scale, not to its line, and turned the
    # choice to the roll's 0.3 Hz; a channel of noise alone holds no line
    fs = 1000.0
    t = np.arange(20000) / fs
    roll = three_sines(t, 5e-3)
    lateral = 2e-5 * np.sin(2 * np.pi * 0.7 * t + 0.5) + 7e-5 * np.sin(2 * np.pi * 1.5 * t + 1.0)
    x = np.column_stack([lateral, roll])
    rng = np.random.default_rng(0)
    assert estimate_frequency(x, fs) == pytest.approx(1.5, rel=1e-3)
    noisy = x + rng.normal(size=x.shape) * [3e-5, 1e-5]
    assert estimate_frequency(noisy, fs) == pytest.approx(1.5, rel=1e-3)
    only_noise = np.column_stack([roll, 1e-5 * rng.normal(size=len(t))])
    assert estimate_frequency(only_noise, fs) == pytest.approx(0.3, rel=1e-2)


def random_sines(rng: np.random.Generator, n: int, m: int, fs: float,
                 amplitudes: list[float], band: tuple[float, float]) -> np.ndarray:
    """``m`` channels (n, m) at ``fs`` Hz, each one sine of an amplitude drawn from
    ``amplitudes``, a frequency uniform in ``band`` (Hz) and a random phase."""
    t = np.arange(n) / fs
    return np.column_stack([rng.choice(amplitudes) * np.sin(
        2 * np.pi * rng.uniform(*band) * t + rng.uniform(0, 6)) for _ in range(m)])


def near_ties(rng: np.random.Generator, second_line: bool = False
              ) -> tuple[int, np.ndarray, np.ndarray, int, np.ndarray]:
    """Channels whose peaks nearly tie against their own scale (pure sines, the last a copy of
    the first; with ``second_line`` the first also carries a line at 31 Hz) with 0.1 % noise, at
    100 Hz: samples n, the Hann-windowed channels (m, n), their scales (m,), the 8x-padded
    length and each channel's coarse spectrum over its scale (m, nfft / 16 + 1)."""
    fs = 100.0
    n, m = int(rng.integers(200, 3000)), int(rng.integers(2, 7))
    x = random_sines(rng, n, m, fs, [1e-3, 1.0, 1e3], (0.3, 20))
    x[:, -1] = x[:, 0]
    if second_line:
        x[:, 0] += 0.9 * np.std(x[:, 0]) * np.sqrt(2) * np.sin(2 * np.pi * 31.0 * np.arange(n) / fs)
    x += 1e-3 * rng.standard_normal(x.shape) * np.std(x, axis=0)
    centred = x - x.mean(axis=0)
    scale = centred.std(axis=0)
    nfft = 1 << int(np.ceil(np.log2(8 * n)))
    windowed = (centred * np.hanning(n)[:, None]).T
    coarse = np.abs(np.fft.rfft(windowed, nfft // 8, axis=1)) / scale[:, None]
    return n, windowed, scale, nfft, coarse


def test_estimate_frequency_transforms_only_channels_that_can_hold_the_peak():
    # pure sines score alike against their own scale, so channels nearly tie (two share
    # a sine): the channels left out by the coarse spectrum's bound must not hold the largest
    # peak of every channel's full 8x-padded transform
    from stewartid.signals.differentiation import _peak_channels

    rng = np.random.default_rng(3)
    for _ in range(40):
        n, windowed, scale, nfft, coarse = near_ties(rng)
        m = len(windowed)
        relative = np.abs(np.fft.rfft(windowed, nfft, axis=1)[:, 1:]) / scale[:, None]
        peaks = np.argmax(relative, axis=1)
        values = relative[np.arange(m), peaks]
        top = np.flatnonzero(values == values.max())
        kept = _peak_channels(coarse, n)
        assert set(top) <= set(kept)
        assert np.all(values[np.setdiff1d(np.arange(m), kept)] < values.max())


def test_zoomed_bins_are_the_padded_transforms_bins():
    # the chirp transform of a band against numpy's whole transform, bands at either end included;
    # both sum n terms of |x|: round-off of the order of n eps max|x| each
    from stewartid.signals.differentiation import _zoom_spectrum

    rng = np.random.default_rng(8)
    for _ in range(20):
        n = int(rng.integers(50, 5000))
        nfft = 1 << int(np.ceil(np.log2(8 * n)))
        x = rng.standard_normal(n)
        full = np.fft.rfft(x, nfft)
        count = int(rng.integers(1, 200))
        for first in (0, int(rng.integers(0, nfft // 2 - count)), nfft // 2 + 1 - count):
            zoomed = _zoom_spectrum(x, nfft, first, count)
            bound = 100 * n * np.finfo(float).eps * np.abs(x).max()
            assert np.abs(zoomed - full[first:first + count]).max() < bound


def test_the_fine_winner_is_the_channel_of_the_largest_peak_of_every_whole_transform():
    # channels that nearly tie (pure sines against their own scale, two sharing one, a channel of
    # two lines far apart): the zoomed bands pick the row _dominant picks from whole transforms
    from stewartid.signals.differentiation import _dominant, _fine_winner, _peak_channels

    rng = np.random.default_rng(4)
    for _ in range(40):
        n, windowed, scale, nfft, coarse = near_ties(rng, second_line=True)
        kept = _peak_channels(coarse, n)
        relative = np.abs(np.fft.rfft(windowed[kept], nfft, axis=1)[:, 1:]) / scale[kept, None]
        winner = _fine_winner(windowed[kept], coarse[kept], scale[kept], nfft)
        assert winner.start == _dominant(relative)


def test_a_records_plain_peak_is_the_same_whether_asked_first_or_after_the_refined_frequency():
    # a read-only record's refined estimate leaves its plain peak (refine=False) in the cache,
    # from its coarse spectrum: it must be what the plain estimate computes on its own
    rng = np.random.default_rng(5)
    fs = 500.0
    for _ in range(30):
        n, m = int(rng.integers(300, 5000)), int(rng.integers(1, 7))
        x = random_sines(rng, n, m, fs, [1e-3, 1.0], (0.5, 30))
        x += 1e-2 * rng.standard_normal(x.shape) * np.std(x, axis=0)
        plain = estimate_frequency(x.copy(), fs, refine=False)
        record = x.copy()
        record.flags.writeable = False
        estimate_frequency(record, fs)
        assert estimate_frequency(record, fs, refine=False) == plain


def test_acceleration_frequency_takes_the_line_of_largest_acceleration():
    # a pitch record of three sines of falling amplitude (0.6, 0.3, 0.15 at 0.3, 0.7, 1.5 Hz):
    # the 0.3 Hz line is the largest, the 1.5 Hz one carries the most acceleration (0.15 x 1.5^2
    # against 0.6 x 0.3^2), with and without white noise; a single sine with a 2 % third harmonic
    # keeps the sine (the harmonic is below LINE_FLOOR)
    fs = 1000.0
    t = np.arange(20000) / fs
    pitch = three_sines(t, 5e-3)
    rng = np.random.default_rng(1)
    for x in (pitch, pitch + 1e-5 * rng.normal(size=len(t))):
        assert estimate_frequency(x, fs) == pytest.approx(0.3, rel=1e-2)
        assert acceleration_frequency(x, fs) == pytest.approx(1.5, rel=1e-2)
    sine = np.sin(2 * np.pi * 0.5 * t) + 0.02 * np.sin(2 * np.pi * 1.5 * t)
    assert acceleration_frequency(sine, fs) == pytest.approx(0.5, rel=1e-3)
    # a validation fold's piece (one second) takes the record's
    whole = np.column_stack([pitch, pitch])
    whole.flags.writeable = False
    piece = whole[:1000]
    share_frequency(piece, whole)
    assert acceleration_frequency(piece, fs) == acceleration_frequency(whole, fs)


def test_acceleration_frequency_is_not_taken_by_white_noise():
    # noise as large as the sine: its largest bins pass LINE_FLOOR of the sine's line (about
    # 350 sigma against 250 A on 20 000 Hann-windowed samples) and, weighted by f^2, would
    # outrank it; they stay below LINE_NOISE_POWER median bins
    fs = 1000.0
    t = np.arange(20000) / fs
    x = np.sin(2 * np.pi * 0.5 * t) + np.random.default_rng(2).normal(size=len(t))
    assert acceleration_frequency(x, fs) == pytest.approx(0.5, rel=1e-2)


def test_result_json_round_trip_and_table(tmp_path, paper, truth):
    M, B = truth
    data = [make_experiment(paper, M, B, k) for k in range(6)]
    result = FourierIdentifier().fit(data, paper).result_
    path = result.to_json(tmp_path / "r.json")
    back = IdentificationResult.from_json(path)
    assert back.M == pytest.approx(result.M)
    assert back.std_errors_B == pytest.approx(result.std_errors_B)
    assert back.method == "fourier"
    table = back.comparison_table(M, B)
    assert len(table) == len(PAPER_ENTRIES) == 20
    assert list(table["entry"][:2]) == ["Mt(1,1)", "Mt(2,2)"]
    assert table["error_percent"].max() < 1e-3


@pytest.mark.slow
def test_example_c10_method_a(example_dir, example_platform, example_truth):
    """Independent simulator, Coulomb 10 N m: Mt's diagonal is accurate, Bt carries the
    Coulomb bias (Bt(1,1) too large by tens of %)."""
    est = FourierIdentifier().fit([example_dir], example_platform)
    table = est.result_.comparison_table(example_truth["Mt"], example_truth["Bt"])
    diag_M = table[(table.matrix == "M") & (table.i == table.j)]
    assert diag_M["error_percent"].max() < 0.1
    assert est.B_[0, 0] > 1.2 * example_truth["Bt"][0, 0]


@pytest.mark.slow
def test_noise_alone_adds_no_friction_allowance_and_friction_in_noise_is_caught(paper, truth):
    """Force noise has a third harmonic of its own: below the 1 % significance point it is not
    read as friction (the error bars stay the noise's), while a square wave whose third
    harmonic stands well above the noise is caught and its bias covered."""
    M, B = truth
    rng = np.random.default_rng(3)

    def fit(with_friction: bool) -> FourierIdentifier:
        return square_wave_fit(paper, M, B, with_friction, periods=12, force_noise=20.0,
                               rng=rng)

    from stewartid.reports.identification.friction_text import third_harmonic_lines

    quiet_fit = fit(False)
    assert "does not show" in third_harmonic_lines(quiet_fit.result_)[0]
    quiet = quiet_fit.result_.diagnostics["friction_bias"]
    # white noise alone: the statistic is chi-squared below its 1 % point (a fixed seed)
    assert quiet["statistic"] < quiet["threshold"]
    assert np.count_nonzero(np.asarray(quiet["third_harmonic"])) == 0
    assert np.all(np.asarray(quiet["bound_B"]) == 0)
    rubbing = fit(True)
    diagnostics = rubbing.result_.diagnostics["friction_bias"]
    assert diagnostics["statistic"] > diagnostics["threshold"]
    assert "shows Coulomb friction" in third_harmonic_lines(rubbing.result_)[0]
    assert np.all(np.abs(rubbing.B_ - B) <= 3 * rubbing.std_errors_["B"])


def test_a_third_harmonic_in_a_noise_free_channel_counts_as_friction():
    """A channel without noise shows any third harmonic: it is friction, not noise."""
    from stewartid.identification.harmonics import third_harmonic

    blocks = np.zeros((8, 2, 6))
    blocks[:, 0, 2] = 0.5                      # channel z: a third harmonic, no scatter
    covariance = np.diag([1.0, 1.0, 0.0, 1.0, 1.0, 1.0])
    amplitudes, statistic, threshold = third_harmonic([blocks], covariance)
    assert statistic > threshold and amplitudes[0][2] == pytest.approx(0.5)
    quiet = np.zeros((8, 2, 6))
    amplitudes, statistic, threshold = third_harmonic([quiet], covariance)
    assert statistic < threshold and not np.any(amplitudes[0])


def test_a_record_shorter_than_a_period_is_refused_naming_both(paper, truth):
    """0.1 s of a 0.5 Hz sine: the message names the record length and the 2 s period."""
    M, B = truth
    data = [make_experiment(paper, M, B, k, frequency_hz=0.5, periods=0.05, sample_rate=1000.0)
            for k in range(6)]
    with pytest.raises(IdentificationError) as found:
        FourierIdentifier().fit(data, paper)
    message = str(found.value)
    assert "lasts 0.1 s" in message and "about 2 s" in message and "spectral" not in message
    # a whole period passes the check
    whole = [make_experiment(paper, M, B, k, frequency_hz=0.5, periods=4, sample_rate=200.0)
             for k in range(6)]
    FourierIdentifier().fit(whole, paper)
