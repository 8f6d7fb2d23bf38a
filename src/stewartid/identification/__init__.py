"""Identification of the inertial and viscous matrices Mt, Bt of a Stewart platform.

One module per method over a small shared base; each method registers itself in
:mod:`~stewartid.identification.registry`:

- :mod:`~stewartid.identification.registry`: the one list of methods and presets;
- :mod:`~stewartid.identification.base`: the estimator base class (scikit-learn contract);
- :mod:`~stewartid.identification.preparation`: measured experiments with Jacobians and
  gravity at every measured pose;
- :mod:`~stewartid.identification.solvers`: weighted and errors-in-variables least squares;
- :mod:`~stewartid.identification.wavelet.intervals`: constant-direction intervals, (a, b) points;
- :mod:`~stewartid.identification.wavelet.noise`: measurement noise estimated from the data;
- :mod:`~stewartid.identification.result`: the result object and its JSON file;
- :mod:`~stewartid.identification.wavelet.estimator`: Method B (Zhang 2020);
- :mod:`~stewartid.identification.fourier`: Method A (Tian et al.), first-harmonic Fourier;
- :mod:`~stewartid.identification.least_squares`: time-domain least squares with Coulomb terms.

Submodules are imported on first use so that ``import stewartid.identification`` stays light.
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
