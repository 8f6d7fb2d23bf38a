"""The electric plant: servo motors with current loops on ball screws, against independent truth.

The current loop against its analytic first-order response (and RK4's exact amplification of it),
the logged currents against the forces the model's inverse dynamics needs and against the servo's
demand delayed by the loop, MuJoCo's electric legs against ours, the current limit, the encoders'
grid, the logs of currents and the example platform. Tolerances are derived in each test.
"""

from __future__ import annotations

import math
from importlib import resources

import numpy as np
import pytest
from typer.testing import CliRunner

from roundoff import EPS
from stewartid.cli import app
from stewartid.datasets.dataset import read_dataset
from stewartid.design.limits import resolve_limits
from stewartid.errors import ConfigError
from stewartid.model.dynamics import inverse_dynamics
from stewartid.model.linearization import nominal_matrices
from stewartid.platform import load_platform
from stewartid.simulation import (
    SimulationResult,
    Sine,
    multisine_excitation,
    plant,
    simulate_experiment,
    write_experiments,
)
from stewartid.simulation.controller import command_tables, controller_parameters
from stewartid.simulation.electric import (
    current_bandwidth,
    electric_parameters,
    step_response,
)
from stewartid.simulation.hydraulics import hydraulic_parameters
from stewartid.simulation.stability import initial_state

with resources.as_file(resources.files("stewartid") / "data/electric.toml") as _path:
    ELECTRIC_TOML = _path


@pytest.fixture(scope="module")
def electric():
    """The example electric motion platform (400 kg moving, 2 kHz logs)."""
    return load_platform(ELECTRIC_TOML)


def _excitation(platform, duration_scale=1.0):
    """Heave, surge and roll at 2-3 Hz after a 0.1 s fade-in: leg rates reverse within 0.3 s; leg
    inertial forces up to 210 N, the order of the screw friction (80 N)."""
    return multisine_excitation(platform, [Sine(2, 0.005, 2.0), Sine(0, 0.0015, 2.6),
                                           Sine(3, 0.0015, 3.0, 1.0)], fade_in=0.1,
                                name="electric_check")


@pytest.fixture(scope="module")
def run(electric):
    """0.6 s of the example platform on the plant: (measured data set, true record)."""
    return simulate_experiment(electric, _excitation(electric), 0.6)


# -- the current loop ------------------------------------------------------------------------

def test_current_loop_step_response_is_first_order(electric):
    """A current step through the compiled plant: servo gains zero, so the current command is the
    stepped feed-forward alone, whatever the platform does.

    RK4 on i' = w_c (u - i) with u constant over the step amplifies the error by exactly
    R(z) = 1 + z + z^2/2 + z^3/6 + z^4/24, z = -h w_c: the currents are i0 + du (1 - R^n) to
    round-off (a few eps of the current, summed over the n steps: 100 eps). Against the analytic
    du (1 - exp(-w_c t)) they differ by |R^n - exp(n z)| <= n |R - e^z| max(R, e^z)^(n - 1),
    < 4e-5 du here (h w_c = 0.31, |R - e^z| about z^5 / 120 = 2.5e-5).
    """
    fs = 20000.0
    platform = electric.replace(sensors__sample_rate=fs)
    params = platform.parameters()
    upper = np.ascontiguousarray(platform.upper_joints)
    base = np.ascontiguousarray(platform.base_joints)
    n_out = 101  # 5 ms, five time constants
    q0 = np.tile(platform.neutral_pose, (2 * (n_out - 1) + 1, 1))
    lengths, rates, forces = command_tables(params, upper, base, q0, np.zeros_like(q0), True)
    hp = hydraulic_parameters(platform.hydraulics, platform.neutral_leg_length)
    ep = electric_parameters(platform.actuator)
    cp = controller_parameters(platform)
    y0 = initial_state(platform, q0[0], forces[0], hp, cp)
    cp[:3] = 0.0  # K_p, K_i, K_d: the demand is the feed-forward
    kt = platform.actuator.force_constant
    step = np.array([2.0, -1.0, 0.5, 3.0, -2.5, 1.0])  # A
    stepped = forces + kt * step
    h = 1.0 / fs
    status, _, _, states, *_ = plant.integrate(
        y0, h, 1, n_out, lengths, rates, stepped, params, upper, base, hp, cp, ep,
        plant.DRIVE_ELECTRIC, 1e-4)
    assert status == plant.STATUS_OK
    currents = states[:, plant.S_I:plant.S_I + 6] - y0[plant.S_I:plant.S_I + 6]
    w = 2 * math.pi * current_bandwidth(platform.actuator)
    z = -h * w
    R = 1 + z + z ** 2 / 2 + z ** 3 / 6 + z ** 4 / 24
    n = np.arange(n_out)[:, None]
    exact_rk4 = step * (1 - R ** n)
    scale = np.abs(states[:, plant.S_I:plant.S_I + 6]).max()
    np.testing.assert_allclose(currents, exact_rk4, rtol=0, atol=100 * EPS * scale)
    analytic = step_response(n * h, 1.0, current_bandwidth(platform.actuator)) * step
    bound = (n * abs(R - math.exp(z)) * max(R, math.exp(z)) ** np.maximum(n - 1, 0)).max()
    assert bound < 4e-5
    assert np.abs(currents - analytic).max() < bound * np.abs(step).max() + 100 * EPS * scale


# -- the currents along a motion ------------------------------------------------------------

def test_logged_currents_are_the_forces_the_model_needs(electric, run, tmp_path):
    """Logged currents (i1..i6 in the CSV) times force_constant are the forces the model's inverse
    dynamics needs along the simulated motion: reflected masses and screw friction included.

    The plant's force is force_constant times its current state, which moves the platform: along
    the motion the inverse dynamics returns it, to the round-off of the log's i = f / kt and
    f = kt i (2 eps) and of two 6x6 solves of cond(M J^-T) (1e3 eps of the largest force). The
    current loop's lag is between the demand and the current (next test), not here. The same
    motion without the reflected masses needs forces that differ by far more.
    """
    dataset, record = run
    kt = electric.actuator.force_constant
    result = SimulationResult([dataset], {}, [record], kt)
    write_experiments(result, tmp_path)
    header = (tmp_path / f"{dataset.name}.csv").read_text().splitlines()[0]
    assert header.endswith('"i1","i2","i3","i4","i5","i6"')
    logged = read_dataset(tmp_path / f"{dataset.name}.csv", electric)
    np.testing.assert_allclose(logged.forces, dataset.forces, rtol=2 * EPS)
    needed = inverse_dynamics(electric, record.q, record.q_dot, record.q_ddot)
    np.testing.assert_allclose(logged.forces, needed, rtol=0, atol=1e3 * EPS * np.abs(needed).max())
    np.testing.assert_allclose(record.currents * kt, record.forces, rtol=EPS)
    bare = inverse_dynamics(electric.replace(actuator__reflected_mass=0.0), record.q,
                            record.q_dot, record.q_ddot)
    assert np.abs(bare - needed).max() > 1e6 * 1e3 * EPS * np.abs(needed).max()


def test_currents_follow_the_demand_within_the_loops_lag(electric, run):
    """|kt i - f_d| <= sup |f_d'| / w_c: the error e = kt i - f_d of a first-order loop obeys
    e' = -w_c e - f_d', from e = 0 at the equilibrium start. sup |f_d'| is estimated from the
    sampled demand's differences, which average it over a period: the bound is taken 1.5 times.
    The lag is visible: above a tenth of the bound.
    """
    _, record = run
    w = 2 * math.pi * current_bandwidth(electric.actuator)
    rate = np.abs(np.diff(record.demands, axis=0)).max() / np.diff(record.t)[0]
    lag = np.abs(record.forces - record.demands).max()
    assert lag <= 1.5 * rate / w
    assert lag > 0.1 * rate / w


# -- MuJoCo ----------------------------------------------------------------------------------

def test_plant_and_mujoco_agree_on_electric_legs(electric):
    """The same motors, servo and command on both engines, screw friction 80 N along each leg.

    Away from a reversal of a leg's rate the two friction laws give Fc sign(l') alike; around one
    our law passes through Fc l' / sqrt(l'^2 + s^2) (s = 1e-4 m/s) while MuJoCo's friction row
    sticks: the forces differ by up to 2 Fc = 160 N for the time the rate stays within the
    smoothing, 2 s / |l''| < 1 ms at these accelerations (> 0.2 m/s^2). On a leg mass of
    m >= m_r = 30 kg, that impulse moves the leg by at most 2 Fc t^2 / (2 m) = 2.7e-6 m per
    reversal before the servo acts; the record has two or three per leg: 1e-5 m (and rad over
    the joint radius, 0.6 m: 2e-5 rad). The currents then differ by the servo's reaction to
    that error, K_p 1e-5 m + K_d 2 Fc t / m = 10 N + 80 N, and by the friction difference itself
    while it lasts, 2 Fc: 0.44 A in all. Measured: 2.2e-6 m, 1.9e-6 rad, 4.2 N (7 mA).
    """
    pytest.importorskip("mujoco")
    from stewartid.mujoco.closed_loop import simulate_mujoco

    excitation = _excitation(electric)
    ours, record = simulate_experiment(electric, excitation, 0.3)
    theirs = simulate_mujoco(electric, excitation, 0.3)
    assert np.array_equal(theirs.t, record.t)
    err = np.abs(theirs.pose - record.q)
    assert err[:, :3].max() < 1e-5
    assert err[:, 3:].max() < 2e-5
    kt = electric.actuator.force_constant
    assert np.abs(theirs.forces - record.forces).max() / kt < 2 * 80.0 / kt + 90.0 / kt
    # a real motion and real currents to reproduce
    assert np.abs(record.q - electric.neutral_pose)[:, 2].max() > 2e-3
    assert np.ptp(record.currents, axis=0).min() > 0.1


@pytest.mark.slow
def test_plant_and_mujoco_agree_without_screw_friction_to_integration_error(electric):
    """Without Coulomb friction along the legs only the engines' numerics differ: MuJoCo's welds
    (time constant 2h) and both RK4s at h = 71 us; measured 6e-10 m, 3e-9 rad, 0.005 N.
    Tolerances 5e-7 (m and rad, as for the hydraulic legs) and 1 N (the servo's K_p times the
    pose tolerance, 0.5 N, doubled).
    """
    pytest.importorskip("mujoco")
    from stewartid.mujoco.closed_loop import simulate_mujoco

    platform = electric.replace(actuator__coulomb=0.0)
    excitation = _excitation(platform)
    _, record = simulate_experiment(platform, excitation, 0.6)
    theirs = simulate_mujoco(platform, excitation, 0.6)
    err = np.abs(theirs.pose - record.q)
    assert err[:, :3].max() < 5e-7 and err[:, 3:].max() < 5e-7
    assert np.abs(theirs.forces - record.forces).max() < 1.0


# -- limits and sensors ----------------------------------------------------------------------

def test_current_limit_is_respected_and_reached(electric):
    """With a peak current of 1.9 A (holding needs 1.66 A) the demand saturates: the command is
    clamped and a first-order loop never overshoots a bounded command; RK4's amplification
    R(z) in (0, 1) keeps that to the round-off of the clamp's f_max / kt (2 eps)."""
    platform = electric.replace(actuator__peak_current=1.9)
    dataset, record = simulate_experiment(platform, _excitation(platform), 0.4)
    assert np.abs(record.currents).max() <= 1.9 * (1 + 4 * EPS)
    assert np.abs(record.currents).max() > 0.999 * 1.9
    with pytest.raises(ConfigError, match=r"cannot hold the platform at rest: a leg needs 1\.6\d* "
                                          r"A, above \[actuator\] peak_current = 1\.5 A; raise"):
        simulate_experiment(electric.replace(actuator__peak_current=1.5),
                            _excitation(electric), 0.1)


def test_encoders_give_lengths_on_their_grid(electric, run, tmp_path):
    """Logged lengths are whole counts of 1 um (to the representation of k 1e-6, 1e-10 of a
    count for metre lengths); an ideal encoder (0) leaves them off the grid."""
    dataset, record = run
    counts = dataset.lengths / 1e-6
    assert np.abs(counts - np.round(counts)).max() < 1e-6
    assert np.abs(dataset.lengths - record.lengths).max() <= 0.5e-6 * (1 + 1e-9)
    ideal = electric.replace(actuator__encoder_resolution=0.0)
    clean, _ = simulate_experiment(ideal, _excitation(ideal), 0.05)
    assert np.abs(clean.lengths / 1e-6 - np.round(clean.lengths / 1e-6)).max() > 0.1


# -- the command line and the example platform -----------------------------------------------

def test_simulate_logs_currents_and_its_noise_is_half_a_percent_of_each_rms(tmp_path):
    """``simulate`` on the electric platform logs t, pose, l1..l6, i1..i6; ``--noise`` scatters each
    current by 0.5 % of its RMS: within 3 standard errors 1 / sqrt(2 n) of a standard deviation
    from n = 501 samples per channel (9.5 %), and no length noise beyond the encoder."""
    runs = {}
    for name, extra in (("clean", []), ("noisy", ["--noise", "--seed", "2"])):
        out = tmp_path / name
        result = CliRunner().invoke(app, ["simulate", "--platform", str(ELECTRIC_TOML),
                                          "--duration", "0.25", "--jobs", "1", "--frequency",
                                          "2", "--out", str(out), *extra])
        assert result.exit_code == 0, result.output
        assert "currents i1..i6" in result.output
        runs[name] = read_dataset(out / "exp3.csv", load_platform(ELECTRIC_TOML))
    clean, noisy = runs["clean"], runs["noisy"]
    np.testing.assert_array_equal(clean.lengths, noisy.lengths)
    rms = np.sqrt(np.mean(clean.forces ** 2, axis=0))
    scatter = np.std(noisy.forces - clean.forces, axis=0)
    np.testing.assert_allclose(scatter / rms, 0.005, rtol=3 / math.sqrt(2 * 501))


def test_simulate_refuses_electric_for_hydraulic_legs(tmp_path):
    result = CliRunner().invoke(app, ["simulate", "--actuator", "electric", "--out",
                                      str(tmp_path / "out")])
    assert result.exit_code == 2
    assert "--actuator electric: platform 'paper' has hydraulic legs" in result.stderr
    assert 'give the platform an [actuator] with kind = "electric"' in result.stderr
    assert len(result.stderr.strip().splitlines()) == 1 and not (tmp_path / "out").exists()


def test_example_platform_is_a_small_electric_motion_platform(electric):
    a = electric.actuator
    moving = electric.moving_body.mass
    assert 200 <= moving <= 900 and electric.electric_legs
    assert 0.05 * moving <= a.reflected_mass <= 0.10 * moving
    limits = resolve_limits(electric)
    assert limits.leg_velocity == pytest.approx(a.screw_speed * a.screw_lead)
    assert limits.actuator_force == pytest.approx(a.peak_current * a.force_constant)
    assert limits.stroke_max - limits.stroke_min == pytest.approx(0.3)
    # holding takes 15 % of the peak current; Mt positive definite
    static = inverse_dynamics(electric, electric.neutral_pose, np.zeros(6), np.zeros(6))
    assert 0.05 < np.abs(static).max() / limits.actuator_force < 0.3
    assert np.linalg.eigvalsh(nominal_matrices(electric)[0]).min() > 0
    # screw friction of the order of a leg's inertial force along the tests' command (210 N)
    q, q_dot, q_ddot = _excitation(electric).evaluate(np.linspace(0.1, 1.0, 500))
    inertial = (inverse_dynamics(electric, q, q_dot, q_ddot, friction=False)
                - inverse_dynamics(electric, q, q_dot, 0 * q_ddot, friction=False))
    assert 0.3 < a.coulomb / np.abs(inertial).max() < 3
