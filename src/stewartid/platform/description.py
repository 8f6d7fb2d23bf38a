"""The platform description: a frozen :class:`Platform` from TOML (``docs/platform-format.md``) or the
``paper`` preset (Zhang 2020, Tables 1-2), refusing bad keys, types and unbuildable geometry when
built. Paper frame: x forward, y right, z down, origin at the base joint plane's centre.
"""

from __future__ import annotations

import dataclasses
import math
from importlib import resources
from pathlib import Path
from typing import Any, NamedTuple

import numpy as np

from stewartid.errors import ConfigError
from stewartid.fields import section_from_mapping, section_to_mapping
from stewartid.files import read_toml
from stewartid.model import parameters as layout
from stewartid.platform.sections import (
    Actuator,
    Controller,
    Friction,
    Geometry,
    Hydraulics,
    Inertia,
    Limits,
    Payload,
    Sensors,
)

#: Standard gravity used throughout the model (m/s^2), as in the paper's model.
GRAVITY = 9.81

#: Names of the six generalized coordinates of the pose q, in the paper's order (m, m, m,
#: rad, rad, rad): the one definition used by data files, identifiers, tables and figures.
COORDINATES = ("x", "y", "z", "rx", "ry", "rz")


#: TOML sections of a platform description, in file order, with their dataclass.
SECTIONS: dict[str, type] = {cls.section: cls for cls in (Geometry, Inertia, Payload, Friction,
                                                          Actuator, Hydraulics, Controller,
                                                          Sensors, Limits)}
#: Sections that must be present in every file; the others take their documented defaults.
REQUIRED_SECTIONS = ("geometry", "inertia", "friction")
# [payload] alone has no defaults: its absence means no payload (Platform.payload None).
# [actuator] absent is a hydraulic leg with nothing along it, and is written as absent, so that
# the descriptions (and the data files' meta.json) of hydraulic platforms stay as they were.


class MovingBody(NamedTuple):
    """The moving body, platform and payload, as one rigid body (platform frame).

    Attributes
    ----------
    mass : float
        kg.
    com : ndarray, shape (3,)
        From the reference point (m).
    inertia : ndarray, shape (3, 3)
        About the reference point (kg m^2).
    """

    mass: float
    com: np.ndarray
    inertia: np.ndarray


@dataclasses.dataclass(frozen=True)
class Platform:
    """A complete, validated description of a Stewart platform.

    Attributes
    ----------
    geometry, inertia, friction : Geometry, Inertia, Friction
        The required sections.
    actuator : Actuator
        Leg actuators: kind, reflected mass and friction along the legs, motor constants;
        absent, a hydraulic leg adding nothing along the leg.
    hydraulics, controller, sensors : Hydraulics, Controller, Sensors
        Plant simulator settings; documented defaults when absent.
    limits : Limits
        Operating limits of excitation design; derived defaults when absent.
    payload : Payload or None
        A rigid payload moving with the platform; None when absent.
    name : str
        "paper" for the preset, the file stem otherwise.
    """

    geometry: Geometry
    inertia: Inertia
    friction: Friction
    actuator: Actuator = dataclasses.field(default_factory=Actuator)
    hydraulics: Hydraulics = dataclasses.field(default_factory=Hydraulics)
    controller: Controller = dataclasses.field(default_factory=Controller)
    sensors: Sensors = dataclasses.field(default_factory=Sensors)
    limits: Limits = dataclasses.field(default_factory=Limits)
    payload: Payload | None = None
    name: str = "platform"

    def __post_init__(self) -> None:
        # each section checked its own fields (sign, physical range) when it was built
        _check_buildable(self)

    # -- derived geometry -------------------------------------------------------------------
    @property
    def upper_joints(self) -> np.ndarray:
        """Upper gimbal points (6, 3) (m), row k leg k+1, platform frame from the reference point."""
        g = self.geometry
        angles = _upper_angles(g.upper_half_angle)
        return np.column_stack([
            g.upper_radius * np.cos(angles),
            g.upper_radius * np.sin(angles),
            np.full(6, g.reference_height),
        ])

    @property
    def base_joints(self) -> np.ndarray:
        """Lower gimbal points (6, 3) (m), row k leg k+1, fixed frame; z = 0 is their plane."""
        g = self.geometry
        angles = _lower_angles(g.lower_half_angle)
        return np.column_stack([
            g.lower_radius * np.cos(angles),
            g.lower_radius * np.sin(angles),
            np.zeros(6),
        ])

    @property
    def neutral_pose(self) -> np.ndarray:
        """Neutral pose q (m, rad): z = -(neutral_height + reference_height)."""
        g = self.geometry
        return np.array([0.0, 0.0, -(g.neutral_height + g.reference_height), 0.0, 0.0, 0.0])

    @property
    def neutral_leg_length(self) -> float:
        """Length of each leg at the neutral pose (m)."""
        return float(np.linalg.norm(self.upper_joints[0] + self.neutral_pose[:3]
                                    - self.base_joints[0]))

    @property
    def hydraulic_legs(self) -> bool:
        """Whether the simulator drives the legs as valve-controlled cylinders: a hydraulic
        ``[actuator]`` in ``[hydraulics] mode = "hydraulic"``. Otherwise each leg is a servo motor
        (:attr:`electric_legs`) or, in mode "ideal", applies its demanded force exactly.
        """
        return self.actuator.kind == "hydraulic" and self.hydraulics.mode == "hydraulic"

    @property
    def electric_legs(self) -> bool:
        """Whether the simulator drives the legs as servo motors on ball screws, each with its
        current loop: an electric ``[actuator]`` unless ``[hydraulics] mode = "ideal"``.
        """
        return self.actuator.kind == "electric" and self.hydraulics.mode == "hydraulic"

    @property
    def moving_body(self) -> MovingBody:
        """Platform and payload as one rigid body about the reference point (parallel-axis theorem); without
        a payload exactly the platform, centre of mass at the reference point, inertia diagonal.
        """
        i, p = self.inertia, self.payload
        inertia = np.diag(np.asarray(i.platform_inertia, dtype=float))
        if p is None:
            return MovingBody(i.platform_mass, np.zeros(3), inertia)
        c = np.asarray(p.com, dtype=float)
        mass = i.platform_mass + p.mass
        shifted = p.inertia_matrix + p.mass * (c @ c * np.eye(3) - np.outer(c, c))
        return MovingBody(mass, p.mass * c / mass, inertia + shifted)

    def parameters(self) -> np.ndarray:
        """Mass and friction parameters (N_PARAMETERS,) as :mod:`stewartid.model.parameters` lays out."""
        i, f, body = self.inertia, self.friction, self.moving_body
        packed = np.empty(layout.N_PARAMETERS)
        packed[layout.MASS] = body.mass
        packed[[layout.IXX, layout.IYY, layout.IZZ]] = np.diag(body.inertia)
        packed[[layout.IXY, layout.IXZ, layout.IYZ]] = body.inertia[[0, 0, 1], [1, 2, 2]]
        packed[[layout.COM_X, layout.COM_Y, layout.COM_Z]] = body.com
        packed[layout.M_UPPER], packed[layout.M_LOWER] = i.upper_leg_mass, i.lower_leg_mass
        packed[layout.D_UPPER], packed[layout.D_LOWER] = i.upper_leg_com, i.lower_leg_com
        packed[layout.I_UPPER], packed[layout.I_LOWER] = i.upper_leg_inertia, i.lower_leg_inertia
        packed[layout.VISCOUS], packed[layout.COULOMB] = f.gimbal_viscous, f.coulomb
        packed[layout.GRAVITY] = GRAVITY
        a = self.actuator
        packed[layout.REFLECTED_MASS] = a.reflected_mass
        packed[layout.LEG_VISCOUS], packed[layout.LEG_COULOMB] = a.viscous, a.coulomb
        return packed

    # -- construction and serialisation -----------------------------------------------------
    def replace(self, **sections_or_values: Any) -> Platform:
        """A copy with whole sections, or single values as ``section__key=value``, replaced.

        Examples
        --------
        >>> paper = load_platform("paper")
        >>> paper.replace(friction__coulomb=30.0).friction.coulomb
        30.0
        """
        updates: dict[str, Any] = {}
        tables: dict[str, dict[str, Any]] = {}
        for key, value in sections_or_values.items():
            if "__" in key:
                section, field = key.split("__", 1)
                if section not in tables:
                    current = sections_or_values.get(section, getattr(self, section))
                    # None: an absent [payload], built from the keys given here alone
                    tables[section] = {} if current is None else section_to_mapping(current)
                tables[section][field] = value
            else:
                updates[key] = value
        # each section built once, with all its new values (a new [payload] needs every key)
        for section, table in tables.items():
            updates[section] = section_from_mapping(SECTIONS[section], table, section)
        return dataclasses.replace(self, **updates)

    def to_dict(self) -> dict[str, Any]:
        """All sections as plain dictionaries (JSON/TOML ready); an absent payload and a default
        [actuator] (hydraulic, nothing along the legs) left out.
        """
        return {name: section_to_mapping(getattr(self, name)) for name in SECTIONS
                if getattr(self, name) is not None
                and not (name == "actuator" and self.actuator == Actuator())}

    def to_toml(self) -> str:
        """The description as TOML text that :func:`load_platform` reads back identically."""
        lines = [f"# stewartid platform description: {self.name}"]
        for name, table in self.to_dict().items():
            lines.append(f"\n[{name}]")
            for key, value in table.items():
                if value is not None:  # a derived default: TOML has no null
                    lines.append(f"{key} = {_toml_value(value)}")
        return "\n".join(lines) + "\n"


def _toml_value(value: Any) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, str):
        return '"' + value.replace("\\", "\\\\").replace('"', '\\"') + '"'
    if isinstance(value, list | tuple):
        return "[" + ", ".join(_toml_value(v) for v in value) + "]"
    return repr(value)


def _upper_angles(half_angle: float) -> np.ndarray:
    centres = np.repeat(np.deg2rad([0.0, 120.0, 240.0]), 2)
    return centres + np.tile([-half_angle, half_angle], 3)


def _lower_angles(half_angle: float) -> np.ndarray:
    centres = np.deg2rad([300.0, 60.0, 60.0, 180.0, 180.0, 300.0])
    return centres + half_angle * np.array([1.0, -1.0, 1.0, -1.0, 1.0, -1.0])


def _check_buildable(platform: Platform) -> None:
    """Refuse geometries whose six legs cannot be built as the numbering assumes."""
    g = platform.geometry
    for key in ("upper_half_angle", "lower_half_angle"):
        value = getattr(g, key)
        if not value < math.pi / 6:
            raise ConfigError(
                f"[geometry] {key} = {value} rad: the two joints of a pair must stay within "
                f"their 120 deg sector, so it must be < pi/6 = {math.pi / 6:.4f} rad."
            )
    length = platform.neutral_leg_length
    for key in ("upper_leg_com", "lower_leg_com"):
        value = getattr(platform.inertia, key)
        if not value < length:
            raise ConfigError(
                f"[inertia] {key} = {value} m lies beyond the leg, whose neutral length is "
                f"{length:.4f} m; give the distance from the gimbal point along the leg."
            )


def platform_from_mapping(document: Any, name: str = "platform") -> Platform:
    """Build a :class:`Platform` from a parsed TOML document.

    Raises
    ------
    ConfigError
        If a section is missing or unknown, or any key fails validation.
    """
    if not isinstance(document, dict):
        raise ConfigError("a platform description must be a TOML document of tables.")
    unknown = sorted(set(document) - set(SECTIONS))
    if unknown:
        raise ConfigError(
            f"unknown section [{unknown[0]}]; valid sections are: "
            + ", ".join(f"[{s}]" for s in SECTIONS) + "."
        )
    for section in REQUIRED_SECTIONS:
        if section not in document:
            raise ConfigError(f"missing section [{section}]; see docs/platform-format.md.")
    sections = {
        key: section_from_mapping(cls, document[key], key)
        for key, cls in SECTIONS.items() if key in document
    }
    return Platform(name=name, **sections)


def load_platform(source: str | Path) -> Platform:
    """Load a platform description.

    Parameters
    ----------
    source : str or Path
        ``"paper"`` for the preset of Zhang (2020), Tables 1-2, or a TOML file's path.

    Returns
    -------
    Platform

    Raises
    ------
    ConfigError
        If the file does not exist, is not valid TOML, or fails validation.
    """
    if str(source) == "paper":
        with resources.as_file(resources.files("stewartid") / "data/paper.toml") as path:
            return _build(read_toml(path, "the paper preset"), "paper", "the paper preset")
    path = Path(source)
    if not path.is_file():
        raise ConfigError(
            f"platform file {str(path)!r} not found; give a TOML file or 'paper' for the preset."
        )
    return _build(read_toml(path, "platform file"), path.stem, str(path))


def _build(document: dict[str, Any], name: str, where: str) -> Platform:
    try:
        return platform_from_mapping(document, name)
    except ConfigError as exc:
        raise ConfigError(f"{where}: {exc}") from None
