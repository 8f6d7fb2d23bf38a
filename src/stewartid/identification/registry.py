"""The one list of identification methods, read by the command line, reproduction and reports.

Methods register with :func:`register_method`; discovery imports :data:`BUILTIN_MODULES` first.
"""

from __future__ import annotations

import dataclasses
import importlib
import pkgutil
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import Any

from stewartid.errors import ConfigError

#: Modules of the built-in methods, in registration order.
BUILTIN_MODULES = ("stewartid.identification.wavelet", "stewartid.identification.fourier",
                   "stewartid.identification.least_squares", "stewartid.verdict.consensus",
                   "stewartid.physical.estimator")


@dataclass(frozen=True)
class MethodSpec:
    """A registered identification method (or a preset of one).

    Attributes
    ----------
    name : str
        On the command line and in result files, e.g. ``"ls"``.
    display_name : str
        In tables, figures and reports.
    letter : str or None
        The paper's letter (``"A"``, ``"B"``), if it reports the method.
    reference : str
    description : str
        One line.
    color : str
        Matplotlib colour.
    estimator_class : type
    defaults : mapping
        Settings for ``estimator_class`` (a preset's; empty for a method).
    preset_of : str or None
        Method this preset configures.
    compared : bool
        Run by ``identify --method all`` and the reproduction.
    """

    name: str
    display_name: str
    letter: str | None
    reference: str
    description: str
    color: str
    estimator_class: type
    defaults: Mapping[str, Any] = field(default_factory=dict)
    preset_of: str | None = None
    compared: bool = True

    def create(self, **settings: Any) -> Any:
        """A new estimator with this spec's defaults updated by ``settings``."""
        return create_identifier(self.name, **settings)


@dataclass(frozen=True)
class Preset:
    """A named configuration of a method, given to :func:`register_method`."""

    settings: Mapping[str, Any]
    display_name: str
    description: str
    color: str
    letter: str | None = None


_REGISTRY: dict[str, MethodSpec] = {}
_discovered = False


def register(spec: MethodSpec) -> MethodSpec:
    """Add ``spec`` to the registry; returns it.

    Raises
    ------
    ConfigError
        If another class already registered the name.
    """
    known = _REGISTRY.get(spec.name)
    if known is not None and _qualified(known.estimator_class) != _qualified(spec.estimator_class):
        raise ConfigError(f"method name {spec.name!r} is already registered by "
                          f"{_qualified(known.estimator_class)}; choose another name.")
    if spec.preset_of is not None and spec.preset_of not in _REGISTRY:
        raise ConfigError(f"preset {spec.name!r} configures {spec.preset_of!r}, which is not "
                          "registered; register the method first.")
    _REGISTRY[spec.name] = dataclasses.replace(spec, defaults=dict(spec.defaults))
    return _REGISTRY[spec.name]


def register_method(*, name: str, display_name: str, reference: str, description: str,
                    color: str, letter: str | None = None,
                    presets: Mapping[str, Preset] | None = None,
                    compared: bool = True) -> Callable[[type], type]:
    """Class decorator registering an estimator class as method ``name`` (and its presets)."""

    def decorate(cls: type) -> type:
        cls.method = name
        register(MethodSpec(name, display_name, letter, reference, description, color, cls,
                            compared=compared))
        for preset_name, preset in (presets or {}).items():
            register(MethodSpec(preset_name, preset.display_name, preset.letter, reference,
                                preset.description, preset.color, cls,
                                dict(preset.settings), preset_of=name))
        return cls

    return decorate


def _qualified(cls: type) -> str:
    return f"{cls.__module__}.{cls.__qualname__}"


def _module_order() -> list[str]:
    package = importlib.import_module("stewartid.identification")
    found = sorted(f"stewartid.identification.{info.name}"
                   for info in pkgutil.iter_modules(package.__path__)
                   if not info.name.startswith("_"))
    return [*BUILTIN_MODULES, *(m for m in found if m not in BUILTIN_MODULES)]


def _discover() -> None:
    global _discovered
    if _discovered:
        return
    for module in _module_order():
        importlib.import_module(module)
    _discovered = True


def registered_methods() -> tuple[MethodSpec, ...]:
    """Every registered method, built-ins first, then presets."""
    _discover()
    modules = _module_order()
    position = {name: k for k, name in enumerate(_REGISTRY)}

    def module_rank(cls: type) -> int:
        # a method is a module or a subpackage of one of the discovered modules
        return next((k for k, m in enumerate(modules)
                     if cls.__module__ == m or cls.__module__.startswith(m + ".")),
                    len(modules))

    def order(spec: MethodSpec) -> tuple[bool, int, int]:
        return (spec.preset_of is not None, module_rank(spec.estimator_class), position[spec.name])

    return tuple(sorted(_REGISTRY.values(), key=order))


def method_spec(name: str) -> MethodSpec:
    """The registered method or preset ``name``.

    Raises
    ------
    ConfigError
        For an unknown name.
    """
    _discover()
    try:
        return _REGISTRY[name]
    except KeyError:
        names = ", ".join(spec.name for spec in registered_methods())
        raise ConfigError(f"unknown method {name!r}; expected one of {names}.") from None


def create_identifier(name: str, **settings: Any) -> Any:
    """A new estimator for method or preset ``name``, the preset's settings updated by ``settings``.

    Raises
    ------
    ConfigError
        For an unknown method or setting.
    """
    spec = method_spec(name)
    cls = spec.estimator_class
    valid = cls.param_names()
    unknown = [key for key in settings if key not in valid]
    if unknown:
        raise ConfigError(f"method {name!r} has no setting {unknown[0]!r}; its settings are "
                          f"{', '.join(valid)}.")
    return cls(**{**spec.defaults, **settings})


def estimates_only(name: str, **settings: Any) -> Any:
    """:func:`create_identifier` with the refits that only widen standard errors (the sampling
    check, the Coulomb signs' window check) off unless asked for: they cost extra fits."""
    accepted = method_spec(name).estimator_class.param_names()
    settings = {**{check: False for check in ("sampling_check", "sign_window_check")
                   if check in accepted}, **settings}
    return create_identifier(name, **settings)


__all__ = ["BUILTIN_MODULES", "MethodSpec", "Preset", "create_identifier", "estimates_only",
           "method_spec", "register", "register_method", "registered_methods"]
