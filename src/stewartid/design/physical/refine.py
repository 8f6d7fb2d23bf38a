"""The physical design's pick played on the plant, refined where the servo allows less than the
commanded motion, and predicted along what it played.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from typing import NamedTuple

import numpy as np

from stewartid.design.candidates import Design
from stewartid.design.optimise import within_plant_limits
from stewartid.design.physical.information import ParameterPrediction, played_states, predict_parameters
from stewartid.design.physical.search import (
    PLANT_EVALUATIONS,
    PLANT_ROUNDS,
    PLANT_TOLERANCE,
    PhysicalCandidate,
    design_objective,
    judged_against,
    plant_scales,
    refine_for_plant,
)
from stewartid.platform import Platform
from stewartid.simulation.sensors import SensorNoise

#: Information-matrix rate of the final prediction (Hz): the regressor is filtered with the
#: estimator's kernel there (:func:`~stewartid.design.physical.information.kernel_filtered`), which
#: needs a few dozen samples per kernel window.
FINAL_RATE = 100.0


class PlayedPick(NamedTuple):
    """A candidate played on the plant, with its final predictions.

    Attributes
    ----------
    pick : PhysicalCandidate
        As the search chose it.
    design : Design
        As played, records over ``max_use`` scaled down.
    records : list of ExperimentRecord
        True plant signals.
    uses : list of LimitUse
    prediction, commanded : ParameterPrediction
        Final predictions (filtered, :data:`FINAL_RATE`) along the plant's motion and the command.
    """

    pick: PhysicalCandidate
    design: Design
    records: list
    uses: list
    prediction: ParameterPrediction
    commanded: ParameterPrediction


def played_pick(platform: Platform, best: PhysicalCandidate, budget_s: float,
                noise: SensorNoise, payload: bool, max_use: float,
                evaluations: int = PLANT_EVALUATIONS,
                progress: Callable[[str], None] | None = None,
                accuracy: Mapping[str, float] | None = None) -> PlayedPick:
    """The search's pick played and predicted as the final design; where the plant allowed less
    (:func:`~stewartid.design.physical.search.plant_scales`) the search is refined and replayed for
    up to :data:`~stewartid.design.physical.search.PLANT_ROUNDS` rounds. The pick whose worse
    prediction has the smallest objective wins.
    """
    if progress:
        progress("playing the design on the plant")
    picks = [_played(platform, best, noise, payload, max_use, accuracy)]
    scales = plant_scales(best.design, picks[0].design)
    for _ in range(PLANT_ROUNDS if evaluations > 0 else 0):
        if np.all(scales >= 1 - PLANT_TOLERANCE):
            break
        if progress:
            progress(f"the plant allows {scales.min():.2f} of a record's commanded "
                     "amplitudes: refining the search against that")
        refined = refine_for_plant(platform, budget_s, noise, payload, max_use,
                                   picks[-1].pick.parameters, scales, evaluations, accuracy,
                                   search_correction(platform, picks[-1], noise, payload))
        picks.append(_played(platform, refined, noise, payload, max_use, accuracy))
        scales = scales * plant_scales(refined.design, picks[-1].design)
    return min(picks, key=lambda p: max(design_objective(p.prediction),
                                        design_objective(p.commanded)))


def _played(platform: Platform, pick: PhysicalCandidate, noise: SensorNoise, payload: bool,
            max_use: float, accuracy: Mapping[str, float] | None) -> PlayedPick:
    """``pick`` played within ``max_use``, with final predictions along plant motion and command."""
    design, records, uses = within_plant_limits(platform, pick.design, max_use)
    return PlayedPick(pick, design, records, uses, *(judged_against(predict_parameters(
        platform, design, noise, payload, FINAL_RATE, states=states, filtered=True), accuracy)
        for states in (played_states(records, design, FINAL_RATE), None)))


def search_correction(platform: Platform, played: PlayedPick, noise: SensorNoise,
                      payload: bool) -> dict[str, float]:
    """Ratio of a played pick's final prediction (worse of plant and command, filtered) to the
    search's (commanded, unfiltered), per payload quantity and ``"worst"``.
    """
    search = predict_parameters(platform, played.design, noise, payload)
    final = (played.prediction, played.commanded)
    correction = {"worst": max(p.worst_relative_std for p in final) / search.worst_relative_std}
    if payload:
        correction.update({k: max(p.payload_std_errors[k] for p in final) / value
                           for k, value in search.payload_std_errors.items()})
    return correction


__all__ = ["FINAL_RATE", "PlayedPick", "played_pick", "search_correction"]
