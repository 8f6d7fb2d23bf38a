"""Choosing the physical design: all-DOF multisines scaled to the limits, :func:`design_objective`
minimised over eight family parameters by seeded random candidates then Nelder-Mead, each
within a fixed evaluation count so the design does not depend on the machine's speed.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable, Mapping

import numpy as np
import scipy.optimize

from stewartid.design.candidates import Design
from stewartid.design.limits import (
    LIMIT_NAMES,
    LimitUse,
    amplitude_scale,
    limit_use,
    resolve_limits,
    rest_use,
)
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
    """Limit use of a design's commanded motion at ``rate_hz`` (records in sequence, rigid-body
    forces J_lq^-T Y pi), and the states: (q, q_dot, q_ddot) each (K, 6) and the standard
    regressor (K, 6, N_STANDARD).
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
    """Largest use of any limit per record, shape (records,), from :func:`commanded_limit_use`."""
    edges = record_ends(design, rate_hz)
    return np.array([use.use[a:b].max() for a, b in zip(edges[:-1], edges[1:], strict=True)])


def scale_to_limits(platform: Platform, design: Design, max_use: float | np.ndarray,
                    rate_hz: float = INFORMATION_RATE, rounds: int = 4
                    ) -> tuple[Design, LimitUse, tuple]:
    """Scale each record's amplitudes, on its own, until its commanded motion uses ``max_use``
    (scalar or per record, within 2 %) of its most used limit; return design, use and states.
    """
    target = np.broadcast_to(np.asarray(max_use, dtype=float), len(design.records))
    rest = rest_use(platform)
    edges = record_ends(design, rate_hz)
    for _ in range(rounds):
        use, states = commanded_limit_use(platform, design, rate_hz)
        peaks = record_peaks(design, use, rate_hz)
        if np.all(np.abs(peaks - target) <= 0.02 * target):
            break
        limits = [dict(zip(LIMIT_NAMES, use.use[a:b].max(axis=0), strict=True))
                  for a, b in zip(edges[:-1], edges[1:], strict=True)]
        design = dataclasses.replace(design, records=tuple(
            r.scaled(amplitude_scale(peak, rest, aim))
            for r, peak, aim in zip(design.records, limits, target, strict=True)))
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
        Six DOF log-weights, log speed, second-frequency share.
    commanded_peak : dict of str to float
        Peak use of every limit by the commanded motion.
    """

    design: Design
    prediction: ParameterPrediction
    parameters: np.ndarray
    commanded_peak: dict[str, float]

    @property
    def score(self) -> float:
        """:func:`design_objective` of the prediction."""
        return design_objective(self.prediction)


def design_objective(prediction: ParameterPrediction,
                     correction: Mapping[str, float] | None = None) -> float:
    """What the search minimises: the worst relative standard error; in payload mode with the
    payload's quantities held within their accuracy
    (:func:`~stewartid.design.physical.payload_accuracy.payload_objective`). ``correction``
    (:func:`~stewartid.design.physical.refine.search_correction`) multiplies those terms.
    """
    factor = correction or {}
    if not prediction.payload:
        return prediction.criterion * factor.get("worst", 1.0)
    std = {k: v * factor.get(k, 1.0) for k, v in prediction.payload_std_errors.items()}
    return payload_objective(prediction.worst_relative_std * factor.get("worst", 1.0), std,
                             prediction.accuracy)


def criterion_text(prediction: ParameterPrediction) -> str:
    """The criterion's value, unit and what sets it, in words."""
    if not prediction.payload:
        return (f"worst relative SE {prediction.worst_relative_std:.3g} % "
                f"({prediction.worst_parameter})")
    ratio, worst = payload_criterion(prediction.payload_std_errors, prediction.accuracy)
    return (f"worst SE over required accuracy {ratio:.3g} ({worst}), worst relative SE "
            f"{prediction.worst_relative_std:.3g} % ({prediction.worst_parameter})")


def _bounds(payload: bool) -> tuple[np.ndarray, np.ndarray]:
    speeds = np.log(speed_bounds(payload))
    return (np.array([WEIGHT_BOUNDS[0]] * 6 + [speeds[0], SHARE_BOUNDS[0]]),
            np.array([WEIGHT_BOUNDS[1]] * 6 + [speeds[1], SHARE_BOUNDS[1]]))


def speed_bounds(payload: bool) -> tuple[float, float]:
    """Bounds on the frequency pool's speed: :data:`SPEED_BOUNDS` or :data:`PAYLOAD_SPEED_BOUNDS`."""
    return PAYLOAD_SPEED_BOUNDS if payload else SPEED_BOUNDS


def candidate(platform: Platform, budget_s: float, noise: SensorNoise, payload: bool,
              parameters: np.ndarray, max_use: float, scales: np.ndarray | None = None,
              accuracy: Mapping[str, float] | None = None) -> PhysicalCandidate:
    """One family member at the limits with its prediction; record amplitudes times ``scales``
    (:func:`plant_scales`) when given, payload mode judged against ``accuracy``.
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
    """``prediction`` with payload mode's criterion against ``accuracy`` (None: the required one)."""
    return prediction if accuracy is None else dataclasses.replace(prediction,
                                                                   accuracy=dict(accuracy))


def plant_scales(design: Design, played: Design) -> np.ndarray:
    """Per record, factor (<= 1) the plant's limits scaled ``played`` from ``design``; shape (records,)."""
    return np.array([np.linalg.norm(b.amplitudes) / np.linalg.norm(a.amplitudes)
                     for a, b in zip(design.records, played.records, strict=True)])


def refine_for_plant(platform: Platform, budget_s: float, noise: SensorNoise, payload: bool,
                     max_use: float, start: np.ndarray, scales: np.ndarray,
                     evaluations: int = PLANT_EVALUATIONS,
                     accuracy: Mapping[str, float] | None = None,
                     correction: Mapping[str, float] | None = None) -> PhysicalCandidate:
    """Nelder-Mead again from ``start``, record k of each candidate scaled by the played pick's
    plant scale k, so the motion is judged as the plant will allow; best by :func:`design_objective`
    with ``correction``.
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
    """Member of the family with the smallest :func:`design_objective`.

    Parameters
    ----------
    platform : Platform
    budget_s : float
        Total motion time (s).
    noise : SensorNoise
    payload : bool
        Judge the payload's ten parameters, else every base parameter but friction and offsets.
    max_use : float
        Fraction of the most used limit reached, in (0, 1].
    seed : int
        Random candidates and phases.
    random_candidates, local_evaluations : int
        Evaluations of the random stage and of Nelder-Mead.
    progress : callable, optional
        Receives a line per stage.
    accuracy : mapping, optional
        Payload mode's required accuracies (default
        :data:`~stewartid.design.physical.payload_accuracy.REQUIRED_PAYLOAD_ACCURACY`).
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
