"""stewartid: dynamic parameter identification of Stewart platforms.

Model (kinematics, two-part-leg dynamics with joint friction, linearisation), a hydraulic
plant simulator, and identification of the inertial and viscous matrices by the Fourier
method of Tian et al., the wavelet method of Zhang (2020, doi:10.3390/math8020257) and
time-domain least squares.
"""

from stewartid.errors import (
    ConfigError,
    DataError,
    IdentificationError,
    KinematicsError,
    StewartidError,
)
from stewartid.platform import Platform, load_platform

__version__ = "0.1.0"

__all__ = [
    "ConfigError",
    "DataError",
    "IdentificationError",
    "KinematicsError",
    "Platform",
    "StewartidError",
    "__version__",
    "load_platform",
]
