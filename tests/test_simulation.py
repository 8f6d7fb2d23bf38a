"""Plant simulator: convergence, agreement with the dynamics model, kinematics, data files."""

from __future__ import annotations

import json

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.interpolate import CubicSpline

from roundoff import EPS, newton_pose_bound
from stewartid.datasets.dataset import read_dataset
from stewartid.errors import ConfigError
from stewartid.model.dynamics import (
    ModelTerms,
    forward_dynamics,
    friction_forces,
    gravity_forces,
    mass_matrix,
)
from stewartid.model.kinematics import leg_lengths
from stewartid.model.linearization import nominal_matrices
from stewartid.simulation import (
    SensorNoise,
    paper_experiments,
    simulate_experiment,
    simulate_experiments,
    write_experiments,
)


@pytest.fixture(scope="module")
def short_set(paper):
    """Six hydraulic experiments of 3 s, Coulomb 5 N m, ideal sensors."""
    return simulate_experiments(paper, coulomb=5.0, duration_s=3.0, fade_in=1.0)


def scaled_error(A, A0):
    """|A - A0| / sqrt(|A0_ii A0_jj|): every entry relative to the scale of its row/column."""
    d = np.sqrt(np.abs(np.diag(A0)))
    return np.abs(A - A0) / np.outer(d, d)


def test_step_halving_changes_signals_by_less_than_tolerance(paper):
    """RK4 at the default 0.5 ms step against 0.25 ms, full hydraulic loop with friction."""
    plant = paper.replace(friction__coulomb=30.0)
    excitation = paper_experiments(plant, fade_in=0.5)[3]
    _, coarse = simulate_experiment(plant, excitation, 1.5, step=5e-4)
    _, fine = simulate_experiment(plant, excitation, 1.5, step=2.5e-4)
    # stated tolerances: 1e-9 m / 1e-9 rad on the pose, 0.5 N on the leg forces. A bound on
    # RK4's discretisation error (measured 2e-11 m, h^4), not on round-off: 3000 steps add
    # about sqrt(3000) eps |q| = 5e-14 m, so the check holds on any CPU
    assert np.max(np.abs(coarse.q - fine.q)) < 1e-9
    assert np.max(np.abs(coarse.forces - fine.forces)) < 0.5
    # and the recorded lengths are far below any leg-length sensor resolution apart
    assert np.max(np.abs(coarse.lengths - fine.lengths)) < 1e-9


def test_ideal_frictionless_plant_matches_forward_dynamics(paper):
    plant = paper.replace(hydraulics__mode="ideal", friction__coulomb=0.0,
                          friction__gimbal_viscous=0.0)
    excitation = paper_experiments(plant, fade_in=0.5)[0]
    _, rec = simulate_experiment(plant, excitation, 1.0)
    # pointwise: the recorded acceleration is the model's forward dynamics
    qdd = forward_dynamics(plant, rec.q, rec.q_dot, rec.forces, friction=False)
    # both solve M qdd = J^T f - G - C at the same states; the right side cancels from gravity's
    # scale to M qdd, so round-off is ||M^-1|| eps |G| plus the solve's cond(M) eps |qdd|
    M = mass_matrix(plant, rec.q)
    inverse_norm = np.abs(np.linalg.inv(M)).sum(axis=2).max()
    bound = 64 * EPS * (inverse_norm * np.abs(gravity_forces(plant, rec.q)).max()
                        + np.linalg.cond(M).max() * np.max(np.abs(rec.q_ddot)))
    assert np.max(np.abs(qdd - rec.q_ddot)) < bound
    # integrated: the model's own ODE under the recorded forces gives the same motion
    spline = CubicSpline(rec.t, rec.forces)

    def ode(t, y):
        return np.concatenate([y[6:], forward_dynamics(plant, y[:6], y[6:], spline(t),
                                                       friction=False)])

    sol = solve_ivp(ode, (0, rec.t[-1]), np.concatenate([rec.q[0], rec.q_dot[0]]),
                    t_eval=rec.t, rtol=1e-10, atol=1e-12, method="DOP853")
    assert np.max(np.abs(sol.y[:6].T - rec.q)) < 1e-8


def test_forward_kinematics_block_recovers_true_pose(paper, short_set):
    for dataset, record in zip(short_set.datasets, short_set.states, strict=True):
        # forward kinematics stopped at a 1e-12 m leg-length residual
        assert np.max(np.abs(dataset.pose - record.q)) < newton_pose_bound(paper, record.q)


def test_leg_lengths_consistent_with_pose(paper, short_set):
    for dataset in short_set.datasets:
        # the forward kinematics' stopping residual, 1e-12 m, plus round-off of the lengths
        residual = np.max(np.abs(leg_lengths(paper, dataset.pose) - dataset.lengths))
        assert residual < 1e-12 + 8 * EPS * dataset.lengths.max()


@pytest.mark.parametrize("fmt", ["csv", "parquet"])
def test_written_files_load_back_identically(tmp_path, short_set, fmt):
    write_experiments(short_set, tmp_path, format=fmt)
    for dataset in short_set.datasets:
        back = read_dataset(tmp_path / f"{dataset.name}.{fmt}")
        for field in ("t", "pose", "lengths", "forces"):
            np.testing.assert_array_equal(getattr(back, field), getattr(dataset, field))
    meta = json.loads((tmp_path / "meta.json").read_text())
    M, B = nominal_matrices(load := __import__("stewartid").load_platform("paper"))
    np.testing.assert_allclose(meta["nominal"]["M"], M)
    assert meta["seed"] == 0 and meta["version"] and load.name == "paper"
    assert meta["platform"]["friction"]["coulomb"] == 5.0


def test_output_folder_with_results_is_refused_unless_forced(tmp_path, short_set):
    write_experiments(short_set, tmp_path)
    with pytest.raises(ConfigError, match="already holds results.*--force"):
        write_experiments(short_set, tmp_path)
    write_experiments(short_set, tmp_path, force=True)


def test_tracking_is_good_at_the_paper_excitation(short_set):
    for record in short_set.states:
        amplitude = np.sqrt(np.mean((record.command_lengths - record.command_lengths[0]) ** 2,
                                    axis=0))
        # relative to the motion of the most-moving leg (some legs barely move)
        assert np.max(record.tracking_error()) / np.max(amplitude) < 0.03


def test_noise_is_seeded_and_has_the_stated_level(paper):
    noise = SensorNoise(length_noise=1e-5, force_noise=20.0)
    excitation = paper_experiments(paper, fade_in=0.5)[2]
    a, rec = simulate_experiment(paper, excitation, 1.0, noise,
                                 np.random.default_rng(7))
    b, _ = simulate_experiment(paper, excitation, 1.0, noise, np.random.default_rng(7))
    np.testing.assert_array_equal(a.lengths, b.lengths)
    assert np.std(a.lengths - rec.lengths) == pytest.approx(1e-5, rel=0.05)
    assert np.std(a.forces - rec.forces) == pytest.approx(20.0, rel=0.05)


@pytest.mark.parametrize("kwargs, match", [
    ({"duration_s": -1.0}, "duration must be > 0"),
    ({"frequency_hz": 600.0}, "Nyquist"),
    ({"seed": -3}, "seed must be"),
])
def test_bad_settings_are_refused(paper, kwargs, match):
    with pytest.raises(ConfigError, match=match):
        simulate_experiments(paper, **kwargs)


def least_squares_fit(platform, result):
    """Plain time-domain LS of [Mt Bt c] after the fade-in, G(q) subtracted, J at the pose."""
    X, Y = [], []
    for dataset, record in zip(result.datasets, result.states, strict=True):
        keep = record.t >= 2.0
        terms = ModelTerms(platform, dataset.pose[keep])
        Y.append(np.einsum("nji,nj->ni", terms.leg_jacobian, dataset.forces[keep])
                 - terms.gravity)
        X.append(np.column_stack([record.q_ddot[keep], record.q_dot[keep],
                                  np.ones(keep.sum())]))
    theta = np.linalg.lstsq(np.vstack(X), np.vstack(Y), rcond=None)[0]
    return theta[:6].T, theta[6:12].T


@pytest.mark.slow
@pytest.mark.parametrize("actuator", ["ideal", "hydraulic"])
def test_least_squares_on_simulated_data_recovers_nominal_matrices(paper, actuator):
    """Coulomb 0, no noise: LS on the plant's data recovers the nominal Mt, Bt within 1 %.

    Measured 5e-5 (scaled) for both actuator types. The bar catches a servo loop that
    oscillates: with an unstable inner force loop the plant settles into a 64 Hz limit cycle
    in the non-excited DOFs, whose products with the pose-dependent terms cost 3 % on
    Mt(6,6) and 6 % on Bt(6,4).
    """
    result = simulate_experiments(paper, coulomb=0.0, duration_s=10.0, actuator=actuator)
    M, B = least_squares_fit(paper, result)
    M0, B0 = nominal_matrices(paper)
    assert np.max(scaled_error(M, M0)) < 0.01
    assert np.max(scaled_error(B, B0)) < 0.01


def test_recorded_force_and_acceleration_are_the_same_instant(short_set, paper):
    """M(q) q_ddot + h + G + F(q_dot) = J^T f holds sample by sample on the recorded data."""
    plant = paper.replace(friction__coulomb=5.0)
    for dataset, record in zip(short_set.datasets, short_set.states, strict=True):
        terms = ModelTerms(plant, record.q, record.q_dot)
        lhs = (np.einsum("nij,nj->ni", terms.mass_matrix, record.q_ddot)
               + terms.velocity_product + terms.gravity
               + friction_forces(plant, record.q, record.q_dot))
        rhs = np.einsum("nji,nj->ni", terms.leg_jacobian, dataset.forces)
        assert np.max(np.abs(lhs - rhs)) < 1e-6 * np.max(np.abs(rhs))


def test_unstable_servo_loop_is_refused(paper):
    plant = paper.replace(controller__force_loop_gain=2.0e-5)
    excitation = paper_experiments(plant, fade_in=0.5)[0]
    with pytest.raises(ConfigError, match=r"exp1: the leg servo loop is unstable \(a mode at "
                                          r"6\d\.\d Hz.*lower \[controller\] force_loop_gain"):
        simulate_experiment(plant, excitation, 0.5)


def test_cli_writes_files_and_refuses_bad_input(tmp_path):
    from typer.testing import CliRunner

    from stewartid.cli import app

    runner = CliRunner()
    out = tmp_path / "run"
    ok = runner.invoke(app, ["simulate", "--out", str(out), "--duration", "0.3",
                             "--coulomb", "5", "--format", "parquet"])
    assert ok.exit_code == 0, ok.output
    assert sorted(p.name for p in out.iterdir())[:2] == ["exp1.parquet", "exp2.parquet"]
    for args, match in ((["--out", str(out), "--duration", "0.3"], "already holds results"),
                        (["--out", str(tmp_path / "a"), "--duration", "-1"], "duration"),
                        (["--out", str(tmp_path / "b"), "--frequency", "900"], "Nyquist"),
                        (["--out", str(tmp_path / "c"), "--platform", "missing.toml"],
                         "not found")):
        bad = runner.invoke(app, ["simulate", *args])
        assert bad.exit_code == 2 and match in bad.output
        assert len(bad.output.strip().splitlines()) == 1


def test_cli_noise_flag_switches_on_reference_noise(tmp_path):
    """``--noise``: 20 um on the leg lengths, 0.5 % of the static leg force on the forces."""
    import json

    from typer.testing import CliRunner

    from stewartid.cli import app

    out = tmp_path / "noisy"
    result = CliRunner().invoke(app, ["simulate", "--out", str(out), "--noise",
                                      "--duration", "1.5", "--actuator", "ideal"])
    assert result.exit_code == 0, result.output
    noise = json.loads((out / "meta.json").read_text())["noise"]
    assert noise["length_noise"] == 20e-6
    # the paper platform's static leg load is ~30.5 kN (MODEL.md)
    assert noise["force_noise"] == pytest.approx(0.005 * 30_495, rel=1e-3)


def test_worker_processes_give_the_same_data(paper):
    """Experiments on two worker processes: the same data, bit for bit, as in one process."""
    serial = simulate_experiments(paper, coulomb=5.0, duration_s=0.3, fade_in=0.2)
    parallel = simulate_experiments(paper, coulomb=5.0, duration_s=0.3, fade_in=0.2, jobs=2)
    for a, b in zip(serial.datasets, parallel.datasets, strict=True):
        assert a.name == b.name
        assert np.array_equal(a.pose, b.pose) and np.array_equal(a.forces, b.forces)
    with pytest.raises(ConfigError, match="jobs must be a positive integer"):
        simulate_experiments(paper, duration_s=0.3, jobs=0)
