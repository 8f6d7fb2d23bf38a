"""Command files of a design (CSV at the controller rate: ``t``, absolute pose in m, rad,
``l1..l6`` in m), and playing any excitation file on the plant.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

import numpy as np
from scipy.interpolate import CubicSpline

import stewartid
from stewartid.datasets.columns import read_csv_columns, to_numbers
from stewartid.datasets.log_format import decode_text
from stewartid.design.candidates import Design
from stewartid.errors import ConfigError, DataError
from stewartid.files import write_text_atomic
from stewartid.model.kinematics import forward_kinematics, inverse_kinematics
from stewartid.model.linearization import nominal_matrices
from stewartid.platform import COORDINATES, Platform
from stewartid.signals.differentiation import estimate_frequency
from stewartid.simulation.experiments import (
    SimulationResult,
    electric_meta,
    logged_force_constant,
    noise_generator,
    simulate_experiment,
)
from stewartid.simulation.sensors import SensorNoise

LENGTH_COLUMNS = tuple(f"l{k}" for k in range(1, 7))


def command_table(platform: Platform, design: Design, rate_hz: float
                  ) -> list[tuple[str, np.ndarray]]:
    """Per record, (name, table (N, 13)): t (s), pose (m, rad), leg lengths (m) at ``rate_hz``."""
    if not (math.isfinite(rate_hz) and rate_hz > 0):
        raise ConfigError(f"controller rate must be > 0 Hz; got {rate_hz!r}.")
    out = []
    for playable in design.playable(platform):
        nyquist = rate_hz / 2
        if not playable.max_frequency < nyquist / 10:
            raise ConfigError(f"controller rate {rate_hz:g} Hz is too low for "
                              f"{playable.max_frequency:g} Hz; use at least "
                              f"{20 * playable.max_frequency:g} Hz.")
        t = np.arange(int(math.floor(playable.record.duration * rate_hz + 1e-9)) + 1) / rate_hz
        q, _, _ = playable.evaluate(t)
        out.append((playable.name, np.column_stack(
            [t, q, inverse_kinematics(platform, q).lengths])))
    return out


def write_commands(platform: Platform, design: Design, directory: str | Path,
                   rate_hz: float = 500.0) -> list[Path]:
    """Write one command file ``<record>.csv`` per record into ``directory``; return the paths."""
    directory = Path(directory)
    directory.mkdir(parents=True, exist_ok=True)
    header = ",".join(("t", *COORDINATES, *LENGTH_COLUMNS))
    paths = []
    for name, table in command_table(platform, design, rate_hz):
        lines = [header] + [",".join(f"{v:.10g}" for v in row) for row in table]
        paths.append(write_text_atomic(directory / f"{name}.csv", "\n".join(lines) + "\n"))
    return paths


@dataclasses.dataclass(frozen=True)
class TabulatedExcitation:
    """A sampled pose trajectory played through a cubic spline.

    Attributes
    ----------
    t : ndarray, shape (N,)
        s, strictly increasing, from 0.
    pose : ndarray, shape (N, 6)
        m, rad.
    name : str
    max_frequency : float
        Dominant frequency (Hz), for the plant's sampling check.
    """

    t: np.ndarray
    pose: np.ndarray
    name: str
    max_frequency: float

    @property
    def duration(self) -> float:
        """s."""
        return float(self.t[-1] - self.t[0])

    def evaluate(self, t: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Pose, velocity and acceleration at ``t`` (s), each (N, 6); held after the end."""
        spline = CubicSpline(self.t, self.pose, axis=0, bc_type="clamped")
        inside = np.clip(np.asarray(t, dtype=float), self.t[0], self.t[-1])
        return spline(inside), spline(inside, 1), spline(inside, 2)


def read_excitation(path: str | Path, platform: Platform) -> TabulatedExcitation:
    """Read an excitation file: ``t`` with the pose columns or ``l1..l6``.

    Raises
    ------
    DataError
        Unreadable, missing columns, non-finite values, or time not strictly increasing.
    """
    path = Path(path)
    if not path.is_file():
        raise DataError(f"{path}: no such excitation file.")
    text = decode_text(path.read_bytes(), str(path))
    try:
        frame = read_csv_columns(text, str(path))
    except DataError as exc:
        raise DataError(f"{path}: not a readable CSV table ({exc.__cause__}).") from None
    columns = set(frame)
    if "t" not in columns:
        raise DataError(f"{path}: missing column 't' (s).")
    has_pose = set(COORDINATES) <= columns
    if not has_pose and not set(LENGTH_COLUMNS) <= columns:
        raise DataError(f"{path}: give the pose columns {', '.join(COORDINATES)} (m, rad) or "
                        f"the leg lengths {', '.join(LENGTH_COLUMNS)} (m).")
    used = ["t", *(COORDINATES if has_pose else LENGTH_COLUMNS)]
    values = np.column_stack([to_numbers(frame[name]) for name in used])
    if not np.all(np.isfinite(values)):
        raise DataError(f"{path}: non-finite values in columns {', '.join(used)}.")
    t = values[:, 0] - values[0, 0]
    if len(t) < 4 or not np.all(np.diff(t) > 0):
        raise DataError(f"{path}: t must be strictly increasing over at least 4 samples.")
    pose = values[:, 1:] if has_pose else forward_kinematics(platform, values[:, 1:])
    rate = (len(t) - 1) / t[-1]
    return TabulatedExcitation(t=t, pose=pose, name=path.stem,
                               max_frequency=estimate_frequency(pose, rate))


def simulate_excitations(platform: Platform, excitations: Sequence[Any],
                         noise: SensorNoise | None = None, seed: int = 0,
                         progress: Callable[[int, int, str], Any] | None = None,
                         current_noise: float = 0.0):
    """Play excitations on the plant, one experiment each (``exp1..expN``); return a
    :class:`~stewartid.simulation.SimulationResult`.

    Parameters
    ----------
    platform : Platform
    excitations : sequence
        :class:`TabulatedExcitation` or :meth:`~stewartid.design.candidates.Design.playable` records.
    noise : SensorNoise, optional
        Default: the platform's ``[sensors]``.
    seed : int
        One stream per experiment, as ``simulate``.
    progress : callable, optional
        ``progress(done, total, name)``.
    current_noise : float
        Electric legs: noise of each motor current as a fraction of its RMS, as ``simulate``.
    """
    noise = SensorNoise.from_sensors(platform.sensors) if noise is None else noise
    datasets, records, sources = [], [], []
    for k, excitation in enumerate(excitations):
        duration = (excitation.duration if hasattr(excitation, "duration")
                    else excitation.record.duration)
        dataset, record = simulate_experiment(platform, excitation, duration, noise,
                                              noise_generator(seed, k, len(excitations)),
                                              current_noise=current_noise)
        datasets.append(dataclasses.replace(dataset, name=f"exp{k + 1}"))
        records.append(record)
        sources.append(excitation.name)
        if progress is not None:
            progress(k + 1, len(excitations), excitation.name)
    M, B = nominal_matrices(platform)
    meta = {"platform": platform.to_dict(), "platform_name": platform.name,
            "excitation": {"sources": sources}, "noise": dataclasses.asdict(noise),
            "seed": int(seed),
            "tracking_error_rms": [r.tracking_error().tolist() for r in records],
            "nominal": {"M": M.tolist(), "B": B.tolist()}, "version": stewartid.__version__,
            **electric_meta(platform, current_noise)}
    return SimulationResult(datasets, meta, records, logged_force_constant(platform))
