"""A real rig's sensor imperfections: channel delay, coloured noise, mains hum, drift.

Every check is against independent truth: the analytically delayed sine and the rigid-body
model evaluated at the delayed instants (delay), the filter's own frequency response from
``scipy.signal.sosfreqz`` (coloured noise: its standard deviation, its -3 dB point and the
statistical tolerance from the sample size), the Fourier coefficient of an exact number of
mains periods (hum), Brownian-motion variances (drift), and the sensor model as it was before
these imperfections existed (default path, bit for bit).
"""

from __future__ import annotations

import dataclasses
import json
import re

import numpy as np
import pytest
from scipy import signal

from stewartid.datasets.dataset import Dataset
from stewartid.errors import ConfigError
from stewartid.model.dynamics import inverse_dynamics
from stewartid.model.kinematics import inverse_kinematics
from stewartid.simulation import SensorNoise, degrade, simulate_experiment, sine_excitation
from stewartid.simulation.imperfections import (
    delay_signal,
    lowpass_noise,
    lowpass_sections,
    random_walk,
)
from stewartid.simulation.sensors import measure_legs

RATE = 1000.0
#: Cubic-spline interpolation error of a function with bounded fourth derivative, in units of
#: h^4 max|x''''| (Hall & Meyer 1976, the spline with exact end slopes); the end slopes of
#: :func:`delay_signal`, five-point differences, add at most h^5 max|x^(5)| / 5.
SPLINE_CONSTANT = 5.0 / 384.0


def _times(seconds: float, rate: float = RATE) -> np.ndarray:
    return np.arange(int(round(seconds * rate)) + 1) / rate


@pytest.mark.parametrize("delay", [0.3e-3, 0.5e-3, 2e-3, 3.7e-3])
@pytest.mark.parametrize("frequency", [1.5, 25.0])
def test_a_sine_delayed_is_the_analytically_delayed_sine(delay, frequency):
    t = _times(5.0)
    h = 1.0 / RATE
    values = np.column_stack([np.sin(2 * np.pi * frequency * t + phase) for phase in (0.4, 2.0)])
    out = delay_signal(t, values, delay)
    late = t >= delay
    truth = np.column_stack([np.sin(2 * np.pi * frequency * (t[late] - delay) + phase)
                             for phase in (0.4, 2.0)])
    error = np.abs(out[late] - truth)
    omega_h = 2 * np.pi * frequency * h
    bound = SPLINE_CONSTANT * omega_h ** 4 + omega_h ** 5 / 5
    assert error.max() <= bound + 1e-14, (error.max(), bound)
    # before the record: the first sample held (the rig at rest)
    np.testing.assert_array_equal(out[~late], np.broadcast_to(values[0], out[~late].shape))


def test_a_whole_number_of_samples_is_a_shift():
    """2 ms at 1 kHz: the samples two places later, to round-off, on any signal."""
    t = _times(2.0)
    values = np.random.default_rng(5).standard_normal((len(t), 6))
    out = delay_signal(t, values, 2e-3)
    np.testing.assert_allclose(out[2:], values[:-2], rtol=0, atol=1e-12)
    np.testing.assert_array_equal(out[:2], values[[0, 0]])
    np.testing.assert_array_equal(delay_signal(t, values, 0.0), values)


def _model_record(platform, t):
    """True pose (N, 6), leg lengths and frictionless actuator forces of a smooth motion."""
    w1, w2 = 2 * np.pi * 0.5, 2 * np.pi * 1.3
    amplitude = np.array([0.02, 0.015, 0.01, 0.01, 0.012, 0.015])

    def motion(time):
        phase = np.arange(6)[None, :]
        q = platform.neutral_pose + amplitude * (np.sin(w1 * time[:, None] + phase)
                                                 + 0.3 * np.sin(w2 * time[:, None] + 2 * phase))
        qd = amplitude * (w1 * np.cos(w1 * time[:, None] + phase)
                          + 0.3 * w2 * np.cos(w2 * time[:, None] + 2 * phase))
        qdd = -amplitude * (w1 ** 2 * np.sin(w1 * time[:, None] + phase)
                            + 0.3 * w2 ** 2 * np.sin(w2 * time[:, None] + 2 * phase))
        return q, inverse_dynamics(platform, q, qd, qdd, friction=False)

    return motion


def _spline_bound(values: np.ndarray) -> float:
    """The spline's error bound with h^4 x'''' and h^5 x^(5) from the samples' fourth and
    fifth differences (each h^k x^(k) at a point between the samples it spans)."""
    return float(SPLINE_CONSTANT * np.abs(np.diff(values, 4, axis=0)).max()
                 + np.abs(np.diff(values, 5, axis=0)).max() / 5)


def test_degrade_delays_forces_and_lengths_as_the_model_at_the_delayed_instants(paper):
    """Forces 0.5 ms late, lengths 0.3 ms late: the rigid-body model's forces, leg lengths and
    pose at t - delay (the pose from forward kinematics of the delayed lengths)."""
    t = _times(4.0)
    motion = _model_record(paper, t)
    q, forces = motion(t)
    clean = Dataset(t=t, pose=q, lengths=inverse_kinematics(paper, q).lengths, forces=forces,
                    name="model")
    late = degrade(clean, paper, SensorNoise(force_delay=0.5e-3, length_delay=0.3e-3), rng=1)
    inside = t >= 0.5e-3
    _, forces_late = motion(t[inside] - 0.5e-3)
    np.testing.assert_allclose(late.forces[inside], forces_late, rtol=0,
                               atol=_spline_bound(forces) + 1e-9)
    inside = t >= 0.3e-3
    q_late, _ = motion(t[inside] - 0.3e-3)
    lengths_late = inverse_kinematics(paper, q_late).lengths
    length_bound = _spline_bound(clean.lengths) + 1e-14
    np.testing.assert_allclose(late.lengths[inside], lengths_late, rtol=0, atol=length_bound)
    # forward kinematics solves to 1e-12 m on the lengths; J_lq^-1 is of order 1 m/m here
    np.testing.assert_allclose(late.pose[inside], q_late, rtol=0, atol=10 * length_bound + 1e-10)
    assert late.name == "model" and np.array_equal(late.t, t)


def test_default_sensor_model_is_the_one_before_the_imperfections(paper):
    """Zero imperfections: the measured data, bit for bit, of the sensor model as it was,
    quantise(true + bias + N(0, std^2)) for lengths then forces from the same generator, and
    a hum or drift switched on leaves the noise of that seed unchanged."""
    t = _times(1.0)
    rng = np.random.default_rng(0)
    lengths = 3.4 + 0.01 * rng.standard_normal((len(t), 6))
    forces = 3e4 + 500 * rng.standard_normal((len(t), 6))
    noise = SensorNoise(length_noise=2e-5, length_bias=1e-6, length_resolution=1e-6,
                        force_noise=150.0, force_bias=-3.0, force_resolution=0.5)
    reference = np.random.default_rng(11)
    old_lengths = 1e-6 * np.round((lengths + 1e-6 + reference.normal(0.0, 2e-5, lengths.shape))
                                  / 1e-6)
    old_forces = 0.5 * np.round((forces - 3.0 + reference.normal(0.0, 150.0, forces.shape)) / 0.5)
    new_lengths, new_forces = measure_legs(lengths, forces, noise, np.random.default_rng(11), t)
    assert np.array_equal(new_lengths, old_lengths) and np.array_equal(new_forces, old_forces)
    hummed = dataclasses.replace(noise, force_resolution=0.0, length_resolution=0.0)
    plain_l, plain_f = measure_legs(lengths, forces, hummed, np.random.default_rng(3), t)
    drift_l, hum_f = measure_legs(lengths, forces, dataclasses.replace(
        hummed, hum_amplitude=10.0, length_drift=1e-6), np.random.default_rng(3), t)
    hum = hum_f - plain_f
    assert np.abs(hum).max() <= 10.0 + 1e-9 and np.abs(hum).max() > 9.0
    assert 0 < np.abs(drift_l - plain_l).max() < 1e-5


def test_simulate_with_a_whole_sample_force_delay_shifts_the_forces_only(paper):
    """On the plant: 2 ms at 1 kHz gives the forces of the undelayed run two samples later;
    the lengths and pose are those of the undelayed run, bit for bit."""
    excitation = sine_excitation(paper, 3, 0.02, 1.0, fade_in=0.2)
    noise = SensorNoise(length_noise=1e-5)
    plain, _ = simulate_experiment(paper, excitation, 0.6, noise, np.random.default_rng(4))
    late, _ = simulate_experiment(paper, excitation, 0.6,
                                  dataclasses.replace(noise, force_delay=2e-3),
                                  np.random.default_rng(4))
    assert np.array_equal(late.pose, plain.pose) and np.array_equal(late.lengths, plain.lengths)
    np.testing.assert_allclose(late.forces[2:], plain.forces[:-2], rtol=1e-13)
    np.testing.assert_array_equal(late.forces[:2], plain.forces[[0, 0]])


def _filter_moments(cutoff: float, order: int) -> float:
    """Sum over lags of the squared autocorrelation of the filtered noise, from the filter's
    frequency response: (1/2 pi) int |H|^4 / ((1/2 pi) int |H|^2)^2."""
    _, response = signal.sosfreqz(lowpass_sections(cutoff, order, RATE), worN=1 << 16)
    power = np.abs(response) ** 2
    return float(np.mean(power ** 2) / np.mean(power) ** 2)


@pytest.mark.parametrize("cutoff, order", [(20.0, 4), (100.0, 2)])
def test_filtered_force_noise_has_the_requested_std_and_cutoff(cutoff, order):
    std = 150.0
    t = _times(200.0)
    zero = np.zeros((len(t), 6))
    noise = SensorNoise(force_noise=std, force_lowpass=cutoff, force_lowpass_order=order)
    _, forces = measure_legs(zero, zero, noise, np.random.default_rng(8), t)
    # the sample variance of a Gaussian process: relative standard error
    # sqrt(2 sum rho_k^2 / N) per leg, six independent legs pooled
    n = forces.size
    relative = np.sqrt(2 * _filter_moments(cutoff, order) / n)
    assert abs(np.mean(forces ** 2) / std ** 2 - 1) <= 4 * relative
    # the spectrum: flat below the cut-off, half (-3 dB) at it; Welch's estimate at one
    # 1 Hz bin has a relative standard error of about sqrt(2 / segments)
    frequency, psd = signal.welch(forces, fs=RATE, nperseg=int(RATE), axis=0)
    psd = psd.mean(axis=1)
    segments = 6 * (2 * len(t) // int(RATE) - 1)
    passband = psd[(frequency > 0) & (frequency <= cutoff / 4)].mean()
    ratio = psd[np.argmin(np.abs(frequency - cutoff))] / passband
    assert abs(ratio - 0.5) <= 4 * 0.5 * np.sqrt(2 / segments), ratio
    # ... which puts the -3 dB crossing within (that tolerance / order) of the cut-off
    crossing = np.interp(-0.5, -psd[frequency > 0] / passband, frequency[frequency > 0])
    assert abs(crossing / cutoff - 1) <= 4 * np.sqrt(2 / segments) / order, crossing
    # an octave above: the digital Butterworth response (bilinear transform),
    # 1 / (1 + (tan(pi f / fs) / tan(pi fc / fs))^(2 n))
    warped = np.tan(np.pi * 2 * cutoff / RATE) / np.tan(np.pi * cutoff / RATE)
    above = psd[np.argmin(np.abs(frequency - 2 * cutoff))] / passband
    assert above == pytest.approx(1 / (1 + warped ** (2 * order)), rel=4 * np.sqrt(2 / segments))


def test_filtered_noise_is_stationary_from_the_first_sample():
    """The filter runs before the record: the first samples already have the full variance
    (a filter started at rest would give a fraction of it)."""
    first = np.vstack([lowpass_noise(np.random.default_rng(seed), 5, 2.0, 10.0, 6, RATE)
                       for seed in range(500)])
    variance = np.mean(first.reshape(500, 5, 6) ** 2, axis=(0, 2))
    assert np.all(np.abs(variance / 4.0 - 1) <= 4 * np.sqrt(2 / 3000)), variance


@pytest.mark.parametrize("frequency", [50.0, 60.0])
def test_hum_is_a_spectral_line_of_the_requested_amplitude(frequency):
    """20 s of exactly 1000 (1200) mains periods: the Fourier coefficient at the mains
    frequency has the hum's amplitude on every leg, alone (to round-off) and under white
    noise (standard error std sqrt(2 / N))."""
    t = _times(20.0)[:-1]
    zero = np.zeros((len(t), 6))
    for std, tolerance in ((0.0, 1e-9), (150.0, 4 * 150.0 * np.sqrt(2 / len(t)))):
        noise = SensorNoise(force_noise=std, hum_amplitude=30.0, hum_frequency=frequency)
        _, forces = measure_legs(zero, zero, noise, np.random.default_rng(2), t)
        spectrum = np.fft.rfft(forces, axis=0) * 2 / len(t)
        line = int(round(frequency * 20.0))
        np.testing.assert_allclose(np.abs(spectrum[line]), 30.0, rtol=0, atol=tolerance)
        if std == 0:
            others = np.delete(np.abs(spectrum), line, axis=0)
            assert others.max() <= 1e-9
            phases = np.angle(spectrum[line])
            assert np.ptp(phases) > 0.1  # one phase per leg
    again = measure_legs(zero, zero, noise, np.random.default_rng(2), t)[1]
    assert np.array_equal(again, forces)


def test_drift_is_a_random_walk_with_the_requested_std_at_the_end():
    n, std, seeds = 1001, 5.0, 400
    walks = np.stack([random_walk(n, std, np.random.default_rng(seed)) for seed in range(seeds)])
    assert np.all(walks[:, 0] == 0)
    count = seeds * 6
    for k, share in ((n - 1, 1.0), ((n - 1) // 2, 0.5)):
        variance = np.mean(walks[:, k] ** 2)
        assert abs(variance / (share * std ** 2) - 1) <= 4 * np.sqrt(2 / count), (k, variance)
    # increments independent: successive steps uncorrelated
    steps = np.diff(walks, axis=1).reshape(-1, 6)
    correlation = np.mean(steps[1:] * steps[:-1]) / np.mean(steps ** 2)
    assert abs(correlation) <= 4 / np.sqrt(steps.size)


def test_degrade_quantises_the_lengths_and_recomputes_the_pose(paper):
    t = _times(0.5)
    q, forces = _model_record(paper, t)(t)
    clean = Dataset(t=t, pose=q, lengths=inverse_kinematics(paper, q).lengths, forces=forces)
    coarse = degrade(clean, paper, SensorNoise(length_resolution=1e-5, force_resolution=2.0))
    steps = coarse.lengths / 1e-5
    np.testing.assert_allclose(steps, np.round(steps), rtol=0, atol=1e-6)
    assert np.abs(coarse.lengths - clean.lengths).max() <= 0.5e-5 + 1e-12
    assert np.abs(coarse.forces - clean.forces).max() <= 1.0 + 1e-9
    np.testing.assert_allclose(inverse_kinematics(paper, coarse.pose).lengths, coarse.lengths,
                               rtol=0, atol=1e-11)
    # forces only: the pose and lengths are left as they were
    hum = degrade(clean, paper, SensorNoise(hum_amplitude=5.0), rng=np.random.default_rng(1))
    assert np.array_equal(hum.pose, clean.pose) and np.array_equal(hum.lengths, clean.lengths)


def test_bad_imperfections_are_refused_in_one_line(paper):
    with pytest.raises(ConfigError, match="'force_delay' parameter of SensorNoise must be >= 0"):
        SensorNoise(force_delay=-1e-3)
    with pytest.raises(ConfigError, match="force_delay.* outside the physical range 0 to 1 s"):
        SensorNoise(force_delay=2.0)
    with pytest.raises(ConfigError, match="force_lowpass_order.* must be an integer in"):
        SensorNoise(force_lowpass_order=0)
    with pytest.raises(ConfigError, match="'force_noise' .* or a list of 6 numbers"):
        SensorNoise(force_noise=[1.0, 2.0])
    assert SensorNoise(force_noise=np.arange(6)).force_noise == (0.0, 1.0, 2.0, 3.0, 4.0, 5.0)
    t = _times(0.1)
    zero = np.zeros((len(t), 6))
    with pytest.raises(ConfigError, match="force_lowpass = 600 Hz is not below the Nyquist"):
        measure_legs(zero, zero, SensorNoise(force_noise=1.0, force_lowpass=600.0),
                     np.random.default_rng(0), t)
    with pytest.raises(ConfigError, match="need the sample times; pass t"):
        measure_legs(zero, zero, SensorNoise(force_delay=1e-3), np.random.default_rng(0))
    assert SensorNoise(force_lowpass_order=8, hum_frequency=60.0).is_ideal
    assert not SensorNoise(force_drift=1.0).is_ideal


def test_cli_flags_are_written_to_meta_and_checked(tmp_path):
    from typer.testing import CliRunner

    from stewartid.cli import app

    out = tmp_path / "rig"
    result = CliRunner().invoke(app, [
        "simulate", "--out", str(out), "--duration", "0.5", "--actuator", "ideal",
        "--jobs", "1", "--noise", "--force-delay", "0.002", "--length-delay", "0.0005",
        "--force-lowpass", "20", "--force-lowpass-order", "2", "--hum", "30",
        "--hum-frequency", "60", "--force-drift", "40", "--length-drift", "1e-6",
        "--force-resolution", "0.5", "--length-resolution", "1e-6"])
    assert result.exit_code == 0, result.output
    noise = json.loads((out / "meta.json").read_text())["noise"]
    assert noise | {"length_noise": 0, "force_noise": 0} == {
        "length_noise": 0, "length_bias": 0.0, "length_resolution": 1e-6, "force_noise": 0,
        "force_bias": 0.0, "force_resolution": 0.5, "length_delay": 0.0005,
        "force_delay": 0.002, "force_lowpass": 20.0, "force_lowpass_order": 2,
        "hum_amplitude": 30.0, "hum_frequency": 60.0, "length_drift": 1e-6,
        "force_drift": 40.0}
    for flags, message in ((["--force-lowpass", "20"], "colours the force noise, which is zero"),
                           (["--noise", "--force-lowpass", "600"],
                            "--force-lowpass must be in \\(0, 500\\) \\(Hz\\) when sampling"),
                           (["--hum-frequency", "60"], "--hum-frequency has no effect without"),
                           (["--force-delay", "2"], "--force-delay = 2 s is outside the")):
        bad = CliRunner().invoke(app, ["simulate", "--out", str(tmp_path / "bad"), *flags])
        assert bad.exit_code == 2, bad.output
        assert len(bad.output.strip().splitlines()) == 1
        assert re.search(message, bad.output), bad.output
