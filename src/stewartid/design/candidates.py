"""Excitation designs: records q(t) = q0 + d a(t) sin(2 pi f t) along a fixed pose direction d,
with level schedules a(t); two levels give Method B's ``friction="shared"`` two speeds with one
joint-direction pattern, separating viscous from Coulomb friction.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Sequence

import numpy as np

from stewartid.errors import ConfigError
from stewartid.platform import COORDINATES, Platform
from stewartid.simulation.excitation import DEFAULT_AMPLITUDES


def quintic_ramp(s: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Quintic smoothstep on s in [0, 1] and its first two derivatives in s."""
    s = np.clip(s, 0.0, 1.0)
    return (s ** 3 * (10 - 15 * s + 6 * s ** 2), 30 * s ** 2 * (1 - s) ** 2,
            60 * s * (1 - s) * (1 - 2 * s))


def fade_envelope(t: np.ndarray, fade: float, duration: float
                  ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Quintic fade-in over ``fade`` s times fade-out ending at ``duration`` s, and its first two
    time derivatives, each shaped like ``t``.
    """
    rise, d_rise, dd_rise = quintic_ramp(t / fade)
    fall, d_fall, dd_fall = quintic_ramp((duration - t) / fade)
    k = 1.0 / fade
    return (rise * fall, k * (d_rise * fall - rise * d_fall),
            k * k * (dd_rise * fall - 2 * d_rise * d_fall + rise * dd_fall))


@dataclasses.dataclass(frozen=True)
class DesignedRecord:
    """One record: a sine along a fixed pose direction under a level schedule.

    Attributes
    ----------
    direction : tuple of 6 float
        Motion per unit level (m, rad).
    frequency_hz : float
    levels : tuple of float
        Amplitude levels multiplying ``direction``, held in turn.
    hold_periods : int
        Whole periods held per level.
    fade_periods : int
        Periods of each fade and ramp between levels.
    name : str
    """

    direction: tuple[float, ...]
    frequency_hz: float
    levels: tuple[float, ...] = (1.0,)
    hold_periods: int = 10
    fade_periods: int = 1
    name: str = "exp"

    def __post_init__(self) -> None:
        direction = tuple(float(v) for v in np.asarray(self.direction, dtype=float).ravel())
        if len(direction) != 6 or not any(direction) or not all(map(math.isfinite, direction)):
            raise ConfigError(f"record {self.name}: direction must be 6 finite values, not all "
                              f"zero (m, rad); got {self.direction!r}.")
        object.__setattr__(self, "direction", direction)
        object.__setattr__(self, "levels", tuple(float(v) for v in self.levels))
        if not (math.isfinite(self.frequency_hz) and self.frequency_hz > 0):
            raise ConfigError(f"record {self.name}: frequency_hz must be > 0 Hz; got "
                              f"{self.frequency_hz!r}.")
        if not self.levels or not all(v > 0 and math.isfinite(v) for v in self.levels):
            raise ConfigError(f"record {self.name}: levels must be one or more numbers > 0; "
                              f"got {self.levels!r}.")
        for key in ("hold_periods", "fade_periods"):
            value = getattr(self, key)
            if not (isinstance(value, int) and value >= 1):
                raise ConfigError(f"record {self.name}: {key} must be an integer >= 1; got "
                                  f"{value!r}.")

    @property
    def period(self) -> float:
        """s."""
        return 1.0 / self.frequency_hz

    @property
    def duration(self) -> float:
        """Record length (s): fades, holds and ramps."""
        n = len(self.levels)
        return self.period * (n * self.hold_periods + (n + 1) * self.fade_periods)

    @property
    def max_frequency(self) -> float:
        """Highest frequency of the motion (Hz)."""
        return self.frequency_hz

    def scaled(self, factor: float) -> DesignedRecord:
        """The record with every amplitude times ``factor``."""
        return dataclasses.replace(self, direction=tuple(factor * v for v in self.direction))

    def envelope(self, t: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Envelope a(t) and its first two time derivatives, each (N,)."""
        t = np.asarray(t, dtype=float)
        a, da, dda = np.zeros_like(t), np.zeros_like(t), np.zeros_like(t)
        fade, hold = self.fade_periods * self.period, self.hold_periods * self.period
        start, previous = 0.0, 0.0
        for level in (*self.levels, 0.0):
            w, dw, ddw = quintic_ramp((t - start) / fade)
            a += (level - previous) * w
            da += (level - previous) * dw / fade
            dda += (level - previous) * ddw / fade ** 2
            start += fade + hold
            previous = level
        return a, da, dda

    def evaluate_offsets(self, t: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """dq, dq_dot, dq_ddot about the base pose, each (N, 6)."""
        t = np.asarray(t, dtype=float)
        a, da, dda = self.envelope(t)
        omega = 2 * math.pi * self.frequency_hz
        s, c = np.sin(omega * t), np.cos(omega * t)
        d = np.asarray(self.direction)
        scalar = (a * s, da * s + a * omega * c,
                  dda * s + 2 * da * omega * c - a * omega ** 2 * s)
        return tuple(np.outer(x, d) for x in scalar)

    def to_dict(self) -> dict:
        """JSON-ready data; :func:`record_from_dict` reads it back."""
        return {**dataclasses.asdict(self), "direction": list(self.direction),
                "levels": list(self.levels), "duration_s": self.duration}


def record_from_dict(data: dict) -> DesignedRecord:
    """Inverse of :meth:`DesignedRecord.to_dict`."""
    fields = {f.name for f in dataclasses.fields(DesignedRecord)}
    return DesignedRecord(**{k: (tuple(v) if isinstance(v, list) else v)
                             for k, v in data.items() if k in fields})


@dataclasses.dataclass(frozen=True)
class PlayableRecord:
    """A designed record about a base pose, played as an
    :class:`~stewartid.simulation.excitation.Excitation`."""

    record: DesignedRecord
    base_pose: tuple[float, ...]

    @property
    def name(self) -> str:
        """Record label."""
        return self.record.name

    @property
    def max_frequency(self) -> float:
        """Hz."""
        return self.record.max_frequency

    def evaluate(self, t: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Pose, velocity and acceleration at ``t`` (s), each (N, 6)."""
        dq, dqd, dqdd = self.record.evaluate_offsets(t)
        return dq + np.asarray(self.base_pose), dqd, dqdd


@dataclasses.dataclass(frozen=True)
class Design:
    """Records run one after the other, each from rest at neutral.

    Attributes
    ----------
    records : tuple of DesignedRecord
        Or any record with the same interface, e.g. :class:`~stewartid.design.multisine.MultisineRecord`.
    label : str
        Short description for reports.
    """

    records: tuple[DesignedRecord, ...]
    label: str = "design"

    @property
    def duration(self) -> float:
        """Total motion time (s)."""
        return float(sum(r.duration for r in self.records))

    def playable(self, platform: Platform) -> list[PlayableRecord]:
        """The records about the platform's neutral pose."""
        base = tuple(platform.neutral_pose)
        return [PlayableRecord(r, base) for r in self.records]

    def to_dict(self) -> dict:
        """JSON-ready data."""
        return {"label": self.label, "duration_s": self.duration,
                "records": [r.to_dict() for r in self.records]}


def design_from_dict(data: dict) -> Design:
    """Inverse of :meth:`Design.to_dict`."""
    return Design(tuple(record_from_dict(r) for r in data["records"]), data.get("label", ""))


def unit_direction(dof: int, amplitude: float) -> tuple[float, ...]:
    """Direction moving DOF ``dof`` (0..5) alone by ``amplitude`` (m or rad)."""
    d = [0.0] * 6
    d[dof] = float(amplitude)
    return tuple(d)


def paper_design(frequency_hz: float = 0.5, duration_s: float = 20.0,
                 amplitudes: Sequence[float] = DEFAULT_AMPLITUDES) -> Design:
    """The paper's set: record k a single-level sine on DOF k, ``duration_s`` rounded to whole periods."""
    periods = max(1, round(duration_s * frequency_hz) - 2)
    return Design(tuple(
        DesignedRecord(unit_direction(k, amplitudes[k]), frequency_hz, (1.0,), periods, 1,
                       f"exp{k + 1}") for k in range(6)),
        f"paper: 6 single-DOF sines, {frequency_hz:g} Hz, {duration_s:g} s each")


def scheduled_design(amplitudes: Sequence[float], frequency_hz: float | Sequence[float],
                     durations_s: Sequence[float],
                     levels: Sequence[float] | Sequence[Sequence[float]] = (1.0, 0.5),
                     label: str | None = None) -> Design:
    """Six single-DOF records with level schedules, each about its own duration.

    Parameters
    ----------
    amplitudes : sequence of 6 float
        Largest amplitude per DOF (m, rad).
    frequency_hz : float or sequence of 6 float
    durations_s : sequence of 6 float
        Rounded down to whole hold periods per level.
    levels : sequence of float, or 6 sequences of float
        Relative levels, largest first, for every record or per record.
    label : str, optional
    """
    schedules = ([tuple(v) for v in levels] if isinstance(levels[0], Sequence)
                 else [tuple(levels)] * 6)
    if len(schedules) != 6:
        raise ConfigError(f"levels must be one schedule or six (one per record); got "
                          f"{len(schedules)}.")
    frequencies = [float(v) for v in np.broadcast_to(np.asarray(frequency_hz, dtype=float), 6)]
    records = []
    for k, (schedule, frequency) in enumerate(zip(schedules, frequencies, strict=True)):
        peak = max(schedule)
        hold = int((durations_s[k] * frequency - (len(schedule) + 1)) // len(schedule))
        if hold < 1:
            raise ConfigError(f"record {k + 1}: {durations_s[k]:.3g} s is too short for "
                              f"{len(schedule)} levels at {frequency:g} Hz.")
        records.append(DesignedRecord(unit_direction(k, amplitudes[k] * peak), frequency,
                                      tuple(v / peak for v in schedule), hold, 1, f"exp{k + 1}"))
    text = label or (f"6 single-DOF records, {schedule_label(frequencies, 'Hz')}, levels "
                     + schedule_label(schedules))
    return Design(tuple(records), text)


def schedule_label(schedules: Sequence, unit: str = "") -> str:
    """Short text for one schedule per record: '1/0.5' when all equal, else runs
    ('x and y 0.75 Hz, z 0.5 Hz, rotations 0.75 Hz'), ``unit`` after each value.
    """
    tail = f" {unit}" if unit else ""
    names = ["/".join(f"{v:g}" for v in np.atleast_1d(s)) + tail for s in schedules]
    if len(set(names)) == 1:
        return names[0]
    runs: list[list] = []
    for k, name in enumerate(names):
        if runs and runs[-1][2] == name:
            runs[-1][1] = k
        else:
            runs.append([k, k, name])
    groups = {(0, 2): "translations", (3, 5): "rotations"}
    return ", ".join(f"{groups.get((a, b), ' and '.join(COORDINATES[a:b + 1]))} {name}"
                     for a, b, name in runs)


__all__ = ["COORDINATES", "Design", "DesignedRecord", "PlayableRecord", "design_from_dict",
           "fade_envelope", "paper_design", "quintic_ramp", "record_from_dict", "schedule_label",
           "scheduled_design", "unit_direction"]
