"""Excitation trajectories: base pose + fade-in window x sum of sines, q, q_dot, q_ddot analytic;
:func:`paper_experiments` is the set of Zhang (2020), Section 4.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Sequence

import numpy as np

from stewartid.errors import ConfigError
from stewartid.platform import COORDINATES, Platform

#: Default sine amplitudes of the paper's experiments: 20 mm in translation, 10 mrad in
#: rotation; small enough for the linearised model, large enough that inertial and viscous
#: forces dominate Coulomb friction.
DEFAULT_AMPLITUDES = (0.02, 0.02, 0.02, 0.01, 0.01, 0.01)
#: Default fade-in duration (s): one period at the paper's 0.5 Hz.
DEFAULT_FADE_IN = 2.0


@dataclasses.dataclass(frozen=True)
class Sine:
    """One sine on one pose coordinate: offset + amplitude * sin(2 pi f t + phase).

    Attributes
    ----------
    dof : int
        0..5 for x, y, z, rx, ry, rz.
    amplitude, offset : float
        m or rad; the offset is not faded.
    frequency_hz : float
    phase : float
        rad.
    """

    dof: int
    amplitude: float
    frequency_hz: float
    phase: float = 0.0
    offset: float = 0.0

    def __post_init__(self) -> None:
        if not (isinstance(self.dof, int | np.integer) and 0 <= self.dof < 6):
            raise ConfigError(f"Sine dof must be an integer 0..5 (x, y, z, rx, ry, rz); "
                              f"got {self.dof!r}.")
        if not (math.isfinite(self.frequency_hz) and self.frequency_hz > 0):
            raise ConfigError(f"Sine frequency_hz must be > 0 Hz; got {self.frequency_hz!r}.")
        for name in ("amplitude", "phase", "offset"):
            if not math.isfinite(getattr(self, name)):
                raise ConfigError(f"Sine {name} must be finite; got {getattr(self, name)!r}.")


def _fade(t: np.ndarray, duration: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Quintic smoothstep w from 0 to 1 over ``duration`` with w', w'': zero at t = 0 (start at rest)."""
    if duration <= 0:
        one = np.ones_like(t)
        return one, np.zeros_like(t), np.zeros_like(t)
    s = np.clip(t / duration, 0.0, 1.0)
    inside = (t > 0) & (t < duration)
    w = s ** 3 * (10 - 15 * s + 6 * s ** 2)
    dw = np.where(inside, 30 * s ** 2 * (1 - s) ** 2 / duration, 0.0)
    ddw = np.where(inside, 60 * s * (1 - s) * (1 - 2 * s) / duration ** 2, 0.0)
    return w, dw, ddw


@dataclasses.dataclass(frozen=True)
class Excitation:
    """A pose trajectory: base pose + fade-in window x sum of sines (plus constant offsets).

    Attributes
    ----------
    sines : tuple of Sine
        Several on one DOF make a multi-sine.
    base_pose : tuple of 6 float
        m, rad; usually the neutral pose.
    fade_in : float
        Quintic fade-in (s); 0 for none.
    name : str
    """

    sines: tuple[Sine, ...]
    base_pose: tuple[float, ...]
    fade_in: float = DEFAULT_FADE_IN
    name: str = "exp"

    def __post_init__(self) -> None:
        object.__setattr__(self, "sines", tuple(self.sines))
        base = tuple(float(v) for v in np.asarray(self.base_pose, dtype=float).ravel())
        if len(base) != 6:
            raise ConfigError(f"base_pose must have 6 values (m, rad); got {len(base)}.")
        object.__setattr__(self, "base_pose", base)
        if not (math.isfinite(self.fade_in) and self.fade_in >= 0):
            raise ConfigError(f"fade_in must be >= 0 s; got {self.fade_in!r}.")

    @property
    def max_frequency(self) -> float:
        """Highest sine frequency (Hz), 0 without sines."""
        return max((s.frequency_hz for s in self.sines), default=0.0)

    def evaluate(self, t: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """q, q_dot, q_ddot (N, 6) at times ``t`` (s): m, rad and their derivatives."""
        t = np.asarray(t, dtype=float)
        n = t.shape[0]
        q = np.tile(np.asarray(self.base_pose), (n, 1))
        qd = np.zeros((n, 6))
        qdd = np.zeros((n, 6))
        w, dw, ddw = _fade(t, self.fade_in)
        for s in self.sines:
            om = 2 * math.pi * s.frequency_hz
            arg = om * t + s.phase
            y = s.amplitude * np.sin(arg)
            dy = s.amplitude * om * np.cos(arg)
            ddy = -om * om * y
            q[:, s.dof] += s.offset + w * y
            qd[:, s.dof] += dw * y + w * dy
            qdd[:, s.dof] += ddw * y + 2 * dw * dy + w * ddy
        return q, qd, qdd


def sine_excitation(platform: Platform, dof: int, amplitude: float, frequency_hz: float,
                    phase: float = 0.0, offset: float = 0.0, fade_in: float = DEFAULT_FADE_IN,
                    name: str | None = None) -> Excitation:
    """A single sine on one DOF (0..5 for x, y, z, rx, ry, rz) about the neutral pose.

    Amplitude and offset in m or rad, phase in rad, fade-in in s; named ``"<dof name>_sine"`` by default.
    """
    return Excitation((Sine(dof, amplitude, frequency_hz, phase, offset),),
                      tuple(platform.neutral_pose), fade_in,
                      name or f"{COORDINATES[dof]}_sine")


def multisine_excitation(platform: Platform, sines: Sequence[Sine],
                         fade_in: float = DEFAULT_FADE_IN, name: str = "multisine") -> Excitation:
    """Several sines, on one or more DOFs, about the neutral pose."""
    return Excitation(tuple(sines), tuple(platform.neutral_pose), fade_in, name)


def paper_experiments(platform: Platform, frequency_hz: float = 0.5,
                      amplitudes: Sequence[float] = DEFAULT_AMPLITUDES,
                      fade_in: float = DEFAULT_FADE_IN) -> list[Excitation]:
    """The paper's six experiments, ``exp1..exp6``: experiment k excites DOF k with a sine from rest.

    ``amplitudes`` per DOF (m, rad), ``fade_in`` in s.
    """
    amplitudes = tuple(float(a) for a in amplitudes)
    if len(amplitudes) != 6:
        raise ConfigError(f"amplitudes must have 6 values (one per DOF); got {len(amplitudes)}.")
    return [sine_excitation(platform, k, amplitudes[k], frequency_hz, fade_in=fade_in,
                            name=f"exp{k + 1}") for k in range(6)]


def excitation_to_dict(excitation: Excitation) -> dict:
    """Plain-data description of an excitation (for meta.json)."""
    return {
        "name": excitation.name,
        "base_pose": list(excitation.base_pose),
        "fade_in": excitation.fade_in,
        "sines": [dataclasses.asdict(s) for s in excitation.sines],
    }
