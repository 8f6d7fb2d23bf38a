"""The force constant of electric legs, calibrated by a known test mass.

An electric leg's force is its motor current times the force constant of ``[actuator]``: a
force constant wrong by a factor c scales every force, hence every identified mass, inertia and
friction level, by c. A test mass of known weight, identified in payload mode on the platform
file, tells c.
"""

from __future__ import annotations

import numpy as np

from stewartid.errors import ConfigError
from stewartid.model import regressor as reg
from stewartid.physical.estimator import PhysicalResult, known_platform
from stewartid.platform import Platform


def corrected_force_constant(platform: Platform, result: PhysicalResult,
                             test_mass: float) -> float:
    """The force constant (N/A) under which a payload-mode fit weighs the test mass right.

    With forces scaled by c (the file's force constant over the true one), payload mode finds
    m_hat = c (m_0 + m_t) - m_0, m_0 the known moving mass (the base parameter ``m``: platform
    and legs' upper parts), so c = (m_hat + m_0) / (m_t + m_0) and the true force constant is
    the file's over c. The legs' other parameters, known in payload mode, leave an error of
    order (c - 1) times their share of the forces.

    Parameters
    ----------
    platform : Platform
        The description the fit used (electric ``[actuator]``), without the test mass.
    result : PhysicalResult
        Of ``PhysicalIdentifier(payload=True)`` on logs with the test mass fixed to the platform.
    test_mass : float
        Its mass, kg, weighed independently.

    Raises
    ------
    ConfigError
        Not an electric platform, not a payload-mode result, or a test mass not > 0.
    """
    if platform.actuator.kind != "electric":
        raise ConfigError('corrected_force_constant needs [actuator] kind = "electric" (the '
                          f'forces come from currents); got kind = "{platform.actuator.kind}".')
    if result.diagnostics.get("mode") != "payload":
        raise ConfigError("corrected_force_constant needs a payload-mode result "
                          "(PhysicalIdentifier(payload=True), identify --payload); got a "
                          f"{result.diagnostics.get('mode', 'full')}-mode result.")
    if not test_mass > 0:
        raise ConfigError(f"test_mass must be > 0 kg; got {test_mass!r}.")
    base = reg.base_parameters(known_platform(platform))
    known = float(base.combination[base.names.index("m")]
                  @ reg.standard_parameters(known_platform(platform)))
    scale = (result.parameters["payload.m"] + known) / (test_mass + known)
    return float(platform.actuator.force_constant / scale)


def force_constant_scale_error(result: PhysicalResult, platform: Platform,
                               test_mass: float) -> float:
    """Standard error (N/A) of :func:`corrected_force_constant` from the mass's standard error."""
    base = reg.base_parameters(known_platform(platform))
    known = float(base.combination[base.names.index("m")]
                  @ reg.standard_parameters(known_platform(platform)))
    mass, std = result.parameters["payload.m"], result.parameter_std_errors["payload.m"]
    constant = corrected_force_constant(platform, result, test_mass)
    return float(constant * std / (mass + known)) if np.isfinite(std) else float("nan")


__all__ = ["corrected_force_constant", "force_constant_scale_error"]
