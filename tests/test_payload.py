"""A payload on the platform: the moving body with its centre of mass off the reference point
and a full inertia matrix, against independent truth.

- MuJoCo composes the platform body and a payload body (``fullinertia``, ``pos``) itself; its
  equations projected on our coordinates must give our M(q), h(q, q_dot) and G(q).
- Lagrange's equations from an independent kinetic and potential energy: every body's
  velocity by complex-step differentiation of its position (exact to round-off), M the
  Hessian of T in q_dot, G the gradient of V, h from the Christoffel symbols of M.
- Limits that must hold exactly: a massless payload is no payload; a payload centred on the
  reference point with principal axes along the platform's is extra [inertia].
"""

from __future__ import annotations

import json

import numpy as np
import pytest
from typer.testing import CliRunner

from roundoff import EPS
from stewartid.cli import app
from stewartid.errors import ConfigError
from stewartid.model.dynamics import (
    ModelTerms,
    friction_forces,
    gravity_forces,
    mass_matrix,
    potential_energy,
    velocity_product_forces,
)
from stewartid.model.linearization import nominal_matrices, nominal_terms
from stewartid.platform import GRAVITY, load_platform

#: A 2.5 t cabin, off-centre and above the reference point, its axes not the platform's.
CABIN = {"mass": 2500.0, "com": [0.3, -0.2, -0.5],
         "inertia": [900.0, 1100.0, 1300.0, 120.0, -80.0, 60.0]}
#: Pose offsets from neutral of the random poses (m, rad).
SPAN = np.array([0.1, 0.1, 0.1, 0.06, 0.06, 0.06])
#: Rates of the random states (m/s, rad/s): large enough that h is far above round-off.
RATES = np.array([0.3, 0.3, 0.3, 0.4, 0.4, 0.4])


@pytest.fixture(scope="module")
def loaded(paper):
    return paper.replace(**{f"payload__{key}": value for key, value in CABIN.items()})


def random_states(platform, n, seed):
    rng = np.random.default_rng(seed)
    q = platform.neutral_pose + rng.uniform(-1.0, 1.0, (n, 6)) * SPAN
    return q, rng.uniform(-1.0, 1.0, (n, 6)) * RATES


def payload_toml(paper, tmp_path, **payload):
    """The paper's platform file with a [payload] section, its path."""
    lines = [f"{key} = {json.dumps(value)}" for key, value in payload.items()]
    path = tmp_path / "loaded.toml"
    path.write_text(paper.to_toml() + "\n[payload]\n" + "\n".join(lines) + "\n")
    return path


# -- the description ------------------------------------------------------------------------

def test_moving_body_combines_platform_and_payload(paper, loaded):
    """Mass, centre of mass and inertia about the reference point, by hand for CABIN."""
    body = loaded.moving_body
    m = paper.inertia.platform_mass + 2500.0
    assert body.mass == m
    np.testing.assert_allclose(body.com, 2500.0 * np.array(CABIN["com"]) / m, rtol=4 * EPS)
    x, y, z = CABIN["com"]
    # 2500 kg at (0.3, -0.2, -0.5): sum of squares 0.38 m^2; products -2500 x y etc.
    expected = np.diag(paper.inertia.platform_inertia) + np.array([
        [900.0 + 2500.0 * (y * y + z * z), 120.0 - 2500.0 * x * y, -80.0 - 2500.0 * x * z],
        [120.0 - 2500.0 * x * y, 1100.0 + 2500.0 * (x * x + z * z), 60.0 - 2500.0 * y * z],
        [-80.0 - 2500.0 * x * z, 60.0 - 2500.0 * y * z, 1300.0 + 2500.0 * (x * x + y * y)]])
    np.testing.assert_allclose(body.inertia, expected, rtol=4 * EPS)


def test_file_round_trip_and_absent_section(paper, loaded, tmp_path):
    path = tmp_path / "loaded.toml"
    path.write_text(loaded.to_toml())
    assert load_platform(path).payload == loaded.payload
    assert paper.payload is None and "[payload]" not in paper.to_toml()


@pytest.mark.parametrize("payload, message", [
    ({**CABIN, "inertia": [900.0, 1100.0, 1300.0, 1200.0, 0.0, 0.0]},
     r"\[payload\] inertia = \[900.0, 1100.0, 1300.0, 1200.0, 0.0, 0.0\] kg m\^2 is not "
     r"positive definite .*check the signs of the products"),
    ({**CABIN, "inertia": [100.0, 100.0, 300.0, 0.0, 0.0, 0.0]},
     r"\[payload\] inertia = .* principal moments 100, 100, 300, the largest above the sum of "
     r"the other two"),
    ({**CABIN, "mass": 0.0}, r"\[payload\] inertia = .* for a payload of zero mass"),
    ({**CABIN, "mass": -5.0}, r"\[payload\] mass must be >= 0 \(kg\)"),
    ({**CABIN, "com": [0.3, -0.2]}, r"\[payload\] com must be a list of 3 numbers"),
    ({**CABIN, "inertia": [900.0, 1100.0, 1300.0]}, r"\[payload\] inertia must be a list of 6"),
    ({"mass": 2500.0, "com": [0.0, 0.0, 0.0]}, r"\[payload\] is missing required key 'inertia'"),
    ({**CABIN, "com": [300.0, 0.0, 0.0]}, r"\[payload\] com\[0\] = 300 m is outside the "
                                          r"physical range"),
])
def test_bad_payload_is_refused_in_one_line(paper, tmp_path, payload, message):
    path = payload_toml(paper, tmp_path, **payload)
    with pytest.raises(ConfigError, match="loaded.toml: " + message) as caught:
        load_platform(path)
    assert "\n" not in str(caught.value)
    result = CliRunner().invoke(app, ["nominal", "--platform", str(path)])
    lines = result.stderr.strip().splitlines()
    assert result.exit_code == 2 and len(lines) == 1 and "[payload]" in lines[0], result.output


def test_flat_plate_is_accepted(paper, tmp_path):
    """A thin plate meets the triangle inequality with equality: Izz = Ixx + Iyy."""
    plate = {"mass": 100.0, "com": [0.0, 0.0, -0.1], "inertia": [2.0, 3.0, 5.0, 0.0, 0.0, 0.0]}
    assert load_platform(payload_toml(paper, tmp_path, **plate)).payload.mass == 100.0


# -- exact limits ---------------------------------------------------------------------------

def test_massless_payload_is_no_payload(paper):
    empty = paper.replace(payload__mass=0.0, payload__com=[0.4, -0.3, 0.2],
                          payload__inertia=[0.0] * 6)
    q, qd = random_states(paper, 20, seed=1)
    for a, b in zip(nominal_terms(empty, q[0]), nominal_terms(paper, q[0]), strict=True):
        assert np.array_equal(a, b)
    bare, with_empty = ModelTerms(paper, q, qd), ModelTerms(empty, q, qd)
    for name in ("mass_matrix", "velocity_product", "gravity", "leg_jacobian"):
        assert np.array_equal(getattr(with_empty, name), getattr(bare, name)), name
    assert np.array_equal(potential_energy(empty, q), potential_energy(paper, q))


def test_centred_principal_payload_is_extra_inertia(paper):
    """Centre of mass at the reference point, axes along the platform's: the same numbers as
    adding its mass and principal inertias to [inertia]."""
    extra = {"mass": 1800.0, "inertia": [700.0, 900.0, 1100.0]}
    loaded = paper.replace(payload__mass=extra["mass"], payload__com=[0.0, 0.0, 0.0],
                           payload__inertia=[*extra["inertia"], 0.0, 0.0, 0.0])
    heavier = paper.replace(
        inertia__platform_mass=paper.inertia.platform_mass + extra["mass"],
        inertia__platform_inertia=[a + b for a, b in zip(paper.inertia.platform_inertia,
                                                         extra["inertia"], strict=True)])
    for a, b in zip(nominal_matrices(loaded), nominal_matrices(heavier), strict=True):
        assert np.array_equal(a, b)
    q, qd = random_states(paper, 10, seed=2)
    t1, t2 = ModelTerms(loaded, q, qd), ModelTerms(heavier, q, qd)
    for name in ("mass_matrix", "velocity_product", "gravity"):
        np.testing.assert_array_equal(getattr(t1, name), getattr(t2, name))


def test_lean_leg_terms_carry_the_payload_to_the_last_bit(loaded):
    """The numpy gravity of the identify path is the compiled kernel's, payload moment too."""
    from stewartid.model.kinematics import compute_leg_terms

    q, _ = random_states(loaded, 50, seed=3)
    lean, full = compute_leg_terms(loaded, q), ModelTerms(loaded, q)
    assert np.array_equal(lean.gravity, full.gravity)
    assert np.array_equal(lean.leg_jacobian, full.leg_jacobian)
    assert np.abs(full.gravity[:, 3:5]).min() > 100.0  # the payload's moment is there


# -- independent truth: Lagrange's equations from complex-step body velocities ---------------

def _rotation(angles):
    """Rz(rz) Ry(ry) Rx(rx), written out here; complex angles allowed."""
    rx, ry, rz = angles
    cx, sx, cy, sy, cz, sz = np.cos(rx), np.sin(rx), np.cos(ry), np.sin(ry), np.cos(rz), np.sin(rz)
    Rx = np.array([[1, 0, 0], [0, cx, -sx], [0, sx, cx]])
    Ry = np.array([[cy, 0, sy], [0, 1, 0], [-sy, 0, cy]])
    Rz = np.array([[cz, -sz, 0], [sz, cz, 0], [0, 0, 1]])
    return Rz @ Ry @ Rx


def _bodies(platform, q):
    """Positions of every centre of mass, the platform rotation and the leg directions at a
    (possibly complex) pose: platform, payload, lower and upper leg parts."""
    i, p = platform.inertia, platform.payload
    R = _rotation(q[3:])
    A = q[:3] + platform.upper_joints @ R.T
    s = A - platform.base_joints
    u = s / np.sqrt(np.sum(s * s, axis=1))[:, None]  # no abs: complex-step safe
    return {"platform": q[:3], "payload": q[:3] + R @ np.asarray(p.com),
            "lower": platform.base_joints + i.lower_leg_com * u,
            "upper": A - i.upper_leg_com * u, "R": R, "u": u}


def _velocities(platform, q, qd, h=1e-30):
    """d/dt of every entry of :func:`_bodies` along q_dot, by complex step (exact)."""
    plus = _bodies(platform, q + 1j * h * qd)
    real = _bodies(platform, q.astype(complex))
    return {key: value.imag / h for key, value in plus.items()}, \
        {key: value.real for key, value in real.items()}


def independent_kinetic_energy(platform, q, qd):
    """1/2 sum m v^2 + 1/2 w^T I w over platform, payload and leg parts (no leg spin)."""
    i, p = platform.inertia, platform.payload
    v, x = _velocities(platform, q, qd)
    R = x["R"]
    W = v["R"] @ R.T
    omega = np.array([W[2, 1], W[0, 2], W[1, 0]])
    I_world = R @ (np.diag(i.platform_inertia) + p.inertia_matrix) @ R.T
    w_leg = np.cross(x["u"], v["u"])
    return 0.5 * (i.platform_mass * v["platform"] @ v["platform"] + omega @ I_world @ omega
                  + p.mass * v["payload"] @ v["payload"]
                  + i.lower_leg_mass * np.sum(v["lower"] ** 2)
                  + i.upper_leg_mass * np.sum(v["upper"] ** 2)
                  + (i.lower_leg_inertia + i.upper_leg_inertia) * np.sum(w_leg ** 2))


def independent_mass_matrix(platform, q):
    """The Hessian of T in q_dot, by polarization of the exact quadratic form."""
    E = np.eye(6)
    T = [independent_kinetic_energy(platform, q, e) for e in E]
    M = np.diag(2.0 * np.array(T))
    for a in range(6):
        for b in range(a + 1, 6):
            M[a, b] = M[b, a] = independent_kinetic_energy(platform, q, E[a] + E[b]) - T[a] - T[b]
    return M


def independent_gravity(platform, q, h=1e-30):
    """dV/dq by complex step, V = -g sum m z (z down)."""
    i, p = platform.inertia, platform.payload
    grad = np.empty(6)
    for k in range(6):
        x = _bodies(platform, q + 1j * h * np.eye(6)[k])
        V = -GRAVITY * (i.platform_mass * x["platform"][2] + p.mass * x["payload"][2]
                        + i.lower_leg_mass * x["lower"][:, 2].sum()
                        + i.upper_leg_mass * x["upper"][:, 2].sum())
        grad[k] = V.imag / h
    return grad


def christoffel_velocity_product(platform, q, qd, step=1e-4):
    """h_i = sum_jk Gamma_ijk qd_j qd_k, Gamma_ijk = 1/2 (dM_ij/dq_k + dM_ik/dq_j - dM_jk/dq_i),
    dM/dq by five-point central differences of the independent M."""
    dM = np.empty((6, 6, 6))  # dM[k] = dM/dq_k
    for k, e in enumerate(np.eye(6)):
        at = [independent_mass_matrix(platform, q + s * step * e) for s in (-2, -1, 1, 2)]
        dM[k] = (at[0] - 8 * at[1] + 8 * at[2] - at[3]) / (12 * step)
    gamma = 0.5 * (np.einsum("kij->ijk", dM) + np.einsum("jik->ijk", dM)
                   - np.einsum("ijk->ijk", dM))
    return np.einsum("ijk,j,k->i", gamma, qd, qd)


def test_equation_of_motion_follows_lagrange(loaded):
    """M, G and h against Lagrange's equations of the independent energies.

    M and G are exact to round-off (complex-step velocities, a quadratic form): sums of a few
    dozen products, below 1e-12 relative. h carries the five-point difference of M, truncation
    step^4 ~ 1e-16 and round-off eps/step ~ 2e-12 relative to M; 1e-8 of |h| is far above
    both and far below any error in a term of the equations. Measured: 8e-16 (M), 4e-16 (G),
    1e-11 (h).
    """
    q, qd = random_states(loaded, 3, seed=4)
    for qk, qdk in zip(q, qd, strict=True):
        M = mass_matrix(loaded, qk)
        d = np.sqrt(np.diag(M))
        assert np.abs(independent_mass_matrix(loaded, qk) - M).max() < 1e-12 * d.max() ** 2
        G = gravity_forces(loaded, qk)
        np.testing.assert_allclose(G, independent_gravity(loaded, qk), rtol=0,
                                   atol=1e-12 * np.abs(G).max())
        h = velocity_product_forces(loaded, qk, qdk)
        np.testing.assert_allclose(h, christoffel_velocity_product(loaded, qk, qdk), rtol=0,
                                   atol=1e-8 * np.abs(h).max())


# -- MuJoCo: the same body composed by another engine ---------------------------------------

def _mujoco_velocity_product(platform, model, data, q, qd, step=1e-3):
    """V^T (c(v) + M_joint dV/dt q_dot), V = S P the map from q_dot to MuJoCo's joint rates:
    MuJoCo's equations projected on our coordinates at q_ddot = 0. dV/dt along q + t q_dot by
    a five-point difference (truncation step^4, round-off eps/step: 1e-12 relative)."""
    from stewartid.mujoco import state as mujoco_state

    def V(t):
        mujoco_state.set_state(platform, model, data, q + t * qd)
        return mujoco_state.closure_map(model, data) @ mujoco_state.platform_velocity_map(
            (q + t * qd)[3:])

    V_dot = (V(-2 * step) - 8 * V(-step) + 8 * V(step) - V(2 * step)) / (12 * step)
    mujoco_state.set_state(platform, model, data, q)
    V0, M, rest = V(0.0), mujoco_state.dense_mass_matrix(model, data), data.qfrc_bias.copy()
    mujoco_state.set_state(platform, model, data, q, qd)
    return V0.T @ (data.qfrc_bias - rest + M @ V_dot @ qd)


def test_mujoco_composes_the_same_moving_body(loaded):
    """M, G (at rest) and h (in motion) of MuJoCo with a payload body against ours, <= 1e-6.

    The two engines differ by MuJoCo's token inertia about the leg axes (1e-9 of the
    transverse, ``tests/test_mujoco.py``) and by round-off of the 42-coordinate projection;
    h also by its difference quotient. Measured: 8e-15 (M), 4e-16 (G), 4e-12 (h); the products
    of inertia with the wrong sign would be off by 4e-3 on M.
    """
    mujoco = pytest.importorskip("mujoco")
    from stewartid.mujoco import model as mjcf
    from stewartid.mujoco import state as mujoco_state

    model = mjcf.load_model(loaded)
    data = mujoco.MjData(model)
    assert model.body("payload").mass[0] == 2500.0
    q, qd = random_states(loaded, 5, seed=5)
    for qk, qdk in zip([loaded.neutral_pose, *q], [qd[0], *qd], strict=True):
        t = mujoco_state.platform_space_terms(loaded, model, data, qk)
        M = mass_matrix(loaded, qk)
        d = np.sqrt(np.diag(M))
        assert np.max(np.abs(t["mass_matrix"] - M) / np.outer(d, d)) < 1e-6
        G = gravity_forces(loaded, qk)
        assert np.abs(t["gravity"] - G).max() < 1e-6 * np.abs(G).max()
        h = velocity_product_forces(loaded, qk, qdk)
        theirs = _mujoco_velocity_product(loaded, model, data, qk, qdk)
        assert np.abs(theirs - h).max() < 1e-6 * np.abs(h).max()


def test_plant_carries_the_payload(loaded):
    """The simulator's record obeys the loaded body's equation of motion, not the bare one."""
    from stewartid.simulation import paper_experiments, simulate_experiment

    plant = loaded.replace(hydraulics__mode="ideal")
    _, record = simulate_experiment(plant, paper_experiments(plant, fade_in=0.5)[3], 1.0)

    def residual(platform):
        terms = ModelTerms(platform, record.q, record.q_dot)
        lhs = (np.einsum("nij,nj->ni", terms.mass_matrix, record.q_ddot)
               + terms.velocity_product + terms.gravity
               + friction_forces(platform, record.q, record.q_dot))
        rhs = np.einsum("nji,nj->ni", terms.leg_jacobian, record.forces)
        return np.abs(lhs - rhs).max() / np.abs(rhs).max()

    assert residual(plant) < 1e-6
    assert residual(plant.replace(payload=None)) > 1e-2


# -- stewartid nominal --pose ---------------------------------------------------------------

def _nominal_json(*args):
    result = CliRunner().invoke(app, ["nominal", *args, "--json"])
    assert result.exit_code == 0, result.output
    return {key: np.asarray(value) for key, value in json.loads(result.stdout).items()}


def test_cli_nominal_at_a_pose(paper, loaded, tmp_path):
    """At the neutral pose --pose gives the model's neutral Mt, Bt exactly; at another pose
    with a payload, Mt and G agree with MuJoCo's."""
    neutral = ",".join(repr(float(v)) for v in paper.neutral_pose)
    plain, at = _nominal_json("--platform", "paper"), _nominal_json("--platform", "paper",
                                                                   "--pose", neutral)
    assert set(plain) == {"M", "B"} and set(at) == {"M", "B", "G"}
    assert np.array_equal(at["M"], plain["M"]) and np.array_equal(at["B"], plain["B"])
    G = gravity_forces(paper, paper.neutral_pose)  # the compiled kernel: same sums, same order
    np.testing.assert_allclose(at["G"], G, rtol=0, atol=16 * EPS * np.abs(G).max())

    mujoco = pytest.importorskip("mujoco")
    from stewartid.mujoco import model as mjcf
    from stewartid.mujoco import state as mujoco_state

    path = tmp_path / "loaded.toml"
    path.write_text(loaded.to_toml())
    q = loaded.neutral_pose + np.array([0.05, -0.04, 0.03, 0.02, -0.03, 0.04])
    out = _nominal_json("--platform", str(path), "--pose", ",".join(repr(float(v)) for v in q))
    model = mjcf.load_model(loaded)
    t = mujoco_state.platform_space_terms(loaded, model, mujoco.MjData(model), q)
    d = np.sqrt(np.diag(out["M"]))
    assert np.max(np.abs(t["mass_matrix"] - out["M"]) / np.outer(d, d)) < 1e-6
    assert np.abs(t["gravity"] - out["G"]).max() < 1e-6 * np.abs(out["G"]).max()


@pytest.mark.parametrize("pose, message", [
    ("0,0,-4.4,0,0", "--pose must be six numbers X,Y,Z,RX,RY,RZ: the absolute pose"),
    ("0,0,-4.4,0,0,x", "--pose must be six numbers"),
    ("0,0,-4.4,0,0,nan", "--pose must be six numbers"),
    ("0,0,0,0,0,0", "--pose 0,0,0,0,0,0 is outside the workspace: leg "),
    ("0,0,-4.42,0.5,0,0", "is outside the workspace"),
])
def test_cli_nominal_refuses_a_bad_pose(pose, message):
    result = CliRunner().invoke(app, ["nominal", "--pose", pose])
    lines = result.stderr.strip().splitlines()
    assert result.exit_code == 2 and len(lines) == 1, result.output
    assert message in lines[0] and "Traceback" not in result.output
