"""Identification of the inertial and viscous matrices Mt, Bt of a Stewart platform.

One module per method, registered in :mod:`~stewartid.identification.registry`; submodules load on first use.
"""

from __future__ import annotations

import importlib
from typing import Any

_EXPORTS = {
    "BaseIdentifier": "base",
    "Experiment": "preparation",
    "prepare": "preparation",
    "solve_least_squares": "solvers",
    "IdentificationResult": "result",
    "comparison_rows": "result",
    "comparison_table": "result",
    "MethodSpec": "registry",
    "create_identifier": "registry",
    "method_spec": "registry",
    "registered_methods": "registry",
    "FourierIdentifier": "fourier",
    "LeastSquaresIdentifier": "least_squares",
    "WaveletIdentifier": "wavelet",
}


def __getattr__(name: str) -> Any:
    try:
        module = _EXPORTS[name]
    except KeyError:
        raise AttributeError(f"module 'stewartid.identification' has no attribute {name!r}") \
            from None
    return getattr(importlib.import_module(f"stewartid.identification.{module}"), name)


__all__ = sorted(_EXPORTS)
