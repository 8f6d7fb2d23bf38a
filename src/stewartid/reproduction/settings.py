"""Settings and result object of a reproduction of the paper's comparison (Zhang 2020): every
registered method and preset at each Coulomb level (0, 5, 30 N m) on the plant simulator."""

from __future__ import annotations

import math
import os
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from stewartid.errors import ConfigError
from stewartid.reproduction.comparison import ComparisonResults

#: Coulomb friction levels of the paper's experiments (N·m per joint axis).
COULOMB_LEVELS = (0.0, 5.0, 30.0)
#: Excitation frequency of the paper's experiments (Hz).
FREQUENCY_HZ = 0.5
#: Record length per experiment (s): full run and ``--quick`` (the shortest every method runs on).
FULL_DURATION_S = 20.0
QUICK_DURATION_S = 6.0



def default_methods() -> tuple[str, ...]:
    """Every method and preset the comparisons run (``MethodSpec.compared``), in registry order."""
    from stewartid.identification.registry import registered_methods

    return tuple(spec.name for spec in registered_methods() if spec.compared)


#: Coulomb level (index into the levels run, from the top) whose experiment is plotted.
TRACE_EXPERIMENT = 0


@dataclass(frozen=True)
class ReproduceSettings:
    """What a reproduction runs.

    Attributes
    ----------
    quick : bool
        Shortened records (``QUICK_DURATION_S``), for tests and CI.
    duration_s : float
        Record length per experiment (s).
    frequency_hz : float
        Sine excitation frequency (Hz).
    coulomb_levels : tuple of float
        Coulomb friction per joint axis, one plant each (N m).
    methods : tuple of str
        Registered method names; every method and preset by default.
    seed : int
        Simulator noise seed, the same at every level.
    jobs : int
        Worker processes (1: in this process).
    platform : str
        ``"paper"`` or a platform TOML file.
    noise_case : bool
        Also run every method at the highest level with reference sensor noise.
    """

    quick: bool = False
    duration_s: float = FULL_DURATION_S
    frequency_hz: float = FREQUENCY_HZ
    coulomb_levels: tuple[float, ...] = COULOMB_LEVELS
    methods: tuple[str, ...] = field(default_factory=lambda: default_methods())
    seed: int = 0
    jobs: int = 1
    platform: str = "paper"
    noise_case: bool = True

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready settings."""
        return {"quick": self.quick, "duration_s": self.duration_s,
                "frequency_hz": self.frequency_hz,
                "coulomb_levels": list(self.coulomb_levels), "methods": list(self.methods),
                "seed": self.seed, "jobs": self.jobs, "platform": self.platform,
                "experiments": 6, "noise_case": self.noise_case}


def make_settings(quick: bool = False, jobs: int | None = None, seed: int = 0,
                  duration_s: float | None = None,
                  coulomb_levels: Sequence[float] = COULOMB_LEVELS,
                  methods: Sequence[str] | None = None, platform: str = "paper",
                  frequency_hz: float = FREQUENCY_HZ, noise_case: bool = True
                  ) -> ReproduceSettings:
    """Validated :class:`ReproduceSettings`; ``jobs=None`` uses every core."""
    jobs = (os.cpu_count() or 1) if jobs is None else jobs
    if isinstance(jobs, bool) or not isinstance(jobs, int) or jobs < 1:
        raise ConfigError(f"jobs must be a positive integer (worker processes); got {jobs!r}.")
    duration = (QUICK_DURATION_S if quick else FULL_DURATION_S) if duration_s is None \
        else float(duration_s)
    if not (math.isfinite(duration) and duration > 0):
        raise ConfigError(f"duration_s must be a positive number of seconds; got {duration_s!r}.")
    levels = tuple(float(c) for c in coulomb_levels)
    if not levels or any(not (math.isfinite(c) and c >= 0) for c in levels):
        raise ConfigError(f"coulomb_levels must be non-negative numbers (N·m); got "
                          f"{list(coulomb_levels)!r}.")
    known = default_methods()
    methods = known if methods is None else tuple(methods)
    unknown = [m for m in methods if m not in known]
    if unknown or not methods:
        raise ConfigError(f"unknown method(s) {unknown!r}; expected some of {list(known)}.")
    if isinstance(seed, bool) or not isinstance(seed, int | np.integer) or seed < 0:
        raise ConfigError(f"seed must be a non-negative integer; got {seed!r}.")
    return ReproduceSettings(quick=bool(quick), duration_s=duration,
                             frequency_hz=float(frequency_hz), coulomb_levels=levels,
                             methods=methods, seed=int(seed), jobs=int(jobs),
                             platform=str(platform), noise_case=bool(noise_case))


@dataclass(frozen=True)
class ReproduceOutput:
    """What :func:`~stewartid.reproduction.run.run_reproduce` produced.

    Attributes
    ----------
    results : ComparisonResults
    directory : Path
    files : list of Path
        Every file written.
    runtime_s : float
        Wall time (s).
    """

    results: ComparisonResults
    directory: Path
    files: list[Path] = field(default_factory=list)
    runtime_s: float = 0.0


__all__ = ["COULOMB_LEVELS", "FREQUENCY_HZ", "FULL_DURATION_S", "QUICK_DURATION_S",
           "TRACE_EXPERIMENT", "ReproduceOutput", "ReproduceSettings", "default_methods",
           "make_settings"]
