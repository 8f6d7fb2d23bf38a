"""The physical design's pick against the plant: played, refined where the plant allows less
of it than its commanded motion at the limits, and predicted along the motion it played.

The plant's servo does not follow the command exactly, so a record may keep only part of its
amplitudes; :func:`played_pick` keeps the best pick by the worse of its final predictions
along the plant's motion and along the command.
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
        As played: records whose plant states used more than ``max_use`` of a limit scaled
        down.
    records : list of ExperimentRecord
        Its true signals on the plant.
    uses : list of LimitUse
        Their limit use.
    prediction, commanded : ParameterPrediction
        Final predictions (filtered, at :data:`FINAL_RATE`) along the plant's motion and
        along the command.
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
    """The search's pick played on the plant and predicted as the final design is.

    Where the plant allowed less of a record than its commanded motion at the limits
    (:func:`~stewartid.design.physical.search.plant_scales`), the search is refined against that
    (:func:`~stewartid.design.physical.search.refine_for_plant`, corrected by
    :func:`search_correction`) and its pick played too, for up to
    :data:`~stewartid.design.physical.search.PLANT_ROUNDS` rounds.

    Returns
    -------
    PlayedPick
        Of the picks, the one whose worse prediction has the smallest
        :func:`~stewartid.design.physical.search.design_objective`.
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
    """``pick`` played on the plant within ``max_use``, and its final predictions along the
    plant's motion and along the command (a machine that tracks it exactly moves less)."""
    design, records, uses = within_plant_limits(platform, pick.design, max_use)
    return PlayedPick(pick, design, records, uses, *(judged_against(predict_parameters(
        platform, design, noise, payload, FINAL_RATE, states=states, filtered=True), accuracy)
        for states in (played_states(records, design, FINAL_RATE), None)))


def search_correction(platform: Platform, played: PlayedPick, noise: SensorNoise,
                      payload: bool) -> dict[str, float]:
    """How much a played pick's final prediction (the worse of plant and command, filtered)
    exceeds the search's prediction of the same records (commanded, unfiltered).

    Per payload quantity and for the worst relative standard error (``"worst"``): what
    :func:`~stewartid.design.physical.search.refine_for_plant` multiplies its candidates'
    predictions by.
    """
    search = predict_parameters(platform, played.design, noise, payload)
    final = (played.prediction, played.commanded)
    correction = {"worst": max(p.worst_relative_std for p in final) / search.worst_relative_std}
    if payload:
        correction.update({k: max(p.payload_std_errors[k] for p in final) / value
                           for k, value in search.payload_std_errors.items()})
    return correction


__all__ = ["FINAL_RATE", "PlayedPick", "played_pick", "search_correction"]
