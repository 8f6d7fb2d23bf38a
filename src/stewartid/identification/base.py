"""The estimator base class every identifier derives from (scikit-learn estimator contract)."""

from __future__ import annotations

import inspect
from collections.abc import Sequence
from numbers import Integral
from pathlib import Path
from typing import Any, ClassVar

from stewartid.datasets.dataset import Dataset
from stewartid.errors import ConfigError, NotFittedError
from stewartid.fields import Constraint, Interval, positive, validate_parameters
from stewartid.identification.preparation import resolve_datasets, resolve_platform
from stewartid.identification.result import IdentificationResult, with_model_floor
from stewartid.identification.sampling import check_sampling
from stewartid.platform import Platform


class BaseIdentifier:
    """Base class of the identifiers.

    Learned attributes set by :meth:`fit`: ``M_``, ``B_`` (6, 6), ``std_errors_`` (dict ``"M"``, ``"B"``;
    widened where sampling limits them, at least the model's approximation floor of
    :func:`~stewartid.identification.result.with_model_floor`), ``condition_number_``,
    ``result_`` (IdentificationResult), plus the method-specific ones a subclass's ``_fit`` returns.
    """

    #: Registry name of the method, stored in the result (set by ``register_method``).
    method: ClassVar[str] = "base"

    #: Constraints of the settings, by name (a setting is valid if it satisfies one of its
    #: list; None allows None), checked by :meth:`fit`.
    _parameter_constraints: ClassVar[dict[str, Sequence[Constraint | None]]] = {}

    @classmethod
    def param_names(cls) -> list[str]:
        """Names of the settings ``__init__`` takes, in its order."""
        signature = inspect.signature(cls.__init__)
        return [name for name in signature.parameters if name != "self"]

    def get_params(self, deep: bool = True) -> dict[str, Any]:
        """Settings given to ``__init__`` (``deep`` is accepted for scikit-learn)."""
        return {name: getattr(self, name) for name in self.param_names()}

    def set_params(self, **params: Any) -> BaseIdentifier:
        """Change settings; returns self.

        Raises
        ------
        ConfigError
            For a name that is not a setting of this identifier.
        """
        valid = self.param_names()
        for key, value in params.items():
            if key not in valid:
                raise ConfigError(f"{type(self).__name__} has no setting {key!r}; valid "
                                  f"settings are {', '.join(valid)}.")
            setattr(self, key, value)
        return self

    def __repr__(self) -> str:
        args = ", ".join(f"{k}={v!r}" for k, v in self.get_params().items())
        return f"{type(self).__name__}({args})"

    def __getattr__(self, name: str) -> Any:
        # only called when normal lookup fails: a learned attribute read before fit
        if name.endswith("_") and not name.startswith("_"):
            raise NotFittedError(f"this {type(self).__name__} is not fitted yet: call "
                                 f"fit(datasets, platform) before reading {name!r}.")
        raise AttributeError(f"{type(self).__name__!r} object has no attribute {name!r}")

    def _settings(self) -> dict[str, Any]:
        """The settings a result records: the parameters (tuples as lists), without the worker
        count, which changes no result."""
        return {k: (list(v) if isinstance(v, tuple) else v) for k, v in self.get_params().items()
                if k != "jobs"}

    def _validate_params(self) -> None:
        """Check the settings against ``_parameter_constraints``; raises ConfigError."""
        validate_parameters(self._parameter_constraints, self.get_params(), type(self).__name__)

    def fit(self, datasets: Any, platform: Platform | str | Path) -> BaseIdentifier:
        """Identify Mt and Bt from experiments; returns self.

        Parameters
        ----------
        datasets : Dataset, path, or sequence of them
            One per experiment.
        platform : Platform, 'paper' or TOML path
        """
        from stewartid.parallel import one_blas_thread

        self._validate_params()
        platform = resolve_platform(platform)
        data = resolve_datasets(datasets, platform)
        with one_blas_thread():
            result, learned = self._fit(data, platform)
            if getattr(self, "sampling_check", False):
                result, learned = self._check_sampling(data, platform, result, learned)
            result = with_model_floor(result)
        attributes = {"result_": result, "M_": result.M, "B_": result.B,
                      "std_errors_": {"M": result.std_errors_M, "B": result.std_errors_B},
                      "condition_number_": result.condition_number, **learned}
        for name, value in attributes.items():
            if not name.endswith("_"):
                raise RuntimeError(f"{type(self).__name__}._fit returned the learned "
                                   f"attribute {name!r}, whose name does not end in '_'.")
            setattr(self, name, value)
        return self

    def _fit(self, datasets: list[Dataset], platform: Platform
             ) -> tuple[IdentificationResult, dict[str, Any]]:
        """The result and the method-specific learned attributes."""
        raise NotImplementedError

    def _check_sampling(self, datasets: list[Dataset], platform: Platform,
                        result: IdentificationResult, learned: dict[str, Any]
                        ) -> tuple[IdentificationResult, dict[str, Any]]:
        """``_fit``'s output, standard errors widened where sampling limits them."""
        return check_sampling(lambda part: self._fit(part, platform)[0], datasets,
                              result), learned


#: Constraints of the Savitzky-Golay settings of the time-domain methods: the window (s),
#: None for the default, and the polynomial order.
DIFFERENTIATION_CONSTRAINTS: dict[str, list[Constraint | None]] = {
    "window": [positive(), None],
    "order": [Interval(Integral, 3, None)],
}


__all__ = ["DIFFERENTIATION_CONSTRAINTS", "BaseIdentifier"]
