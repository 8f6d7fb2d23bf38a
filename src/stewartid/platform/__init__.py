"""The platform description: geometry, inertia, friction, actuators, controller, sensors and
limits of a hexapod, read from TOML into a frozen :class:`Platform`.

- :mod:`~stewartid.platform.description`: :class:`Platform`, :func:`load_platform`;
- :mod:`~stewartid.platform.sections`: one frozen dataclass per TOML section, each field with
  its unit, description and constraint.
"""

from stewartid.platform.description import (
    COORDINATES,
    GRAVITY,
    REQUIRED_SECTIONS,
    Platform,
    load_platform,
    platform_from_mapping,
)
from stewartid.platform.sections import (
    Controller,
    Friction,
    Geometry,
    Hydraulics,
    Inertia,
    Limits,
    Sensors,
)

__all__ = ["COORDINATES", "GRAVITY", "REQUIRED_SECTIONS", "Controller", "Friction", "Geometry",
           "Hydraulics", "Inertia", "Limits", "Platform", "Sensors", "load_platform",
           "platform_from_mapping"]
