"""Identification of electric hexapods: the leg's Coulomb friction in least squares, the
reflected mass and friction along the legs in the physical model, ``--platform-out``'s
``[actuator]``, the force constant's calibration by a test mass, and the report's part.

The records are the compiled model's inverse dynamics (reflected mass in M and h, friction along
the legs in F; not the regressor) along all-DOFs multisines, with white force noise of 0.5 % of
the RMS leg force; the truth is the platform file's parameters and ``nominal_matrices``.
"""

from __future__ import annotations

import numpy as np
import pytest

from stewartid.datasets.dataset import Dataset
from stewartid.errors import ConfigError, IdentificationError
from stewartid.identification.least_squares import LeastSquaresIdentifier
from stewartid.model import regressor as reg
from stewartid.model.dynamics import inverse_dynamics
from stewartid.model.kinematics import leg_jacobian, leg_lengths
from stewartid.model.linearization import nominal_matrices
from stewartid.physical.calibration import corrected_force_constant
from stewartid.physical.estimator import PhysicalIdentifier
from stewartid.physical.identified_platform import identified_platform
from stewartid.platform import platform_from_mapping
from stewartid.reports.identification.physical_section import actuator_lines

#: A 400 kg electric hexapod: reflected mass 7.5 % of the platform's per leg, leg Coulomb
#: friction of the order of the inertial leg force of the records.
ELECTRIC = {
    "geometry": {"upper_radius": 0.55, "lower_radius": 0.75, "neutral_height": 0.70,
                 "upper_half_angle": 0.12, "lower_half_angle": 0.10, "reference_height": 0.15},
    "inertia": {"platform_mass": 400.0, "platform_inertia": [45.0, 48.0, 80.0],
                "upper_leg_mass": 6.0, "lower_leg_mass": 9.0, "upper_leg_com": 0.25,
                "lower_leg_com": 0.2, "upper_leg_inertia": 0.05, "lower_leg_inertia": 0.08},
    "friction": {"gimbal_viscous": 2.0, "coulomb": 0.5},
    "actuator": {"kind": "electric", "reflected_mass": 30.0, "viscous": 400.0,
                 "coulomb": 60.0, "force_constant": 250.0, "screw_lead": 0.01},
}
#: A payload on it (kg, m, kg m^2).
PAYLOAD = {"mass": 80.0, "com": [0.06, -0.04, -0.12],
           "inertia": [3.0, 3.5, 4.0, 0.1, -0.05, 0.08]}
#: Multisine frequencies (Hz), one per DOF, rotated from record to record.
HZ = (0.7, 0.9, 1.1, 1.3, 1.5, 1.7)
AMPLITUDES = (0.02, 0.02, 0.02, 0.01, 0.01, 0.01)


@pytest.fixture(scope="module")
def electric():
    return platform_from_mapping(ELECTRIC, name="electric")


@pytest.fixture(scope="module")
def loaded(electric):
    return electric.replace(**{f"payload__{k}": v for k, v in PAYLOAD.items()})


def model_records(platform, records=2, sample_rate=500.0, duration=8.0, noise_share=0.005,
                  seed=0):
    """All-DOFs multisine records of the model's inverse dynamics, white force noise of
    ``noise_share`` of the RMS leg force."""
    rng = np.random.default_rng(seed)
    t = np.arange(int(duration * sample_rate)) / sample_rate
    out = []
    for k in range(records):
        q = np.tile(platform.neutral_pose, (len(t), 1))
        qd, qdd = np.zeros_like(q), np.zeros_like(q)
        for d in range(6):
            a, w, phase = AMPLITUDES[d], 2 * np.pi * HZ[(d + k) % 6], 0.7 * d + k
            q[:, d] += a * np.sin(w * t + phase)
            qd[:, d] += a * w * np.cos(w * t + phase)
            qdd[:, d] -= a * w * w * np.sin(w * t + phase)
        forces = inverse_dynamics(platform, q, qd, qdd)
        forces = forces + noise_share * np.sqrt(np.mean(forces ** 2)) * rng.standard_normal(
            forces.shape)
        out.append(Dataset(t=t, pose=q, lengths=leg_lengths(platform, q), forces=forces,
                           name=f"exp{k + 1}"))
    return out


@pytest.fixture(scope="module")
def records(electric):
    return model_records(electric)


def test_regressor_has_the_reflected_mass(electric, paper):
    """Y pi against the model's J_lq^T f_a with a reflected mass (round-off), and the column is
    computed for electric legs only: a hydraulic platform's base parameters are as before."""
    q, qd, qdd = reg.random_states(electric, 20, seed=5)
    expected = np.einsum("nji,nj->ni", leg_jacobian(electric, q),
                         inverse_dynamics(electric, q, qd, qdd))
    found = reg.regressor(electric, q, qd, qdd) @ reg.standard_parameters(electric)
    assert np.abs(found - expected).max() < 1e-12 * np.abs(expected).max()
    assert "reflected_mass" in reg.base_parameters(electric).names
    hydraulic = reg.base_parameters(paper)
    assert "reflected_mass" not in hydraulic.names
    assert "reflected_mass" in hydraulic.unidentifiable


def test_least_squares_fits_the_legs_coulomb_friction(electric, records):
    """On by default for electric legs: Mt within 1 %, Bt within 8 % on the diagonal, the leg's
    Coulomb level within 3 %; without it Bt is several times off."""
    M0, B0 = nominal_matrices(electric)
    fitted = LeastSquaresIdentifier().fit(records, electric)
    d = np.arange(6)
    assert np.abs(fitted.M_[d, d] / M0[d, d] - 1).max() < 0.01
    assert np.abs(fitted.B_[d, d] / B0[d, d] - 1).max() < 0.08
    assert abs(fitted.leg_coulomb_ / 60.0 - 1) < 0.03
    without = LeastSquaresIdentifier(leg_coulomb=False).fit(records, electric)
    assert np.isnan(without.leg_coulomb_)
    assert np.abs(without.B_[d, d] / B0[d, d] - 1).max() > 0.3


def test_method_b_fits_the_legs_coulomb_friction_on_all_dofs(electric, records):
    """All DOFs at once leave Method B no interval long enough for free constants: its windows
    carry the legs' Coulomb pattern, J_lq^T sign(l_dot), beside the joints'. Without it the
    screw's friction passes for damping (Bt of the order of 100 % off)."""
    from stewartid.identification.wavelet import WaveletIdentifier

    M0, B0 = nominal_matrices(electric)
    fitted = WaveletIdentifier().fit(records, electric)
    d = np.arange(6)
    assert fitted.result_.diagnostics["friction_model"] == "coulomb"
    assert np.abs(fitted.M_[d, d] / M0[d, d] - 1).max() < 0.01
    assert np.abs(fitted.B_[d, d] / B0[d, d] - 1).max() < 0.08
    leg = fitted.result_.diagnostics["leg_coulomb"]
    assert abs(leg / 60.0 - 1) < 0.05


def test_method_b_solves_its_soft_sign_rates_side_by_side_to_the_bit(electric, records):
    """One friction model (the windows): its fits at the soft-sign rates and its half-window
    refit on two workers give the one-process result to the bit."""
    from stewartid.identification.wavelet import WaveletIdentifier

    alone, side = (WaveletIdentifier(jobs=jobs).fit(records, electric).result_
                   for jobs in (1, 2))
    assert side.diagnostics["friction_model"] == "coulomb"
    for name in ("M", "B", "std_errors_M", "std_errors_B"):
        assert np.array_equal(getattr(alone, name), getattr(side, name)), name
    assert alone.diagnostics["soft_sign_weights"] == side.diagnostics["soft_sign_weights"]


def test_least_squares_leaves_hydraulic_legs_alone(paper):
    from stewartid.identification.least_squares import uses_leg_coulomb

    assert not uses_leg_coulomb(None, paper) and uses_leg_coulomb(True, paper)


def test_physical_model_finds_the_actuators(electric, records):
    """Full mode: reflected mass within 3 %, viscous and Coulomb friction along the legs within
    10 %; ``--platform-out`` writes them in [actuator]."""
    fitted = PhysicalIdentifier().fit(records, electric)
    p = fitted.parameters_
    assert abs(p["reflected_mass"] / 30.0 - 1) < 0.03
    assert abs(p["viscous[actuator]"] / 400.0 - 1) < 0.10
    assert abs(p["coulomb[actuator]"] / 60.0 - 1) < 0.10
    written = identified_platform(electric, fitted.result_).actuator
    assert (written.reflected_mass, written.viscous, written.coulomb) == (
        p["reflected_mass"], p["viscous[actuator]"], p["coulomb[actuator]"])
    assert written.force_constant == 250.0  # what the fit cannot tell stays


def test_payload_mode_and_the_force_constant(electric, loaded):
    """Payload mode on the bare file: mass within 0.5 %, centre within 5 mm, the reflected mass
    a nuisance parameter; with the file's force constant 3 % too high, the test mass gives it
    back within 0.3 %."""
    data = model_records(loaded, seed=1)
    fitted = PhysicalIdentifier(payload=True).fit(data, electric)
    section = fitted.result_.diagnostics["payload"]
    assert abs(section["mass"] / PAYLOAD["mass"] - 1) < 0.005
    assert np.linalg.norm(np.subtract(section["com"], PAYLOAD["com"])) < 0.005
    assert "reflected_mass" in fitted.parameters_
    assert identified_platform(electric, fitted.result_).actuator.reflected_mass == (
        fitted.parameters_["reflected_mass"])
    # the currents the drive logs are f / 250; a file that says 257.5 N/A scales every force
    wrong = electric.replace(actuator__force_constant=257.5)
    scaled = [Dataset(t=d.t, pose=d.pose, lengths=d.lengths, forces=d.forces * 1.03,
                      name=d.name) for d in data]
    result = PhysicalIdentifier(payload=True).fit(scaled, wrong).result_
    assert result.parameters["payload.m"] > 1.1 * PAYLOAD["mass"]  # every mass scales
    assert abs(corrected_force_constant(wrong, result, PAYLOAD["mass"]) / 250.0 - 1) < 0.003


def test_force_constant_refusals(electric, paper, records):
    full = PhysicalIdentifier(sampling_check=False).fit(records, electric).result_
    with pytest.raises(ConfigError, match="needs a payload-mode result"):
        corrected_force_constant(electric, full, 80.0)
    with pytest.raises(ConfigError, match='needs \\[actuator\\] kind = "electric"'):
        corrected_force_constant(paper, full, 80.0)


def test_report_part_on_the_actuators(electric, paper, records):
    """The physical section's actuator part: the legs' values and the force constant's scale."""
    result = PhysicalIdentifier(sampling_check=False).fit(records, electric).result_
    text = "\n".join(actuator_lines(result, electric))
    assert "reflected mass" in text and "(file: 30 kg)" in text
    assert "250 N/A" in text and "corrected_force_constant" in text
    assert actuator_lines(result, paper) == []


def test_an_electric_drives_log_is_taken_as_logged(electric, records):
    """A drive samples currents and encoders in one cycle: the default estimates no delay (the
    screw's friction would bias it), and says so; --delay auto still estimates one."""
    from stewartid.comparison import align_experiments

    default = align_experiments(records, electric)
    assert default.entry["source"] == "not estimated" and not default.entry["applied"]
    assert "electric drive" in default.entry["reason"]
    assert default.experiments == records
    # asked, it is estimated: here refused, as on any log with one frequency per DOF
    with pytest.raises(IdentificationError, match="one frequency only"):
        align_experiments(records, electric, "auto")
