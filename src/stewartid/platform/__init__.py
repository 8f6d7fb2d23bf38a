"""The platform description: a hexapod's geometry, inertia, friction, actuators, controller,
sensors and limits, read from TOML into a frozen :class:`~stewartid.platform.Platform`.
"""

from stewartid.platform.description import (
    COORDINATES,
    GRAVITY,
    Platform,
    load_platform,
    platform_from_mapping,
)

__all__ = ["COORDINATES", "GRAVITY", "Platform", "load_platform", "platform_from_mapping"]
