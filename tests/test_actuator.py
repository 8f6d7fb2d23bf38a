"""Electric legs ([actuator]): the section, the model with reflected masses and friction along the
legs against independent truth (MuJoCo's mass matrix, leg accelerations by finite differences of
the inverse kinematics, the power balance), limits, and logs of motor currents and angles."""

from __future__ import annotations

import json
import math
import tomllib
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from typer.testing import CliRunner

from roundoff import EPS
from stewartid.cli import app
from stewartid.datasets.dataset import dataset_from_frame, read_dataset
from stewartid.datasets.log_format import load_log_format, log_format_from_mapping
from stewartid.design.limits import resolve_limits
from stewartid.errors import ConfigError, DataError, DataWarning
from stewartid.model.dynamics import (
    COULOMB_SMOOTHING,
    forward_dynamics,
    inverse_dynamics,
    kinetic_energy,
    potential_energy,
)
from stewartid.model.kinematics import leg_jacobian, leg_lengths
from stewartid.model.linearization import nominal_matrices, nominal_terms, viscous_matrix
from stewartid.platform import load_platform, platform_from_mapping
from stewartid.platform.sections import Actuator

DOCS = Path(__file__).parents[1] / "docs"
#: The section of docs/platform-format.md.
ELECTRIC = dict(kind="electric", reflected_mass=48.0, viscous=250.0, coulomb=80.0,
                force_constant=410.0, screw_lead=0.010)


def electric(platform, **values):
    """``platform`` with the electric legs of :data:`ELECTRIC` (and ``values`` over them)."""
    return platform.replace(**{f"actuator__{k}": v for k, v in {**ELECTRIC, **values}.items()})


# -- the section ----------------------------------------------------------------------------

def test_absent_section_is_a_hydraulic_leg_adding_nothing(paper):
    assert paper.actuator == Actuator()
    assert (paper.actuator.kind, paper.actuator.reflected_mass, paper.actuator.viscous,
            paper.actuator.coulomb, paper.actuator.force_constant) == ("hydraulic", 0.0, 0.0,
                                                                       0.0, None)
    # written as absent: the descriptions and meta.json of hydraulic platforms are unchanged
    assert "actuator" not in paper.to_dict() and "[actuator]" not in paper.to_toml()


def test_section_round_trips_through_toml(tmp_path, paper):
    document = tomllib.loads(paper.to_toml())
    document["actuator"] = {**ELECTRIC, "peak_current": 120.0, "screw_speed": 50.0}
    platform = platform_from_mapping(document, "electric")
    path = tmp_path / "electric.toml"
    path.write_text(platform.to_toml())
    again = load_platform(path)
    assert again.actuator == platform.actuator
    assert again.actuator.force_constant == 410.0 and again.actuator.screw_speed == 50.0
    assert again.to_dict() == platform.to_dict()


def test_the_documented_section_reads(paper):
    text = (DOCS / "platform-format.md").read_text()
    block = text.split("```toml\n[actuator]")[1].split("```")[0]
    table = tomllib.loads("[actuator]" + block)["actuator"]
    assert Actuator(**table) == electric(paper).actuator


@pytest.mark.parametrize(("values", "match"), [
    ({"reflected_mass": -48.0}, r"^\[actuator\] reflected_mass must be >= 0 \(kg\)\. Got -48\.0"),
    ({"kind": "pneumatic"}, r"^\[actuator\] kind must be one of 'hydraulic', 'electric'"),
    ({"kind": "electric"}, r'^\[actuator\] kind = "electric" needs force_constant \(N/A.*add it'),
    ({"force_constant": 410.0}, r'^\[actuator\] force_constant describes an electric actuator '
                                r'but kind = "hydraulic"; set kind = "electric" or remove'),
    ({"kind": "electric", "force_constant": 410.0, "screw_speed": 50.0},
     r"^\[actuator\] screw_speed = 50.0 rev/s needs screw_lead"),
    ({"screw_lead": 10.0}, r"^\[actuator\] screw_lead = 10 m is outside the physical range"),
])
def test_bad_sections_are_refused_in_one_line(paper, values, match):
    with pytest.raises(ConfigError, match=match) as caught:
        paper.replace(**{f"actuator__{k}": v for k, v in values.items()})
    assert "\n" not in str(caught.value)


def test_unknown_key_names_the_valid_ones(paper):
    document = tomllib.loads(paper.to_toml())
    document["actuator"] = {"kind": "electric", "force_constant": 410.0, "lead": 0.01}
    with pytest.raises(ConfigError, match=r"\[actuator\] has unknown key 'lead'; valid keys "
                                          "are: kind, reflected_mass"):
        platform_from_mapping(document)


# -- the model --------------------------------------------------------------------------------

def test_hydraulic_results_are_unchanged_to_the_bit(paper):
    """An explicit hydraulic [actuator] with nothing along the legs is the absent section: the
    nominal matrices, G and leg forces are the very same numbers (the actuator's terms are
    skipped, not added as zeros)."""
    explicit = paper.replace(actuator=Actuator(kind="hydraulic", reflected_mass=0.0))
    q = paper.neutral_pose + np.array([0.02, -0.01, 0.03, 0.01, -0.02, 0.015])
    for pose in (None, q):
        for a, b in zip(nominal_terms(paper, pose), nominal_terms(explicit, pose), strict=True):
            assert a.tobytes() == b.tobytes()
    rates = np.array([0.1, -0.2, 0.05, 0.02, 0.03, -0.04])
    assert (inverse_dynamics(paper, q, rates, rates).tobytes()
            == inverse_dynamics(explicit, q, rates, rates).tobytes())


def test_nominal_matrices_gain_the_legs_reflected_mass_and_damping(paper):
    """Mt + J^T m_r J and Bt + J^T c J, J = J_lq at the pose: to the round-off of the entries'
    sums (a few eps of the largest entry)."""
    moving = electric(paper)
    offset = np.array([0.05, 0.0, -0.03, 0.02, 0.0, 0.01])
    for pose in (paper.neutral_pose, paper.neutral_pose + offset):
        M0, B0 = nominal_matrices(paper, pose)
        M, B = nominal_matrices(moving, pose)
        J = leg_jacobian(paper, pose)
        np.testing.assert_allclose(M, M0 + 48.0 * J.T @ J, rtol=0, atol=64 * EPS * np.abs(M).max())
        np.testing.assert_allclose(B, B0 + 250.0 * J.T @ J, rtol=0, atol=64 * EPS * np.abs(B).max())
        np.testing.assert_array_equal(viscous_matrix(moving, pose), B)
    # visible: 48 kg on each of six legs inclined 39 deg from vertical, 1.2 % of Mt(z, z)
    assert (M - M0)[2, 2] == pytest.approx(48.0 * (J[:, 2] ** 2).sum())
    assert (M - M0)[2, 2] > 0.01 * M0[2, 2]


#: Angular frequencies (rad/s) of :func:`_trajectory`.
OMEGA = 2 * math.pi * np.array([1.0, 0.8, 1.2, 0.9, 1.1, 0.7])


def _trajectory(platform, t):
    """A smooth motion of every DOF (0.7-1.2 Hz, phases apart): q, q_dot, q_ddot (N, 6)."""
    amplitude = np.array([0.05, 0.04, 0.03, 0.03, 0.025, 0.02])
    phase = np.arange(6) * 0.7
    w = OMEGA
    angle = np.outer(t, w) + phase
    q = platform.neutral_pose + amplitude * np.sin(angle)
    return q, amplitude * w * np.cos(angle), -amplitude * w ** 2 * np.sin(angle)


#: Step (s) of the five-point differences: truncation h^4 f^(5) / 30 below 1e-10 of these
#: motions' derivatives, round-off of the leg lengths (8 eps l) over h^2 a few 1e-9 m/s^2.
STEP = 1e-3


def _five_point(f, h):
    """First and second derivatives at the middle of five samples (5, ...) spaced h."""
    d1 = (f[0] - 8 * f[1] + 8 * f[3] - f[4]) / (12 * h)
    d2 = (-f[0] + 16 * f[1] - 30 * f[2] + 16 * f[3] - f[4]) / (12 * h * h)
    return d1, d2


def test_leg_forces_carry_reflected_mass_and_friction_along_each_leg(paper):
    """f_electric - f_hydraulic = m_r l_ddot + c l_dot + Fc l_dot / sqrt(l_dot^2 + s^2) leg by leg,
    l_dot and l_ddot by finite differences of the inverse kinematics along a motion: an
    independent check of the J_lq_dot q_dot term, which is half of l_ddot here."""
    moving = electric(paper)
    times = np.linspace(0.1, 1.9, 7)
    offsets = np.arange(-2, 3) * STEP
    q, qd, qdd = _trajectory(paper, (times[None] + offsets[:, None]).ravel())
    lengths = leg_lengths(paper, q).reshape(5, len(times), 6)
    l_dot, l_ddot = _five_point(lengths, STEP)
    middle = slice(2 * len(times), 3 * len(times))
    difference = (inverse_dynamics(moving, q[middle], qd[middle], qdd[middle])
                  - inverse_dynamics(paper, q[middle], qd[middle], qdd[middle]))
    expected = (48.0 * l_ddot + 250.0 * l_dot
                + 80.0 * l_dot / np.sqrt(l_dot ** 2 + COULOMB_SMOOTHING ** 2))
    # the differences' round-off of 8 eps l per length: (1 + 16 + 30 + 16 + 1) / 12 of it / h^2
    # on l_ddot, times m_r, and (1 + 8 + 8 + 1) / 12 of it / h on l_dot, times c and the
    # regularised sign's largest slope Fc / s; each leg force's own solve, 1000 eps |f|
    roundoff = 8 * EPS * lengths.max()
    forces = inverse_dynamics(moving, q[middle], qd[middle], qdd[middle])
    bound = (48.0 * 64 / 12 * roundoff / STEP ** 2
             + (250.0 + 80.0 / COULOMB_SMOOTHING) * 18 / 12 * roundoff / STEP
             + 1000 * EPS * np.abs(forces).max())
    assert np.abs(difference - expected).max() < bound
    # the velocity-product part of m_r l_ddot (up to 8 N here) is far above the bound: the
    # check sees it
    J = leg_jacobian(paper, q[middle])
    bias = l_ddot - np.einsum("nij,nj->ni", J, qdd[middle])
    assert 48.0 * np.abs(bias).max() > 1e4 * bound


def test_power_of_the_leg_forces_is_the_rate_of_energy_with_the_rotors(paper):
    """Without friction, sum f l_dot = d/dt (T + 1/2 m_r sum l_dot^2 + V), T and V of the platform and
    legs without the actuator (the rotors' weight rests on the housings: no potential energy)."""
    moving = electric(paper, viscous=0.0, coulomb=0.0)
    offsets = np.arange(-2, 3) * STEP
    times = np.linspace(0.2, 1.8, 5)
    q, qd, qdd = _trajectory(paper, (times[None] + offsets[:, None]).ravel())
    l_dot = np.einsum("nij,nj->ni", leg_jacobian(paper, q), qd)
    energy = (kinetic_energy(paper, q, qd) + 0.5 * 48.0 * (l_dot ** 2).sum(axis=1)
              + potential_energy(paper, q)).reshape(5, len(times))
    rate, _ = _five_point(energy, STEP)
    middle = slice(2 * len(times), 3 * len(times))
    power = (inverse_dynamics(moving, q[middle], qd[middle], qdd[middle], friction=False)
             * l_dot[middle]).sum(axis=1)
    # the stencil's truncation h^4 E^(5) / 30, E's fifth derivative at most (2 omega_max)^4 times
    # its first (the energies are quadratic in the motion), and the round-off of the energies
    # (about 6e5 J, mostly V, each a sum of some 20 terms): 18/12 x 16 eps E / h
    truncation = STEP ** 4 / 30 * (2 * OMEGA.max()) ** 4 * np.abs(power).max()
    bound = truncation + 18 / 12 * 16 * EPS * np.abs(energy).max() / STEP
    assert np.abs(power - rate).max() < bound
    assert np.abs(power).max() > 1e3  # the balance is not trivially met


def test_forward_dynamics_inverts_inverse_dynamics_with_the_actuator(paper, rng):
    moving = electric(paper)
    q, qd, qdd = _trajectory(paper, rng.uniform(0, 2, 8))
    forces = inverse_dynamics(moving, q, qd, qdd)
    back = forward_dynamics(moving, q, qd, forces)
    # a 6x6 solve of cond(M) about 10 each way
    np.testing.assert_allclose(back, qdd, rtol=0, atol=1e-10 * np.abs(qdd).max())


def test_the_simulator_moves_electric_legs_with_the_model(paper):
    """The plant's recorded accelerations are the model's forward dynamics under its recorded leg
    forces (force_constant times the motor currents): reflected masses and leg friction are in the
    simulator too."""
    from stewartid.simulation import Sine, multisine_excitation, simulate_experiment

    moving = electric(paper).replace(sensors__sample_rate=500.0)
    assert not moving.hydraulic_legs and paper.hydraulic_legs
    excitation = multisine_excitation(moving, [Sine(2, 0.01, 1.0), Sine(0, 0.01, 1.5)])
    _, record = simulate_experiment(moving, excitation, 0.5)
    qdd = forward_dynamics(moving, record.q, record.q_dot, record.forces)
    np.testing.assert_allclose(record.q_ddot, qdd, rtol=0, atol=1e-9 * np.abs(qdd).max())
    hydraulic = forward_dynamics(paper, record.q, record.q_dot, record.forces)
    assert np.abs(hydraulic - qdd).max() > 1e-3 * np.abs(qdd).max()


# -- MuJoCo: an independent mass matrix --------------------------------------------------------

def test_mujoco_mass_matrix_with_armature_matches_nominal(paper):
    """MuJoCo's joint-space mass matrix, the slides' armature included, reduced to the platform's
    six coordinates through the closed-loop constraints (V^T M V, as tests/test_mujoco.py), is our
    nominal Mt with the reflected masses; its damping V^T D V is our Bt at neutral.

    The mechanisms differ only by MuJoCo's token axial inertia of the legs (1e-9 of the transverse
    inertia): 1e-10 of the diagonal, as for the hydraulic legs, and well inside 1e-6 relative.
    Measured: 7e-15 relative."""
    mujoco = pytest.importorskip("mujoco")
    from stewartid.mujoco import model as mjcf
    from stewartid.mujoco import state as mujoco_state

    moving = electric(paper)
    model = mjcf.load_model(moving)
    data = mujoco.MjData(model)
    slides = mujoco_state.Indices(model).slide_dof
    assert (model.dof_armature[slides] == 48.0).all() and (model.dof_damping[slides] == 250.0).all()
    assert (model.dof_frictionloss[slides] == 80.0).all()
    rng = np.random.default_rng(7)
    span = np.array([0.1, 0.1, 0.1, 0.06, 0.06, 0.06])
    for q in [moving.neutral_pose, *(moving.neutral_pose + rng.uniform(-1, 1, (4, 6)) * span)]:
        theirs = mujoco_state.platform_space_terms(moving, model, data, q)
        M, B, _ = nominal_terms(moving, q)
        scale = np.sqrt(np.outer(np.diag(M), np.diag(M)))
        assert np.max(np.abs(theirs["mass_matrix"] - M) / scale) < 1e-10
        assert np.linalg.norm(theirs["mass_matrix"] - M) / np.linalg.norm(M) < 1e-6
        # the reflected masses' share is far above the agreement
        M0 = nominal_terms(paper, q)[0]
        assert np.linalg.norm(M - M0) / np.linalg.norm(M) > 1e-3
    theirs = mujoco_state.platform_space_terms(moving, model, data, moving.neutral_pose)
    B = viscous_matrix(moving, moving.neutral_pose)
    assert np.abs(theirs["viscous"] - B).max() < 1000 * EPS * np.abs(B).max()


def test_hydraulic_mjcf_has_no_slide_attributes(paper):
    from stewartid.mujoco.model import build_mjcf

    text = build_mjcf(paper)
    assert 'type="slide" axis="0 0 1"/>' in text and "armature" not in text


# -- limits and the command line ---------------------------------------------------------------

def test_limits_come_from_screw_speed_and_peak_current(paper):
    hydraulic = resolve_limits(paper)
    plain = resolve_limits(electric(paper))
    assert (plain.leg_velocity, plain.actuator_force) == (hydraulic.leg_velocity,
                                                          hydraulic.actuator_force)
    limits = resolve_limits(electric(paper, screw_speed=50.0, peak_current=150.0))
    assert limits.leg_velocity == pytest.approx(50.0 * 0.010)
    assert limits.actuator_force == pytest.approx(150.0 * 410.0)
    given = resolve_limits(electric(paper, screw_speed=50.0).replace(limits__leg_velocity=0.3))
    assert given.leg_velocity == 0.3


def test_nominal_command_shows_the_actuator(tmp_path, paper):
    path = tmp_path / "electric.toml"
    path.write_text(electric(paper).to_toml())
    pose = "0.01,0,-4.4239,0,0.01,0"
    result = CliRunner().invoke(app, ["nominal", "--platform", str(path), "--pose", pose,
                                      "--json"])
    assert result.exit_code == 0, result.output
    printed = json.loads(result.stdout)
    M, B, _ = nominal_terms(electric(paper), np.array([0.01, 0, -4.4239, 0, 0.01, 0]))
    np.testing.assert_allclose(printed["M"], M, rtol=1e-15)
    np.testing.assert_allclose(printed["B"], B, rtol=1e-15)
    shown = CliRunner().invoke(app, ["nominal", "--platform", str(path)])
    assert "legs +48 kg" in shown.stdout and "legs +250 N s/m" in shown.stdout


# -- logs of motor currents and angles ---------------------------------------------------------

@pytest.fixture(scope="module")
def frame(example_dir) -> pd.DataFrame:
    """The first 5 s of exp1 of the independent example, as logged (forces in N)."""
    return pd.read_csv(example_dir / "exp1.csv", nrows=5000)


def _currents(frame, force_constant, unit=1.0):
    """``frame`` with f1..f6 replaced by the currents that give them, in A / ``unit``."""
    log = frame.drop(columns=[f"f{k}" for k in range(1, 7)])
    for k in range(1, 7):
        log[f"i{k}"] = frame[f"f{k}"] / force_constant / unit
    return log


def test_currents_in_place_of_forces(frame, example_platform):
    reference = dataset_from_frame(frame, example_platform)
    platform = electric(example_platform)
    read = dataset_from_frame(_currents(frame, 410.0), platform)
    # one division and one multiplication: 2 eps of each force
    np.testing.assert_allclose(read.forces, reference.forces, rtol=2 * EPS)


def test_currents_without_force_constant_name_the_fix(frame, example_platform):
    with pytest.raises(ConfigError, match=r"has motor currents i1..i6 but platform 'platform' "
                                          r"has no force constant; add force_constant \(N/A"):
        dataset_from_frame(_currents(frame, 410.0), example_platform)
    with pytest.raises(ConfigError, match="pass platform="):
        dataset_from_frame(_currents(frame, 410.0).drop(columns=["l1"]), None)


def test_plausibility_speaks_of_currents_and_force_constant(frame, example_platform):
    # logged with 410 N/A, read with 533 N/A: 1.3 times the weight
    platform = electric(example_platform, force_constant=533.0)
    with pytest.warns(DataWarning, match=r"the currents i1..i6 carry 1.3 times the weight of "
                                         r"platform .* force_constant = 533 N/A in \[actuator\].*"
                                         r"or a wrong force_constant in \[actuator\]"):
        dataset_from_frame(_currents(frame, 410.0), platform)
    with pytest.raises(DataError, match=r"carry 6.1 times .*; wrong force_constant in \[actuator\] "
                                        r"or current unit \(A\)\?"):
        dataset_from_frame(_currents(frame, 410.0), electric(example_platform,
                                                             force_constant=2500.0))
    with pytest.raises(DataError, match=r"currents in mA\? map them with --columns i1..i6=:mA"):
        dataset_from_frame(_currents(frame, 410.0, unit=1e-3), electric(example_platform))
    flipped = _currents(frame, 410.0)
    flipped["i3"] = 0.0 * flipped["i3"]
    with pytest.raises(DataError, match=r"column i3 carries 0 times its static load"):
        dataset_from_frame(flipped, electric(example_platform))


def test_mapping_reads_currents_in_milliamperes(tmp_path, frame, example_platform):
    path = tmp_path / "drive.csv"
    _currents(frame, 410.0, unit=1e-3).to_csv(path, index=False, float_format="%.17g")
    read = read_dataset(path, electric(example_platform), log_format=load_log_format("i1..i6=:mA"))
    np.testing.assert_allclose(read.forces, dataset_from_frame(frame, example_platform).forces,
                               rtol=4 * EPS)


def test_mapping_turns_motor_angles_into_leg_lengths(tmp_path, frame, example_platform):
    """l = length_at_zero_angle + screw_lead angle / (2 pi): motor angles in revolutions, one
    reference length per leg, currents for forces (the documented mapping)."""
    platform = electric(example_platform)
    zero = 2.0 + 0.01 * np.arange(6)
    log = _currents(frame, 410.0).drop(columns=["x", "y", "z", "rx", "ry", "rz"])
    for k in range(1, 7):
        log[f"Motor{k}"] = (frame[f"l{k}"] - zero[k - 1]) / 0.010
        log = log.drop(columns=[f"l{k}"])
    path = tmp_path / "drive.csv"
    log.to_csv(path, index=False, float_format="%.17g")
    mapping = log_format_from_mapping({"columns": {"motor1..motor6": "Motor{k}:rev"},
                                       "motors": {"length_at_zero_angle": list(zero)}}, "test")
    read = read_dataset(path, platform, log_format=mapping)
    # (l - l0) / lead, then x 2 pi, / 2 pi x lead + l0: a few eps of the length
    np.testing.assert_allclose(read.lengths, frame[[f"l{k}" for k in range(1, 7)]].to_numpy(),
                               rtol=0, atol=16 * EPS * 4.0)
    inline = load_log_format("motor1..motor6=Motor{k}:rev,length_at_zero_angle=2.0")
    assert inline.length_at_zero_angle == (2.0,) * 6
    with pytest.raises(DataError, match=r"need the screw lead; add screw_lead \(m per motor "
                                        r"revolution\) to \[actuator\]"):
        read_dataset(path, electric(example_platform, screw_lead=None), log_format=mapping)
    with pytest.raises(DataError, match=r"need length_at_zero_angle \(m, the leg length where a "
                                        r"motor angle reads 0\) in \[motors\] of --columns"):
        read_dataset(path, platform, log_format=load_log_format("motor1..motor6=Motor{k}:rev"))
    with pytest.raises(ConfigError, match=r"length_at_zero_angle must be a leg length in m"):
        load_log_format("length_at_zero_angle=2000")


def test_worked_mapping_of_an_electric_drive_log(tmp_path, frame, example_platform):
    """docs/logs.md, worked mapping 3: time in ms, motor angles in revolutions, currents in mA."""
    text = (DOCS / "logs.md").read_text()
    (block,) = [b for b in text.split("```toml\n") if b.startswith("# controller_electric.toml")]
    mapping = log_format_from_mapping(tomllib.loads(block.split("```")[0]), "docs")
    log = pd.DataFrame({"Time": frame["t"] * 1e3})
    for k in range(1, 7):
        log[f"Motor{k}"] = (frame[f"l{k}"] - 2.95) / 0.010
    for k in range(1, 7):
        log[f"Iq{k}"] = frame[f"f{k}"] / 410.0 * 1e3
    path = tmp_path / "drive.csv"
    log.to_csv(path, index=False, float_format="%.17g")
    read = read_dataset(path, electric(example_platform), log_format=mapping)
    reference = dataset_from_frame(frame, example_platform)
    np.testing.assert_allclose(read.lengths, reference.lengths, rtol=0, atol=16 * EPS * 4.0)
    np.testing.assert_allclose(read.forces, reference.forces, rtol=4 * EPS)
    np.testing.assert_allclose(read.t, reference.t, rtol=0, atol=4 * EPS * reference.t.max())


def test_simulate_refuses_hydraulic_cylinders_for_electric_legs(tmp_path, paper):
    path = tmp_path / "electric.toml"
    path.write_text(electric(paper).to_toml())
    result = CliRunner().invoke(app, ["simulate", "--platform", str(path), "--actuator",
                                      "hydraulic", "--out", str(tmp_path / "sim")])
    assert result.exit_code == 2
    assert "platform 'electric' has electric legs" in result.stderr
    assert len(result.stderr.strip().splitlines()) == 1


def test_regressor_takes_the_friction_along_the_legs(paper):
    """Y pi of the physical model's regressor, whose actuator columns are the friction along the
    legs, against the model's J_lq^T f (a few hundred eps, as tests/test_physical_model.py); the
    reflected mass's column is tested in tests/test_electric_identification.py."""
    from stewartid.model import regressor as reg

    moving = electric(paper, reflected_mass=0.0)
    q, qd, qdd = reg.random_states(moving, 20, seed=3)
    J = leg_jacobian(moving, q)
    expected = np.einsum("nji,nj->ni", J, inverse_dynamics(moving, q, qd, qdd))
    found = reg.regressor(moving, q, qd, qdd) @ reg.standard_parameters(moving)
    assert np.abs(found - expected).max() < 1e3 * EPS * np.abs(expected).max()
    # the legs' friction is seen: without it the two differ
    bare = reg.regressor(paper, q, qd, qdd) @ reg.standard_parameters(paper)
    assert np.abs(bare - expected).max() > 1e3 * 1e3 * EPS * np.abs(expected).max()
