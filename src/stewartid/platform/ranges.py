"""Physical ranges of every number in a platform description.

The checks of :mod:`stewartid.fields` say whether a value is a finite number of the right
sign; this table says whether it can describe a real hexapod, from a desktop positioner to a
large shaking table. A value outside its range is almost always a unit mistake (a platform
file in millimetres, a mass in grams, a pressure in bar) and is refused with its key named,
before it turns into a failed identification far from its cause. Ranges are wide on purpose:
they catch factors of a thousand, not unusual designs.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping
from typing import Any

from stewartid.errors import ConfigError

#: (lowest, highest) value of each key, in the key's SI unit, by TOML section.
PHYSICAL_RANGES: dict[str, dict[str, tuple[float, float]]] = {
    "geometry": {
        "upper_radius": (0.01, 50.0),
        "lower_radius": (0.01, 50.0),
        "neutral_height": (0.01, 50.0),
        "upper_half_angle": (0.0, math.pi / 2),
        "lower_half_angle": (0.0, math.pi / 2),
        "reference_height": (0.0, 50.0),
    },
    "inertia": {
        "platform_mass": (0.01, 1e6),
        "platform_inertia": (1e-6, 1e9),
        "upper_leg_mass": (0.0, 1e5),
        "lower_leg_mass": (0.0, 1e5),
        "upper_leg_com": (0.0, 50.0),
        "lower_leg_com": (0.0, 50.0),
        "upper_leg_inertia": (0.0, 1e7),
        "lower_leg_inertia": (0.0, 1e7),
    },
    "friction": {
        "gimbal_viscous": (0.0, 1e9),
        "coulomb": (0.0, 1e7),
    },
    "hydraulics": {
        "supply_pressure": (1e5, 1e8),
        "return_pressure": (0.0, 1e7),
        "bore_diameter": (1e-3, 2.0),
        "rod_diameter": (1e-3, 2.0),
        "stroke": (1e-3, 20.0),
        "dead_volume": (1e-9, 1.0),
        "bulk_modulus": (1e7, 1e10),
        "valve_rated_flow": (1e-7, 1.0),
        "valve_rated_pressure_drop": (1e4, 1e8),
        "valve_bandwidth": (0.1, 1e4),
        "valve_damping": (0.01, 10.0),
        "leakage": (0.0, 1e-8),
        "orifice_transition_pressure": (1.0, 1e7),
    },
    "controller": {
        "proportional_gain": (1e-3, 1e12),
        "integral_gain": (0.0, 1e14),
        "derivative_gain": (0.0, 1e10),
        "force_loop_gain": (1e-12, 1.0),
    },
    "sensors": {
        "sample_rate": (1.0, 1e6),
        "length_noise": (0.0, 0.1),
        "length_bias": (-1.0, 1.0),
        "length_resolution": (0.0, 0.1),
        "force_noise": (0.0, 1e7),
        "force_bias": (-1e7, 1e7),
        "force_resolution": (0.0, 1e7),
    },
    "limits": {
        "stroke_min": (0.01, 100.0),
        "stroke_max": (0.01, 100.0),
        "leg_velocity": (1e-4, 100.0),
        "leg_acceleration": (1e-3, 1e4),
        "actuator_force": (1.0, 1e9),
        "gimbal_angle": (1e-3, math.pi / 2),
    },
}


def check_physical_ranges(sections: Mapping[str, Any]) -> None:
    """Refuse any number of a platform description outside :data:`PHYSICAL_RANGES`.

    Parameters
    ----------
    sections : mapping of str to dataclass
        Section name (``"geometry"``, ...) to its frozen section dataclass.

    Raises
    ------
    ConfigError
        Naming the section, the key, the value with its unit and the range.
    """
    for name, section in sections.items():
        ranges = PHYSICAL_RANGES.get(name, {})
        for field in dataclasses.fields(section):
            if field.name not in ranges:
                continue
            value = getattr(section, field.name)
            values = value if isinstance(value, tuple) else (value,)
            low, high = ranges[field.name]
            for index, v in enumerate(values):
                if v is None or isinstance(v, bool | str) or low <= v <= high:
                    continue
                unit = field.metadata.get("unit", "")
                label = field.name if len(values) == 1 else f"{field.name}[{index}]"
                raise ConfigError(f"[{name}] {label} = {v:g} {unit} is outside the physical "
                                  f"range {low:g} to {high:g} {unit}; check its unit (SI).")


__all__ = ["PHYSICAL_RANGES", "check_physical_ranges"]
