"""Identification of the inertial and viscous matrices Mt, Bt of a Stewart platform.

One module per method over a small shared base:

- :mod:`~stewartid.identification.base`: measured experiments (Jacobians and gravity at every
  measured pose), the shared least-squares solver, the estimator base class;
- :mod:`~stewartid.identification.results`: the result object and the paper's table layout;
- :mod:`~stewartid.identification.signals`: noise-aware differentiation;
- :mod:`~stewartid.identification.fourier`: Method A (Tian et al.), first-harmonic Fourier;
- :mod:`~stewartid.identification.wavelet`: Method B (Zhang 2020), wavelet transform on
  constant-direction intervals;
- :mod:`~stewartid.identification.least_squares`: time-domain least squares with Coulomb terms.

Submodules are imported on first use so that ``import stewartid.identification`` stays light.
"""

from __future__ import annotations

import importlib
from typing import Any

_EXPORTS = {
    "BaseIdentifier": "base",
    "Experiment": "base",
    "prepare": "base",
    "solve_least_squares": "base",
    "IdentificationResult": "results",
    "PAPER_ENTRIES": "results",
    "comparison_table": "results",
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
