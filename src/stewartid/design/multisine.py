"""Records moving every DOF at once, q_d(t) = q0_d + a(t) sum_h A[d, h] sin(2 pi F[d, h] t + phi[d, h]),
a(t) a quintic fade: the physical parameters need motion spanning the workspace.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Sequence

import numpy as np

from stewartid.design.candidates import Design, fade_envelope
from stewartid.errors import ConfigError
from stewartid.simulation.excitation import DEFAULT_AMPLITUDES

#: Frequencies (Hz) of the reference all-DOFs multisine: record k moves DOF d at
#: ``REFERENCE_HZ[(d + k) % 6]``; close enough that the estimator's kernel passes them all.
REFERENCE_HZ = (0.3, 0.45, 0.6, 0.75, 0.9, 1.05)
#: Fade-in and fade-out of every multisine record (s).
MULTISINE_FADE = 2.0
#: Longest record (s): the budget is split into records no longer than this.
RECORD_LENGTH = 20.0


def _table(value, name: str) -> tuple[tuple[float, ...], ...]:
    array = np.atleast_2d(np.asarray(value, dtype=float))
    if array.shape[0] != 6 or not np.all(np.isfinite(array)):
        raise ConfigError(f"multisine record: {name} must be 6 rows of finite numbers (one per "
                          f"DOF); got shape {array.shape}.")
    return tuple(tuple(float(v) for v in row) for row in array)


@dataclasses.dataclass(frozen=True)
class MultisineRecord:
    """Every DOF at once: sines per DOF under a fade-in and fade-out.

    Attributes
    ----------
    amplitudes, frequencies_hz, phases : tuple of 6 tuples of H float
        A (m, rad), F (Hz, > 0), phi (rad).
    duration : float
        s, fades included.
    fade : float
        Each fade (s), at most half the duration.
    name : str
    """

    amplitudes: tuple[tuple[float, ...], ...]
    frequencies_hz: tuple[tuple[float, ...], ...]
    phases: tuple[tuple[float, ...], ...]
    duration: float
    fade: float = MULTISINE_FADE
    name: str = "exp"

    def __post_init__(self) -> None:
        for key in ("amplitudes", "frequencies_hz", "phases"):
            object.__setattr__(self, key, _table(getattr(self, key), key))
        shapes = {np.shape(getattr(self, k)) for k in ("amplitudes", "frequencies_hz", "phases")}
        if len(shapes) != 1:
            raise ConfigError(f"record {self.name}: amplitudes, frequencies_hz and phases must "
                              f"have one shape; got {sorted(shapes)}.")
        if not min(map(min, self.frequencies_hz)) > 0:
            raise ConfigError(f"record {self.name}: frequencies must be > 0 Hz.")
        if not (math.isfinite(self.duration) and 0 < 2 * self.fade <= self.duration):
            raise ConfigError(f"record {self.name}: duration {self.duration!r} s must be finite "
                              f"and at least twice the fade {self.fade!r} s.")

    @property
    def max_frequency(self) -> float:
        """Highest frequency (Hz)."""
        return float(np.max(self.frequencies_hz))

    def scaled(self, factor: float) -> MultisineRecord:
        """The record with every amplitude times ``factor``."""
        return dataclasses.replace(self, amplitudes=np.asarray(self.amplitudes) * factor)

    def envelope(self, t: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Fade envelope and its first two time derivatives, each (N,)."""
        return fade_envelope(t, self.fade, self.duration)

    def evaluate_offsets(self, t: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """dq, dq_dot, dq_ddot about the base pose, each (N, 6)."""
        t = np.asarray(t, dtype=float)
        omega = 2 * math.pi * np.asarray(self.frequencies_hz)  # (6, H)
        amplitude = np.asarray(self.amplitudes)
        angle = t[:, None, None] * omega + np.asarray(self.phases)
        s, c = np.sin(angle), np.cos(angle)
        x = np.sum(amplitude * s, axis=2)
        dx = np.sum(amplitude * omega * c, axis=2)
        ddx = -np.sum(amplitude * omega ** 2 * s, axis=2)
        a, da, dda = (v[:, None] for v in self.envelope(t))
        return a * x, da * x + a * dx, dda * x + 2 * da * dx + a * ddx

    def to_dict(self) -> dict:
        """JSON-ready data."""
        return {"kind": "multisine", "name": self.name, "duration_s": self.duration,
                "fade_s": self.fade,
                **{key: [list(row) for row in getattr(self, key)]
                   for key in ("amplitudes", "frequencies_hz", "phases")}}


def record_lengths(budget_s: float, length: float = RECORD_LENGTH) -> list[float]:
    """The budget (s) split into equal records of at most ``length`` s."""
    if not (math.isfinite(budget_s) and budget_s >= 4 * MULTISINE_FADE):
        raise ConfigError(f"budget must be at least {4 * MULTISINE_FADE:g} s for records "
                          f"that move every DOF; got {budget_s!r} s.")
    n = max(1, math.ceil(budget_s / length - 1e-9))
    return [budget_s / n] * n


def multisine_design(budget_s: float, amplitudes: Sequence[float], speed: float = 1.0,
                     share: float = 0.0, seed: int = 0, label: str | None = None,
                     record_length: float = RECORD_LENGTH, fade: float = MULTISINE_FADE
                     ) -> Design:
    """Physical design family: all-DOF records, the frequency pool rotated by record so every DOF
    meets every frequency and no two DOFs share one in a record.

    Parameters
    ----------
    budget_s : float
        Total motion (s), split by :func:`record_lengths`.
    amplitudes : sequence of 6 float
        Sum of each DOF's amplitudes (m, rad).
    speed : float
        Pool = ``speed * REFERENCE_HZ``.
    share : float
        Fraction of amplitude at a second frequency, three pool places on.
    seed : int
        Phases.
    label : str, optional
    record_length, fade : float
        Longest record and each fade (s).
    """
    if not 0 <= share < 1:
        raise ConfigError(f"share must be in [0, 1); got {share!r}.")
    pool = speed * np.asarray(REFERENCE_HZ)
    amplitude = np.asarray(amplitudes, dtype=float)
    rng = np.random.default_rng(seed)
    records = []
    for k, length in enumerate(record_lengths(budget_s, record_length)):
        index = (np.arange(6) + k) % 6
        frequencies = np.column_stack([pool[index], pool[(index + 3) % 6]])
        weights = np.column_stack([amplitude * (1 - share), amplitude * share])
        records.append(MultisineRecord(weights, frequencies, rng.uniform(0, 2 * math.pi, (6, 2)),
                                       length, fade, name=f"exp{k + 1}"))
    text = label or (f"{len(records)} all-DOF multisine records, {min(pool):.3g}-"
                     f"{max(pool):.3g} Hz, second-frequency share {share:.2f}")
    return Design(tuple(records), text)


def all_dofs_multisine(budget_s: float, scale: float = 1.0, slower: float = 1.0) -> Design:
    """Reference design: record k moves DOF d at ``REFERENCE_HZ[(d + k) % 6] / slower``, ``scale``
    times the paper's amplitude, phase ``0.5 d + k`` rad.
    """
    records = []
    for k, length in enumerate(record_lengths(budget_s)):
        index = (np.arange(6) + k) % 6
        records.append(MultisineRecord(
            scale * np.asarray(DEFAULT_AMPLITUDES)[:, None],
            np.asarray(REFERENCE_HZ)[index][:, None] / slower,
            (0.5 * np.arange(6) + k)[:, None], length, name=f"exp{k + 1}"))
    amplitude = "the paper's amplitudes" if scale == 1 else f"{scale:g} x the paper's amplitudes"
    pace = "" if slower == 1 else f", frequencies / {slower:g}"
    return Design(tuple(records), f"all-DOFs multisine at {amplitude}{pace}, "
                                  f"{len(records)} x {records[0].duration:g} s")


__all__ = ["MULTISINE_FADE", "MultisineRecord", "RECORD_LENGTH", "REFERENCE_HZ",
           "all_dofs_multisine", "multisine_design", "record_lengths"]
