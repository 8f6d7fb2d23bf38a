"""Short validation record of a design: every DOF at once at frequencies of its own, within the
limits, showing a wrong coupling that friction compensated (``identify --validate``).
"""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path

import numpy as np

from stewartid.design.candidates import fade_envelope
from stewartid.files import write_text_atomic
from stewartid.model.kinematics import inverse_kinematics
from stewartid.platform import COORDINATES, Platform
from stewartid.simulation.excitation import DEFAULT_AMPLITUDES

#: Frequency of each DOF in the validation record (Hz): within the paper's band, pairwise
#: ratios far from small-integer ones so that no harmonic falls on another DOF's line.
VALIDATION_HZ = (0.37, 0.53, 0.71, 0.89, 1.13, 1.31)
#: Share of the most used limit the commanded validation motion reaches.
VALIDATION_USE = 0.5
#: Length of the validation record (s) and of its fade-in and fade-out.
VALIDATION_DURATION = 20.0
VALIDATION_FADE = 2.0


@dataclasses.dataclass(frozen=True)
class ValidationRecord:
    """Every DOF at once, each at its own frequency, faded in and out.

    Attributes
    ----------
    amplitudes, frequencies_hz : tuple of 6 float
        m, rad; Hz.
    duration, fade : float
        s; fade at each end.
    base_pose : tuple of 6 float
        Neutral pose (m, rad).
    name : str
    """

    amplitudes: tuple[float, ...]
    frequencies_hz: tuple[float, ...] = VALIDATION_HZ
    duration: float = VALIDATION_DURATION
    fade: float = VALIDATION_FADE
    base_pose: tuple[float, ...] = (0.0,) * 6
    name: str = "validation"

    @property
    def max_frequency(self) -> float:
        """Highest frequency (Hz)."""
        return max(self.frequencies_hz)

    def envelope(self, t: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Fade envelope and its first two time derivatives, each (N,)."""
        return fade_envelope(t, self.fade, self.duration)

    def evaluate_offsets(self, t: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """dq, dq_dot, dq_ddot about the base pose, each (N, 6)."""
        t = np.asarray(t, dtype=float)
        a, da, dda = self.envelope(t)
        omega = 2 * math.pi * np.asarray(self.frequencies_hz)
        phase = 2 * math.pi * np.arange(6) / 6
        s, c = np.sin(np.outer(t, omega) + phase), np.cos(np.outer(t, omega) + phase)
        amplitude = np.asarray(self.amplitudes)
        a, da, dda = a[:, None], da[:, None], dda[:, None]
        return (amplitude * a * s, amplitude * (da * s + a * omega * c),
                amplitude * (dda * s + 2 * da * omega * c - a * omega ** 2 * s))

    def evaluate(self, t: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Pose, velocity and acceleration at ``t`` (s), each (N, 6)."""
        dq, dq_dot, dq_ddot = self.evaluate_offsets(t)
        return dq + np.asarray(self.base_pose), dq_dot, dq_ddot


def validation_record(platform: Platform, duration_s: float = VALIDATION_DURATION,
                      max_use: float = VALIDATION_USE) -> ValidationRecord:
    """The paper's amplitudes rescaled until the commanded motion uses ``max_use`` of its top limit."""
    from stewartid.design.optimise import commanded_use

    record = ValidationRecord(tuple(DEFAULT_AMPLITUDES), duration=float(duration_s),
                              base_pose=tuple(platform.neutral_pose))
    for _ in range(3):
        peak = max(commanded_use(platform, record).peak.values())
        record = dataclasses.replace(record, amplitudes=tuple(
            np.asarray(record.amplitudes) * max_use / peak))
    return record


def write_validation_record(platform: Platform, directory: str | Path,
                            rate_hz: float = 500.0, duration_s: float = VALIDATION_DURATION
                            ) -> Path:
    """Write ``validation.csv`` (t, x..rz, l1..l6 at ``rate_hz``) into ``directory``; return the path."""
    record = validation_record(platform, duration_s)
    t = np.arange(int(math.floor(record.duration * rate_hz + 1e-9)) + 1) / rate_hz
    q, _, _ = record.evaluate(t)
    table = np.column_stack([t, q, inverse_kinematics(platform, q).lengths])
    header = ",".join(("t", *COORDINATES, *(f"l{k}" for k in range(1, 7))))
    lines = [header] + [",".join(f"{v:.10g}" for v in row) for row in table]
    return write_text_atomic(Path(directory) / f"{record.name}.csv", "\n".join(lines) + "\n")


__all__ = ["VALIDATION_DURATION", "VALIDATION_FADE", "VALIDATION_HZ", "VALIDATION_USE",
           "ValidationRecord", "validation_record", "write_validation_record"]
