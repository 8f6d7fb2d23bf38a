"""The physical model: the regressor against the model's inverse dynamics, finite differences
and MuJoCo; its base parameters; identification of simulated data; the command line.

- Y(q, q_dot, q_ddot) pi reproduces M q_ddot + h + G + F of the compiled model (an independent
  implementation: Kane's equations per body in scalar loops, checked against Lagrange and
  MuJoCo in ``tests/test_payload.py``).
- Each column is the derivative of the inverse dynamics with respect to a field of the
  platform file (a central difference, exact for the model's at most quadratic dependence),
  mapped to the standard parameters by the physics written out here (parallel axes).
- The base parameters reproduce Y pi; the upper parts' mass folds into the moving body as six
  point masses at the upper joints.
- Noise-free records of our plant, and of MuJoCo's model of the same machine, identify a
  payload and the moving body's mass.
"""

from __future__ import annotations

import json

import numpy as np
import pytest
from typer.testing import CliRunner

from roundoff import EPS
from stewartid.cli import app
from stewartid.datasets.dataset import write_dataset
from stewartid.model import matrix_regressors
from stewartid.model import regressor as reg
from stewartid.model.dynamics import ModelTerms, friction_forces
from stewartid.model.linearization import nominal_matrices, nominal_terms
from stewartid.physical.estimator import PhysicalIdentifier
from stewartid.physical.identified_platform import identified_platform
from stewartid.platform import load_platform
from stewartid.simulation import (
    DEFAULT_AMPLITUDES,
    SensorNoise,
    Sine,
    multisine_excitation,
    simulate_experiment,
)

#: The payload of the identification tests: 2 t off-centre with products of inertia.
PAYLOAD = {"mass": 2000.0, "com": [-0.20, 0.30, -0.50],
           "inertia": [1800.0, 2200.0, 2600.0, -120.0, 80.0, 160.0]}
#: Frequencies (Hz) of the all-DOFs multisine: DOF d of experiment k at HZ[(d + k) % 6].
HZ = (0.3, 0.45, 0.6, 0.75, 0.9, 1.05)
#: Record length (s) of the simulated experiments (the first 2 s fade in).
DURATION = 4.0


@pytest.fixture(scope="module")
def loaded(paper):
    return paper.replace(friction__coulomb=30.0,
                         **{f"payload__{key}": value for key, value in PAYLOAD.items()})


def inverse_dynamics(platform, q, qd, qdd):
    """M q_ddot + h + G + F of the compiled model: J_lq^T f, shape (N, 6)."""
    t = ModelTerms(platform, q, qd)
    return (np.einsum("nij,nj->ni", t.mass_matrix, qdd) + t.velocity_product + t.gravity
            + friction_forces(platform, q, qd))


def test_regressor_reproduces_the_inverse_dynamics(loaded):
    """50 random states: Y pi against the model, relative to the largest force; both sum a
    few hundred products of O(|f|) terms, so a few hundred eps."""
    q, qd, qdd = reg.random_states(loaded, 50, seed=1)
    expected = inverse_dynamics(loaded, q, qd, qdd)
    found = reg.regressor(loaded, q, qd, qdd) @ reg.standard_parameters(loaded)
    assert np.abs(found - expected).max() < 1e3 * EPS * np.abs(expected).max()


ENTRIES = ("I_xx", "I_yy", "I_zz", "I_xy", "I_xz", "I_yz")
ROWS, COLS = [0, 1, 2, 0, 0, 1], [0, 1, 2, 1, 2, 2]


def _shifted(values, k, h):
    out = list(values)
    out[k] += h
    return out


def _field_derivatives(platform):
    """Fields of the platform file: (label, the platform with the field moved by h, and
    d pi / d field from the physics of each: masses times distances, parallel axes)."""
    i, p = platform.inertia, platform.payload
    c, mass = np.array(p.com), p.mass
    fields = []

    def add(label, move, **changes):
        d = np.zeros(reg.N_STANDARD)
        for names, v in changes.items():
            d[reg.parameter_index(names.split("|"))] = v
        fields.append((label, move, d))

    add("platform_mass", lambda h: platform.replace(inertia__platform_mass=i.platform_mass + h),
        m=1.0)
    for k in range(3):
        add(f"platform_inertia[{k}]", lambda h, k=k: platform.replace(
            inertia__platform_inertia=_shifted(i.platform_inertia, k, h)), **{ENTRIES[k]: 1.0})
    shift = (c @ c * np.eye(3) - np.outer(c, c))[ROWS, COLS]  # parallel axes, per kg
    add("payload.mass", lambda h: platform.replace(payload__mass=mass + h), m=1.0,
        **{"mc_x": c[0], "mc_y": c[1], "mc_z": c[2]}, **dict(zip(ENTRIES, shift, strict=True)))
    for j in range(3):
        e = np.eye(3)[j]
        d_shift = mass * (2 * c[j] * np.eye(3) - np.outer(e, c) - np.outer(c, e))[ROWS, COLS]
        add(f"payload.com[{j}]", lambda h, j=j: platform.replace(
            payload__com=_shifted(p.com, j, h)), **{f"mc_{'xyz'[j]}": mass},
            **dict(zip(ENTRIES, d_shift, strict=True)))
    for k, name in enumerate(ENTRIES):
        add(f"payload.inertia[{k}]", lambda h, k=k: platform.replace(
            payload__inertia=_shifted(p.inertia, k, h)), **{name: 1.0})
    for part, m, d in (("upper", i.upper_leg_mass, i.upper_leg_com),
                       ("lower", i.lower_leg_mass, i.lower_leg_com)):
        x = part[0]
        masses = {"m_u": 1.0} if part == "upper" else {}
        add(f"{part}_leg_mass", lambda h, part=part, m=m: platform.replace(
            **{f"inertia__{part}_leg_mass": m + h}), **masses, **{f"md_{x}": d, f"J_{x}": d * d})
        add(f"{part}_leg_com", lambda h, part=part, d=d: platform.replace(
            **{f"inertia__{part}_leg_com": d + h}), **{f"md_{x}": m, f"J_{x}": 2 * m * d})
        add(f"{part}_leg_inertia", lambda h, part=part: platform.replace(
            **{f"inertia__{part}_leg_inertia": getattr(i, f"{part}_leg_inertia") + h}),
            **{f"J_{x}": 1.0})
    f = platform.friction
    add("gimbal_viscous", lambda h: platform.replace(friction__gimbal_viscous=f.gimbal_viscous + h),
        **{"viscous[lower_gimbal]|viscous[upper_gimbal]": 1.0})
    add("coulomb", lambda h: platform.replace(friction__coulomb=f.coulomb + h),
        **{"coulomb[lower_gimbal]|coulomb[upper_gimbal]|coulomb[revolute]": 1.0})
    return fields


def test_columns_are_derivatives_of_the_inverse_dynamics(loaded):
    """Central differences in each field of the file against Y d pi / d field. The model is at
    most quadratic in a field (m d^2), so the difference has no truncation error; its
    round-off is eps |f| / h."""
    q, qd, qdd = reg.random_states(loaded, 8, seed=2)
    Y = reg.regressor(loaded, q, qd, qdd)
    scale = np.abs(inverse_dynamics(loaded, q, qd, qdd)).max()
    for label, move, d_pi in _field_derivatives(loaded):
        h = 1e-2
        difference = (inverse_dynamics(move(h), q, qd, qdd)
                      - inverse_dynamics(move(-h), q, qd, qdd)) / (2 * h)
        assert np.abs(difference - Y @ d_pi).max() < 1e2 * EPS * scale / h, label


def test_offset_columns_are_the_leg_jacobian_rows(loaded):
    """A force-sensor offset on leg i adds J_lq^T e_i: J_lq from the kinematics module."""
    from stewartid.model.kinematics import leg_jacobian

    q, qd, qdd = reg.random_states(loaded, 4, seed=3)
    Y = reg.regressor(loaded, q, qd, qdd)[:, :, reg.parameter_index(reg.OFFSET_PARAMETERS)]
    np.testing.assert_allclose(Y, np.swapaxes(leg_jacobian(loaded, q), 1, 2), rtol=0,
                               atol=10 * EPS)


def test_mujoco_mass_matrix_and_gravity_through_the_regressor(loaded):
    """MuJoCo's M(q) and G(q) of the loaded platform against the regressor's acceleration and
    rest columns (the engines agree to 1e-6, ``tests/test_payload.py``)."""
    mujoco = pytest.importorskip("mujoco")
    from stewartid.mujoco import model as mjcf
    from stewartid.mujoco import state as mujoco_state

    model = mjcf.load_model(loaded)
    data = mujoco.MjData(model)
    pi = reg.standard_parameters(loaded)
    for q in reg.random_states(loaded, 3, seed=4)[0]:
        t = mujoco_state.platform_space_terms(loaded, model, data, q)
        M = matrix_regressors.inertia_regressor(loaded, q) @ pi
        d = np.sqrt(np.diag(M))
        assert np.max(np.abs(t["mass_matrix"] - M) / np.outer(d, d)) < 1e-6
        G = reg.regressor(loaded, q, np.zeros(6), np.zeros(6)) @ pi
        assert np.abs(t["gravity"] - G).max() < 1e-6 * np.abs(G).max()


def test_columns_at_rest_are_those_of_a_motion_too_slow_to_matter(loaded):
    """At rest the regressor skips the velocity and acceleration terms; the full evaluation at
    rates and accelerations of 1e-150 (their products far below round-off) must agree, the
    Coulomb columns taking their signs from the same given rates."""
    q, signs, _ = reg.random_states(loaded, 20, seed=5)
    rest = np.zeros_like(q)
    at_rest = reg.regressor(loaded, q, rest, rest, coulomb_rates=signs)
    slow = reg.regressor(loaded, q, np.full_like(q, 1e-150), np.full_like(q, 1e-150),
                         coulomb_rates=signs)
    assert np.abs(at_rest - slow).max() <= 10 * EPS * np.abs(slow).max()


def test_base_parameters_reproduce_the_regressor(loaded):
    """Y_base pi_base = Y pi for random pi on states the base was not found on; the upper
    parts are point masses at the upper joints (m_u folds into m six times, into the
    inertias as sum |a|^2 - a a^T), J_l shares J_u's column; the count is the same for
    other random states."""
    base = reg.base_parameters(loaded)
    q, qd, qdd = reg.random_states(loaded, 30, seed=11)
    Y = reg.regressor(loaded, q, qd, qdd)
    pi = np.random.default_rng(7).uniform(-1.0, 1.0, reg.N_STANDARD) * np.maximum(
        np.abs(reg.standard_parameters(loaded)), 1.0)
    full, reduced = Y @ pi, Y[:, :, base.columns] @ (base.combination @ pi)
    assert np.abs(reduced - full).max() < 1e-9 * np.abs(full).max()
    row = dict(zip(base.names, base.combination, strict=True))
    m_u = reg.parameter_index(["m_u"])[0]
    a = loaded.upper_joints
    assert row["m"][m_u] == pytest.approx(6.0, abs=1e-9)
    assert row["I_xx"][m_u] == pytest.approx(np.sum(a[:, 1] ** 2 + a[:, 2] ** 2), rel=1e-9)
    assert row["mc_z"][m_u] == pytest.approx(np.sum(a[:, 2]), rel=1e-9)
    assert row["J_u"][reg.parameter_index(["J_l"])[0]] == pytest.approx(1.0, abs=1e-9)
    assert "m_u" not in base.names and "J_l" not in base.names
    assert {len(reg.base_parameters(loaded, seed=s).names) for s in (1, 2)} == {len(base.names)}


def test_nominal_mt_and_bt_through_the_regressor(loaded):
    """The acceleration and viscous columns at rest give the model's Mt and Bt."""
    pi = reg.standard_parameters(loaded)
    M, B, _ = nominal_terms(loaded)
    assert np.abs(matrix_regressors.inertia_regressor(loaded) @ pi - M).max() < 1e3 * EPS * np.abs(M).max()
    assert np.abs(matrix_regressors.viscous_regressor(loaded) @ pi - B).max() < 1e3 * EPS * np.abs(B).max()


# -- identification on simulated records ---------------------------------------------------

@pytest.fixture(scope="module")
def records(loaded):
    """Six noise-free all-DOFs multisine records of the loaded plant (Coulomb 30 N m)."""
    out = []
    for k in range(6):
        sines = [Sine(d, DEFAULT_AMPLITUDES[d] * 0.7, HZ[(d + k) % 6], 0.5 * d + k)
                 for d in range(6)]
        out.append(simulate_experiment(loaded, multisine_excitation(
            loaded, sines, name=f"exp{k + 1}"), DURATION, noise=SensorNoise(),
            rng=np.random.default_rng(0))[0])
    return out


def test_payload_mode_recovers_the_payload(loaded, records):
    """On the bare paper platform: mass within 0.5 %, centre of mass within 5 mm, principal
    inertias within 5 %, and the TOML's Mt within the standard errors of the result's."""
    bare = loaded.replace(payload=None)
    fitted = PhysicalIdentifier(payload=True).fit(records, bare)
    found = fitted.result_.diagnostics["payload"]
    assert not fitted.fixed_
    assert abs(found["mass"] - PAYLOAD["mass"]) < 5e-3 * PAYLOAD["mass"]
    assert np.abs(np.subtract(found["com"], PAYLOAD["com"])).max() < 5e-3
    assert np.all(np.abs(np.subtract(found["inertia"][:3], PAYLOAD["inertia"][:3]))
                  < 0.05 * np.array(PAYLOAD["inertia"][:3]))
    M_true, B_true = nominal_matrices(loaded)
    assert np.abs(fitted.M_ - M_true).max() < 1e-3 * np.abs(M_true).max()


def test_full_mode_recovers_the_moving_body_mass(loaded, records):
    """Base parameter m = body mass + 6 upper-part masses; with the file's leg masses the
    body's mass within 0.2 %."""
    fitted = PhysicalIdentifier().fit(records, loaded)
    body_mass = fitted.parameters_["m"] - 6 * loaded.inertia.upper_leg_mass
    assert abs(body_mass - loaded.moving_body.mass) < 2e-3 * loaded.moving_body.mass
    written = identified_platform(loaded, fitted.result_)
    assert abs(written.moving_body.mass - loaded.moving_body.mass) < 2e-3 * written.moving_body.mass
    M = nominal_matrices(written)[0]
    assert np.all(np.abs(M - fitted.M_) <= fitted.std_errors_["M"] + 1e-9 * np.abs(M).max())


@pytest.mark.slow
def test_another_engines_log_identifies_the_payload(loaded):
    """Two 3 s records of the MuJoCo model (its own rigid-body algorithms, Cardan chains and
    friction constraints, ideal actuators; every DOF at three times the paper's amplitude),
    noise-free: payload mode meets the acceptance's 0.5 %, 5 mm and 5 % with every payload
    parameter within 4.5 of its standard errors (measured: 0.068 %, 1.5 mm, 0.56 %, largest
    1.4 SE), and full mode the moving body's mass within 0.2 % (0.084 %)."""
    pytest.importorskip("mujoco")
    from stewartid.mujoco.closed_loop import simulate_mujoco

    records = []
    for k in range(2):
        sines = [Sine(d, 3 * DEFAULT_AMPLITUDES[d], HZ[(d + k) % 6], 0.5 * d + k)
                 for d in range(6)]
        records.append(simulate_mujoco(loaded, multisine_excitation(
            loaded, sines, fade_in=0.5, name=f"exp{k + 1}"), 3.0, step=5e-4))
    fitted = PhysicalIdentifier(payload=True).fit(records, loaded.replace(payload=None))
    found = fitted.result_.diagnostics["payload"]
    assert abs(found["mass"] - PAYLOAD["mass"]) < 5e-3 * PAYLOAD["mass"]
    assert np.abs(np.subtract(found["com"], PAYLOAD["com"])).max() < 5e-3
    assert np.all(np.abs(np.subtract(found["inertia"][:3], PAYLOAD["inertia"][:3]))
                  < 0.05 * np.array(PAYLOAD["inertia"][:3]))
    own = (reg.standard_parameters(loaded) - reg.standard_parameters(loaded.replace(
        payload=None)))[reg.parameter_index(reg.BODY_PARAMETERS)]
    for name, truth in zip(reg.BODY_PARAMETERS, own, strict=True):
        key = f"payload.{name}"
        assert abs(fitted.parameters_[key] - truth) < 4.5 * fitted.parameter_std_errors_[key]
    full = PhysicalIdentifier().fit(records, loaded)
    body_mass = full.parameters_["m"] - 6 * loaded.inertia.upper_leg_mass
    assert abs(body_mass - loaded.moving_body.mass) < 2e-3 * loaded.moving_body.mass


def translation_records(platform, sample_rate=200.0):
    """Three records of the model's own inverse dynamics (friction on) along x, y and z sines
    of several frequencies, the platform never turning."""
    from stewartid.datasets.dataset import Dataset
    from stewartid.model.dynamics import inverse_dynamics as forces_of
    from stewartid.model.kinematics import leg_lengths

    t = np.arange(int(6 * sample_rate)) / sample_rate
    out = []
    for dof in range(3):
        q = np.tile(platform.neutral_pose, (len(t), 1))
        qd, qdd = np.zeros_like(q), np.zeros_like(q)
        for f, a in ((0.5, 0.02), (1.3, 0.01)):
            w = 2 * np.pi * f
            q[:, dof] += a * np.sin(w * t)
            qd[:, dof] += a * w * np.cos(w * t)
            qdd[:, dof] -= a * w * w * np.sin(w * t)
        out.append(Dataset(t=t, pose=q, lengths=leg_lengths(platform, q),
                           forces=forces_of(platform, q, qd, qdd), name=f"exp{dof + 1}"))
    return out


def multisine_records(platform, scale, sample_rate=500.0, duration=8.0):
    """Six records of the model's own inverse dynamics (friction on): every DOF at once, DOF
    d of record k at HZ[(d + k) % 6] Hz and ``scale`` times the paper's amplitude."""
    from stewartid.datasets.dataset import Dataset
    from stewartid.model.dynamics import inverse_dynamics as forces_of
    from stewartid.model.kinematics import leg_lengths

    t = np.arange(int(duration * sample_rate)) / sample_rate
    out = []
    for k in range(6):
        w = 2 * np.pi * np.array([HZ[(d + k) % 6] for d in range(6)])
        a = scale * np.array(DEFAULT_AMPLITUDES)
        phase = 0.5 * np.arange(6) + k
        q = platform.neutral_pose + a * np.sin(w * t[:, None] + phase)
        qd = a * w * np.cos(w * t[:, None] + phase)
        qdd = -a * w * w * np.sin(w * t[:, None] + phase)
        out.append(Dataset(t=t, pose=q, lengths=leg_lengths(platform, q),
                           forces=forces_of(platform, q, qd, qdd), name=f"exp{k + 1}"))
    return out


def test_filtered_equation_holds_at_large_amplitude(loaded):
    """At four times the paper's amplitudes the model's nonlinear terms matter; the regressor
    is evaluated at every sample before it is filtered, so the filtered equation holds
    exactly and the noise-free model's own records give back every base parameter: the
    moving body's mass and inertias within 1e-4, the legs' first moments and inertia within
    2e-3 (the Savitzky-Golay acceleration's gain is within 1e-4 of one in the kernel's
    band). A regressor evaluated at the filtered motion instead put md_u 12 % and J_u 50 %
    off on such records."""
    fitted = PhysicalIdentifier().fit(multisine_records(loaded, 4.0), loaded)
    base = reg.base_parameters(loaded)
    truth = dict(zip(base.names, base.combination @ reg.standard_parameters(loaded),
                     strict=True))
    assert not fitted.fixed_
    relative = {name: abs(value / truth[name] - 1.0) for name, value in fitted.parameters_.items()
                if abs(truth[name]) > 1.0}
    assert max(relative[n] for n in ("m", "I_xx", "I_yy", "I_zz")) < 1e-4, relative
    assert max(relative[n] for n in ("md_u", "md_l", "J_u")) < 2e-3, relative


def test_unexcited_parameters_are_fixed_and_named(loaded):
    """Without rotation the payload's inertias cannot be told (their columns vanish): they are
    fixed at the file's values (none: zero), named with the reason, their standard errors
    null; the mass is still identified."""
    bare = loaded.replace(payload=None)
    fitted = PhysicalIdentifier(payload=True).fit(translation_records(loaded), bare)
    inertias = {f"payload.{name}" for name in ENTRIES[:3]}
    assert inertias <= set(fitted.fixed_)
    assert all("not excited" in fitted.fixed_[name] for name in inertias)
    for name in inertias:
        assert fitted.parameters_[name] == 0.0 and np.isnan(fitted.parameter_std_errors_[name])
    assert abs(fitted.parameters_["payload.m"] - PAYLOAD["mass"]) < 5e-3 * PAYLOAD["mass"]
    document = fitted.result_.to_dict()
    assert all(document["parameter_std_errors"][name] is None for name in inertias)


# -- the command line ------------------------------------------------------------------------

@pytest.mark.slow
def test_cli_contract(loaded, records, tmp_path):
    """result.json keeps today's keys and adds the model's; --platform-out loads and gives
    the identified Mt within its standard errors."""
    files = []
    for d in records:
        files.append(tmp_path / f"{d.name}.csv")
        write_dataset(d, files[-1])
    bare = tmp_path / "bare.toml"
    bare.write_text(loaded.replace(payload=None).to_toml())
    out, written = tmp_path / "result.json", tmp_path / "identified.toml"
    result = CliRunner().invoke(app, ["identify", "--model", "physical", "--payload",
                                      "--platform", str(bare), "--out", str(out),
                                      "--platform-out", str(written), *map(str, files)])
    assert result.exit_code == 0, result.output
    document = json.loads(out.read_text())
    assert {"M", "B", "std_errors_M", "std_errors_B", "model", "parameters",
            "parameter_std_errors", "base_parameters"} <= set(document)
    assert document["model"] == "physical"
    assert set(document["parameters"]) == set(document["parameter_std_errors"])
    assert set(document["parameters"]) == set(document["base_parameters"])
    platform = load_platform(written)
    M = nominal_matrices(platform)[0]
    assert np.all(np.abs(M - np.array(document["M"]))
                  <= np.array(document["std_errors_M"]) + 1e-9 * np.abs(M).max())
    refused = CliRunner().invoke(app, ["identify", "--payload", "--platform", str(bare),
                                       *map(str, files)])
    assert refused.exit_code == 2 and "--model physical" in refused.output
    assert "Traceback" not in refused.output
