"""The platform description: geometry, inertia, friction, actuators, controller, sensors and
limits of a hexapod, read from TOML into a frozen :class:`Platform`.

- :mod:`~stewartid.platform.description`: :class:`Platform`, :func:`load_platform`;
- :mod:`~stewartid.platform.sections`: one frozen dataclass per TOML section, each field with
  its unit, description and constraint (including its physical range).
"""

from stewartid.platform.description import (
    COORDINATES,
    GRAVITY,
    Platform,
    load_platform,
    platform_from_mapping,
)

__all__ = ["COORDINATES", "GRAVITY", "Platform", "load_platform", "platform_from_mapping"]
