"""One frozen dataclass per TOML table of a platform description, each field declared with unit,
description, constraint and default; ranges are wide, to catch unit slips (mm, g, bar).
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Sequence

import numpy as np

from stewartid.errors import ConfigError
from stewartid.fields import (
    BOOLEAN,
    ListOf,
    Options,
    Section,
    finite,
    nonnegative,
    positive,
    spec,
)

#: Actuator models understood by [hydraulics] mode.
ACTUATOR_MODES = ("hydraulic", "ideal")
#: Kinds of leg actuator understood by [actuator] kind.
ACTUATOR_KINDS = ("hydraulic", "electric")
#: [actuator] keys that describe a servo motor and its ball screw: electric actuators only.
ELECTRIC_KEYS = ("force_constant", "screw_lead", "peak_current", "screw_speed",
                 "current_bandwidth", "encoder_resolution")
#: Current-loop bandwidth (Hz) of an electric [actuator] that gives none.
DEFAULT_CURRENT_BANDWIDTH = 1000.0
#: Leg travel per encoder count (m) of an electric [actuator] that gives none.
DEFAULT_ENCODER_RESOLUTION = 1e-6


@dataclasses.dataclass(frozen=True)
class Geometry(Section):
    """Joint layout of a 6-6 hexapod (paper, Table 1)."""

    section = "geometry"

    upper_radius: float = spec("m", "radius of the circle through the upper (platform) joints",
                               positive(0.01, 50.0))
    lower_radius: float = spec("m", "radius of the circle through the lower (base) joints",
                               positive(0.01, 50.0))
    neutral_height: float = spec("m", "lower joint plane to upper joint plane at neutral",
                                 positive(0.01, 50.0))
    upper_half_angle: float = spec("rad", "half the angle between the two joints of an upper "
                                   "pair", positive(0.0, math.pi / 2))
    lower_half_angle: float = spec("rad", "half the angle between the two joints of a lower "
                                   "pair", positive(0.0, math.pi / 2))
    reference_height: float = spec(
        "m", "upper joint plane to the reference point (platform centre of mass), away from "
        "the base", nonnegative(0.0, 50.0))


@dataclasses.dataclass(frozen=True)
class Inertia(Section):
    """Masses and inertias of the platform and of the two parts of each leg (paper, Table 2)."""

    section = "inertia"

    platform_mass: float = spec("kg", "mass of the moving platform", positive(0.01, 1e6))
    platform_inertia: tuple[float, float, float] = spec(
        "kg m^2", "principal inertias of the platform about its centre of mass",
        ListOf(positive(1e-6, 1e9), length=3))
    upper_leg_mass: float = spec("kg", "mass of a leg's upper part (piston rod)", nonnegative(0.0, 1e5))
    lower_leg_mass: float = spec("kg", "mass of a leg's lower part (cylinder)", nonnegative(0.0, 1e5))
    upper_leg_com: float = spec("m", "upper gimbal point to the upper part's centre of mass",
                                nonnegative(0.0, 50.0))
    lower_leg_com: float = spec("m", "lower gimbal point to the lower part's centre of mass",
                                nonnegative(0.0, 50.0))
    upper_leg_inertia: float = spec(
        "kg m^2", "transverse inertia of the upper part about its centre of mass",
        nonnegative(0.0, 1e7))
    lower_leg_inertia: float = spec(
        "kg m^2", "transverse inertia of the lower part about its centre of mass",
        nonnegative(0.0, 1e7))


@dataclasses.dataclass(frozen=True)
class Payload(Section):
    """A rigid payload fixed to the platform, moving with it as one body; zero mass, no inertia.

    Products of inertia are the matrix's entries (Ixy = -integral x y dm), MuJoCo's ``fullinertia`` order.
    """

    section = "payload"

    mass: float = spec("kg", "mass of the payload", nonnegative(0.0, 1e6))
    com: tuple[float, float, float] = spec(
        "m", "[x, y, z] of the payload's centre of mass in the platform frame, from the "
        "reference point", ListOf(finite(-50.0, 50.0), length=3))
    inertia: tuple[float, float, float, float, float, float] = spec(
        "kg m^2", "[Ixx, Iyy, Izz, Ixy, Ixz, Iyz] about the payload's centre of mass, platform "
        "frame; the products are entries of the inertia matrix (Ixy = -sum x y dm)",
        ListOf(finite(-1e9, 1e9), length=6))

    def __post_init__(self) -> None:
        super().__post_init__()
        check_payload_inertia(self.mass, self.inertia_matrix)

    @property
    def inertia_matrix(self) -> np.ndarray:
        """Inertia matrix (3, 3) about the payload's centre of mass (kg m^2)."""
        return inertia_matrix(self.inertia)


def inertia_matrix(entries: Sequence[float]) -> np.ndarray:
    """Symmetric 3x3 matrix of [Ixx, Iyy, Izz, Ixy, Ixz, Iyz] (kg m^2), products as off-diagonal entries."""
    xx, yy, zz, xy, xz, yz = (float(v) for v in entries)
    return np.array([[xx, xy, xz], [xy, yy, yz], [xz, yz, zz]])


#: Relative slack of the triangle inequality of principal moments (of their sum): an
#: inertia rounded to a few digits from an exact flat body may cross the bound by as much.
TRIANGLE_SLACK = 1e-6


def check_payload_inertia(mass: float, inertia: np.ndarray) -> None:
    """Refuse an inertia no mass distribution has: not positive definite about the centre of mass,
    principal moments breaking the triangle inequalities, or inertia without mass.

    Raises
    ------
    ConfigError
        Naming ``[payload] inertia`` and what to check.
    """
    entries = f"{[float(v) for v in inertia[[0, 1, 2, 0, 0, 1], [0, 1, 2, 1, 2, 2]]]}"
    if mass == 0.0:
        if np.any(inertia != 0.0):
            raise ConfigError(f"[payload] inertia = {entries} kg m^2 for a payload of zero "
                              "mass: a body without mass has no inertia; give its mass or "
                              "set inertia = [0, 0, 0, 0, 0, 0].")
        return
    moments = np.linalg.eigvalsh(inertia)
    if not moments[0] > 0.0:
        raise ConfigError(
            f"[payload] inertia = {entries} kg m^2 is not positive definite (principal moments "
            f"{', '.join(f'{m:.6g}' for m in moments)}); check the signs of the products, "
            "which are entries of the matrix (Ixy = -sum x y dm, MuJoCo's fullinertia).")
    if moments[2] > moments[0] + moments[1] + TRIANGLE_SLACK * moments.sum():
        raise ConfigError(
            f"[payload] inertia = {entries} kg m^2 has principal moments "
            f"{', '.join(f'{m:.6g}' for m in moments)}, the largest above the sum of the "
            "other two, which no mass distribution gives; check the inertias and their axes.")


@dataclasses.dataclass(frozen=True)
class Friction(Section):
    """Joint friction: viscous on the four gimbal axes, Coulomb on all five rotational axes."""

    section = "friction"

    gimbal_viscous: float = spec("N m s/rad", "viscous coefficient of each gimbal axis",
                                 nonnegative(0.0, 1e9))
    coulomb: float = spec("N m", "Coulomb friction torque of each rotational joint axis",
                          nonnegative(0.0, 1e7), default=0.0)


@dataclasses.dataclass(frozen=True)
class Actuator(Section):
    """What each leg's actuator adds along the leg (all six alike): a reflected mass and friction.

    An electric leg is a ball screw driven by a servo motor: its rotor and screw, turning at
    2 pi / lead rad per metre of stroke, weigh J (2 pi / lead)^2 along the leg, and its force is
    the motor current times a force constant (no force sensor). The simulator gives each motor a
    first-order current loop of ``current_bandwidth`` limited to ``peak_current``, and an encoder
    of ``encoder_resolution`` that measures the leg length. The defaults, a hydraulic leg with
    nothing along it, leave the model of ``[inertia]`` and ``[friction]`` as it is.
    """

    section = "actuator"

    kind: str = spec("-", "'hydraulic' ([hydraulics] applies) or 'electric' (servo motor and "
                     "ball screw)", Options(ACTUATOR_KINDS), default="hydraulic")
    reflected_mass: float = spec("kg", "mass seen along each leg by its rotating parts, "
                                 "J (2 pi / screw_lead)^2 for a rotor and screw of inertia J",
                                 nonnegative(0.0, 1e5), default=0.0)
    viscous: float = spec("N s/m", "viscous friction along each leg (screw, nut, seals)",
                          nonnegative(0.0, 1e8), default=0.0)
    coulomb: float = spec("N", "Coulomb friction along each leg", nonnegative(0.0, 1e7),
                          default=0.0)
    force_constant: float | None = spec(
        "N/A", "leg force per motor current, Kt 2 pi eta / screw_lead (electric; required)",
        positive(1e-3, 1e7), default=None)
    screw_lead: float | None = spec("m", "leg travel per motor revolution (electric)",
                                    positive(1e-5, 1.0), default=None)
    peak_current: float | None = spec("A", "largest motor current (electric; default: no "
                                      "force limit from the motor)", positive(1e-3, 1e5),
                                      default=None)
    screw_speed: float | None = spec("rev/s", "largest motor speed (electric, with "
                                     "screw_lead; default: no speed limit from the motor)",
                                     positive(1e-3, 1e4), default=None)
    current_bandwidth: float | None = spec(
        "Hz", "-3 dB bandwidth of each motor's current loop (electric; default 1000 Hz)",
        positive(1.0, 1e5), default=None)
    encoder_resolution: float | None = spec(
        "m", "leg travel per count of each motor's encoder, screw_lead / counts per revolution "
        "(electric; default 1e-6 m; 0: an ideal encoder)", nonnegative(0.0, 1e-2), default=None)

    def __post_init__(self) -> None:
        super().__post_init__()
        if self.kind == "electric":
            if self.force_constant is None:
                raise ConfigError(
                    '[actuator] kind = "electric" needs force_constant (N/A, the leg force per '
                    "motor current, Kt 2 pi eta / screw_lead): the leg forces are computed "
                    "from the currents; add it.")
            if self.screw_speed is not None and self.screw_lead is None:
                raise ConfigError(f"[actuator] screw_speed = {self.screw_speed} rev/s needs "
                                  "screw_lead (m per revolution) to give a leg speed; add it.")
            return
        given = [key for key in ELECTRIC_KEYS if getattr(self, key) is not None]
        if given:
            raise ConfigError(f'[actuator] {given[0]} describes an electric actuator but kind '
                              f'= "{self.kind}"; set kind = "electric" or remove {given[0]}.')


@dataclasses.dataclass(frozen=True)
class Hydraulics(Section):
    """Hydraulic actuators of the legs (all six alike): servo-valve, cylinder and oil.

    Defaults size a ~14 t flight-simulator hexapod: 21 MPa, 100/70 mm cylinders of 1 m stroke,
    200 L/min 80 Hz valves, bulk modulus 1.2 GPa.
    """

    section = "hydraulics"

    mode: str = spec("-", "'hydraulic' (valve, cylinder, oil; electric legs: their motors) or "
                     "'ideal' (the demanded force is applied exactly)", Options(ACTUATOR_MODES),
                     default="hydraulic")
    supply_pressure: float = spec("Pa", "supply pressure p_s", positive(1e5, 1e8), default=21.0e6)
    return_pressure: float = spec("Pa", "return (tank) pressure p_r", nonnegative(0.0, 1e7), default=0.5e6)
    bore_diameter: float = spec("m", "cylinder bore (piston side area A_A = pi D^2 / 4)",
                                positive(1e-3, 2.0), default=0.100)
    rod_diameter: float = spec("m", "piston rod diameter (rod side area A_B = A_A - pi d^2/4)",
                               positive(1e-3, 2.0), default=0.070)
    stroke: float = spec("m", "usable stroke, centred on the neutral leg length",
                         positive(1e-3, 20.0), default=1.0)
    dead_volume: float = spec("m^3", "oil volume of each chamber at its end of stroke, with "
                              "the hose to the valve", positive(1e-9, 1.0), default=0.5e-3)
    bulk_modulus: float = spec("Pa", "effective bulk modulus of the oil (with hose "
                               "compliance)", positive(1e7, 1e10), default=1.2e9)
    valve_rated_flow: float = spec("m^3/s", "valve flow at full opening and rated pressure "
                                   "drop (200 L/min)", positive(1e-7, 1.0),
                                   default=200.0 / 60000.0)
    valve_rated_pressure_drop: float = spec("Pa", "total valve pressure drop (both metering "
                                            "edges) at which the rated flow is given",
                                            positive(1e4, 1e8), default=7.0e6)
    valve_bandwidth: float = spec("Hz", "natural frequency of the spool (second-order model)",
                                  positive(0.1, 1e4), default=80.0)
    valve_damping: float = spec("-", "damping ratio of the spool", positive(0.01, 10.0), default=0.7)
    leakage: float = spec("m^3/(s Pa)", "internal (cross-piston) leakage coefficient",
                          nonnegative(0.0, 1e-8), default=2.0e-13)
    orifice_transition_pressure: float = spec(
        "Pa", "pressure drop below which orifice flow turns from turbulent (square root) to "
        "laminar (linear), which keeps the flow law differentiable at zero drop",
        positive(1.0, 1e7), default=1.0e5)

    def __post_init__(self) -> None:
        super().__post_init__()
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
class Controller(Section):
    """Leg-length servo: PID on each leg length giving a force demand (N), applied exactly by ``ideal``
    actuators; ``hydraulic`` ones open the valve in proportion to the force error.
    """

    section = "controller"

    proportional_gain: float = spec("N/m", "PID proportional gain on the leg-length error",
                                    positive(1e-3, 1e12), default=1.0e7)
    integral_gain: float = spec("N/(m s)", "PID integral gain", nonnegative(0.0, 1e14), default=5.0e7)
    derivative_gain: float = spec("N s/m", "PID derivative gain (on the leg-rate error)",
                                  nonnegative(0.0, 1e10), default=4.0e5)
    gravity_feedforward: bool = spec("-", "add the static leg forces that hold the commanded "
                                     "pose against gravity", BOOLEAN, default=True)
    force_loop_gain: float = spec("1/N", "inner force loop (hydraulic mode): valve opening, "
                                  "as a fraction of full opening, per newton of force error",
                                  positive(1e-12, 1.0), default=1.0e-5)


@dataclasses.dataclass(frozen=True)
class Sensors(Section):
    """Sampling and sensor imperfections of the recorded data (defaults: ideal sensors)."""

    section = "sensors"

    sample_rate: float = spec("Hz", "sampling rate of the recorded signals",
                              positive(1.0, 1e6), default=1000.0)
    length_noise: float = spec("m", "standard deviation of the leg-length sensor noise",
                               nonnegative(0.0, 0.1), default=0.0)
    length_bias: float = spec("m", "constant offset of every leg-length sensor",
                              finite(-1.0, 1.0), default=0.0)
    length_resolution: float = spec("m", "quantisation step of the leg-length sensors "
                                    "(0: none)", nonnegative(0.0, 0.1), default=0.0)
    force_noise: float = spec("N", "standard deviation of the actuator force measurement "
                              "noise (force-equivalent of the pressure transducers)",
                              nonnegative(0.0, 1e7), default=0.0)
    force_bias: float = spec("N", "constant offset of every force measurement",
                             finite(-1e7, 1e7), default=0.0)
    force_resolution: float = spec("N", "quantisation step of the force measurement (0: none)",
                                   nonnegative(0.0, 1e7), default=0.0)


@dataclasses.dataclass(frozen=True)
class Limits(Section):
    """Operating limits an excitation must respect (``stewartid design``).

    Keys left out are derived by :func:`stewartid.design.limits.resolve_limits` from the stroke, the
    rated valve flow and the cylinder's stall forces, or, for an electric ``[actuator]``, from its
    screw_speed and peak_current when given.
    """

    section = "limits"

    stroke_min: float | None = spec("m", "shortest allowed leg length (default: neutral "
                                    "length - stroke / 2)", positive(0.01, 100.0), default=None)
    stroke_max: float | None = spec("m", "longest allowed leg length (default: neutral "
                                    "length + stroke / 2)", positive(0.01, 100.0), default=None)
    leg_velocity: float | None = spec("m/s", "largest leg-length rate (default: screw_speed "
                                      "screw_lead of an electric [actuator], else rated valve "
                                      "flow / piston area)", positive(1e-4, 100.0),
                                      default=None)
    leg_acceleration: float = spec("m/s^2", "largest leg-length acceleration",
                                   positive(1e-3, 1e4), default=5.0)
    actuator_force: float | None = spec("N", "largest |actuator force| (default: peak_current "
                                        "force_constant of an electric [actuator], else the "
                                        "smaller of the cylinder's stall forces)",
                                        positive(1.0, 1e9), default=None)
    gimbal_angle: float = spec("rad", "largest deflection of a leg from its neutral "
                               "direction, at either gimbal", positive(1e-3, math.pi / 2),
                               default=0.35)

    def __post_init__(self) -> None:
        super().__post_init__()
        if (self.stroke_min is not None and self.stroke_max is not None
                and not self.stroke_min < self.stroke_max):
            raise ConfigError(f"[limits] stroke_min = {self.stroke_min} m must be below "
                              f"stroke_max = {self.stroke_max} m.")


__all__ = ["ACTUATOR_KINDS", "ACTUATOR_MODES", "DEFAULT_CURRENT_BANDWIDTH",
           "DEFAULT_ENCODER_RESOLUTION", "ELECTRIC_KEYS", "TRIANGLE_SLACK", "Actuator",
           "Controller", "Friction", "Geometry", "Hydraulics", "Inertia", "Limits", "Payload",
           "Sensors", "check_payload_inertia", "inertia_matrix"]
