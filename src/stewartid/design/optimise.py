"""Choosing a design: a small grid of schedules, each with the largest amplitudes within ``max_use``
of every limit, scaled down where the plant exceeds it, predicted at full length (bias does not
shrink with time); the best by :func:`required_score` is checked by a Monte Carlo.
"""

from __future__ import annotations

import dataclasses
import itertools
from collections.abc import Callable, Mapping, Sequence

import numpy as np

from stewartid.design.candidates import Design, DesignedRecord, scheduled_design, unit_direction
from stewartid.design.limits import (
    LimitUse,
    amplitude_scale,
    limit_use,
    record_limit_use,
    resolve_limits,
    rest_use,
)
from stewartid.design.prediction import Prediction, plant_records, predict_accuracy
from stewartid.design.weak_information import (
    checked_prediction,
    has_information,
    information_prediction,
)
from stewartid.errors import ConfigError
from stewartid.model.dynamics import inverse_dynamics
from stewartid.model.kinematics import inverse_kinematics, leg_jacobian
from stewartid.parallel import worker_count
from stewartid.platform import Platform
from stewartid.reference.published import PAPER_ENTRIES
from stewartid.simulation.excitation import DEFAULT_AMPLITUDES
from stewartid.simulation.sensors import SensorNoise

#: Records that share a frequency: surge and sway, heave (all legs alike), the rotations.
FREQUENCY_GROUPS = ((0, 1), (2,), (3, 4, 5))
#: Frequencies tried (Hz) for each of :data:`FREQUENCY_GROUPS`.
DEFAULT_FREQUENCIES = ((0.75,), (0.5, 0.75), (0.75,))
#: Level schedules tried, relative to the largest amplitude: one for every record, or six.
#: Two well separated levels let Method B tell viscous from Coulomb friction.
DEFAULT_SCHEDULES = ((1.0, 0.3),)
#: Largest amplitudes, as multiples of the paper's (20 mm, 10 mrad) per DOF: beyond them the
#: pose dependence of M(q) and of the joint Jacobians shows in the noise-free estimate.
DEFAULT_AMPLITUDE_CAP = (6.0, 6.0, 6.0, 4.0, 4.0, 4.0)
#: Accuracy required of each group of the paper's entries (% of nominal).
REQUIRED_ACCURACY = {"Mt diagonal": 0.5, "Bt diagonal": 2.0, "couplings": 8.0}


def entry_group(key: tuple[str, int, int]) -> str:
    """Group (a key of :data:`REQUIRED_ACCURACY`) of a paper entry (matrix, row, column)."""
    matrix, row, column = key
    if row != column:
        return "couplings"
    return "Mt diagonal" if matrix == "M" else "Bt diagonal"


def commanded_use(platform: Platform, record: DesignedRecord) -> LimitUse:
    """Limit use of a record played exactly (inverse kinematics, rigid-body forces with friction)."""
    rate = platform.sensors.sample_rate
    t = np.arange(int(record.duration * rate) + 1) / rate
    dq, q_dot, q_ddot = record.evaluate_offsets(t)
    q = dq + platform.neutral_pose
    jacobian = leg_jacobian(platform, q)
    rates = np.einsum("nij,nj->ni", jacobian, q_dot)
    accelerations = np.gradient(rates, t, axis=0)
    return limit_use(platform, resolve_limits(platform), t, q,
                     inverse_kinematics(platform, q).lengths, rates, accelerations,
                     inverse_dynamics(platform, q, q_dot, q_ddot))


def largest_root(g: Callable[[float], float], low: float, high: float, tolerance: float
                 ) -> float:
    """Largest x in [low, high] with g(x) <= 0 within ``tolerance``, for increasing g; 0 when
    g(low) > 0. Illinois regula falsi: limit use is nearly linear in amplitude.
    """
    g_low, g_high = g(low), g(high)
    if g_low > 0:
        return 0.0
    side = 0
    while high - low > tolerance:
        x = (low * g_high - high * g_low) / (g_high - g_low)
        x = min(max(x, low + 0.25 * tolerance), high - 0.25 * tolerance)
        value = g(x)
        if value <= 0:
            low, g_low = x, value
            g_high *= 0.5 if side == -1 else 1.0
            side = -1
        else:
            high, g_high = x, value
            g_low *= 0.5 if side == 1 else 1.0
            side = 1
    return low


def largest_amplitudes(platform: Platform, frequency_hz: float | Sequence[float],
                       max_use: float = 0.7,
                       cap: float | Sequence[float] = DEFAULT_AMPLITUDE_CAP) -> np.ndarray:
    """Per DOF, the largest sine amplitude (6,), m, rad, within ``max_use`` of every limit.

    Parameters
    ----------
    platform : Platform
    frequency_hz : float or sequence of 6 float
    max_use : float
        In (0, 1].
    cap : float or sequence of 6 float
        Upper bound, multiple of the paper's amplitudes.
    """
    if not 0 < max_use <= 1:
        raise ConfigError(f"max_use must be in (0, 1]; got {max_use!r}.")
    frequencies = np.broadcast_to(np.asarray(frequency_hz, dtype=float), 6)
    ceilings = np.broadcast_to(np.asarray(cap, dtype=float), 6) * np.asarray(DEFAULT_AMPLITUDES)
    out = np.zeros(6)
    for k in range(6):
        def peak(amplitude: float, k: int = k) -> float:
            record = DesignedRecord(unit_direction(k, amplitude), frequencies[k], (1.0,), 1, 1)
            return max(commanded_use(platform, record).peak.values())

        if peak(ceilings[k]) <= max_use:
            out[k] = ceilings[k]
            continue
        low = largest_root(lambda a, k=k: peak(a, k) - max_use, 1e-6 * ceilings[k],
                           ceilings[k], 2.0 ** -20 * ceilings[k])
        if low == 0.0:
            raise ConfigError(f"no motion of {['x', 'y', 'z', 'rx', 'ry', 'rz'][k]} at "
                              f"{frequencies[k]:g} Hz stays within {max_use:.0%} of the "
                              "limits (the static load alone exceeds them?); check [limits].")
        out[k] = low
    return out


def within_plant_limits(platform: Platform, design: Design, max_use: float,
                        rounds: int = 4, workers: int | None = None
                        ) -> tuple[Design, list, list[LimitUse]]:
    """Play a design on the plant (``workers`` processes) and scale down, round by round, records
    whose true states use more than ``max_use`` of a limit; return the design, its noise-free
    records and their limit uses.
    """
    records = plant_records(platform, design, workers)
    uses = [record_limit_use(platform, r) for r in records]
    rest = rest_use(platform)
    for _ in range(rounds):
        peaks = [max(u.peak.values()) for u in uses]
        over = [k for k, p in enumerate(peaks) if p > max_use + 1e-3]
        if not over:
            return design, records, uses
        changed = list(design.records)
        for k in over:
            changed[k] = changed[k].scaled(amplitude_scale(uses[k].peak, rest, 0.995 * max_use))
        design = dataclasses.replace(design, records=tuple(changed))
        again = plant_records(platform, Design(tuple(changed[k] for k in over)), workers)
        for k, record in zip(over, again, strict=True):
            records[k], uses[k] = record, record_limit_use(platform, record)
    if any(u.exceeded for u in uses):
        raise ConfigError(f"the design still exceeds the limits on the plant after {rounds} "
                          "reductions; lower --max-use or check [limits].")
    return design, records, uses


def within_plant_limits_all(platform: Platform, designs: Sequence[Design], max_use: float,
                            workers: int | None = None
                            ) -> list[tuple[Design, list, tuple[LimitUse, ...]]]:
    """:func:`within_plant_limits` of several designs, each distinct record played once."""
    distinct = list(dict.fromkeys(r for d in designs for r in d.records))
    played, records, uses = within_plant_limits(platform, Design(tuple(distinct)), max_use,
                                                workers=workers)
    found = {r: k for k, r in enumerate(distinct)}
    out = []
    for design in designs:
        keys = [found[r] for r in design.records]
        out.append((dataclasses.replace(design, records=tuple(played.records[k] for k in keys)),
                    [records[k] for k in keys], tuple(uses[k] for k in keys)))
    return out


def required_score(prediction: Prediction,
                   required: Mapping[str, float] = REQUIRED_ACCURACY) -> float:
    """Design criterion: max over the 20 entries of (|bias| + 2 SE) / required accuracy; below 1
    every entry is expected within its group's accuracy.
    """
    need = np.array([required[entry_group(k)] for k in PAPER_ENTRIES])
    return float(np.max((prediction.relative_bias + 2 * prediction.relative_std) / need))


@dataclasses.dataclass(frozen=True)
class Candidate:
    """One evaluated design: prediction and limit use on the plant."""

    design: Design
    prediction: Prediction
    plant_use: tuple[LimitUse, ...] = ()
    required: Mapping[str, float] = dataclasses.field(
        default_factory=lambda: dict(REQUIRED_ACCURACY))

    @property
    def score(self) -> float:
        """:func:`required_score` of the prediction."""
        return required_score(self.prediction, self.required)


def optimise_design(platform: Platform, budget_s: float, noise: SensorNoise,
                    method: str = "wavelet",
                    frequencies: Sequence[Sequence[float]] = DEFAULT_FREQUENCIES,
                    schedules: Sequence[Sequence] = DEFAULT_SCHEDULES,
                    max_use: float = 0.7, cap: float | Sequence[float] = DEFAULT_AMPLITUDE_CAP,
                    screening_seeds: int = 8, seeds: int = 8, source: str = "plant",
                    required: Mapping[str, float] = REQUIRED_ACCURACY,
                    progress: Callable[[str], None] | None = None,
                    workers: int | None = None,
                    realisations: Callable[[int, int], None] | None = None,
                    ) -> tuple[Candidate, list[Candidate]]:
    """Choose the design of the family with the smallest :func:`required_score`.

    Parameters
    ----------
    platform : Platform
    budget_s : float
        Total motion time (s) of the six records.
    noise : SensorNoise
    method : str
        Method the design is for.
    frequencies : sequence of 3 sequences of float
        Hz tried per :data:`FREQUENCY_GROUPS` group.
    schedules : sequence
        Level plans: one schedule for every record, or six.
    max_use : float
        Fraction of every limit used (plant states with ``"plant"``, commanded with ``"model"``).
    cap : float or sequence of 6 float
        Amplitude cap, multiple of the paper's.
    screening_seeds : int
        Realisations per candidate for methods without
        :func:`~stewartid.design.weak_information.has_information`.
    seeds : int
        Realisations of the best candidate's Monte Carlo, >= 2.
    source : {"plant", "model"}
    required : mapping
        Accuracy (%) per :data:`REQUIRED_ACCURACY` group.
    progress : callable, optional
        One line of text per step.
    workers : int, optional
    realisations : callable, optional
        Called with (done, total) per realisation.

    Returns
    -------
    best : Candidate
        Checked with ``seeds`` realisations.
    screened : list of Candidate
    """
    say = progress or (lambda text: None)
    if not budget_s > 0:
        raise ConfigError(f"budget must be > 0 s; got {budget_s!r}.")
    if set(required) != set(REQUIRED_ACCURACY) or not all(v > 0 for v in required.values()):
        raise ConfigError(f"required must give a positive accuracy (%) for each of "
                          f"{', '.join(REQUIRED_ACCURACY)}; got {dict(required)!r}.")
    if len(frequencies) != len(FREQUENCY_GROUPS):
        raise ConfigError(f"frequencies must give {len(FREQUENCY_GROUPS)} sequences (surge and "
                          f"sway, heave, rotations); got {len(frequencies)}.")
    amplitudes, designs = {}, []
    for *chosen, levels in itertools.product(*frequencies, schedules):
        f = [0.0] * 6
        for members, value in zip(FREQUENCY_GROUPS, chosen, strict=True):
            for k in members:
                f[k] = value
        for value in set(f):
            if value not in amplitudes:
                amplitudes[value] = largest_amplitudes(platform, value, max_use, cap)
        designs.append(scheduled_design([amplitudes[v][k] for k, v in enumerate(f)], f,
                                        [budget_s / 6] * 6, levels))
    if source == "plant":
        candidates = within_plant_limits_all(platform, designs, max_use, workers)
    else:
        candidates = [(d, None, tuple(commanded_use(platform, r) for r in d.records))
                      for d in designs]
    analytic = has_information(method)

    def predict(design: Design, records: list | None, count: int) -> Prediction:
        if analytic:
            return information_prediction(platform, design, noise, method, count,
                                          source=source, records=records, workers=workers,
                                          progress=realisations)
        return predict_accuracy(platform, design, noise, method, count, source=source,
                                records=records, workers=workers, progress=realisations)

    how = "information matrix" if analytic else f"{screening_seeds} seeds"
    screened = []
    for design, records, uses in candidates if len(candidates) > 1 else ():
        prediction = predict(design, records, 0 if analytic else screening_seeds)
        screened.append(Candidate(design, prediction, tuple(uses), dict(required)))
        say(f"{design.label}: criterion {screened[-1].score:.2f} (worst |bias| + 2 SE over "
            f"the required accuracy, {how})")
    index = int(np.argmin([c.score for c in screened])) if screened else 0
    design, records, uses = candidates[index]
    if analytic and screened:  # the best one's information-matrix prediction, checked
        prediction = checked_prediction(
            screened[index].prediction,
            predict_accuracy(platform, design, noise, method, seeds, source=source,
                             records=records, workers=worker_count(workers, seeds),
                             progress=realisations))
    else:
        prediction = predict(design, records, seeds)
    final = Candidate(design, prediction, tuple(uses), dict(required))
    say(f"{design.label}: criterion {final.score:.2f}, predicted worst relative SE "
        f"{prediction.worst_relative_std:.2f} % ({prediction.method})")
    return final, screened or [final]


