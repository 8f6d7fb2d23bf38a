"""The kernels of :mod:`stewartid.model.kernels` compiled with numba (cached on disk), calling
each other's compiled copies.
"""

from __future__ import annotations

from collections.abc import Callable
from types import FunctionType
from typing import Any

from numba import njit

from stewartid.model import kernels as _kernel_code


def _compile_all() -> dict[str, Callable[..., Any]]:
    # The copies share one globals namespace in which every kernel name is bound to its
    # compiled copy before the first (lazy) compilation resolves the calls; numba's disk cache
    # keys them by the source file and line in _kernel_code, so edits there invalidate it.
    kernels = {name: value for name, value in vars(_kernel_code).items()
               if isinstance(value, FunctionType) and value.__module__ == _kernel_code.__name__}
    namespace = dict(vars(_kernel_code))
    for name, function in kernels.items():
        copy = FunctionType(function.__code__, namespace, name, function.__defaults__)
        copy.__doc__ = function.__doc__
        namespace[name] = njit(cache=True)(copy)
    return {name: namespace[name] for name in kernels}


# leg_vector, model_terms, batch_terms, forward_dynamics_sample, ...: each kernel by its name
globals().update(_compile_all())
