"""Refusals of what the methods cannot do: Method A on motion that is not one sine, an
experiment given twice, a DOF left unexcited; each one line and exit code 2 from the CLI."""

from __future__ import annotations

import shutil

import numpy as np
import pytest
from typer.testing import CliRunner

from linear_model_data import AMPLITUDES, make_experiment, random_matrices
from stewartid.cli import app
from stewartid.datasets.dataset import Dataset, read_datasets, write_dataset
from stewartid.datasets.excitation import (
    MIN_RELATIVE_EXCITATION,
    check_excitation,
    dof_scales,
    excitation_per_dof,
    spectral_lines,
)
from stewartid.datasets.set_checks import check_experiment_set
from stewartid.errors import DataError, IdentificationError
from stewartid.identification.fourier import FourierIdentifier
from stewartid.model.kinematics import leg_lengths

#: Mt, Bt of the model data (symmetric positive definite, realistic magnitudes).
TRUTH = random_matrices(np.random.default_rng(3))


def _one_line(result) -> str:
    assert result.exit_code == 2, result.output
    lines = result.output.strip().splitlines()
    assert len(lines) == 1, result.output
    return lines[0]


# -- spectral lines against analytic sines -----------------------------------------------------

def test_spectral_lines_find_the_sines_and_their_amplitude_ratios():
    fs, duration = 200.0, 20.0
    t = np.arange(int(fs * duration)) / fs
    x = (1.0 * np.sin(2 * np.pi * 0.3 * t) + 0.5 * np.sin(2 * np.pi * 0.7 * t + 1.0)
         + 0.25 * np.sin(2 * np.pi * 1.5 * t + 2.0) + 0.03 * t)   # and a drift
    lines = spectral_lines(np.column_stack([x, 0.2 * x]), fs)
    # a parabola through the log amplitudes of a Hann peak on a 4x padded grid is off by a
    # few thousandths of a bin and 0.3 % in amplitude; the other lines' tails, 4 bins or more
    # away, add under 0.3 % (Hann sidelobes fall 18 dB an octave from -31.5 dB at 2.4 bins)
    assert lines.frequencies_hz == pytest.approx([0.3, 0.7, 1.5], abs=lines.resolution_hz / 20)
    assert lines.amplitudes == pytest.approx([1.0, 0.5, 0.25], rel=0.01)
    assert lines.describe() == "0.30, 0.70, 1.50 Hz"  # 2 decimals: 0.05 Hz resolution


def test_a_pure_sine_is_one_line_whatever_its_phase_to_the_bins():
    fs = 100.0
    t = np.arange(1234) / fs
    for frequency in (0.5, 0.537, 1.91):
        lines = spectral_lines(np.sin(2 * np.pi * frequency * t), fs)
        assert len(lines) == 1
        assert lines.frequencies_hz[0] == pytest.approx(frequency, abs=lines.resolution_hz / 20)
    assert len(spectral_lines(np.zeros((500, 3)), fs)) == 0


# -- Method A ----------------------------------------------------------------------------------

def test_method_a_refuses_several_sines_per_experiment(paper):
    M, B = TRUTH
    # each DOF driven by three sines, as a user's multi-sine test would
    data = [make_experiment(paper, M, B, k, periods=8, extra=[
        (k, 0.5 * AMPLITUDES[k], 2 * np.pi * 2.3, 1.0),
        (k, 0.25 * AMPLITUDES[k], 2 * np.pi * 3.7, 2.0)]) for k in range(6)]
    with pytest.raises(IdentificationError, match=r"^exp1: Method A needs one sine per "
                       r"experiment; the pose of exp1 has 3 spectral lines above 5 % of the "
                       r"largest \(1.0, 2.3, 3.7 Hz\); use Method B or least squares"):
        FourierIdentifier().fit(data, paper)


def test_method_b_refuses_a_record_shorter_than_its_window(paper):
    """A tenth of a period of a 1 Hz sine: the frequency found sets a differentiation window
    longer than the record."""
    from stewartid.identification.wavelet import WaveletIdentifier

    M, B = TRUTH
    data = [make_experiment(paper, M, B, k, periods=0.1) for k in range(6)]
    with pytest.raises(IdentificationError, match=r"^exp1: the record lasts 0.095 s, shorter "
                       r"than the differentiation window .*record a longer experiment"):
        WaveletIdentifier().fit(data, paper)


def test_method_b_validates_pieces_holding_one_period_of_the_slowest_line(paper):
    """10 s records of 0.3, 0.7 and 1.5 Hz lines cut in three folds: the last piece holds one
    period of the 0.3 Hz line, alone a drift whose frequency found tends to zero (a window of
    hours, the fold refused); a piece takes its record's. A record shorter than its window is
    still refused (the test above)."""
    from stewartid.identification.wavelet import WaveletIdentifier
    from stewartid.signals.differentiation import estimate_frequency
    from stewartid.validation.heldout import cross_validate, time_piece

    M, B = TRUTH
    data = [make_experiment(paper, M, B, k, frequency_hz=0.3, periods=3, sample_rate=100.0,
                            extra=[(k, 0.5 * AMPLITUDES[k], 2 * np.pi * 0.7, 1.0),
                                   (k, 0.25 * AMPLITUDES[k], 2 * np.pi * 1.5, 2.0)])
            for k in range(6)]
    last = time_piece(data[0], 2 * len(data[0]) // 3, len(data[0]))
    # the other lines pull the whole record's estimate by under 1 %
    assert estimate_frequency(last.pose, last.sample_rate) == pytest.approx(0.3, rel=1e-2)
    validation = cross_validate(WaveletIdentifier, data, paper, folds=3)
    assert len(validation.fold_results) == 3


def test_method_a_refuses_all_dofs_moving_at_once(paper):
    M, B = TRUTH
    frequencies = [1.0, 1.5, 2.0, 2.5, 3.0, 3.5]
    data = [make_experiment(paper, M, B, k, periods=8, extra=[
        (d, 0.7 * AMPLITUDES[d], 2 * np.pi * frequencies[(d + k) % 6], 0.5 * d)
        for d in range(6) if d != k], name=f"run{k + 1}") for k in range(6)]
    with pytest.raises(IdentificationError, match=r"^run1: .* has 6 spectral lines .*"
                                                  r"\(1.0, 1.5, 2.0, 2.5, 3.0, 3.5 Hz\)"):
        FourierIdentifier().fit(data, paper)


def test_method_a_accepts_a_sine_with_a_small_harmonic_distortion(paper):
    """A 3rd harmonic of 10 % (a servo's distortion) is orthogonal to the first harmonic
    over whole periods: accepted, and the linear model is still recovered exactly."""
    M, B = TRUTH
    data = [make_experiment(paper, M, B, k, periods=8, extra=[
        (k, 0.1 * AMPLITUDES[k], 2 * np.pi * 3.0, 0.4)]) for k in range(6)]
    estimator = FourierIdentifier().fit(data, paper)
    # noise-free model data: what remains is the Savitzky-Golay gain correction's and the
    # frequency refinement's round-off, far below 1e-5 of the largest entry
    assert estimator.M_ == pytest.approx(M, abs=1e-5 * np.abs(M).max())


@pytest.fixture(scope="module")
def paper_sines_on_the_plant(paper):
    """The paper's sines at 1 Hz played once on the plant (6 s, 5 N m of Coulomb friction)."""
    from stewartid.simulation import simulate_experiments

    return simulate_experiments(paper, coulomb=5.0, duration_s=6.0, frequency_hz=1.0,
                                fade_in=1.0, jobs=1)


@pytest.mark.slow
@pytest.mark.parametrize("noise", [False, True])
def test_method_a_accepts_the_paper_sines_on_the_plant(paper, paper_sines_on_the_plant, noise):
    from stewartid.design.prediction import measured_plant_datasets
    from stewartid.simulation.experiments import noise_generator
    from stewartid.simulation.sensors import reference_noise

    run = paper_sines_on_the_plant
    # the paper's [sensors] declare no noise: the noisy case draws the reference noise on the
    # same true signals, as simulate does (test_design.py checks the draw against simulate)
    datasets = (measured_plant_datasets(paper, run.states, reference_noise(paper),
                                        [noise_generator(0, k) for k in range(6)])
                if noise else run.datasets)
    estimator = FourierIdentifier().fit(datasets, paper)
    assert [f[0] for f in estimator.frequencies_] == pytest.approx([1.0] * 6, rel=0.01)


# -- the same experiment twice -----------------------------------------------------------------

@pytest.fixture(scope="module")
def files(tmp_path_factory, paper):
    folder = tmp_path_factory.mktemp("refusals")
    M, B = TRUTH
    return [write_dataset(make_experiment(paper, M, B, k), folder / f"exp{k + 1}.csv")
            for k in range(6)]


def test_the_same_file_twice_is_refused(files):
    names = list(map(str, files))
    line = _one_line(CliRunner().invoke(app, ["identify", "--method", "ls", "--platform",
                                              "paper", names[0], *names[:5]]))
    assert line.startswith(f"error: {names[0]} is given twice: each experiment must be given "
                           "once")


def test_the_same_file_under_two_spellings_is_refused(files):
    names = list(map(str, files))
    other = str(files[0].parent / ".." / files[0].parent.name / files[0].name)
    line = _one_line(CliRunner().invoke(app, ["identify", "--method", "ls", "--platform",
                                              "paper", other, *names[:5]]))
    assert f"{other} and {names[0]} are the same file ({files[0].resolve()})" in line


def test_a_copy_of_an_experiment_is_refused(files, tmp_path):
    copy = tmp_path / "copy.csv"
    shutil.copy(files[2], copy)
    names = list(map(str, files))
    line = _one_line(CliRunner().invoke(app, ["identify", "--method", "fourier", "--platform",
                                              "paper", *names[:5], str(copy)]))
    assert f"{names[2]} and {copy} hold the same experiment (identical pose and forces)" in line


def test_the_set_check_sees_repeated_datasets_by_content(paper):
    M, B = TRUTH
    data = [make_experiment(paper, M, B, k) for k in range(6)]
    renamed = Dataset(t=data[0].t + 5.0, pose=data[0].pose, lengths=data[0].lengths,
                      forces=data[0].forces, name="again")
    with pytest.raises(DataError, match="exp1 and again hold the same experiment"):
        check_experiment_set([*data[:5], renamed], paper)


# -- a DOF left unexcited ----------------------------------------------------------------------

def _multisine(platform, amplitudes, frequencies, periods=40, sample_rate=100.0):
    """One experiment, DOF k a sine of amplitudes[k] at frequencies[k] (Hz), whole periods of
    the slowest; forces do not enter the excitation check."""
    t = np.arange(int(round(periods * sample_rate / min(frequencies)))) / sample_rate
    pose = platform.neutral_pose + np.sin(2 * np.pi * np.outer(t, frequencies)) * amplitudes
    return Dataset(t=t, pose=pose, lengths=leg_lengths(platform, pose),
                   forces=np.zeros_like(pose), name="multisine")


def test_excitation_measure_of_orthogonal_sines_is_their_relative_scale(paper):
    """Sines of different frequencies over whole periods are orthogonal, so each DOF's
    velocity and acceleration are entirely its own: the measure is the smaller of
    s_k a_k w_k / max_j s_j a_j w_j and s_k a_k w_k^2 / max_j s_j a_j w_j^2."""
    amplitudes = np.array([0.01, 0.004, 0.008, 0.002, 0.003, 0.001])
    frequencies = np.array([0.5, 0.7, 0.9, 1.1, 1.3, 1.5])
    measure = excitation_per_dof([_multisine(paper, amplitudes, frequencies)], paper)
    w = 2 * np.pi * frequencies
    velocity = dof_scales(paper) * amplitudes * w
    acceleration = velocity * w
    expected = np.minimum(velocity / velocity.max(), acceleration / acceleration.max())
    # the Savitzky-Golay gains differ from 1 by under 0.3 % at these frequencies, and the
    # ends trimmed by the differentiator leave partial periods: 2 % covers both
    assert measure == pytest.approx(expected, rel=0.02)


def test_a_dof_moved_only_by_coupling_is_named(paper):
    """rz follows x at 1e-4 of its scale with a phase shift: a combination of x's velocity
    and acceleration, so its own share is round-off, and the check names rz and the fix."""
    amplitudes = np.array([0.01, 0.01, 0.01, 0.005, 0.005, 0.0])
    frequencies = np.array([0.5, 0.7, 0.9, 1.1, 1.3, 1.5])
    data = _multisine(paper, amplitudes, frequencies)
    pose = data.pose.copy()
    t = data.t
    pose[:, 5] += 1e-6 * np.sin(2 * np.pi * 0.5 * t + 0.7)
    coupled = Dataset(t=t, pose=pose, lengths=leg_lengths(paper, pose), forces=data.forces)
    assert excitation_per_dof([coupled], paper)[5] < 1e-6
    with pytest.raises(DataError, match=r"^no experiment moves rz enough to identify its "
                       r"column of Mt and Bt \(largest rz motion 0.001 mrad; .* below 1 %\); "
                       r"add an experiment exciting rz, e.g. from `stewartid design`\.$"):
        check_excitation([coupled], paper)


def test_one_experiment_moving_every_dof_is_enough(paper):
    amplitudes = np.array([0.01, 0.01, 0.01, 0.005, 0.005, 0.005])
    data = _multisine(paper, amplitudes, np.array([0.3, 0.45, 0.6, 0.75, 0.9, 1.05]))
    # x at 0.3 Hz has (0.3 / 1.05)^2 of the acceleration of the fastest DOF: about 6 %
    assert excitation_per_dof([data], paper).min() > 5 * MIN_RELATIVE_EXCITATION
    check_experiment_set([data], paper)


def test_independent_example_passes_and_a_forgotten_experiment_is_named(example_dir,
                                                                        example_platform):
    """The independent simulator's six single-DOF experiments pass; without exp6 only the
    other experiments' coupling moves rz."""
    data = read_datasets(sorted(example_dir.glob("exp*.csv")), example_platform)
    measure = excitation_per_dof(data, example_platform)
    assert measure.min() > 50 * MIN_RELATIVE_EXCITATION
    assert excitation_per_dof(data[:5], example_platform)[5] < 0.01 * MIN_RELATIVE_EXCITATION
    with pytest.raises(DataError, match="no experiment moves rz enough"):
        check_experiment_set(data[:5], example_platform)


def test_cli_names_the_unexcited_dof(files):
    line = _one_line(CliRunner().invoke(app, ["identify", "--method", "wavelet", "--platform",
                                              "paper", *map(str, files[:5])]))
    assert line.startswith("error: no experiment moves rz enough to identify its column of Mt "
                           "and Bt (rz never moves)")
