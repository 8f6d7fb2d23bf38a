"""Platform description (TOML) of an identified physical model: payload mode writes ``[payload]``;
full mode the moving body, legs and mean friction levels; both write an electric leg's reflected
mass and friction along the legs in ``[actuator]``.
"""

from __future__ import annotations

import warnings
from pathlib import Path
from typing import Any

import numpy as np

from stewartid.errors import ConfigError
from stewartid.files import write_text_atomic
from stewartid.model import regressor as reg
from stewartid.physical.estimator import (
    PhysicalResult,
    known_platform,
    payload_section,
)
from stewartid.platform import Platform
from stewartid.platform.sections import inertia_matrix

#: The first line of a platform file ``identify --platform-out`` wrote.
IDENTIFIED_HEADER = "# identified by stewartid identify --model physical from"


def _standard_values(platform: Platform, result: PhysicalResult) -> np.ndarray:
    """Standard parameters of a full-mode result, folded-in ones at the file's values."""
    base = reg.base_parameters(platform)
    pi = reg.standard_parameters(platform)
    values = pi.copy()
    for name, column, row in zip(base.names, base.columns, base.combination, strict=True):
        others = row.copy()
        others[column] = 0.0
        values[column] = result.parameters[name] - others @ pi
    return values


def actuator_updates(platform: Platform, parameters: dict[str, float]) -> dict[str, float]:
    """``[actuator]`` keys of identified ``parameters``: reflected mass (kg), viscous (N s/m) and
    Coulomb (N) friction along the legs, for an electric actuator (a hydraulic leg's are left
    as the file has them); those not identified are left out.
    """
    if platform.actuator.kind != "electric":
        return {}
    keys = {"reflected_mass": "reflected_mass", "viscous[actuator]": "viscous",
            "coulomb[actuator]": "coulomb"}
    return {f"actuator__{key}": float(parameters[name]) for name, key in keys.items()
            if name in parameters}


def _full_platform(platform: Platform, result: PhysicalResult) -> Platform:
    """Description of a full-mode result."""
    pi = _standard_values(platform, result)
    value = dict(zip(reg.PARAMETERS, pi, strict=True))
    own = reg.standard_parameters(known_platform(platform))
    body = reg.parameter_index(reg.BODY_PARAMETERS)
    difference = dict(zip((f"payload.{n}" for n in reg.BODY_PARAMETERS), pi[body] - own[body],
                          strict=True))
    i = platform.inertia
    updates = _body_updates(platform, difference, pi[body])
    legs: dict[str, Any] = {}
    if i.upper_leg_mass > 0:
        legs["inertia__upper_leg_com"] = value["md_u"] / i.upper_leg_mass
    if i.lower_leg_mass > 0:
        legs["inertia__lower_leg_com"] = value["md_l"] / i.lower_leg_mass
    d_u = legs.get("inertia__upper_leg_com", i.upper_leg_com)
    d_l = legs.get("inertia__lower_leg_com", i.lower_leg_com)
    legs["inertia__upper_leg_inertia"] = (value["J_u"] + value["J_l"] - i.lower_leg_inertia
                                          - i.upper_leg_mass * d_u ** 2
                                          - i.lower_leg_mass * d_l ** 2)
    gimbals = [value[f"viscous[{t}]"] for t in ("lower_gimbal", "upper_gimbal")]
    updates["friction__gimbal_viscous"] = float(np.mean(gimbals))
    updates["friction__coulomb"] = float(np.mean(
        [value[f"coulomb[{t}]"] for t in reg.JOINT_TYPES]))
    updates.update(actuator_updates(platform, value))
    base = platform.replace(payload=None)
    try:
        return base.replace(**updates, **legs)
    except ConfigError as exc:
        described = base.replace(**updates)  # the body's and friction's errors raise here
        warnings.warn(f"--platform-out: the identified leg parameters are no leg ({exc}); "
                      "the file's leg values are written instead, so the file's Mt differs "
                      "from the identified one by the legs' share.", stacklevel=2)
        return described


#: Share of the moving body's mass and principal inertias a carrier payload takes when the
#: body is not the file's platform plus a payload (:func:`_body_updates`).
CARRIER_SHARE = 0.01


def _body_updates(platform: Platform, difference: dict[str, float], body: np.ndarray
                  ) -> dict[str, Any]:
    """Moving body ``body`` (10,) as platform and payload keys: the file's platform plus the
    difference, else a light carrier payload (CARRIER_SHARE) holding com offset and products.
    """
    payload = {f"payload__{k}": v for k, v in payload_section(difference).items()}
    try:
        platform.replace(payload=None).replace(**payload)
        return payload
    except ConfigError:
        pass
    mass, first, inertia = body[0], body[1:4], inertia_matrix(body[[4, 5, 6, 7, 8, 9]])
    carrier = CARRIER_SHARE * mass
    c = first / carrier
    spread = CARRIER_SHARE * np.diag(inertia)
    shift = carrier * (c @ c * np.eye(3) - np.outer(c, c))
    own = inertia - shift  # the body's inertia less the carrier's point mass
    carried = own - np.diag(np.diag(own)) + np.diag(spread)
    return {"inertia__platform_mass": float(mass - carrier),
            "inertia__platform_inertia": [float(v) for v in np.diag(own) - spread],
            "payload__mass": float(carrier), "payload__com": c.tolist(),
            "payload__inertia": [float(carried[a, b]) for a, b in
                                 ((0, 0), (1, 1), (2, 2), (0, 1), (0, 2), (1, 2))]}


def identified_platform(platform: Platform, result: PhysicalResult) -> Platform:
    """The platform description with the identified parameters.

    Raises
    ------
    ConfigError
        Not a valid description (negative mass, impossible inertia), naming section and key.
    """
    try:
        if result.diagnostics.get("mode") == "payload":
            section = result.diagnostics["payload"]
            return platform.replace(payload=None).replace(
                **{f"payload__{key}": value for key, value in section.items()},
                **actuator_updates(platform, result.parameters))
        return _full_platform(platform, result)
    except ConfigError as exc:
        raise ConfigError(f"the identified parameters are no valid platform description: "
                          f"{exc}") from None


def write_identified(platform: Platform, result: PhysicalResult, platform_out: Path,
                     experiments: int) -> Path:
    """Write ``result``'s description, with the ``identify`` header, to ``platform_out``; return it."""
    identified = identified_platform(platform, result)
    return write_text_atomic(platform_out, f"{IDENTIFIED_HEADER} {experiments} experiments\n"
                             + identified.to_toml())


__all__ = ["IDENTIFIED_HEADER", "actuator_updates", "identified_platform", "write_identified"]
