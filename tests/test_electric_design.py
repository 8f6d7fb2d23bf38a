"""Excitation design for electric legs: the force the design checks includes the reflected mass and
the friction along the legs, a saturated motor counts beyond its limit, and designed records played
on the electric plant stay within peak current and screw speed.
"""

from __future__ import annotations

import dataclasses
from importlib import resources

import numpy as np
import pytest

from stewartid.design.candidates import Design, DesignedRecord, scheduled_design, unit_direction
from stewartid.design.export import simulate_excitations
from stewartid.design.limits import (
    LIMIT_NAMES,
    amplitude_scale,
    record_limit_use,
    resolve_limits,
)
from stewartid.design.multisine import multisine_design
from stewartid.design.optimise import commanded_use, largest_amplitudes, within_plant_limits
from stewartid.design.physical.search import commanded_limit_use, scale_to_limits
from stewartid.errors import ConfigError
from stewartid.model.dynamics import inverse_dynamics
from stewartid.platform import load_platform
from stewartid.simulation import SensorNoise
from stewartid.simulation.excitation import DEFAULT_AMPLITUDES


@pytest.fixture(scope="module")
def electric():
    """The example electric motion platform (data/electric.toml)."""
    with resources.as_file(resources.files("stewartid") / "data/electric.toml") as path:
        return load_platform(path)


def without_actuator_terms(platform):
    """The platform with no reflected mass and no friction along the legs."""
    return dataclasses.replace(platform, actuator=dataclasses.replace(
        platform.actuator, reflected_mass=0.0, viscous=0.0, coulomb=0.0))


def with_peak_current(platform, amperes: float):
    return dataclasses.replace(platform, actuator=dataclasses.replace(
        platform.actuator, peak_current=amperes))


def test_limits_from_the_motor(electric):
    limits = resolve_limits(electric)
    a = electric.actuator
    assert limits.leg_velocity == pytest.approx(a.screw_speed * a.screw_lead)
    assert limits.actuator_force == pytest.approx(a.peak_current * a.force_constant)


def test_commanded_forces_include_reflected_mass_and_leg_friction(electric):
    limits = resolve_limits(electric)
    # matrices: a 2 Hz heave record, forces from the model's inverse dynamics
    record = DesignedRecord(unit_direction(2, 0.02), 2.0, (1.0,), 2, 1, "exp1")
    rate = electric.sensors.sample_rate
    t = np.arange(int(record.duration * rate) + 1) / rate
    dq, q_dot, q_ddot = record.evaluate_offsets(t)
    q = dq + electric.neutral_pose
    full = inverse_dynamics(electric, q, q_dot, q_ddot)
    bare = inverse_dynamics(without_actuator_terms(electric), q, q_dot, q_ddot)
    peak = commanded_use(electric, record).peak["actuator_force"]
    assert peak == pytest.approx(np.abs(full).max() / limits.actuator_force, rel=1e-12)
    # the actuator terms matter here: reflected mass m_r l_ddot and 80 N of screw friction
    assert np.abs(full - bare).max() > 80.0
    # physical model: the regressor's forces, the same inverse dynamics
    design = multisine_design(20.0, 0.3 * np.asarray(DEFAULT_AMPLITUDES))
    use, (q, q_dot, q_ddot, _) = commanded_limit_use(electric, design)
    full = inverse_dynamics(electric, q, q_dot, q_ddot)
    assert use.peak["actuator_force"] == pytest.approx(
        np.abs(full).max() / limits.actuator_force, rel=1e-9)


def test_amplitude_scale_leaves_the_static_force_out():
    rest = dict.fromkeys(LIMIT_NAMES, 0.0) | {"actuator_force": 0.5}
    peak = {**rest, "leg_velocity": 0.6, "actuator_force": 0.8}
    # the force, affine from 0.5 at rest, reaches 0.7 at 2/3 of the amplitude; proportional
    # scaling (0.7 / 0.8) would leave it at 0.725
    assert amplitude_scale(peak, rest, 0.7) == pytest.approx(0.2 / 0.3)
    assert amplitude_scale({**peak, "actuator_force": 0.55}, rest, 0.7) == pytest.approx(0.7 / 0.6)
    with pytest.raises(ConfigError, match=r"at rest already uses 50% of its actuator_force "
                                          r"limit, not below the 40%"):
        amplitude_scale(peak, rest, 0.4)


@pytest.mark.slow
def test_a_saturated_motor_counts_beyond_its_limit(electric):
    weak = with_peak_current(electric, 2.5)
    record = DesignedRecord(unit_direction(2, 0.026), 2.0, (1.0,), 2, 1, "exp1")
    (state,) = simulate_excitations(weak, Design((record,)).playable(weak)).states
    assert np.abs(state.currents).max() == pytest.approx(2.5)
    assert record_limit_use(weak, state).exceeded == ["actuator_force"]
    # within the limit nothing changes: the force use is |force| / (peak_current Kt)
    (state,) = simulate_excitations(electric, Design((record,)).playable(electric)).states
    use = record_limit_use(electric, state)
    assert use.exceeded == []
    assert use.peak["actuator_force"] == pytest.approx(
        np.abs(state.currents).max() / electric.actuator.peak_current)


def played_within_motor_limits(platform, design: Design, max_use: float) -> list[str]:
    """Play ``design`` within ``max_use`` on the plant, simulate it again as ``simulate --noise``
    does, and check every true current and leg rate against the motors' limits; return each
    record's most used limit.
    """
    played, _, uses = within_plant_limits(platform, design, max_use, workers=1)
    assert all(max(u.peak.values()) <= max_use + 1e-3 for u in uses)
    run = simulate_excitations(platform, played.playable(platform), SensorNoise(length_noise=0.0),
                               current_noise=0.005)
    a = platform.actuator
    for state in run.states:
        assert np.abs(state.currents).max() <= max_use * a.peak_current * (1 + 1e-3)
        assert np.abs(state.length_rates).max() <= max_use * a.screw_speed * a.screw_lead * (
            1 + 1e-3)
    return [max(u.peak, key=u.peak.get) for u in uses]


@pytest.mark.slow
@pytest.mark.parametrize("peak_current", [None, 3.0], ids=["electric.toml", "weak-motors"])
def test_designed_sines_stay_within_peak_current_and_screw_speed(electric, peak_current):
    # with 3 A the current, not the screw speed, bounds the heave
    platform = electric if peak_current is None else with_peak_current(electric, peak_current)
    amplitudes = largest_amplitudes(platform, 2.0, 0.7)
    design = scheduled_design(amplitudes, 2.0, [3.0] * 6, (1.0, 0.5))
    design = Design(design.records[2:4])  # heave and roll: the legs' largest forces and rates
    binding = played_within_motor_limits(platform, design, 0.7)
    if peak_current is not None:
        assert binding == ["actuator_force"] * 2


@pytest.mark.slow
@pytest.mark.parametrize("peak_current", [None, 3.0], ids=["electric.toml", "weak-motors"])
def test_designed_multisine_stays_within_peak_current_and_screw_speed(electric, peak_current):
    platform = electric if peak_current is None else with_peak_current(electric, peak_current)
    design = multisine_design(8.0, 3.0 * np.asarray(DEFAULT_AMPLITUDES), record_length=8.0,
                              fade=1.0)
    design, use, _ = scale_to_limits(platform, design, 0.7)
    binding = played_within_motor_limits(platform, design, 0.7)
    if peak_current is not None:
        assert "actuator_force" in binding
