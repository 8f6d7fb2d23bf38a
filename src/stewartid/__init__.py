"""stewartid: dynamic parameter identification of Stewart platforms.

The inertial and viscous matrices Mt, Bt of the linearised model by the wavelet method of
Zhang (2020, doi:10.3390/math8020257), the Fourier method it is compared with and time-domain
least squares, and the rigid-body model's physical parameters; a platform model, a hydraulic
plant simulator and reports.

>>> import stewartid as sid
>>> platform = sid.load_platform("paper")
>>> experiments = sid.simulate_experiments(platform, coulomb=5.0, duration_s=6.0).datasets
>>> comparison = sid.compare_methods(experiments, platform)     # doctest: +SKIP
>>> comparison.trusted, comparison.M, comparison.std_errors["M"]  # doctest: +SKIP

Names are imported on first use, so that ``import stewartid`` stays light.
"""

from __future__ import annotations

import importlib
from typing import Any

from stewartid.errors import (
    ConfigError,
    DataError,
    IdentificationError,
    KinematicsError,
    StewartidError,
)
from stewartid.platform import Platform, load_platform

__version__ = "0.1.0"

_EXPORTS = {
    # data
    "Dataset": "stewartid.datasets",
    "LogFormat": "stewartid.datasets",
    "read_experiments": "stewartid.datasets",
    # model
    "nominal_matrices": "stewartid.model.linearization",
    # simulation
    "SensorNoise": "stewartid.simulation",
    "degrade": "stewartid.simulation",
    "reference_noise": "stewartid.simulation.sensors",
    "simulate_experiments": "stewartid.simulation",
    # identification
    "AveragingPolicy": "stewartid.identification.averaging",
    "IdentificationResult": "stewartid.identification.result",
    "create_identifier": "stewartid.identification.registry",
    "registered_methods": "stewartid.identification.registry",
    "FourierIdentifier": "stewartid.identification.fourier",
    "LeastSquaresIdentifier": "stewartid.identification.least_squares",
    "WaveletIdentifier": "stewartid.identification.wavelet",
    "ConsensusIdentifier": "stewartid.verdict.consensus",
    "PhysicalIdentifier": "stewartid.physical.estimator",
    # comparison, verdict, report
    "Comparison": "stewartid.comparison",
    "PhysicalRequest": "stewartid.comparison",
    "compare_methods": "stewartid.comparison",
    "Verdict": "stewartid.verdict",
    "VerdictPolicy": "stewartid.verdict",
    "write_report": "stewartid.reports.identification.report",
}


def __getattr__(name: str) -> Any:
    try:
        module = _EXPORTS[name]
    except KeyError:
        raise AttributeError(f"module 'stewartid' has no attribute {name!r}") from None
    return getattr(importlib.import_module(module), name)


def __dir__() -> list[str]:
    return sorted(__all__)


__all__ = ["ConfigError", "DataError", "IdentificationError", "KinematicsError", "Platform",
           "StewartidError", "__version__", "load_platform", *sorted(_EXPORTS)]
