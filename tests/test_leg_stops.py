"""Legs that stop: a ball screw's friction sticks at each reversal, where no sign law holds.

The records are analytic stick-slip motions: one sine per DOF that dwells at each of its peaks,
where every leg stands still and its friction is a holding force swinging from +Fc to -Fc
(Fc cos(pi u) over the dwell), anything but the sign law; elsewhere the model's inverse dynamics
with its friction law. The truth is ``nominal_matrices`` and the platform file's friction.
"""

from __future__ import annotations

import numpy as np
import pytest
from tests.test_electric_identification import ELECTRIC

from stewartid.datasets.dataset import Dataset
from stewartid.errors import IdentificationError
from stewartid.identification.least_squares import LeastSquaresIdentifier
from stewartid.identification.stops import (
    Stop,
    filtered_stop_columns,
    find_stops,
    project_out,
    span_basis,
)
from stewartid.model.dynamics import COULOMB_SMOOTHING, inverse_dynamics
from stewartid.model.kinematics import leg_jacobian, leg_lengths
from stewartid.model.linearization import nominal_matrices
from stewartid.physical.estimator import PhysicalIdentifier
from stewartid.platform import platform_from_mapping
from stewartid.signals.differentiation import kernel_filter

AMPLITUDES = (0.02, 0.02, 0.02, 0.01, 0.01, 0.01)


@pytest.fixture(scope="module")
def electric():
    return platform_from_mapping(ELECTRIC, name="electric")


def dwelling_sine(t: np.ndarray, frequency: float, dwell: float
                  ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """sin, its rate and acceleration (per unit amplitude) of a sine that stands still for
    ``dwell`` s at each peak, and the share u in [0, 1) of the dwell at each sample (-1 moving)."""
    omega = 2 * np.pi * frequency
    period = np.pi / omega + dwell
    k, r = np.divmod(t, period)
    phase = np.pi / 2 + k * np.pi + omega * np.clip(r - dwell, 0.0, None)
    moving = r >= dwell
    return (np.sin(phase), omega * np.cos(phase) * moving, -omega ** 2 * np.sin(phase) * moving,
            np.where(moving, -1.0, r / dwell))


def stick_slip_records(platform, sample_rate=500.0, duration=6.0, dwell=0.06, pose_noise=1e-6,
                       force_noise=0.005, seed=0, scale=1.0):
    """One dwelling 1 Hz sine per DOF; in a dwell each leg's friction is Fc cos(pi u) in its
    last direction of motion."""
    rng = np.random.default_rng(seed)
    t = np.arange(int(duration * sample_rate)) / sample_rate
    coulomb = platform.actuator.coulomb
    sliding = platform.replace(actuator__coulomb=0.0)
    out = []
    for dof in range(6):
        x, xd, xdd, share = dwelling_sine(t, 1.0, dwell)
        q = np.tile(platform.neutral_pose, (len(t), 1))
        qd, qdd = np.zeros_like(q), np.zeros_like(q)
        amplitude = scale * AMPLITUDES[dof]
        q[:, dof] += amplitude * x
        qd[:, dof], qdd[:, dof] = amplitude * xd, amplitude * xdd
        rates = np.einsum("nlc,nc->nl", leg_jacobian(platform, q), qd)
        friction = coulomb * rates / np.sqrt(rates ** 2 + COULOMB_SMOOTHING ** 2)
        # the direction before the stop: the peak's sign against the leg's sensitivity
        direction = np.sign(x[:, None] * leg_jacobian(platform, q)[:, :, dof])
        holding = coulomb * direction * np.cos(np.pi * share)[:, None]
        friction = np.where(share[:, None] >= 0, holding, friction)
        forces = inverse_dynamics(sliding, q, qd, qdd) + friction
        forces += force_noise * np.sqrt(np.mean(forces ** 2)) * rng.standard_normal(forces.shape)
        pose = q + pose_noise * rng.standard_normal(q.shape)
        out.append(Dataset(t=t, pose=pose, lengths=leg_lengths(platform, pose), forces=forces,
                           name=f"exp{dof + 1}"))
    return out


@pytest.fixture(scope="module")
def records(electric):
    return stick_slip_records(electric)


def test_span_basis_is_orthonormal_and_spans_the_columns_less_their_near_duplicates():
    """Columns of very different scales, one a copy of another up to 1e-7 of it, one zero: the
    basis is orthonormal, its projector is the SVD's on the singular values kept, and the
    near-duplicate adds no direction while the small but independent column keeps its own."""
    rng = np.random.default_rng(3)
    independent = rng.normal(size=(48, 4)) * np.array([1e3, 1.0, 1e-4, 5.0])
    twin = independent[:, :1] * (1.0 + 1e-7 * rng.normal(size=(48, 1)))
    columns = np.hstack([independent, twin, np.zeros((48, 1))])
    basis = span_basis(columns)
    assert basis.shape == (48, 4)
    # orthonormal to round-off times the condition of the kept columns' Gram
    unit = independent / np.linalg.norm(independent, axis=0)
    condition = np.linalg.cond(unit.T @ unit)
    np.testing.assert_allclose(basis.T @ basis, np.eye(4),
                               atol=100 * condition * np.finfo(float).eps)
    left, _, _ = np.linalg.svd(independent, full_matrices=False)
    # the kept directions lean towards the twin by its 1e-7 difference at most
    np.testing.assert_allclose(basis @ basis.T, left @ left.T, atol=1e-6)
    assert span_basis(np.zeros((48, 2))).shape == (48, 0)


def test_stops_are_found_where_the_legs_stand_still(electric, records):
    """Every dwell is inside a stop of every leg but for the sign rates' smoothing at its ends
    (a few samples), and the stops are not much longer than the dwells."""
    data = records[3]
    share = dwelling_sine(data.t, 1.0, 0.06)[3]
    inner = (share > 0.1) & (share < 0.9)
    found = find_stops(data.pose, leg_jacobian(electric, data.pose), data.sample_rate, 0.2,
                       np.diag(np.full(6, 1e-12)))
    for leg in range(6):
        assert found.stopped[inner, leg].all()
        assert found.stopped[:, leg].mean() < 1.5 * (share >= 0).mean()


@pytest.mark.parametrize("samples", [10, 20, 40])
def test_projection_removes_any_course_of_a_short_stop(samples):
    """A force of any smooth course inside a stop of T s, filtered over W s, lies in the span of
    the stop's two filtered polynomials (impulse and first moment) to within the second moment's
    share, of the order of (T / W)^2."""
    rate, window, n, step = 500.0, 0.2, 2000, 5
    stop = Stop(0, 900, 900 + samples, 2)
    columns = filtered_stop_columns([stop], n, rate, window, step)
    basis = np.linalg.svd(columns, full_matrices=False)[0]
    signal = np.zeros(n)
    u = np.linspace(0.0, 1.0, stop.stop - stop.start)
    signal[stop.start:stop.stop] = 80.0 * np.cos(np.pi * u ** 2)
    filtered = kernel_filter(signal, rate, window)[0][::step]
    assert filtered.shape == columns[:, 0].shape
    left = project_out(basis, filtered)[0]
    assert np.abs(left).max() < (samples / rate / window) ** 2 * np.abs(filtered).max()


def test_least_squares_stays_right_when_the_legs_stick(electric, records):
    """With the stops left out of the sign law: Mt within 1 %, Bt within 8 % on the diagonal,
    the legs' Coulomb level within 3 %, every entry within 4 SE; with the law through them Bt is
    far off."""
    M0, B0 = nominal_matrices(electric)
    d = np.arange(6)
    fitted = LeastSquaresIdentifier().fit(records, electric)
    assert np.abs(fitted.M_[d, d] / M0[d, d] - 1).max() < 0.01
    assert np.abs(fitted.B_[d, d] / B0[d, d] - 1).max() < 0.08
    assert abs(fitted.leg_coulomb_ / electric.actuator.coulomb - 1) < 0.03
    z = np.abs(fitted.B_[d, d] - B0[d, d]) / fitted.result_.std_errors_B[d, d]
    assert z.max() < 4
    law = LeastSquaresIdentifier(leg_stops=False).fit(records, electric)
    assert np.abs(law.B_[d, d] / B0[d, d] - 1).max() > 0.3
    # the report says where the friction was left free, and only then
    from stewartid.reports.identification.friction_text import stop_lines

    shares = [e["stop_rows"] / e["samples"] for e in fitted.result_.diagnostics["experiments"]]
    assert 0 < min(shares) and max(shares) < 0.5
    assert "stood still" in stop_lines(fitted.result_)[0]
    assert stop_lines(law.result_) == []


def test_physical_model_stays_right_when_the_legs_stick(electric, records):
    """Leg viscous and Coulomb friction within 2 % and 4 SE with the stops left out; through
    them the law takes the holding force for a larger Coulomb level and a smaller viscous one."""
    a = electric.actuator
    truth = {"viscous[actuator]": a.viscous, "coulomb[actuator]": a.coulomb}
    fitted = PhysicalIdentifier(sampling_check=False).fit(records, electric)
    for name, value in truth.items():
        error = fitted.parameters_[name] - value
        assert abs(error) < 0.02 * value
        assert abs(error) < 4 * fitted.parameter_std_errors_[name]
    law = PhysicalIdentifier(sampling_check=False, leg_stops=False).fit(records, electric)
    assert law.parameters_["viscous[actuator]"] < 0.96 * a.viscous
    assert law.parameters_["coulomb[actuator]"] > 1.02 * a.coulomb


def test_a_motion_that_barely_moves_is_refused_in_one_line(electric):
    """Legs within their noise most of the time leave nothing for the friction law."""
    still = stick_slip_records(electric, duration=4.0, dwell=0.6, pose_noise=2e-5, scale=0.05)
    with pytest.raises(IdentificationError, match="stand still"):
        LeastSquaresIdentifier().fit(still, electric)
