"""Hydraulic actuator model: orifice law, static equilibrium, natural frequency."""

from __future__ import annotations

import math

import numpy as np
import pytest

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


def test_static_state_holds_the_force_at_rest(paper, hp):
    xv, pa, pb = static_state(hp, 30495.0, paper.neutral_leg_length)
    assert actuator_force(hp, pa, pb) == pytest.approx(30495.0, rel=1e-9)
    dpa, dpb = pressure_rates(hp, xv, pa, pb, paper.neutral_leg_length, 0.0)
    assert abs(dpa) < 1e-3 * pa and abs(dpb) < 1e-3 * pb


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
