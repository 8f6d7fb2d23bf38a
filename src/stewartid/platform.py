"""The platform description: geometry, inertia and joint friction of a 6-6 Stewart platform.

A :class:`Platform` is a frozen dataclass built from a TOML file (format in
``docs/platform-format.md``) or from the shipped ``paper`` preset (Zhang 2020, Tables 1-2).
It checks itself when built: unknown keys, missing keys, wrong types, negative masses and
geometries whose legs cannot be built are refused with one message naming the key.

Frame (the paper's): x forward, y right, z down; origin at the centre of the base joint
plane. Leg numbering follows ``docs/conventions.md`` and is part of the data format.
"""

from __future__ import annotations

import dataclasses
import math
import tomllib
from importlib import resources
from pathlib import Path
from typing import Any

import numpy as np

from stewartid.config import read_toml_text, section_from_mapping, section_to_mapping, spec
from stewartid.errors import ConfigError
from stewartid.platform_ranges import check_physical_ranges

#: Standard gravity used throughout the model (m/s^2), as in the paper's model.
GRAVITY = 9.81

#: Names of the six generalized coordinates of the pose q, in the paper's order (m, m, m,
#: rad, rad, rad): the one definition used by data files, identifiers, tables and figures.
COORDINATES = ("x", "y", "z", "rx", "ry", "rz")


@dataclasses.dataclass(frozen=True)
class Geometry:
    """Joint layout of a 6-6 hexapod (paper, Table 1)."""

    upper_radius: float = spec("m", "radius of the circle through the upper (platform) joints")
    lower_radius: float = spec("m", "radius of the circle through the lower (base) joints")
    neutral_height: float = spec("m", "lower joint plane to upper joint plane at neutral")
    upper_half_angle: float = spec("rad", "half the angle between the two joints of an upper pair")
    lower_half_angle: float = spec("rad", "half the angle between the two joints of a lower pair")
    reference_height: float = spec(
        "m", "upper joint plane to the reference point (platform centre of mass), away from "
        "the base", check="nonnegative")


@dataclasses.dataclass(frozen=True)
class Inertia:
    """Masses and inertias of the platform and of the two parts of each leg (paper, Table 2)."""

    platform_mass: float = spec("kg", "mass of the moving platform")
    platform_inertia: tuple[float, float, float] = spec(
        "kg m^2", "principal inertias of the platform about its centre of mass", length=3)
    upper_leg_mass: float = spec("kg", "mass of a leg's upper part (piston rod)",
                                 check="nonnegative")
    lower_leg_mass: float = spec("kg", "mass of a leg's lower part (cylinder)",
                                 check="nonnegative")
    upper_leg_com: float = spec("m", "upper gimbal point to the upper part's centre of mass",
                                check="nonnegative")
    lower_leg_com: float = spec("m", "lower gimbal point to the lower part's centre of mass",
                                check="nonnegative")
    upper_leg_inertia: float = spec(
        "kg m^2", "transverse inertia of the upper part about its centre of mass",
        check="nonnegative")
    lower_leg_inertia: float = spec(
        "kg m^2", "transverse inertia of the lower part about its centre of mass",
        check="nonnegative")


@dataclasses.dataclass(frozen=True)
class Friction:
    """Joint friction: viscous on the four gimbal axes, Coulomb on all five rotational axes."""

    gimbal_viscous: float = spec("N m s/rad", "viscous coefficient of each gimbal axis",
                                 check="nonnegative")
    coulomb: float = spec("N m", "Coulomb friction torque of each rotational joint axis",
                          check="nonnegative", default=0.0)


#: Actuator models understood by [hydraulics] mode.
ACTUATOR_MODES = ("hydraulic", "ideal")


@dataclasses.dataclass(frozen=True)
class Hydraulics:
    """Hydraulic actuators of the legs: servo-valve, cylinder and oil (same for all six legs).

    Defaults size a flight-simulator class hexapod of about 14 t: a 21 MPa supply, 100/70 mm
    cylinders with 1 m stroke (mid-stroke at the neutral pose; about 165 kN extending force
    against a static load near 31 kN per leg), 200 L/min servo-valves of 80 Hz bandwidth and
    an effective bulk modulus of 1.2 GPa (oil with some hose compliance). With these values
    the hydraulic natural frequency of a leg is about 15-25 Hz.
    """

    mode: str = spec("-", "'hydraulic' (valve, cylinder, oil) or 'ideal' (the demanded force "
                     "is applied exactly)", check="any", default="hydraulic")
    supply_pressure: float = spec("Pa", "supply pressure p_s", default=21.0e6)
    return_pressure: float = spec("Pa", "return (tank) pressure p_r", check="nonnegative",
                                  default=0.5e6)
    bore_diameter: float = spec("m", "cylinder bore (piston side area A_A = pi D^2 / 4)",
                                default=0.100)
    rod_diameter: float = spec("m", "piston rod diameter (rod side area A_B = A_A - pi d^2/4)",
                               default=0.070)
    stroke: float = spec("m", "usable stroke, centred on the neutral leg length", default=1.0)
    dead_volume: float = spec("m^3", "oil volume of each chamber at its end of stroke, with "
                              "the hose to the valve", default=0.5e-3)
    bulk_modulus: float = spec("Pa", "effective bulk modulus of the oil (with hose "
                               "compliance)", default=1.2e9)
    valve_rated_flow: float = spec("m^3/s", "valve flow at full opening and rated pressure "
                                   "drop (200 L/min)", default=200.0 / 60000.0)
    valve_rated_pressure_drop: float = spec("Pa", "total valve pressure drop (both metering "
                                            "edges) at which the rated flow is given",
                                            default=7.0e6)
    valve_bandwidth: float = spec("Hz", "natural frequency of the spool (second-order model)",
                                  default=80.0)
    valve_damping: float = spec("-", "damping ratio of the spool", default=0.7)
    leakage: float = spec("m^3/(s Pa)", "internal (cross-piston) leakage coefficient",
                          check="nonnegative", default=2.0e-13)
    orifice_transition_pressure: float = spec(
        "Pa", "pressure drop below which orifice flow turns from turbulent (square root) to "
        "laminar (linear), which keeps the flow law differentiable at zero drop",
        default=1.0e5)

    def __post_init__(self) -> None:
        if self.mode not in ACTUATOR_MODES:
            raise ConfigError(f"[hydraulics] mode must be one of {ACTUATOR_MODES}; "
                              f"got {self.mode!r}.")
        if not self.rod_diameter < self.bore_diameter:
            raise ConfigError(f"[hydraulics] rod_diameter = {self.rod_diameter} m must be "
                              f"smaller than bore_diameter = {self.bore_diameter} m.")
        if not self.return_pressure < self.supply_pressure:
            raise ConfigError(f"[hydraulics] return_pressure = {self.return_pressure} Pa must "
                              f"be below supply_pressure = {self.supply_pressure} Pa.")

    @property
    def piston_area(self) -> float:
        """Piston-side area A_A (m^2)."""
        return math.pi * self.bore_diameter ** 2 / 4.0

    @property
    def annulus_area(self) -> float:
        """Rod-side (annulus) area A_B (m^2)."""
        return math.pi * (self.bore_diameter ** 2 - self.rod_diameter ** 2) / 4.0


@dataclasses.dataclass(frozen=True)
class Controller:
    """Leg-length servo: PID on each leg length giving a force demand, plus an inner force loop.

    The PID output is the force demand of the leg (N). In ``ideal`` actuator mode it is
    applied exactly; in ``hydraulic`` mode an inner loop opens the valve in proportion to the
    force error (force from the chamber pressures). Defaults give a position bandwidth of
    about 5 Hz per leg for the paper's platform, so that the 0.5 Hz excitation is tracked to
    about 1 % of its amplitude.
    """

    proportional_gain: float = spec("N/m", "PID proportional gain on the leg-length error",
                                    default=1.0e7)
    integral_gain: float = spec("N/(m s)", "PID integral gain", check="nonnegative",
                                default=5.0e7)
    derivative_gain: float = spec("N s/m", "PID derivative gain (on the leg-rate error)",
                                  check="nonnegative", default=4.0e5)
    gravity_feedforward: bool = spec("-", "add the static leg forces that hold the commanded "
                                     "pose against gravity", check="any", default=True)
    force_loop_gain: float = spec("1/N", "inner force loop (hydraulic mode): valve opening, "
                                  "as a fraction of full opening, per newton of force error",
                                  default=1.0e-5)


@dataclasses.dataclass(frozen=True)
class Sensors:
    """Sampling and sensor imperfections of the recorded data (defaults: ideal sensors)."""

    sample_rate: float = spec("Hz", "sampling rate of the recorded signals", default=1000.0)
    length_noise: float = spec("m", "standard deviation of the leg-length sensor noise",
                               check="nonnegative", default=0.0)
    length_bias: float = spec("m", "constant offset of every leg-length sensor", check="any",
                              default=0.0)
    length_resolution: float = spec("m", "quantisation step of the leg-length sensors "
                                    "(0: none)", check="nonnegative", default=0.0)
    force_noise: float = spec("N", "standard deviation of the actuator force measurement "
                              "noise (force-equivalent of the pressure transducers)",
                              check="nonnegative", default=0.0)
    force_bias: float = spec("N", "constant offset of every force measurement", check="any",
                             default=0.0)
    force_resolution: float = spec("N", "quantisation step of the force measurement (0: none)",
                                   check="nonnegative", default=0.0)


@dataclasses.dataclass(frozen=True)
class Limits:
    """Operating limits an excitation must respect (``stewartid design`` and its checks).

    Keys left out are derived from the other sections by
    :func:`stewartid.design.limits.resolve_limits`: the stroke ends from ``[hydraulics]
    stroke`` centred on the neutral leg length, the leg velocity from the rated valve flow
    through the piston area, the force from the smaller of the cylinder's stall forces.
    """

    stroke_min: float | None = spec("m", "shortest allowed leg length (default: neutral "
                                    "length - stroke / 2)", default=None)
    stroke_max: float | None = spec("m", "longest allowed leg length (default: neutral "
                                    "length + stroke / 2)", default=None)
    leg_velocity: float | None = spec("m/s", "largest leg-length rate (default: rated valve "
                                      "flow / piston area)", default=None)
    leg_acceleration: float = spec("m/s^2", "largest leg-length acceleration", default=5.0)
    actuator_force: float | None = spec("N", "largest |actuator force| (default: the smaller "
                                        "of the extending and retracting stall forces)",
                                        default=None)
    gimbal_angle: float = spec("rad", "largest deflection of a leg from its neutral "
                               "direction, at either gimbal", default=0.35)

    def __post_init__(self) -> None:
        if (self.stroke_min is not None and self.stroke_max is not None
                and not self.stroke_min < self.stroke_max):
            raise ConfigError(f"[limits] stroke_min = {self.stroke_min} m must be below "
                              f"stroke_max = {self.stroke_max} m.")


#: TOML sections of a platform description, in file order, with their dataclass.
SECTIONS: dict[str, type] = {"geometry": Geometry, "inertia": Inertia, "friction": Friction,
                             "hydraulics": Hydraulics, "controller": Controller,
                             "sensors": Sensors, "limits": Limits}
#: Sections that must be present in every file; the others take their documented defaults.
REQUIRED_SECTIONS = ("geometry", "inertia", "friction")


@dataclasses.dataclass(frozen=True)
class Platform:
    """A complete, validated description of a Stewart platform.

    Attributes
    ----------
    geometry, inertia, friction : Geometry, Inertia, Friction
        The required sections of the TOML description.
    hydraulics, controller, sensors : Hydraulics, Controller, Sensors
        Plant simulator settings; documented defaults when absent from the file.
    limits : Limits
        Operating limits of excitation design; derived defaults when absent.
    name : str
        Label used in reports ("paper" for the preset, the file stem otherwise).
    """

    geometry: Geometry
    inertia: Inertia
    friction: Friction
    hydraulics: Hydraulics = dataclasses.field(default_factory=Hydraulics)
    controller: Controller = dataclasses.field(default_factory=Controller)
    sensors: Sensors = dataclasses.field(default_factory=Sensors)
    limits: Limits = dataclasses.field(default_factory=Limits)
    name: str = "platform"

    def __post_init__(self) -> None:
        check_physical_ranges({name: getattr(self, name) for name in SECTIONS})
        _check_buildable(self)

    # -- derived geometry -------------------------------------------------------------------
    @property
    def upper_joints(self) -> np.ndarray:
        """Upper joint positions in the platform frame, relative to the reference point.

        Returns
        -------
        ndarray, shape (6, 3)
            Row k is leg k+1's upper gimbal point (m), platform body frame (z down).
        """
        g = self.geometry
        angles = _upper_angles(g.upper_half_angle)
        return np.column_stack([
            g.upper_radius * np.cos(angles),
            g.upper_radius * np.sin(angles),
            np.full(6, g.reference_height),
        ])

    @property
    def base_joints(self) -> np.ndarray:
        """Lower (base) joint positions in the fixed frame.

        Returns
        -------
        ndarray, shape (6, 3)
            Row k is leg k+1's lower gimbal point (m); z = 0 is the base joint plane.
        """
        g = self.geometry
        angles = _lower_angles(g.lower_half_angle)
        return np.column_stack([
            g.lower_radius * np.cos(angles),
            g.lower_radius * np.sin(angles),
            np.zeros(6),
        ])

    @property
    def neutral_pose(self) -> np.ndarray:
        """Pose q = [x, y, z, rx, ry, rz] at neutral (m, rad): z = -(neutral_height + reference_height)."""
        g = self.geometry
        return np.array([0.0, 0.0, -(g.neutral_height + g.reference_height), 0.0, 0.0, 0.0])

    @property
    def neutral_leg_length(self) -> float:
        """Length of each leg at the neutral pose (m)."""
        return float(np.linalg.norm(self.upper_joints[0] + self.neutral_pose[:3]
                                    - self.base_joints[0]))

    def parameters(self) -> np.ndarray:
        """Mass and friction parameters packed for the compiled kernels.

        Returns
        -------
        ndarray, shape (13,)
            [m, Ixx, Iyy, Izz, m_upper, m_lower, d_upper, d_lower, I_upper, I_lower,
            gimbal_viscous, coulomb, gravity].
        """
        i, f = self.inertia, self.friction
        return np.array([
            i.platform_mass, *i.platform_inertia, i.upper_leg_mass, i.lower_leg_mass,
            i.upper_leg_com, i.lower_leg_com, i.upper_leg_inertia, i.lower_leg_inertia,
            f.gimbal_viscous, f.coulomb, GRAVITY,
        ])

    # -- construction and serialisation -----------------------------------------------------
    def replace(self, **sections_or_values: Any) -> Platform:
        """Return a copy with whole sections, or single values as ``section__key=value``, replaced.

        Examples
        --------
        >>> paper = load_platform("paper")
        >>> paper.replace(friction__coulomb=30.0).friction.coulomb
        30.0
        """
        updates: dict[str, Any] = {}
        for key, value in sections_or_values.items():
            if "__" in key:
                section, field = key.split("__", 1)
                table = section_to_mapping(updates.get(section, getattr(self, section)))
                table[field] = value
                updates[section] = section_from_mapping(SECTIONS[section], table, section)
            else:
                updates[key] = value
        return dataclasses.replace(self, **updates)

    def to_dict(self) -> dict[str, Any]:
        """All sections as plain dictionaries (JSON/TOML ready)."""
        return {name: section_to_mapping(getattr(self, name)) for name in SECTIONS}

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
    """Build a :class:`Platform` from a parsed TOML document (a mapping of sections).

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
        ``"paper"`` for the shipped preset of Zhang (2020), Tables 1-2, or the path of a
        TOML file.

    Returns
    -------
    Platform

    Raises
    ------
    ConfigError
        If the file does not exist, is not valid TOML, or fails validation.
    """
    if str(source) == "paper":
        text = resources.files("stewartid").joinpath("data/paper.toml").read_text()
        return _parse(text, "paper", "the paper preset")
    path = Path(source)
    if not path.is_file():
        raise ConfigError(
            f"platform file {str(path)!r} not found; give a TOML file or 'paper' for the preset."
        )
    return _parse(read_toml_text(path), path.stem, str(path))


def _parse(text: str, name: str, where: str) -> Platform:
    try:
        document = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise ConfigError(f"{where} is not valid TOML: {exc}.") from None
    try:
        return platform_from_mapping(document, name)
    except ConfigError as exc:
        raise ConfigError(f"{where}: {exc}") from None
