"""Choosing the physical design: all-DOF multisines at the limits, :func:`design_objective`
minimised.

The family (:func:`~stewartid.design.multisine.multisine_design`) has eight parameters: six
DOF log-weights on the paper's amplitudes, the log speed of the frequency pool and the
second-frequency share. Each candidate is scaled to the limits (:func:`scale_to_limits`) and
judged by its information-matrix prediction. Random candidates (fixed seed), then
Nelder-Mead, each within a fixed number of evaluations, so that the design does not depend on
the machine's speed.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable, Mapping

import numpy as np
import scipy.optimize

from stewartid.design.candidates import Design
from stewartid.design.limits import LimitUse, limit_use, resolve_limits
from stewartid.design.multisine import MULTISINE_FADE, RECORD_LENGTH, multisine_design
from stewartid.design.physical.information import (
    INFORMATION_RATE,
    ParameterPrediction,
    design_rows,
    predict_parameters,
    record_ends,
)
from stewartid.design.physical.payload_accuracy import payload_criterion, payload_objective
from stewartid.errors import ConfigError
from stewartid.model import regressor as reg
from stewartid.model.kinematics import inverse_kinematics, leg_jacobian
from stewartid.platform import Platform
from stewartid.simulation.excitation import DEFAULT_AMPLITUDES
from stewartid.simulation.sensors import SensorNoise

#: Bounds of the search: log-weights of the DOFs, log of the speed, second-frequency share.
WEIGHT_BOUNDS = (-2.5, 2.5)
SPEED_BOUNDS = (0.5, 1.0)
SHARE_BOUNDS = (0.0, 0.6)
#: The speed's bounds in payload mode: faster motion shows the payload's inertia better, and
#: the pose noise it brings falls mostly on the friction, a nuisance there but a result in
#: full mode.
PAYLOAD_SPEED_BOUNDS = (0.5, 2.0)
#: Payload mode's longest record and fade (s): less of the time spent fading. Full mode keeps
#: the reference's, which serve its friction better.
PAYLOAD_RECORD = (30.0, 1.0)
#: Candidates evaluated at random, then by Nelder-Mead from the best.
RANDOM_CANDIDATES = 12
LOCAL_EVALUATIONS = 48
#: Nelder-Mead evaluations of :func:`refine_for_plant`, and how far below 1 a record's plant
#: scale (:func:`plant_scales`) must be for the search to be refined.
PLANT_EVALUATIONS = 24
PLANT_TOLERANCE = 0.02
#: Rounds of :func:`refine_for_plant` at most: a refined pick played on the plant may need
#: its records scaled again.
PLANT_ROUNDS = 2


def commanded_limit_use(platform: Platform, design: Design, rate_hz: float = INFORMATION_RATE
                        ) -> tuple[LimitUse, tuple[np.ndarray, np.ndarray, np.ndarray]]:
    """Limit use of a design's commanded motion at ``rate_hz``, the forces those of the rigid-body
    model (J_lq^-T Y pi), and the states it was taken at.

    Returns
    -------
    use : LimitUse
        Of all records one after the other.
    states : tuple of ndarray
        (q, q_dot, q_ddot), each (K, 6), and the standard regressor there (K, 6, N_STANDARD).
    """
    q, q_dot, q_ddot = design_rows(platform, design, rate_hz)
    jacobian = leg_jacobian(platform, q)
    rows = reg.regressor(platform, q, q_dot, q_ddot)
    generalized = rows @ reg.standard_parameters(platform)
    forces = np.linalg.solve(np.swapaxes(jacobian, 1, 2), generalized[..., None])[..., 0]
    rates = np.einsum("nij,nj->ni", jacobian, q_dot)
    t = np.arange(len(q)) / rate_hz  # records back to back, each from rest: gradients hold
    use = limit_use(platform, resolve_limits(platform), t, q,
                    inverse_kinematics(platform, q).lengths, rates,
                    np.gradient(rates, t, axis=0), forces)
    return use, (q, q_dot, q_ddot, rows)


def record_peaks(design: Design, use: LimitUse, rate_hz: float = INFORMATION_RATE
                 ) -> np.ndarray:
    """Largest use of any limit in each record, from the use of all records one after the other
    at ``rate_hz`` (:func:`commanded_limit_use`); shape (records,).
    """
    edges = record_ends(design, rate_hz)
    return np.array([use.use[a:b].max() for a, b in zip(edges[:-1], edges[1:], strict=True)])


def scale_to_limits(platform: Platform, design: Design, max_use: float | np.ndarray,
                    rate_hz: float = INFORMATION_RATE, rounds: int = 4
                    ) -> tuple[Design, LimitUse, tuple]:
    """Scale each record's amplitudes until its commanded motion uses ``max_use`` of its most
    used limit (within 2 %; one value for all records, or one per record).

    Each record on its own, so that the one reaching a limit first does not hold the others below
    theirs.

    Returns
    -------
    design : Design
    use : LimitUse
    states : tuple of ndarray
        (q, q_dot, q_ddot) of the scaled design at ``rate_hz`` and the standard regressor.
    """
    target = np.broadcast_to(np.asarray(max_use, dtype=float), len(design.records))
    for _ in range(rounds):
        use, states = commanded_limit_use(platform, design, rate_hz)
        peaks = record_peaks(design, use, rate_hz)
        if np.all(np.abs(peaks - target) <= 0.02 * target):
            break
        design = dataclasses.replace(design, records=tuple(
            r.scaled(aim / peak) for r, peak, aim in zip(design.records, peaks, target,
                                                         strict=True)))
    else:
        use, states = commanded_limit_use(platform, design, rate_hz)
    return design, use, states


@dataclasses.dataclass(frozen=True)
class PhysicalCandidate:
    """A candidate of the search with its prediction.

    Attributes
    ----------
    design : Design
    prediction : ParameterPrediction
    parameters : ndarray, shape (8,)
        Log-weights of the six DOFs, log speed, second-frequency share.
    commanded_peak : dict of str to float
        Peak use of every limit by the commanded motion.
    """

    design: Design
    prediction: ParameterPrediction
    parameters: np.ndarray
    commanded_peak: dict[str, float]

    @property
    def score(self) -> float:
        """What the search minimises (:func:`design_objective`)."""
        return design_objective(self.prediction)


def design_objective(prediction: ParameterPrediction,
                     correction: Mapping[str, float] | None = None) -> float:
    """What the search minimises.

    Full mode: the criterion (the worst relative standard error). Payload mode: the ten
    parameters' worst relative standard error with the payload's quantities held within their
    accuracy (:func:`~stewartid.design.physical.payload_accuracy.payload_objective`).
    ``correction`` (:func:`~stewartid.design.physical.refine.search_correction`) multiplies the
    worst relative standard error (``"worst"``) and each payload quantity's.
    """
    factor = correction or {}
    if not prediction.payload:
        return prediction.criterion * factor.get("worst", 1.0)
    std = {k: v * factor.get(k, 1.0) for k, v in prediction.payload_std_errors.items()}
    return payload_objective(prediction.worst_relative_std * factor.get("worst", 1.0), std,
                             prediction.accuracy)


def criterion_text(prediction: ParameterPrediction) -> str:
    """The criterion's value, with its unit and what sets it, in words."""
    if not prediction.payload:
        return (f"worst relative SE {prediction.worst_relative_std:.3g} % "
                f"({prediction.worst_parameter})")
    ratio, worst = payload_criterion(prediction.payload_std_errors, prediction.accuracy)
    return (f"worst SE over required accuracy {ratio:.3g} ({worst}), worst relative SE "
            f"{prediction.worst_relative_std:.3g} % ({prediction.worst_parameter})")


def _bounds(payload: bool) -> tuple[np.ndarray, np.ndarray]:
    """Lower and upper bounds of the search's eight parameters."""
    speeds = np.log(speed_bounds(payload))
    return (np.array([WEIGHT_BOUNDS[0]] * 6 + [speeds[0], SHARE_BOUNDS[0]]),
            np.array([WEIGHT_BOUNDS[1]] * 6 + [speeds[1], SHARE_BOUNDS[1]]))


def speed_bounds(payload: bool) -> tuple[float, float]:
    """The search's bounds on the frequency pool's speed (:data:`SPEED_BOUNDS`, or
    :data:`PAYLOAD_SPEED_BOUNDS` in payload mode).
    """
    return PAYLOAD_SPEED_BOUNDS if payload else SPEED_BOUNDS


def candidate(platform: Platform, budget_s: float, noise: SensorNoise, payload: bool,
              parameters: np.ndarray, max_use: float, scales: np.ndarray | None = None,
              accuracy: Mapping[str, float] | None = None) -> PhysicalCandidate:
    """One member of the family at the limits, with its prediction.

    With ``scales`` (:func:`plant_scales`) each record's amplitudes are then multiplied by its
    own; ``accuracy`` is what payload mode judges against (:func:`judged_against`).
    """
    weights, speed, share = parameters[:6], parameters[6], parameters[7]
    amplitudes = np.exp(np.clip(weights, *WEIGHT_BOUNDS)) * np.asarray(DEFAULT_AMPLITUDES)
    record_length, fade = PAYLOAD_RECORD if payload else (RECORD_LENGTH, MULTISINE_FADE)
    design = multisine_design(budget_s, amplitudes, math.exp(np.clip(speed, *np.log(
        speed_bounds(payload)))), float(np.clip(share, *SHARE_BOUNDS)),
        record_length=record_length, fade=fade)
    design, use, states = scale_to_limits(platform, design, max_use)
    if scales is None:
        prediction = predict_parameters(platform, design, noise, payload, states=states[:3],
                                        rows=states[3])
    else:
        design = dataclasses.replace(design, records=tuple(
            r.scaled(k) for r, k in zip(design.records, scales, strict=True)))
        prediction = predict_parameters(platform, design, noise, payload)
    return PhysicalCandidate(design, judged_against(prediction, accuracy),
                             np.asarray(parameters, dtype=float), use.peak)


def judged_against(prediction: ParameterPrediction, accuracy: Mapping[str, float] | None
                   ) -> ParameterPrediction:
    """``prediction`` with payload mode's criterion taken against ``accuracy`` (keys and units of
    :data:`~stewartid.design.physical.payload_accuracy.REQUIRED_PAYLOAD_ACCURACY`; None: those).
    """
    return prediction if accuracy is None else dataclasses.replace(prediction,
                                                                   accuracy=dict(accuracy))


def plant_scales(design: Design, played: Design) -> np.ndarray:
    """Per record, the factor its amplitudes were scaled by to keep the plant's states within the
    limits (``played`` against ``design``): what the plant's tracking takes from the commanded
    motion. Shape (records,), at most 1.
    """
    return np.array([np.linalg.norm(b.amplitudes) / np.linalg.norm(a.amplitudes)
                     for a, b in zip(design.records, played.records, strict=True)])


def refine_for_plant(platform: Platform, budget_s: float, noise: SensorNoise, payload: bool,
                     max_use: float, start: np.ndarray, scales: np.ndarray,
                     evaluations: int = PLANT_EVALUATIONS,
                     accuracy: Mapping[str, float] | None = None,
                     correction: Mapping[str, float] | None = None) -> PhysicalCandidate:
    """Nelder-Mead again from ``start``, each candidate's record k scaled by the played pick's
    plant scale of record k (:func:`plant_scales`): the motion judged as the plant will allow it.

    Record k keeps its order of frequencies across candidates, so its scale carries over to the
    neighbours; ``correction`` (:func:`~stewartid.design.physical.refine.search_correction`)
    carries the played pick's final prediction over likewise.

    Returns
    -------
    PhysicalCandidate
        The best candidate seen, by :func:`design_objective` with ``correction``.
    """
    lower, upper = _bounds(payload)
    seen: list[PhysicalCandidate] = []

    def score(c: PhysicalCandidate) -> float:
        return design_objective(c.prediction, correction)

    def evaluate(x: np.ndarray) -> float:
        seen.append(candidate(platform, budget_s, noise, payload, np.clip(x, lower, upper),
                              max_use, scales, accuracy))
        return math.log(score(seen[-1]))

    simplex = start + np.vstack([np.zeros(8), 0.15 * (upper - lower) * np.eye(8)])
    scipy.optimize.minimize(evaluate, start, method="Nelder-Mead", options={
        "maxfev": evaluations, "initial_simplex": np.clip(simplex, lower, upper)})
    return min(seen, key=score)


def search_design(platform: Platform, budget_s: float, noise: SensorNoise,
                  payload: bool = False, max_use: float = 0.7, seed: int = 0,
                  random_candidates: int = RANDOM_CANDIDATES,
                  local_evaluations: int = LOCAL_EVALUATIONS,
                  progress: Callable[[str], None] | None = None,
                  accuracy: Mapping[str, float] | None = None) -> PhysicalCandidate:
    """The member of the family with the smallest :func:`design_objective`.

    Parameters
    ----------
    platform : Platform
    budget_s : float
        Total motion time (s).
    noise : SensorNoise
    payload : bool
        Judge the payload's ten parameters (payload mode), else every base parameter but
        friction and offsets.
    max_use : float
        Fraction of the most used limit the commanded motion reaches, in (0, 1].
    seed : int
        Of the random candidates and the phases.
    random_candidates, local_evaluations : int
        Evaluations of the random stage and of Nelder-Mead.
    progress : callable, optional
        Receives a line of text per stage.
    accuracy : mapping, optional
        Payload mode: the accuracy each payload quantity is needed to (default
        :data:`~stewartid.design.physical.payload_accuracy.REQUIRED_PAYLOAD_ACCURACY`).

    Returns
    -------
    PhysicalCandidate
    """
    if not 0 < max_use <= 1:
        raise ConfigError(f"max_use must be in (0, 1]; got {max_use!r}.")
    rng = np.random.default_rng(seed)
    lower, upper = _bounds(payload)
    starts = [np.array([0.0] * 6 + [0.0, 0.0])]  # the reference's shape, at the limits
    starts += [rng.uniform(lower, upper) for _ in range(random_candidates - 1)]
    seen: list[PhysicalCandidate] = []

    def evaluate(x: np.ndarray) -> float:
        seen.append(candidate(platform, budget_s, noise, payload, np.clip(x, lower, upper),
                              max_use, accuracy=accuracy))
        return math.log(seen[-1].score)

    for x in starts:
        evaluate(x)
    best = min(seen, key=lambda c: c.score)
    if progress:
        progress(f"{len(seen)} random candidates: best {criterion_text(best.prediction)}")
    if local_evaluations > 0:
        simplex = best.parameters + np.vstack([np.zeros(8), 0.25 * (upper - lower) * np.eye(8)])
        scipy.optimize.minimize(evaluate, best.parameters, method="Nelder-Mead", options={
            "maxfev": local_evaluations, "initial_simplex": np.clip(simplex, lower, upper),
            "xatol": 1e-3, "fatol": 1e-3})
        best = min(seen, key=lambda c: c.score)
        if progress:
            progress(f"{len(seen)} candidates in all: {criterion_text(best.prediction)}")
    return best


__all__ = ["LOCAL_EVALUATIONS", "PAYLOAD_RECORD", "PAYLOAD_SPEED_BOUNDS", "PLANT_EVALUATIONS",
           "PLANT_ROUNDS", "PLANT_TOLERANCE", "PhysicalCandidate", "RANDOM_CANDIDATES",
           "SHARE_BOUNDS", "SPEED_BOUNDS", "WEIGHT_BOUNDS", "candidate", "commanded_limit_use",
           "criterion_text", "design_objective", "judged_against", "plant_scales",
           "record_peaks", "refine_for_plant", "scale_to_limits", "search_design",
           "speed_bounds"]
