"""The study file: a TOML Monte Carlo study or parameter sweep of the paper's six virtual
experiments over a grid of plant and excitation parameters, ``seeds`` noise seeds per point,
every listed method (format: ``docs/studies.md``)."""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping
from numbers import Integral
from pathlib import Path
from typing import Any

from stewartid.errors import ConfigError
from stewartid.fields import (
    TEXT,
    FieldSpec,
    InstanceOf,
    Interval,
    Options,
    check,
    nonnegative,
    positive,
)
from stewartid.files import read_toml
from stewartid.platform import Platform, load_platform
from stewartid.platform.sections import ACTUATOR_MODES

#: Parameters of a study point, in column order. ``coulomb`` and ``viscous`` default to the
#: platform's friction; ``noise_scale`` multiplies the reference sensor noise
#: (:func:`stewartid.simulation.sensors.reference_noise`).
PARAMETERS: dict[str, FieldSpec] = {
    "coulomb": FieldSpec("N m", "Coulomb friction per joint axis", nonnegative()),
    "viscous": FieldSpec("N m s/rad", "viscous friction per gimbal axis", nonnegative()),
    "noise_scale": FieldSpec("-", "multiple of the reference sensor noise", nonnegative()),
    "frequency": FieldSpec("Hz", "excitation sine frequency", positive()),
    "duration": FieldSpec("s", "record length of each experiment", positive()),
}

#: Defaults of the parameters that do not come from the platform.
DEFAULTS = {"noise_scale": 0.0, "frequency": 0.5, "duration": 20.0}

#: Constraints of the keys of ``[study]`` other than the methods and the point parameters.
STUDY_CONSTRAINTS = {
    "platform": InstanceOf(str, "\"paper\" or a TOML path"),
    "seeds": Interval(Integral, 1, None),
    "first_seed": Interval(Integral, 0, None),
    "actuator": Options(ACTUATOR_MODES),
    "title": TEXT,
}

#: Keys of ``[study]`` other than the point parameters.
STUDY_KEYS = ("methods", *STUDY_CONSTRAINTS)


@dataclasses.dataclass(frozen=True)
class StudySpec:
    """A validated study file.

    Attributes
    ----------
    platform : str
        ``"paper"`` or the platform TOML file's absolute path.
    methods : tuple of str
        Registered method or preset names, in file order.
    seeds : tuple of int
        Noise seeds run at every grid point.
    fixed : dict
        ``{parameter: value}`` not swept (defaults resolved).
    grid : dict
        ``{parameter: tuple of values}`` swept, in file order.
    actuator : str or None
        ``"hydraulic"`` or ``"ideal"``, overriding ``[hydraulics] mode``.
    method_settings : dict
        ``{method: {setting: value}}`` from ``[settings.*]``.
    title : str
    """

    platform: str
    methods: tuple[str, ...]
    seeds: tuple[int, ...]
    fixed: dict[str, float]
    grid: dict[str, tuple[float, ...]]
    actuator: str | None = None
    method_settings: dict[str, dict[str, Any]] = dataclasses.field(default_factory=dict)
    title: str = "Identification study"

    @property
    def size(self) -> int:
        """Number of tasks (grid points × seeds); each gives one row per method."""
        return math.prod(len(values) for values in self.grid.values()) * len(self.seeds)

    def load_platform(self) -> Platform:
        """The platform description the study runs on."""
        return load_platform(self.platform)

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready form (``study.json`` of the output folder)."""
        document = dataclasses.asdict(self)
        document["grid"] = {name: list(values) for name, values in self.grid.items()}
        document["seeds"] = list(self.seeds)
        document["methods"] = list(self.methods)
        return document

    def mismatch(self, other: Mapping[str, Any]) -> str | None:
        """The first setting (not grid, not seeds) where ``other`` (a :meth:`to_dict`) differs, or None."""
        mine = self.to_dict()
        for key in ("platform", "methods", "fixed", "actuator", "method_settings"):
            if mine[key] != other.get(key):
                return key
        if set(mine["grid"]) != set(other.get("grid", {})):
            return "grid parameters"
        return None


def _table(document: Mapping[str, Any], name: str, where: str) -> Mapping[str, Any]:
    table = document.get(name, {})
    if not isinstance(table, Mapping):
        raise ConfigError(f"{where}: [{name}] must be a TOML table; got {table!r}.")
    return table


def _methods(value: Any, where: str) -> tuple[str, ...]:
    from stewartid.identification.registry import method_spec

    if (not isinstance(value, list) or not value
            or not all(isinstance(name, str) for name in value)):
        raise ConfigError(f"{where}: [study] methods must be a non-empty list of method names, "
                          f"e.g. [\"wavelet\", \"fourier\"]; got {value!r}.")
    if len(set(value)) != len(value):
        raise ConfigError(f"{where}: [study] methods lists a method twice: {value!r}.")
    for name in value:
        method_spec(name)
    return tuple(value)


def _grid(table: Mapping[str, Any], where: str) -> dict[str, tuple[float, ...]]:
    grid = {}
    for name, values in table.items():
        if name not in PARAMETERS:
            raise ConfigError(f"{where}: [grid] has unknown key {name!r}; valid keys are: "
                              f"{', '.join(PARAMETERS)}.")
        if not isinstance(values, list) or not values:
            raise ConfigError(f"{where}: [grid] {name} must be a non-empty list of values in "
                              f"{PARAMETERS[name].unit}, e.g. {name} = [0.0, 1.0]; got "
                              f"{values!r}.")
        checked = tuple(PARAMETERS[name].check(f"{where}: [grid] {name}[{k}]", v)
                        for k, v in enumerate(values))
        if len(set(checked)) != len(checked):
            raise ConfigError(f"{where}: [grid] {name} lists a value twice: {values!r}.")
        grid[name] = checked
    return grid


def _method_settings(table: Mapping[str, Any], methods: tuple[str, ...], where: str
                     ) -> dict[str, dict[str, Any]]:
    from stewartid.identification.registry import create_identifier

    settings = {}
    for name, values in table.items():
        if name not in methods:
            raise ConfigError(f"{where}: [settings.{name}] names a method the study does not "
                              f"run; [study] methods are {', '.join(methods)}.")
        if not isinstance(values, Mapping):
            raise ConfigError(f"{where}: [settings.{name}] must be a table of settings.")
        create_identifier(name, **values)
        settings[name] = dict(values)
    return settings


def parse_study(document: Mapping[str, Any], where: str = "study file",
                base: str | Path = ".") -> StudySpec:
    """Validate a decoded study file; ``where`` names it in errors, ``base`` anchors a relative platform.

    Raises
    ------
    ConfigError
        An unknown table or key, a missing, mistyped or out-of-range value, a parameter both fixed
        and swept, an unknown method or setting, or an unloadable platform.
    """
    unknown = sorted(set(document) - {"study", "grid", "settings"})
    if unknown:
        raise ConfigError(f"{where}: unknown table [{unknown[0]}]; valid tables are [study], "
                          "[grid] and [settings.METHOD].")
    study = _table(document, "study", where)
    valid = (*STUDY_KEYS, *PARAMETERS)
    for key in study:
        if key not in valid:
            raise ConfigError(f"{where}: [study] has unknown key {key!r}; valid keys are: "
                              f"{', '.join(valid)}.")
    if "methods" not in study:
        raise ConfigError(f"{where}: [study] is missing required key 'methods' (the methods "
                          "to run, e.g. methods = [\"wavelet\", \"fourier\", \"ls\"]).")
    methods = _methods(study["methods"], where)
    for key, constraint in STUDY_CONSTRAINTS.items():
        if key in study:
            check(f"{where}: [study] {key}", study[key], [constraint])
    platform = study.get("platform", "paper")
    if platform != "paper":
        platform = str((Path(base) / platform).resolve())
    description = load_platform(platform)
    grid = _grid(_table(document, "grid", where), where)
    both = [name for name in grid if name in study]
    if both:
        raise ConfigError(f"{where}: {both[0]!r} is both fixed in [study] and swept in [grid]; "
                          "keep one.")
    defaults = {**DEFAULTS, "coulomb": description.friction.coulomb,
                "viscous": description.friction.gimbal_viscous}
    fixed = {name: PARAMETERS[name].check(f"{where}: [study] {name}", study[name])
             if name in study else float(defaults[name])
             for name in PARAMETERS if name not in grid}
    seeds, first_seed = study.get("seeds", 1), study.get("first_seed", 0)
    return StudySpec(platform=platform, methods=methods,
                     seeds=tuple(range(first_seed, first_seed + seeds)), fixed=fixed,
                     grid=grid, actuator=study.get("actuator"),
                     method_settings=_method_settings(_table(document, "settings", where),
                                                      methods, where),
                     title=study.get("title", "Identification study"))


def load_study(path: str | Path) -> StudySpec:
    """Read and validate a study file (TOML).

    Raises
    ------
    ConfigError
        Missing file, invalid TOML, or :func:`parse_study` fails.
    """
    path = Path(path)
    if not path.is_file():
        raise ConfigError(f"study file {str(path)!r} not found; give the path of a TOML study "
                          "file (see docs/studies.md).")
    return parse_study(read_toml(path, "study file"), str(path), path.parent)


__all__ = ["DEFAULTS", "PARAMETERS", "STUDY_CONSTRAINTS", "StudySpec", "load_study",
           "parse_study"]
