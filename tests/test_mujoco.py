"""MuJoCo as an independent engine: the same mechanism built from a Platform, term by term.

MuJoCo models the hexapod as 42 joint coordinates closed by 6 welds, with its own rigid-body
algorithms (composite rigid body, RNE); we model it in the platform's 6 coordinates (Kane's
method). Projecting MuJoCo's equations with the closure map (``mujoco_state.platform_space_terms``)
must reproduce our mass matrix, gravity and leg Jacobian at any pose, and the same servo on
both must give the same closed-loop motion. Tolerances are derived in each test.
"""

from __future__ import annotations

import sys

import numpy as np
import pytest

from roundoff import EPS

mujoco = pytest.importorskip("mujoco")

from stewartid.model.dynamics import gravity_forces, inverse_dynamics, mass_matrix  # noqa: E402
from stewartid.model.kinematics import leg_jacobian  # noqa: E402
from stewartid.model.linearization import viscous_matrix  # noqa: E402
from stewartid.mujoco import model as mjcf  # noqa: E402
from stewartid.mujoco import state as mujoco_state  # noqa: E402
from stewartid.mujoco.closed_loop import simulate_mujoco  # noqa: E402
from stewartid.platform import load_platform  # noqa: E402
from stewartid.simulation import Sine, multisine_excitation, simulate_experiment  # noqa: E402

#: Pose offsets from neutral of the random set: +-0.1 m, +-0.06 rad, ten times the paper's
#: excitation amplitudes, so that pose-dependent terms differ visibly from neutral.
SPAN = np.array([0.1, 0.1, 0.1, 0.06, 0.06, 0.06])
#: Round-off of a closed-form position chain (joint angles from closed-form inverse kinematics,
#: then MuJoCo's forward kinematics through 7 bodies per leg): 100 eps times the mechanism's
#: size, taken as its largest leg length or pose coordinate (m). Measured: 8e-16 to 2e-15 m.
CHAIN_ROUNDOFF = 100 * EPS
#: Round-off of the closure map's solve with the welds' leg block (condition number 4.8-7.8 on
#: both platforms) followed by sums of up to 42 products: cond x n x eps < 1000 eps, relative.
SOLVE_ROUNDOFF = 1000 * EPS


def _other_platform():
    """A platform unlike the paper's: other radii, heights, leg layout and inertias."""
    return load_platform("paper").replace(
        geometry__upper_radius=1.3, geometry__lower_radius=1.9, geometry__neutral_height=1.6,
        geometry__upper_half_angle=0.2, geometry__lower_half_angle=0.12,
        geometry__reference_height=0.4, inertia__platform_mass=3000.0,
        inertia__platform_inertia=[2500.0, 3100.0, 4200.0], inertia__upper_leg_mass=40.0,
        inertia__lower_leg_mass=65.0, inertia__upper_leg_com=0.35, inertia__lower_leg_com=0.5,
        inertia__upper_leg_inertia=0.9, inertia__lower_leg_inertia=1.7,
        friction__gimbal_viscous=800.0, name="other")


@pytest.fixture(scope="module", params=["paper", "other"])
def engine(request):
    platform = load_platform("paper") if request.param == "paper" else _other_platform()
    model = mjcf.load_model(platform)
    return platform, model, mujoco.MjData(model)


def random_poses(platform, n=12, seed=0):
    rng = np.random.default_rng(seed)
    return platform.neutral_pose + rng.uniform(-1.0, 1.0, (n, 6)) * SPAN


def scaled_error(A, A0):
    """max |A - A0| / sqrt(|A0_ii A0_jj|): entries of mixed units on one scale."""
    d = np.sqrt(np.abs(np.diag(A0)))
    return float(np.max(np.abs(A - A0) / np.outer(d, d)))


def test_model_compiles_closed_at_neutral(engine):
    platform, model, data = engine
    assert (model.nq, model.nv, model.neq, model.nu) == (43, 42, 6, 6)
    mujoco.mj_forward(model, data)
    assert data.nefc == 36  # 6 welds x 6 rows; no Coulomb rows for the paper's Fc = 0
    size = max(platform.neutral_leg_length, np.abs(platform.neutral_pose).max())
    assert np.abs(data.efc_pos[:data.nefc]).max() < CHAIN_ROUNDOFF * size
    assert np.allclose(mujoco_state.leg_lengths(platform, model, data), platform.neutral_leg_length)
    # the end bodies' share of the platform is given back exactly
    total = sum(model.body_mass[model.body(n).id] for n in
                ["platform", *(f"leg{k}_end" for k in range(1, 7))])
    assert total == pytest.approx(platform.inertia.platform_mass, rel=1e-14)


def test_state_round_trip_and_closure(engine):
    """Pose and rates survive the trip to MuJoCo's joints and back; chains stay closed."""
    platform, model, data = engine
    rng = np.random.default_rng(1)
    size = max(platform.neutral_leg_length, np.abs(platform.neutral_pose).max())
    for q in random_poses(platform, 5):
        q_dot = rng.uniform(-1.0, 1.0, 6) * SPAN
        mujoco_state.set_state(platform, model, data, q, q_dot)
        q_back, q_dot_back = mujoco_state.platform_state(model, data)
        # quaternion and atan2/asin round trip: a few eps of the pose's scale
        np.testing.assert_allclose(q_back, q, atol=CHAIN_ROUNDOFF * np.abs(q).max())
        # closure-map solve, then the 3x3 Euler-rate solve (condition near 1 at these angles)
        np.testing.assert_allclose(q_dot_back, q_dot, atol=SOLVE_ROUNDOFF * np.abs(q_dot).max())
        rows = data.efc_type[:data.nefc] == mujoco.mjtConstraint.mjCNSTR_EQUALITY
        # joint angles from closed-form inverse kinematics: the welds hold to round-off
        assert np.abs(data.efc_pos[:data.nefc][rows]).max() < CHAIN_ROUNDOFF * size
        # weld rates J_c S v: residual of a backward-stable solve, n eps |J_c| |v| (|J_c| <= size)
        assert np.abs(data.efc_vel[:data.nefc][rows]).max() < (CHAIN_ROUNDOFF * size
                                                               * np.abs(q_dot).max())
        # slide rates are leg-length rates: MuJoCo's J_lq q_dot is ours
        slide = data.qvel[mujoco_state.Indices(model).slide_dof]
        expected = leg_jacobian(platform, q) @ q_dot
        np.testing.assert_allclose(slide, expected, atol=SOLVE_ROUNDOFF * np.abs(expected).max())


def test_mass_matrix_gravity_and_leg_jacobian_match(engine):
    """V^T M V, V^T qfrc_bias and the slide rows of V against ours at random poses.

    The mechanisms differ only by MuJoCo's token inertia about the leg axes (1e-9 of the
    transverse inertia, seen through the legs' second-order spin) and by round-off in the
    42-coordinate projection, both below 1e-12 relative; 1e-10 leaves a margin for round-off
    on other machines. Measured: 1e-14 (mass matrix, scaled), 4e-16 (gravity), 1e-15 (leg forces).
    """
    platform, model, data = engine
    size = max(platform.neutral_leg_length, np.abs(platform.neutral_pose).max())
    for q in [platform.neutral_pose, *random_poses(platform)]:
        t = mujoco_state.platform_space_terms(platform, model, data, q)
        assert t["constraint_violation"] < CHAIN_ROUNDOFF * size
        assert scaled_error(t["mass_matrix"], mass_matrix(platform, q)) < 1e-10
        G = gravity_forces(platform, q)
        assert np.abs(t["gravity"] - G).max() < 1e-10 * np.abs(G).max()
        J = leg_jacobian(platform, q)
        # the slide rows of the closure map S: one solve with the welds' leg block
        np.testing.assert_allclose(t["leg_jacobian"], J, atol=SOLVE_ROUNDOFF * np.abs(J).max())


def test_static_leg_forces_match(engine):
    """Leg forces that hold each pose at rest: ours inverse_dynamics(q, 0, 0) vs MuJoCo's."""
    platform, model, data = engine
    for q in [platform.neutral_pose, *random_poses(platform, seed=2)]:
        ours = inverse_dynamics(platform, q, np.zeros(6), np.zeros(6))
        theirs = mujoco_state.static_leg_forces(platform, model, data, q)
        # same derivation as above: 1e-10 of the largest leg force (about 30 kN: 3 uN)
        assert np.abs(theirs - ours).max() < 1e-10 * np.abs(ours).max()


def test_viscous_matrix_exact_at_neutral_first_order_elsewhere(engine):
    """Joint damping projected (V^T D V) against our Bt.

    At neutral, every joint's zero, the Cardan axes are our leg frame: equal to round-off.
    Elsewhere the upper chain's hinges are no longer orthogonal (the revolute axis tilts by
    the upper-gimbal angle) and part of the revolute rate appears in the damped gimbal rates:
    a first-order difference, measured as 0.22-0.42 times the largest gimbal angle on both
    platforms (relative to Bt's largest entry). The bound 0.6 x angle checks that order.
    """
    platform, model, data = engine
    t = mujoco_state.platform_space_terms(platform, model, data, platform.neutral_pose)
    B0 = viscous_matrix(platform, platform.neutral_pose)
    # S^T D S: the closure map's round-off carried through sums of 42 products
    assert np.abs(t["viscous"] - B0).max() < SOLVE_ROUNDOFF * np.abs(B0).max()
    hinges = mujoco_state.Indices(model).joint_qpos
    for q in random_poses(platform, 6, seed=3):
        t = mujoco_state.platform_space_terms(platform, model, data, q)
        B = viscous_matrix(platform, q)
        angle = np.abs(data.qpos[hinges]).max()
        assert np.abs(t["viscous"] - B).max() < 0.6 * angle * np.abs(B).max()


def _closed_loop(platform, step=5e-4, duration=2.0):
    """Same servo, same command, both engines: 2 s of a five-DOF multisine.

    Ideal actuators; the plant's PD servo on leg length with gravity feed-forward (integral
    gain 0: MuJoCo would need an extra state per leg for it). Our plant integrates with RK4
    at ``step``; MuJoCo too, with the servo's PD part in the motors' bias and the command
    part through the control callback, both evaluated at every RK4 stage, like ours.
    Returns the two pose records at 1 kHz and the commanded poses.
    """
    plant = platform.replace(hydraulics__mode="ideal", controller__integral_gain=0.0)
    excitation = multisine_excitation(plant, [
        Sine(0, 0.05, 1.0), Sine(2, 0.03, 1.5, 0.5), Sine(3, 0.02, 1.2),
        Sine(4, 0.03, 0.8, 1.0), Sine(5, 0.03, 1.1)], fade_in=0.5, name="mujoco_check")
    _, record = simulate_experiment(plant, excitation, duration, step=step)

    theirs = simulate_mujoco(plant, excitation, duration, step=step)
    assert np.array_equal(theirs.t, record.t)
    return record.q, theirs.pose, excitation.evaluate(record.t)[0]


@pytest.mark.slow
def test_closed_loop_without_friction_agrees_to_integration_error(paper):
    """No joint friction: the two engines differ only by O(h^2) effects of MuJoCo's side.

    The command is evaluated at every stage of both integrators; the welds' compliance (time
    constant 2h) is second order in the step h: measured 1.1e-7 m and 2.4e-8 rad at
    h = 0.5 ms, 2.8e-8 m and 6.0e-9 rad at 0.25 ms. The tracking error itself is about 7 mm:
    the engines agree to 2e-5 of it. Tolerance 5e-7 (m and rad).
    """
    ours, theirs, command = _closed_loop(paper.replace(friction__gimbal_viscous=0.0))
    assert np.abs(ours - command)[:, :3].max() > 1e-3  # a real tracking error to reproduce
    err = np.abs(theirs - ours)
    assert err[:, :3].max() < 5e-7
    assert err[:, 3:].max() < 5e-7


@pytest.mark.slow
def test_closed_loop_with_gimbal_friction_agrees_to_axis_convention(paper):
    """Paper's viscous gimbal friction: the axis convention shows, at first order.

    Along this motion (gimbal angles up to about 0.09 rad) MuJoCo's damping matrix differs
    from our Bt by up to 2 % (see the test above), i.e. up to about 25 N of leg force at the
    0.3 m/s peak rates, which the servo (K_p = 1e7 N/m per leg) turns into micrometres:
    measured 1.8e-6 m and 2.0e-6 rad, unchanged when the step is halved (a modelling, not a
    numerical, difference). Tolerance 1e-5 (m and rad).
    """
    ours, theirs, _ = _closed_loop(paper)
    err = np.abs(theirs - ours)
    assert err[:, :3].max() < 1e-5
    assert err[:, 3:].max() < 1e-5


@pytest.mark.slow
def test_closed_loop_with_coulomb_friction_agrees_to_the_friction_laws(paper):
    """Coulomb friction alone (30 N m on every hinge): MuJoCo's stiff friction rows beside
    our regularised law.

    The two laws differ only around a reversal of a joint's rate (MuJoCo sticks within its
    time constant, ours passes through Fc w / sqrt(w^2 + s^2)): measured 3.0e-7 m and
    1.8e-7 rad. Rows left at MuJoCo's default softness pass 1-2 N m on the upper hinges,
    which the servo turns into 3.5e-6 m and 2.6e-6 rad: the tolerance, 1e-6, lies between.
    """
    ours, theirs, _ = _closed_loop(paper.replace(friction__coulomb=30.0,
                                                 friction__gimbal_viscous=0.0))
    err = np.abs(theirs - ours)
    assert err[:, :3].max() < 1e-6
    assert err[:, 3:].max() < 1e-6


def test_missing_mujoco_names_the_extra(monkeypatch):
    monkeypatch.setitem(sys.modules, "mujoco", None)
    with pytest.raises(ImportError, match=r'stewartid\[mujoco\]'):
        mjcf.require_mujoco()


def test_mjcf_options_are_checked(paper):
    xml = mjcf.build_mjcf(paper, integrator="implicitfast", timestep=1e-3)
    assert 'integrator="implicitfast"' in xml and 'timestep="0.001"' in xml
    with pytest.raises(ValueError, match="integrator"):
        mjcf.build_mjcf(paper, integrator="RK45")
    with pytest.raises(ValueError, match="timestep"):
        mjcf.build_mjcf(paper, timestep=0.0)
    # Coulomb friction becomes frictionloss on the five hinges of each leg
    model = mjcf.load_model(paper.replace(friction__coulomb=5.0))
    assert np.count_nonzero(model.dof_frictionloss == 5.0) == 30
    assert np.count_nonzero(model.dof_damping == paper.friction.gimbal_viscous) == 24


def _command_file(path, platform, amplitude=0.03, duration=0.5):
    """A command file: a heave of ``amplitude`` (m) faded in and out over ``duration`` (s)."""
    t = np.arange(0.0, duration + 1e-9, 1e-3)
    pose = np.tile(platform.neutral_pose, (t.size, 1))
    pose[:, 2] += amplitude * np.sin(np.pi * t / duration) ** 2
    header = "t,x,y,z,rx,ry,rz"
    np.savetxt(path, np.column_stack([t, pose]), delimiter=",", header=header, comments="")
    return path


@pytest.mark.slow
def test_simulate_plays_command_files_on_mujoco_from_the_command_line(paper, tmp_path):
    """``simulate --engine mujoco``: the command file is played (the heave follows it to the
    servo's tracking error: 0.2 mm on 30 mm, measured) and the sensor errors are applied
    (the force channels scatter about the noise-free record by the reference force noise,
    0.5 % of the static leg force: within 4 %, three times the standard error 1 / sqrt(2 n)
    of a standard deviation from n = 6 x 501 samples)."""
    import json

    from typer.testing import CliRunner

    from stewartid.cli import app
    from stewartid.datasets.dataset import read_dataset

    command = _command_file(tmp_path / "heave.csv", paper)
    runs = {}
    for name, extra in (("clean", []), ("noisy", ["--noise", "--seed", "4"])):
        out = tmp_path / name
        result = CliRunner().invoke(app, ["simulate", "--engine", "mujoco", "--jobs", "1",
                                          "--excitation", str(command), "--out", str(out),
                                          *extra])
        assert result.exit_code == 0, result.output
        assert json.loads((out / "meta.json").read_text())["engine"] == "mujoco"
        runs[name] = read_dataset(out / "exp1.csv")
    clean, noisy = runs["clean"], runs["noisy"]
    commanded = np.loadtxt(command, delimiter=",", skiprows=1)[:, 3]
    assert np.abs(clean.pose[:, 2] - commanded).max() < 1e-3
    assert np.ptp(clean.pose[:, 2]) > 0.025
    static = np.mean(clean.forces[0])
    scatter = np.std(noisy.forces - clean.forces)
    assert scatter == pytest.approx(0.005 * static, rel=0.04)


def test_simulate_on_mujoco_refuses_hydraulics_and_a_missing_engine(paper, tmp_path,
                                                                      monkeypatch):
    from typer.testing import CliRunner

    from stewartid.cli import app

    command = _command_file(tmp_path / "heave.csv", paper)
    out = tmp_path / "out"
    base = ["simulate", "--engine", "mujoco", "--excitation", str(command), "--out", str(out)]
    result = CliRunner().invoke(app, [*base, "--actuator", "hydraulic"])
    assert result.exit_code == 2 and "ideal force actuators" in result.output
    monkeypatch.setitem(sys.modules, "mujoco", None)
    result = CliRunner().invoke(app, base)
    assert result.exit_code == 2 and 'stewartid[mujoco]' in result.output
    assert len(result.output.strip().splitlines()) == 1 and not out.exists()
