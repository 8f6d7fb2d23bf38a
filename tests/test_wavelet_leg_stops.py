"""Method B on all-DOF records of legs that stick: the stops' friction left free in its windows.

The records are analytic: every DOF a sine of its own frequency, all along one warped time that
pauses every half second (the platform slows to rest, stands 60 ms, starts again), so every leg
stops at once; in a pause each leg's friction is a holding force swinging from its last
direction of motion to the opposite one (Fc cos(pi u) over the pause), elsewhere the model's
inverse dynamics with its friction law. The truth is ``nominal_matrices``.
"""

from __future__ import annotations

import numpy as np
import pytest
from tests.test_electric_identification import AMPLITUDES, ELECTRIC, HZ

from stewartid.datasets.dataset import Dataset
from stewartid.errors import IdentificationError
from stewartid.identification.stops import Stop
from stewartid.identification.wavelet.estimator import WaveletIdentifier
from stewartid.identification.wavelet.windows import STOP_ROW_SHARE, stop_window_length
from stewartid.model.dynamics import COULOMB_SMOOTHING, inverse_dynamics
from stewartid.model.kinematics import leg_jacobian, leg_lengths
from stewartid.model.linearization import nominal_matrices
from stewartid.platform import platform_from_mapping


@pytest.fixture(scope="module")
def electric():
    return platform_from_mapping(ELECTRIC, name="electric")


def pausing_time(t: np.ndarray, moving: float, ramp: float, dwell: float
                 ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Warped time tau, its rate and acceleration: it runs for ``moving`` s, slows to rest over
    ``ramp`` s (rate (1 + cos(pi s)) / 2), stands for ``dwell`` s and starts again over ``ramp``
    s; and the share u in [0, 1) of the pause at each sample (-1 outside)."""
    k, r = np.divmod(t, moving + 2 * ramp + dwell)
    tau, rate, accel = np.zeros_like(t), np.zeros_like(t), np.zeros_like(t)
    share = -np.ones_like(t)
    run = r < moving
    tau[run], rate[run] = r[run], 1.0
    down = (r >= moving) & (r < moving + ramp)
    s = (r[down] - moving) / ramp
    tau[down] = moving + ramp * (s / 2 + np.sin(np.pi * s) / (2 * np.pi))
    rate[down] = (1 + np.cos(np.pi * s)) / 2
    accel[down] = -np.pi * np.sin(np.pi * s) / (2 * ramp)
    still = (r >= moving + ramp) & (r < moving + ramp + dwell)
    tau[still] = moving + ramp / 2
    share[still] = (r[still] - moving - ramp) / dwell
    up = r >= moving + ramp + dwell
    s = (r[up] - moving - ramp - dwell) / ramp
    tau[up] = moving + ramp / 2 + ramp * (s / 2 - np.sin(np.pi * s) / (2 * np.pi))
    rate[up] = (1 - np.cos(np.pi * s)) / 2
    accel[up] = np.pi * np.sin(np.pi * s) / (2 * ramp)
    return k * (moving + ramp) + tau, rate, accel, share


def pausing_records(platform, records=6, sample_rate=500.0, duration=8.0, pose_noise=1e-6,
                    force_noise=0.005, seed=0) -> list[Dataset]:
    """All-DOF multisines (DOF d of record k at ``HZ[(d + k) % 6]``) along :func:`pausing_time`
    (0.45 s moving, 50 ms ramps, 60 ms pauses), white pose and force noise."""
    rng = np.random.default_rng(seed)
    t = np.arange(int(duration * sample_rate)) / sample_rate
    tau, rate, accel, share = pausing_time(t, 0.45, 0.05, 0.06)
    coulomb = platform.actuator.coulomb
    sliding = platform.replace(actuator__coulomb=0.0)
    out = []
    for k in range(records):
        q = np.tile(platform.neutral_pose, (len(t), 1))
        unwarped, qd, qdd = np.zeros_like(q), np.zeros_like(q), np.zeros_like(q)
        for d in range(6):
            omega, phase = 2 * np.pi * HZ[(d + k) % 6], 0.5 * d + k
            x, xd = np.sin(omega * tau + phase), omega * np.cos(omega * tau + phase)
            q[:, d] += AMPLITUDES[d] * x
            unwarped[:, d] = AMPLITUDES[d] * xd            # d q / d tau
            qd[:, d] = unwarped[:, d] * rate
            qdd[:, d] = AMPLITUDES[d] * (-omega ** 2 * x * rate ** 2 + xd * accel)
        jacobian = leg_jacobian(platform, q)
        legs = np.einsum("nlc,nc->nl", jacobian, qd)
        friction = coulomb * legs / np.sqrt(legs ** 2 + COULOMB_SMOOTHING ** 2)
        last = np.sign(np.einsum("nlc,nc->nl", jacobian, unwarped))
        holding = coulomb * last * np.cos(np.pi * share)[:, None]
        friction = np.where(share[:, None] >= 0, holding, friction)
        forces = inverse_dynamics(sliding, q, qd, qdd) + friction
        forces += force_noise * np.sqrt(np.mean(forces ** 2)) * rng.standard_normal(forces.shape)
        pose = q + pose_noise * rng.standard_normal(q.shape)
        out.append(Dataset(t=t, pose=pose, lengths=leg_lengths(platform, pose), forces=forces,
                           name=f"exp{k + 1}"))
    return out


def test_pausing_time_is_consistent():
    """The warped time's rate and acceleration are its derivatives (central differences)."""
    h = 1e-5
    t = np.linspace(0.0, 3.0, 2001)
    tau, rate, accel, _ = pausing_time(t, 0.45, 0.05, 0.06)
    plus, minus = pausing_time(t + h, 0.45, 0.05, 0.06), pausing_time(t - h, 0.45, 0.05, 0.06)
    assert np.abs((plus[0] - minus[0]) / (2 * h) - rate).max() < 1e-6
    assert np.abs((plus[1] - minus[1]) / (2 * h) - accel).max() < 1e-3 * np.abs(accel).max()


def test_wavelet_stays_right_when_every_leg_sticks(electric):
    """With each stop's friction free in the windows: Mt within 0.5 %, Bt within 2 % on the
    diagonal and every diagonal entry within 3 SE. Through the stops the legs' Coulomb law took
    the holding forces for friction and Bt came out 4-5 % low, 4.6-5.6 SE."""
    M0, B0 = nominal_matrices(electric)
    d = np.arange(6)
    fitted = WaveletIdentifier().fit(pausing_records(electric), electric)
    result = fitted.result_
    assert result.diagnostics["friction_model"] == "coulomb"
    assert np.abs(fitted.M_[d, d] / M0[d, d] - 1).max() < 0.005
    assert np.abs(fitted.B_[d, d] / B0[d, d] - 1).max() < 0.02
    z = np.r_[(fitted.M_[d, d] - M0[d, d]) / result.std_errors_M[d, d],
              (fitted.B_[d, d] - B0[d, d]) / result.std_errors_B[d, d]]
    assert np.abs(z).max() < 3
    # the stops it found cover the pauses, not much more, and the report says so
    from stewartid.reports.identification.friction_text import stop_lines

    t = pausing_records(electric)[0].t
    paused = float((pausing_time(t, 0.45, 0.05, 0.06)[3] >= 0).mean())
    for experiment in result.diagnostics["experiments"]:
        assert paused <= experiment["stopped_share"] < 2 * paused
        assert experiment["stop_window_s"] < 2.0
    assert "stood still" in stop_lines(result)[0]


def test_windows_leave_rows_beside_the_stops():
    """The windows shorten until the stops' terms take at most their share of the rows, and
    stay at the longest length without stops."""
    stops = [Stop(0, 0, 10, 2)] * 120          # 240 terms in 10 s
    length = stop_window_length(stops, 10.0, 8, 2.0)
    assert length * 240 / 10.0 == pytest.approx(STOP_ROW_SHARE * 6 * 8)
    assert stop_window_length([], 10.0, 8, 2.0) == 2.0
    assert stop_window_length(stops[:2], 10.0, 8, 2.0) == 2.0


def test_a_motion_that_barely_moves_is_refused_in_one_line(electric):
    """Legs within their noise most of the time leave nothing for the friction law: refused as
    least squares refuses them."""
    from tests.test_leg_stops import stick_slip_records

    still = stick_slip_records(electric, duration=4.0, dwell=0.6, pose_noise=2e-5, scale=0.05)
    with pytest.raises(IdentificationError, match="stand still"):
        WaveletIdentifier(friction="coulomb").fit(still, electric)


def test_stops_eliminated_as_if_they_were_explicit_unknowns(electric):
    """The Schur complement of the stops' unknowns gives [Mt Bt], the Coulomb levels and their
    standard errors of the same weighted fit with every stop term an explicit unknown."""
    from stewartid.identification.preparation import prepare_experiment
    from stewartid.identification.wavelet.gls import InvariantFit, fit_jointly, standard_errors
    from stewartid.identification.wavelet.weak_form import stack_equations
    from stewartid.identification.wavelet.windows import (
        _designs,
        window_equations,
        window_stops,
    )

    data = pausing_records(electric, records=1, duration=4.0)[0]
    estimator = WaveletIdentifier()
    experiment = prepare_experiment(data, electric, True, joints=True, remainder=True)
    found = estimator._noise_and_intervals(experiment, 1.0)
    stops = window_stops(found, experiment.sample_rate)
    length = stop_window_length(stops, 4.0, 8, 2.0)
    equations = window_equations(experiment, found, 6, 8, 0, False, length, stops=stops)
    local = []
    for e in equations:   # the span of each window's stop columns, independent columns
        u, singular, _ = np.linalg.svd(e.stops.reshape(48, -1), full_matrices=False)
        local.append(u[:, singular > 1e-9 * singular[0]].reshape(6, 8, -1))
    assert all(0 < c.shape[2] < 48 for c in local)
    stacked = stack_equations([e.rows for e in equations])
    designs = _designs(stacked.regressors, np.stack([e.coulomb[0] for e in equations]))
    targets = [stacked.targets[:, :, i] for i in range(6)]
    rng = np.random.default_rng(1)
    start = InvariantFit(theta=np.zeros((6, 12)), noise=rng.uniform(0.5, 2.0, (len(local), 6)),
                         pose_share=np.zeros(6))
    eliminated = fit_jointly(stacked, designs, targets, start, None, 1, local)
    # every stop term a column of its own window's rows
    offsets = np.cumsum([0] + [c.shape[2] for c in local])
    explicit_designs = []
    for i in range(6):
        extra = np.zeros((len(local), 8, offsets[-1]))
        for j, columns in enumerate(local):
            extra[j, :, offsets[j]:offsets[j + 1]] = columns[i]
        explicit_designs.append(np.concatenate([designs[i], extra], axis=2))
    explicit = fit_jointly(stacked, explicit_designs, targets, start, None, 1)
    u = designs[0].shape[-1]
    scale = np.abs(explicit.z[:u]).max()
    assert np.abs(eliminated.z - explicit.z[:u]).max() < 1e-8 * scale
    assert np.allclose(np.concatenate(eliminated.local_z), explicit.z[u:], rtol=1e-6,
                       atol=1e-8 * np.abs(explicit.z[u:]).max())
    np.testing.assert_allclose(standard_errors(designs, targets, eliminated, local),
                               standard_errors(explicit_designs, targets, explicit)[:u],
                               rtol=1e-6)
