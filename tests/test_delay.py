"""The force-channel delay: exact alignment, estimation against injected delays, the refusal
on single-frequency data, and ``identify --delay``.

The data are the paper platform's nominal linear model along analytic multi-sines: the pose is
logged at t_k, the forces at t_k - tau (the model evaluated at the earlier instant, pose and
Jacobian included), so the injected delay is exact and independent of the alignment code.
"""

from __future__ import annotations

import json
import re

import numpy as np
import pytest
from typer.testing import CliRunner

from stewartid.cli import app
from stewartid.datasets.alignment import align_forces, shift_forces
from stewartid.datasets.dataset import Dataset, write_dataset
from stewartid.datasets.excitation import excitation_lines
from stewartid.errors import ConfigError, IdentificationError
from stewartid.identification.delay import MODEL_FLOOR_S, apply_delay, estimate_delay
from stewartid.identification.least_squares import LeastSquaresIdentifier
from stewartid.model.dynamics import ModelTerms
from stewartid.model.kinematics import leg_lengths
from stewartid.model.linearization import nominal_matrices
from stewartid.simulation import (
    DEFAULT_AMPLITUDES,
    SensorNoise,
    Sine,
    multisine_excitation,
    simulate_experiment,
)

AMPLITUDES = np.array([0.01, 0.01, 0.01, 0.005, 0.005, 0.005])
RATE = 500.0
DURATION = 8.0
#: Each DOF's excitation: (relative amplitude, Hz, phase).
MULTISINE = ((1.0, 0.5, 0.0), (0.5, 1.1, 1.0), (0.25, 2.3, 2.0))


def model_experiment(platform, M, B, dof, sines, delay=0.0, noise=0.0, seed=0):
    """Experiment driving ``dof`` with ``sines``; forces logged ``delay`` s late, white noise of
    ``noise`` N added to them."""
    t = np.arange(int(DURATION * RATE)) / RATE

    def state(times):
        q = np.tile(platform.neutral_pose, (len(times), 1))
        qd, qdd = np.zeros_like(q), np.zeros_like(q)
        for relative, frequency, phase in sines:
            a, w = relative * AMPLITUDES[dof], 2 * np.pi * frequency
            q[:, dof] += a * np.sin(w * times + phase)
            qd[:, dof] += a * w * np.cos(w * times + phase)
            qdd[:, dof] -= a * w ** 2 * np.sin(w * times + phase)
        return q, qd, qdd

    q = state(t)[0]
    q_late, qd_late, qdd_late = state(t - delay)
    terms = ModelTerms(platform, q_late)
    y = qdd_late @ M.T + qd_late @ B.T + 50.0
    forces = np.linalg.solve(np.transpose(terms.leg_jacobian, (0, 2, 1)),
                             (y + terms.gravity)[..., None])[..., 0]
    forces = forces + noise * np.random.default_rng(seed).standard_normal(forces.shape)
    return Dataset(t=t, pose=q, lengths=leg_lengths(platform, q), forces=forces,
                   name=f"exp{dof + 1}")


def experiments(platform, sines=MULTISINE, delay=0.0, noise=0.0):
    M, B = nominal_matrices(platform)
    return [model_experiment(platform, M, B, k, sines, delay, noise, seed=k) for k in range(6)]


# --- alignment ---------------------------------------------------------------------------

def test_whole_sample_shift_returns_the_logged_samples(paper):
    data = experiments(paper, delay=0.0)[0]
    shifted = shift_forces(data, 3 / RATE)
    assert len(shifted) == len(data) - 3
    assert np.array_equal(shifted.forces, data.forces[3:])
    assert np.array_equal(shifted.pose, data.pose[:-3])


def test_fractional_shift_recovers_the_undelayed_forces(paper):
    # the cubic spline's error on a 2.3 Hz sine at 500 Hz is (2 pi 2.3 / 500)^4 / 384 ~ 2e-9
    # of its amplitude; the forces' dynamic part is ~1e3 N, the static ~3e4 N
    late = experiments(paper, delay=1.3e-3)[2]
    on_time = experiments(paper, delay=0.0)[2]
    aligned = shift_forces(late, 1.3e-3)
    assert len(aligned) == len(late) - 1  # t + 1.3 ms falls beyond the last sample once
    assert np.abs(aligned.forces - on_time.forces[:-1]).max() < 1e-4
    early = shift_forces(late, -1.3e-3)
    assert early.t[0] == late.t[1] and len(early) == len(late) - 1


def test_a_delay_longer_than_the_record_is_refused(paper):
    with pytest.raises(ConfigError, match="leaves .* samples .* in seconds"):
        align_forces(experiments(paper)[:1], 7.99)


def test_a_given_delay_of_a_quarter_period_of_the_dominant_line_is_refused(paper):
    """Milliseconds written as seconds: MULTISINE's dominant line is its largest, 0.5 Hz (the
    estimate within 1 %: the other lines lean its sine fit), a quarter of its period 0.5 s; a
    delay under it is applied, beyond it refused."""
    data = experiments(paper)
    aligned, entry = apply_delay(data, paper, 0.45)
    assert entry["seconds"] == 0.45 and len(aligned[0]) == len(data[0]) - int(0.45 * RATE)
    for seconds in (0.55, 2.0, -2.0):
        with pytest.raises(ConfigError, match=r"of the period of the motion's dominant line "
                                              r"\(0\.49\d Hz, 2\.0\d s\).* under 0\.50\d s here"):
            apply_delay(data, paper, seconds)


# --- estimation ----------------------------------------------------------------------------

def test_every_dof_shows_its_three_lines(paper):
    lines = excitation_lines(experiments(paper))
    for found in lines:  # resolution of the Hann-windowed 8 s record: 0.125 Hz
        assert np.allclose(found, [f for _, f, _ in MULTISINE], atol=0.07)


@pytest.mark.parametrize("delay", [0.5e-3, 1e-3, 2e-3, 3e-3])
def test_injected_delay_is_recovered_on_noise_free_data(paper, delay):
    # noise-free: the error left is that of the first-order expansion after one alignment,
    # of order (tau - tau_1)^2 w with tau - tau_1 ~ tau^2 w / 2 < 0.1 ms, and the 0.02 %
    # geometric stiffness term tau K q_dot, both far below 1 microsecond
    estimate = estimate_delay(experiments(paper, delay=delay), paper)
    assert estimate.seconds == pytest.approx(delay, abs=1e-6)
    assert estimate.own_std_error < 1e-6
    # the reported one is at least the model's floor
    assert estimate.std_error == pytest.approx(np.hypot(estimate.own_std_error, MODEL_FLOOR_S))


def test_the_estimate_is_the_same_on_worker_processes(paper):
    """The experiments filtered side by side (fork) give the one-process estimate to the bit."""
    data = experiments(paper, delay=2e-3, noise=20.0)
    alone, side = (estimate_delay(data, paper, jobs=jobs) for jobs in (1, 2))
    assert (side.seconds, side.std_error) == (alone.seconds, alone.std_error)


def test_aligned_record_takes_the_motions_terms_of_the_logged_one(paper):
    """Shifted forces keep the motion's samples: the pose's model terms, taken from the logged
    record's rows, equal those of a record built afresh from the aligned samples."""
    from stewartid.identification.preparation import prepare_experiment

    logged = experiments(paper, delay=2e-3)[0]
    whole = prepare_experiment(logged, paper)
    aligned = shift_forces(logged, 2.5e-3)
    shared = prepare_experiment(aligned, paper)
    fresh = prepare_experiment(Dataset(t=aligned.t, pose=np.array(aligned.pose),
                                       lengths=aligned.lengths, forces=aligned.forces), paper)
    assert len(whole.leg_jacobian) > len(aligned)
    # the same formulas on the same samples: at most a few ulps apart (vector code paths differ
    # between CPUs), where a wrong row would be off by 1e-4 or more; the forces are 1e3-1e5 N
    np.testing.assert_allclose(shared.leg_jacobian, fresh.leg_jacobian, rtol=1e-13, atol=1e-14)
    np.testing.assert_allclose(shared.generalized_force, fresh.generalized_force, rtol=1e-13,
                               atol=1e-9)


def test_noisy_estimate_is_within_its_standard_errors(paper):
    # 20 N of white noise per leg force (about the reference noise's share of the dynamics)
    estimate = estimate_delay(experiments(paper, delay=2e-3, noise=20.0), paper)
    assert abs(estimate.seconds - 2e-3) < 4 * estimate.std_error
    assert estimate.std_error < 1e-4


@pytest.mark.slow
def test_single_sine_is_refused_with_the_bias_a_delay_puts_on_bt(paper):
    single = ((1.0, 0.5, 0.0),)
    with pytest.raises(IdentificationError, match="one frequency only") as refused:
        estimate_delay(experiments(paper, sines=single, delay=1e-3), paper)
    stated = float(re.search(r"Bt\(1,1\) ([-+0-9.e]+)", str(refused.value)).group(1))
    # the bias itself, measured: least squares on the same motion with forces 1 ms late
    fitted = [LeastSquaresIdentifier(coulomb=False).fit(experiments(paper, sines=single,
                                                                    delay=delay), paper)
              for delay in (0.0, 1e-3)]
    measured = fitted[1].B_[0, 0] - fitted[0].B_[0, 0]
    assert stated == pytest.approx(measured, rel=0.02)


def test_alignment_removes_the_delay_bias_from_the_matrices(paper):
    M, B = nominal_matrices(paper)
    aligned, entry = apply_delay(experiments(paper, delay=2e-3), paper, "auto")
    fitted = LeastSquaresIdentifier(coulomb=False).fit(aligned, paper)
    assert entry["source"] == "estimated" and entry["applied"]
    assert np.abs(np.diag(fitted.B_) / np.diag(B) - 1).max() < 1e-3
    assert np.abs(np.diag(fitted.M_) / np.diag(M) - 1).max() < 1e-3


def test_no_delay_is_found_in_a_nonlinear_plant_moving_every_dof_at_once(paper):
    # a 1.5 t platform of 0.8 / 1.0 m radii, ideal frictionless legs, every DOF moved at once
    # on equally spaced lines (0.3-1.05 Hz by 0.15 Hz), forces on time: the plant integrates the
    # full rigid-body dynamics, whose products of lines fall on other lines; with the model's
    # departure from its linearisation left in, the estimate was 0.05 +- 0.08 ms
    plant = paper.replace(
        geometry__upper_radius=0.8, geometry__lower_radius=1.0, geometry__neutral_height=1.1,
        geometry__upper_half_angle=0.10, geometry__lower_half_angle=0.08,
        geometry__reference_height=0.45, inertia__platform_mass=1500.0,
        inertia__platform_inertia=[520.0, 580.0, 900.0], inertia__upper_leg_mass=22.0,
        inertia__lower_leg_mass=14.0, inertia__upper_leg_com=0.4, inertia__lower_leg_com=0.35,
        friction__gimbal_viscous=1200.0, friction__coulomb=0.0, hydraulics__mode="ideal",
        hydraulics__stroke=0.5)
    hz = (0.3, 0.45, 0.6, 0.75, 0.9, 1.05)
    records = []
    for k in range(6):
        sines = [Sine(d, 0.7 * DEFAULT_AMPLITUDES[d], hz[(d + k) % 6], 0.5 * d + k)
                 for d in range(6)]
        excitation = multisine_excitation(plant, sines, name=f"exp{k + 1}")
        records.append(simulate_experiment(plant, excitation, 10.0, noise=SensorNoise())[0])
    estimate = estimate_delay(records, plant)
    # noise-free and exactly the model's dynamics: what is left is the integration's error
    assert abs(estimate.seconds) < 1e-6
    assert estimate.own_std_error < 1e-6


# --- command line --------------------------------------------------------------------------

@pytest.fixture(scope="module")
def late_files(tmp_path_factory, paper):
    folder = tmp_path_factory.mktemp("late")
    return [write_dataset(d, folder / f"{d.name}.csv")
            for d in experiments(paper, delay=1e-3)]


@pytest.mark.slow
def test_identify_applies_a_given_delay(tmp_path, late_files):
    out = tmp_path / "result.json"
    result = CliRunner().invoke(app, ["identify", "--method", "ls", "--platform", "paper",
                                      "--delay", "0.001", "--out", str(out),
                                      *map(str, late_files)])
    assert result.exit_code == 0, result.output
    assert "force delay 1.000 ms, given" in result.output
    document = json.loads(out.read_text())
    assert document["delay"] == {"seconds": 0.001, "std_error": None, "applied": True,
                                 "source": "given"}


@pytest.mark.slow
def test_identify_estimates_the_delay(tmp_path, late_files):
    out = tmp_path / "result.json"
    result = CliRunner().invoke(app, ["identify", "--method", "ls", "--platform", "paper",
                                      "--delay", "auto", "--out", str(out),
                                      *map(str, late_files)])
    assert result.exit_code == 0, result.output
    assert re.search(r"force delay 1\.00\d ms \(standard error", result.output)
    delay = json.loads(out.read_text())["delay"]
    assert delay["source"] == "estimated"
    assert delay["seconds"] == pytest.approx(1e-3, abs=1e-6)


@pytest.mark.slow
def test_identify_estimates_and_applies_the_delay_by_default(tmp_path, late_files):
    """Without the flag, a delay the motion identifies and noise cannot explain is removed."""
    out = tmp_path / "result.json"
    result = CliRunner().invoke(app, ["identify", "--method", "ls", "--platform", "paper",
                                      "--out", str(out), *map(str, late_files)])
    assert result.exit_code == 0, result.output
    delay = json.loads(out.read_text())["delay"]
    assert delay["source"] == "estimated" and delay["applied"] is True
    assert delay["seconds"] == pytest.approx(1e-3, abs=1e-6)
    assert "forces aligned" in result.output


@pytest.mark.slow
def test_identify_with_a_zero_delay_uses_the_forces_as_logged(tmp_path, late_files):
    out = tmp_path / "result.json"
    result = CliRunner().invoke(app, ["identify", "--method", "ls", "--platform", "paper",
                                      "--delay", "0", "--out", str(out), *map(str, late_files)])
    assert result.exit_code == 0, result.output
    delay = json.loads(out.read_text())["delay"]
    assert delay["source"] == "given" and delay["seconds"] == 0.0


@pytest.mark.parametrize("value, message", [("2ms", "--delay must be a number of seconds"),
                                            ("nan", "--delay must be a number of seconds"),
                                            ("2", "of the period of the motion's dominant line")])
def test_identify_refuses_a_bad_delay(tmp_path, late_files, value, message):
    out = tmp_path / "result.json"
    result = CliRunner().invoke(app, ["identify", "--method", "ls", "--platform", "paper",
                                      "--delay", value, "--out", str(out),
                                      *map(str, late_files)])
    assert result.exit_code == 2
    assert message in result.output and "Traceback" not in result.output
    assert not out.exists()


@pytest.mark.slow
def test_identify_on_single_sines_notes_the_bias_a_delay_would_put_on_bt(tmp_path, paper):
    """Without --delay on single-frequency data: one note naming the bias per millisecond,
    the bias measured by fitting the same motion with the forces 1 ms late; result.json
    carries it; with a given delay, no note."""
    single = ((1.0, 0.5, 0.0),)
    folder = tmp_path / "single"
    folder.mkdir()
    files = [write_dataset(d, folder / f"{d.name}.csv")
             for d in experiments(paper, sines=single)]
    out = tmp_path / "result.json"
    result = CliRunner().invoke(app, ["identify", "--method", "ls", "--platform", "paper",
                                      "--out", str(out), *map(str, files)])
    assert result.exit_code == 0, result.output
    (note,) = [line for line in result.output.splitlines() if line.startswith("note:")]
    stated = float(re.search(r"Bt\(4,4\) ([-+0-9.e]+)", note).group(1))
    fitted = [LeastSquaresIdentifier(coulomb=False).fit(experiments(paper, sines=single,
                                                                    delay=delay), paper)
              for delay in (0.0, 1e-3)]
    assert stated == pytest.approx(fitted[1].B_[3, 3] - fitted[0].B_[3, 3], rel=0.02)
    sensitivity = json.loads(out.read_text())["diagnostics"]["delay_sensitivity"]
    assert sensitivity["dofs"] == ["x", "y", "z", "rx", "ry", "rz"]
    given = CliRunner().invoke(app, ["identify", "--method", "ls", "--platform", "paper",
                                     "--delay", "0", *map(str, files)])
    assert given.exit_code == 0 and "note:" not in given.output
