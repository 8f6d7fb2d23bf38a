"""Fast logs averaged over blocks of samples before identification: the block mean against the
analytic one, the rule's choice of the block, and a 2 kHz log identified the same both ways."""

from __future__ import annotations

import numpy as np
import pytest

from stewartid.datasets.dataset import MIN_SAMPLES, Dataset
from stewartid.errors import ConfigError
from stewartid.identification.averaging import (
    DEFAULT_AVERAGING,
    AveragingPolicy,
    average_experiments,
    averaging_factor,
    describe_averaging,
)


def _sine_record(rate: float, frequency: float, seconds: float = 10.0, start: float = 0.3,
                 amplitude: float = 0.02, phase: float = 0.4) -> Dataset:
    """Every signal a sine of ``frequency`` (Hz) sampled at ``rate`` (Hz) from ``start`` (s)."""
    t = start + np.arange(int(round(rate * seconds))) / rate
    wave = amplitude * np.sin(2 * np.pi * frequency * t + phase)
    signal = np.outer(wave, np.arange(1.0, 7.0))
    return Dataset(t=t, pose=signal, lengths=1.0 + signal, forces=1e3 * signal, name="exp1")


@pytest.mark.parametrize("samples", [2, 3, 5])
def test_block_means_of_a_sine_are_the_sine_at_the_blocks_mean_times(samples):
    """The mean of k samples of A sin(w t + p) spaced T is A D sin(w t_mean + p) with the
    Dirichlet kernel D = sin(k w T / 2) / (k sin(w T / 2)): no phase, and a gain within
    (w T)^2 (k^2 - 1) / 24 of 1 (the bound max|s''| T^2 (k^2 - 1) / 24 on the sine)."""
    rate, frequency, amplitude, phase = 2000.0, 37.0, 0.02, 0.4   # fast, for a visible gain
    record = _sine_record(rate, frequency, seconds=1.0, amplitude=amplitude, phase=phase)
    averaged = record.averaged(samples)
    step, w = 1.0 / rate, 2 * np.pi * frequency
    blocks = len(record) // samples
    mean_times = record.t[0] + (samples - 1) * step / 2 + samples * step * np.arange(blocks)
    np.testing.assert_allclose(averaged.t, mean_times, rtol=0, atol=1e-12)
    gain = np.sin(samples * w * step / 2) / (samples * np.sin(w * step / 2))
    expected = amplitude * gain * np.sin(w * mean_times + phase)
    # to the rounding of the sine's argument (w t ~ 300 rad: 1e-13 rad)
    np.testing.assert_allclose(averaged.pose[:, 0], expected, rtol=0, atol=1e-14)
    np.testing.assert_allclose(averaged.forces[:, 5], 6e3 * expected, rtol=0, atol=1e-10)
    np.testing.assert_allclose(averaged.lengths[:, 2], 1.0 + 3 * expected, rtol=0, atol=1e-14)
    bound = amplitude * w ** 2 * step ** 2 * (samples ** 2 - 1) / 24
    departure = np.abs(averaged.pose[:, 0] - amplitude * np.sin(w * mean_times + phase))
    assert 0.9 * bound <= departure.max() <= bound
    assert averaged.sample_rate == pytest.approx(rate / samples, rel=1e-9)
    assert averaged.name == record.name


def test_block_means_of_white_noise_are_white_with_a_kth_of_its_variance():
    rng = np.random.default_rng(3)
    n, samples = 200_000, 2
    t = np.arange(n) / 2000.0
    noise = rng.standard_normal((n, 6))
    record = Dataset(t=t, pose=noise, lengths=noise, forces=noise)
    averaged = record.averaged(samples).forces
    blocks = n // samples
    # standard errors of a variance and of a lag-one correlation: sqrt(2 / n), sqrt(1 / n)
    assert np.var(averaged, axis=0) == pytest.approx(np.full(6, 0.5),
                                                      abs=5 * 0.5 * np.sqrt(2 / blocks))
    lag_one = np.sum(averaged[1:] * averaged[:-1], axis=0) / np.sum(averaged ** 2, axis=0)
    assert np.all(np.abs(lag_one) < 5 / np.sqrt(blocks))


def test_an_incomplete_last_block_is_dropped_and_one_sample_is_the_record_itself():
    record = _sine_record(2000.0, 0.5, seconds=0.1005)      # 201 samples
    assert len(record.averaged(2)) == 100 and len(record.averaged(3)) == 67
    assert record.averaged(1) is record


def test_bad_block_sizes_are_refused():
    record = _sine_record(2000.0, 0.5, seconds=0.1)
    with pytest.raises(ConfigError, match="whole number >= 1; got 0"):
        record.averaged(0)
    with pytest.raises(ConfigError, match="whole number >= 1; got 2.0"):
        record.averaged(2.0)
    with pytest.raises(ConfigError, match=f"leaves 50 of 200 \\(at least {MIN_SAMPLES} needed"):
        record.averaged(4)


@pytest.mark.parametrize(("rate", "frequency", "expected"), [
    (1000.0, 0.5, 1),      # at the floor already
    (1500.0, 0.5, 1),      # no whole number of samples keeps 1 kHz
    (2000.0, 0.5, 2),      # the floor decides
    (4000.0, 0.5, 4),
    (1999.99999, 0.5, 2),  # a rate read from rounded time stamps
    (4000.0, 4.0, 2),      # 1000 samples per period: 400 leave room for 2.5, so 2
    (2000.0, 3.0, 1),      # 667 samples per period: averaging 2 would leave 333
    (2000.0, 2.5, 2),      # 800: exactly 400 left
])
def test_the_rule_keeps_the_rate_floor_and_the_sampling_margin(rate, frequency, expected):
    record = _sine_record(rate, frequency)
    assert averaging_factor([record]) == expected
    entry = average_experiments([record]).entry
    assert entry["averaged_samples"] == expected
    assert describe_averaging(entry).startswith(
        "every sample used" if expected == 1 else f"averaged {expected} samples into one")
    assert entry["rate_hz"] == pytest.approx(rate / expected)
    assert entry["samples_per_period"] == pytest.approx(rate / frequency / expected, rel=1e-3)


def test_the_slowest_and_the_fastest_record_decide_for_all():
    slow, fast = _sine_record(4000.0, 0.5), _sine_record(4000.0, 4.0)
    assert averaging_factor([slow, fast]) == 2
    assert averaging_factor([slow, _sine_record(2000.0, 0.5)]) == 2
    averaged = average_experiments([slow, fast])
    assert [len(d) for d in averaged.experiments] == [20000, 20000]


def test_a_record_that_does_not_move_and_a_short_one_are_used_as_logged():
    still = Dataset(t=np.arange(4000) / 4000.0, pose=np.zeros((4000, 6)),
                    lengths=np.ones((4000, 6)), forces=np.zeros((4000, 6)))
    assert averaging_factor([still]) == 1
    short = _sine_record(4000.0, 40.0, seconds=0.05)          # 200 samples, 100 per period
    assert averaging_factor([short], AveragingPolicy(samples_per_period=10.0)) == 3


def test_a_policy_sets_the_floor_and_none_keeps_every_sample():
    record = _sine_record(2000.0, 0.5)
    assert averaging_factor([record], AveragingPolicy(floor_hz=500.0)) == 4
    assert averaging_factor([record], AveragingPolicy(floor_hz=500.0,
                                                      samples_per_period=1000.0)) == 4
    assert averaging_factor([record], AveragingPolicy(floor_hz=100.0,
                                                      samples_per_period=2000.0)) == 2
    kept = average_experiments([record], None)
    assert kept.experiments[0] is record and kept.entry is None
    with pytest.raises(ConfigError, match="'floor_hz' parameter of AveragingPolicy must be a "
                                          "float in the range \\(0, inf\\]. Got -1"):
        AveragingPolicy(floor_hz=-1)
    with pytest.raises(ConfigError, match="'samples_per_period' parameter .* Got nan"):
        AveragingPolicy(samples_per_period=float("nan"))
    assert averaging_factor([record], AveragingPolicy(samples_per_period=float("inf"))) == 1


@pytest.mark.slow
def test_a_2_khz_log_and_its_average_identify_the_same_within_their_errors():
    """The paper's sines at 2 kHz with the reference noise (10 s, Coulomb 30 N m): Method B's and
    least squares' 20 entries from the averaged log within 0.3 of the full-rate fit's standard errors,
    which the averaged fit's match within 10 % in the median; the result says what was done."""
    import stewartid as sid
    from stewartid.platform import load_platform
    from stewartid.reference.published import PAPER_ENTRIES
    from stewartid.simulation import simulate_experiments
    from stewartid.simulation.sensors import reference_noise

    platform = load_platform("paper").replace(friction__coulomb=30.0,
                                              sensors__sample_rate=2000.0)
    data = simulate_experiments(platform, coulomb=30.0, duration_s=10.0, seed=2,
                                noise=reference_noise(platform), jobs=1).datasets
    # two validation folds, the fewest: only the fits on all data are compared
    full = sid.compare_methods(data, platform, ("wavelet", "ls"), folds=2)
    fast = sid.compare_methods(data, platform, ("wavelet", "ls"), folds=2,
                               averaging=DEFAULT_AVERAGING)
    assert "averaging" not in full.result.diagnostics and full.averaging is None
    assert fast.result.diagnostics["averaging"]["averaged_samples"] == 2
    assert fast.averaging["rate_hz"] == pytest.approx(1000.0)
    assert [run.name for run in full.runs] == [run.name for run in fast.runs]
    for one, other in zip(full.runs, fast.runs, strict=True):
        assert one.result is not None and other.result is not None, one.name
        shifts, ratios = [], []
        for matrix, i, j in PAPER_ENTRIES:
            name = "M" if matrix == "M" else "B"
            se = getattr(one.result, f"std_errors_{name}")[i, j]
            shifts.append(abs(getattr(other.result, name)[i, j]
                              - getattr(one.result, name)[i, j]) / se)
            ratios.append(getattr(other.result, f"std_errors_{name}")[i, j] / se)
        assert max(shifts) <= 0.3, f"{one.name}: shifted {max(shifts):.3f} SE"
        assert abs(np.median(ratios) - 1.0) <= 0.1, f"{one.name}: SE ratio {np.median(ratios)}"


def test_identify_average_says_so_and_records_it(tmp_path, paper):
    """``identify --average`` on a 2 kHz log of the linear model (1 Hz sines): one line with the
    rates, ``diagnostics.averaging`` in result.json, the same matrices; without the flag neither."""
    import json

    from typer.testing import CliRunner

    from linear_model_data import make_experiment, random_matrices
    from stewartid.cli import app
    from stewartid.datasets.dataset import write_dataset

    M, B = random_matrices(np.random.default_rng(11))
    paths = [str(write_dataset(make_experiment(paper, M, B, k, sample_rate=2000.0),
                               tmp_path / f"exp{k + 1}.parquet")) for k in range(6)]
    documents = {}
    for flags in ([], ["--average"]):
        out = tmp_path / f"result{len(flags)}.json"
        done = CliRunner().invoke(app, ["identify", "--method", "fourier", "--platform", "paper",
                                        "--out", str(out), *flags, *paths])
        assert done.exit_code == 0, done.output
        said = [line for line in done.output.splitlines() if line.startswith("averaged")]
        documents[bool(flags)] = json.loads(out.read_text())
        assert said == ([] if not flags else [
            "averaged 2 samples into one: 2000 Hz -> 1000 Hz, 1000 samples per period of the "
            "fastest excitation"])
    assert "averaging" not in documents[False]["diagnostics"]
    entry = documents[True]["diagnostics"]["averaging"]
    assert entry["averaged_samples"] == 2 and entry["rate_hz"] == pytest.approx(1000.0)
    for name in ("M", "B"):
        np.testing.assert_allclose(documents[True][name], documents[False][name],
                                   atol=1e-3 * np.abs(documents[False][name]).max())
