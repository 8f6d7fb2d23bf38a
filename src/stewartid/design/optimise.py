"""Choosing a design: amplitudes at the limits, then a small grid and a time allocation.

The family (:func:`~stewartid.design.candidates.scheduled_design`): six single-DOF records at
one frequency, each with a level schedule. For every frequency of the grid the amplitude of
each DOF is the largest whose motion uses at most ``max_use`` of every limit
(:func:`largest_amplitudes`), capped by ``max_amplitudes`` so that the motion stays in the
near-linear range the identified Mt and Bt describe. Each (frequency, schedule) candidate is
predicted on short records (standard errors scaled to the budget by 1 / sqrt(time), which
holds because every record is stationary); the best one is then predicted at full length
with the budget split equally between the six records (``split="equal"``), or re-allocated
so that the worst relative error each record informs is equalised (``split="need"``: record
k informs column k of Mt and Bt, its standard error falls as 1 / sqrt(duration)). The
re-allocation rests on short screening runs with few seeds; on the paper platform it gave
one record 6.7 s of 116 and lost on the plant to the equal split, which is the default.

The criterion is the largest relative standard error over the 20 entries of the paper's
tables; a candidate whose noise-free bias exceeds its standard error on some entry is
ranked by sqrt(bias^2 + SE^2) there instead.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable, Sequence

import numpy as np

from stewartid.design.candidates import Design, DesignedRecord, scheduled_design, unit_direction
from stewartid.design.limits import LimitUse, limit_use, resolve_limits
from stewartid.design.prediction import Prediction, predict_accuracy
from stewartid.dynamics import inverse_dynamics
from stewartid.errors import ConfigError
from stewartid.kinematics import inverse_kinematics, leg_jacobian
from stewartid.platform import Platform
from stewartid.reference.published import PAPER_ENTRIES
from stewartid.simulation.excitation import DEFAULT_AMPLITUDES
from stewartid.simulation.sensors import SensorNoise

#: Frequencies tried (Hz).
DEFAULT_FREQUENCIES = (0.75, 1.0, 1.25)
#: Level plans tried, relative to the largest amplitude: one schedule for every record, or
#: six (translations x, y, z then rotations). Two levels give the rotations intervals of two
#: speeds; the translations, at the amplitude cap, gain more from holding their top level.
DEFAULT_SCHEDULES = ((1.0,), (1.0, 0.5), ((1.0,),) * 3 + ((1.0, 0.5),) * 3)
#: Largest amplitudes, as multiples of the paper's (20 mm, 10 mrad): beyond them the pose
#: dependence of M(q) and of the joint Jacobians shows in the noise-free estimate.
DEFAULT_AMPLITUDE_CAP = 4.0


def commanded_use(platform: Platform, record: DesignedRecord) -> LimitUse:
    """Limit use of a record played exactly: inverse kinematics for the legs, the rigid-body
    model with the platform's friction for the forces."""
    rate = platform.sensors.sample_rate
    t = np.arange(int(record.duration * rate) + 1) / rate
    q, q_dot, q_ddot = design_record_motion(platform, record, t)
    jacobian = leg_jacobian(platform, q)
    rates = np.einsum("nij,nj->ni", jacobian, q_dot)
    accelerations = np.gradient(rates, t, axis=0)
    return limit_use(platform, resolve_limits(platform), t, q,
                     inverse_kinematics(platform, q).lengths, rates, accelerations,
                     inverse_dynamics(platform, q, q_dot, q_ddot))


def design_record_motion(platform: Platform, record: DesignedRecord, t: np.ndarray
                         ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Pose, rate and acceleration of a record about the neutral pose; each (N, 6)."""
    dq, dqd, dqdd = record.evaluate_offsets(t)
    return dq + platform.neutral_pose, dqd, dqdd


def largest_amplitudes(platform: Platform, frequency_hz: float, max_use: float = 0.8,
                       cap: float = DEFAULT_AMPLITUDE_CAP) -> np.ndarray:
    """Per DOF, the largest sine amplitude within ``max_use`` of every limit.

    Parameters
    ----------
    platform : Platform
    frequency_hz : float
        Hz.
    max_use : float
        Fraction of every limit the motion may use, in (0, 1].
    cap : float
        Upper bound, as a multiple of the paper's amplitudes.

    Returns
    -------
    ndarray, shape (6,)
        m, m, m, rad, rad, rad.
    """
    if not 0 < max_use <= 1:
        raise ConfigError(f"max_use must be in (0, 1]; got {max_use!r}.")
    out = np.zeros(6)
    for k in range(6):
        ceiling = cap * DEFAULT_AMPLITUDES[k]

        def peak(amplitude: float, k: int = k) -> float:
            record = DesignedRecord(unit_direction(k, amplitude), frequency_hz, (1.0,), 1, 1)
            return max(commanded_use(platform, record).peak.values())

        if peak(ceiling) <= max_use:
            out[k] = ceiling
            continue
        low, high = 0.0, ceiling
        for _ in range(20):
            middle = 0.5 * (low + high)
            low, high = (middle, high) if peak(middle) <= max_use else (low, middle)
        if low == 0.0:
            raise ConfigError(f"no motion of {['x', 'y', 'z', 'rx', 'ry', 'rz'][k]} at "
                              f"{frequency_hz:g} Hz stays within {max_use:.0%} of the limits "
                              "(the static load alone exceeds them?); check [limits].")
        out[k] = low
    return out


def column_worst(prediction: Prediction) -> np.ndarray:
    """Worst relative error (%) among the paper's entries of each column of Mt and Bt;
    shape (6,). Column k is informed by record k."""
    errors = np.hypot(prediction.relative_std, prediction.relative_bias)
    out = np.zeros(6)
    for (_, _, column), value in zip(PAPER_ENTRIES, errors, strict=True):
        out[column] = max(out[column], value)
    return out


@dataclasses.dataclass(frozen=True)
class Candidate:
    """One evaluated design and its prediction scaled to the budget."""

    design: Design
    prediction: Prediction

    @property
    def score(self) -> float:
        """Worst relative sqrt(bias^2 + SE^2) over the 20 entries (%)."""
        return self.prediction.worst_relative_error


def optimise_design(platform: Platform, budget_s: float, noise: SensorNoise,
                    method: str = "wavelet", frequencies: Sequence[float] = DEFAULT_FREQUENCIES,
                    schedules: Sequence[Sequence] = DEFAULT_SCHEDULES,
                    max_use: float = 0.8, cap: float = DEFAULT_AMPLITUDE_CAP,
                    screening_s: float = 30.0, screening_seeds: int = 6, seeds: int = 20,
                    source: str = "plant", split: str = "equal",
                    progress: Callable[[str], None] | None = None,
                    ) -> tuple[Candidate, list[Candidate]]:
    """Choose the design of the family with the smallest predicted worst relative error.

    Parameters
    ----------
    platform : Platform
    budget_s : float
        Total motion time (s) of the six records.
    noise : SensorNoise
    method : str
        Identification method the design is for.
    frequencies : sequence of float
        Hz.
    schedules : sequence
        Level plans: each one schedule (largest level first) for every record, or six.
    max_use : float
        Fraction of every limit the design may use.
    cap : float
        Amplitude cap, multiple of the paper's amplitudes.
    screening_s : float
        Total length (s) of the candidates during screening.
    screening_seeds, seeds : int
        Noise realisations in screening and for the final prediction.
    source : {"plant", "model"}
        Noise-free data of the predictions (:func:`~stewartid.design.prediction.predict_accuracy`).
    split : {"equal", "need"}
        Budget split between the six records (see the module docstring).
    progress : callable, optional
        Called with one line of text per step.

    Returns
    -------
    best : Candidate
        Predicted at the full budget with ``seeds`` realisations.
    screened : list of Candidate
        Every screened candidate, predictions scaled to the budget.
    """
    say = progress or (lambda text: None)
    if not budget_s > 0:
        raise ConfigError(f"budget must be > 0 s; got {budget_s!r}.")
    if split not in ("equal", "need"):
        raise ConfigError(f"split must be 'equal' or 'need'; got {split!r}.")
    screened = []
    for frequency in frequencies:
        amplitudes = largest_amplitudes(platform, frequency, max_use, cap)
        for levels in schedules:
            count = max(len(p) for p in levels) if isinstance(levels[0], Sequence) \
                else len(levels)
            # at least two held periods per level, whatever the screening length
            short = max(min(screening_s, budget_s) / 6, (3 * count + 1) / frequency)
            design = scheduled_design(amplitudes, frequency, [short] * 6, levels)
            prediction = predict_accuracy(platform, design, noise, method, screening_seeds,
                                          source=source)
            candidate = Candidate(design, prediction.scaled(budget_s / design.duration))
            screened.append(candidate)
            say(f"{design.label}: predicted worst error {candidate.score:.2f} %")
    best = min(screened, key=lambda c: c.score)
    first = best.design.records[0]
    levels = [r.levels for r in best.design.records]
    count = max(len(v) for v in levels)
    amplitudes = np.array([max(np.abs(r.direction)) for r in best.design.records])
    shortest = (2 * count + 1) / first.frequency_hz
    if budget_s < 6 * shortest:
        raise ConfigError(f"a budget of {budget_s:g} s is too short for six records of "
                          f"{count} levels at {first.frequency_hz:g} Hz; give at least "
                          f"{6 * shortest:g} s.")
    if split == "need":
        # duration of record k proportional to its column's variance
        need = column_worst(best.prediction) ** 2
        durations = shortest + (budget_s - 6 * shortest) * need / need.sum()
    else:
        durations = np.full(6, budget_s / 6)
    design = scheduled_design(amplitudes, first.frequency_hz, durations, levels,
                              label=f"{best.design.label}, durations {split}")
    prediction = predict_accuracy(platform, design, noise, method, seeds, source=source)
    say(f"{design.label}: predicted worst error {prediction.worst_relative_error:.2f} % "
        f"({seeds} seeds)")
    return Candidate(design, prediction.scaled(budget_s / design.duration)), screened
