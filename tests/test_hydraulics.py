"""Hydraulic actuator model: orifice law, static equilibrium, natural frequency."""

from __future__ import annotations

import math

import numpy as np
import pytest

from roundoff import EPS
from stewartid.errors import ConfigError
from stewartid.simulation.hydraulics import (
    actuator_force,
    hydraulic_natural_frequency,
    hydraulic_parameters,
    orifice,
    pressure_rates,
    static_state,
    valve_flows,
)
from stewartid.simulation.stability import closed_loop_poles


@pytest.fixture(scope="module")
def hp(paper):
    return hydraulic_parameters(paper.hydraulics, paper.neutral_leg_length)


def test_orifice_is_turbulent_far_from_zero_and_odd():
    assert orifice(7e6, 1e5) == pytest.approx(math.sqrt(7e6), rel=1e-4)
    assert orifice(-2e6, 1e5) == pytest.approx(-orifice(2e6, 1e5))


def test_rated_flow_at_rated_drop(paper, hp):
    h = paper.hydraulics
    # full opening, A at p_r + drop/2 below supply... each edge sees half the rated drop
    pa = h.supply_pressure - h.valve_rated_pressure_drop / 2
    qa, _ = valve_flows(hp, 1.0, pa, 0.0)
    assert qa == pytest.approx(h.valve_rated_flow, rel=1e-3)


@pytest.mark.parametrize("force", [30495.0, 3.0e4, 1.2e5, 0.0, -4.0e4])
def test_static_state_holds_the_force_at_rest(paper, hp, force):
    """Closed form: the chambers hold the force and the valve feeds exactly the leakage."""
    length = paper.neutral_leg_length + 0.013
    xv, pa, pb = static_state(hp, force, length)
    # closed-form pressures, then p_A A_A - p_B A_B: a few eps of the two chamber forces
    chambers = abs(actuator_force(hp, pa, 0.0)) + abs(actuator_force(hp, 0.0, pb))
    assert actuator_force(hp, pa, pb) == pytest.approx(force, abs=16 * EPS * chambers)
    dpa, dpb = pressure_rates(hp, xv, pa, pb, length, 0.0)
    # a pressure drift below 1 Pa/s against ~1e7 Pa chambers
    assert abs(dpa) < 1.0 and abs(dpb) < 1.0
    # the valve opens toward the higher-pressure chamber's supply edge
    assert np.sign(xv) == np.sign(pa - pb)


def test_unholdable_force_is_refused(hp, paper):
    with pytest.raises(ConfigError, match="cannot hold"):
        static_state(hp, 1e7, paper.neutral_leg_length)


def test_natural_frequency_matches_linearised_chambers(paper, hp):
    """Closed form against the pressure equations linearised about mid-stroke."""
    h, m, l0 = paper.hydraulics, 2500.0, paper.neutral_leg_length
    eps = 1e-7
    # stiffness: force rate per unit piston velocity with the valve closed
    dpa, dpb = pressure_rates(hp, 0.0, 1e7, 1e7, l0, eps)
    stiffness = -(dpa * h.piston_area - dpb * h.annulus_area) / eps
    assert hydraulic_natural_frequency(h, m) == pytest.approx(np.sqrt(stiffness / m), rel=1e-6)


def test_default_servo_loop_is_stable_and_damped(paper):
    """Poles of the loop linearised at rest: all in the left half-plane, damping >= 0.15.

    The least-damped pair (the inner force loop with the 80 Hz valve, ~44 Hz) sets the gain
    margin on force_loop_gain: about 1.9 (the loop goes unstable near 1.9e-5 1/N).
    """
    poles = closed_loop_poles(paper)
    assert np.max(poles.real) < 0
    oscillating = poles[np.abs(poles.imag) > 1.0]
    assert np.min(-oscillating.real / np.abs(oscillating)) > 0.15
    doubled = closed_loop_poles(paper.replace(
        controller__force_loop_gain=2 * paper.controller.force_loop_gain))
    fast = doubled[np.argmax(doubled.real)]
    assert fast.real > 0 and 55 < abs(fast.imag) / (2 * np.pi) < 75


def test_ideal_actuator_loop_has_frozen_hydraulic_states(paper):
    poles = closed_loop_poles(paper.replace(hydraulics__mode="ideal"))
    # 24 valve/pressure states do not move: exact zeros; the 18 others are stable
    assert np.sum(poles == 0) == 24
    assert np.max(poles[poles != 0].real) < 0
