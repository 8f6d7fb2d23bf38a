"""A study expanded into tasks, one per (grid point, seed): the methods meet the same data, and a
key hashing parameters and seed lets a resumed run skip finished tasks."""

from __future__ import annotations

import dataclasses
import hashlib
import itertools
import json

from stewartid.studies.spec import PARAMETERS, StudySpec


@dataclasses.dataclass(frozen=True)
class StudyTask:
    """One simulation of a study and its identifications.

    Attributes
    ----------
    parameters : dict
        ``{parameter: value}`` for every :data:`~stewartid.studies.spec.PARAMETERS` name.
    seed : int
        Sensor noise seed.
    """

    parameters: dict[str, float]
    seed: int

    @property
    def key(self) -> str:
        """Stable identifier: 16 hex digits of a SHA-1 of parameters and seed."""
        canonical = json.dumps({**{name: float(self.parameters[name]) for name in PARAMETERS},
                                "seed": int(self.seed)}, sort_keys=True)
        return hashlib.sha1(canonical.encode("ascii")).hexdigest()[:16]

    @property
    def label(self) -> str:
        """Short description, e.g. ``"coulomb=5 noise_scale=1 seed=3"``."""
        values = " ".join(f"{name}={value:g}" for name, value in self.parameters.items())
        return f"{values} seed={self.seed}"


def expand_grid(spec: StudySpec) -> list[StudyTask]:
    """Every task of ``spec`` (``spec.size``, distinct keys): the grid's product times the seeds.

    Seeds are the outer loop, so a run stopped half-way has covered the whole grid."""
    names = list(spec.grid)
    tasks = []
    for seed in spec.seeds:
        for values in itertools.product(*(spec.grid[name] for name in names)):
            point = {**spec.fixed, **dict(zip(names, values, strict=True))}
            tasks.append(StudyTask({name: point[name] for name in PARAMETERS}, seed))
    return tasks


__all__ = ["StudyTask", "expand_grid"]
