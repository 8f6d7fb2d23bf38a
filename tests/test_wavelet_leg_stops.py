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
