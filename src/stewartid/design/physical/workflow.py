"""``stewartid design --model physical`` end to end: search, play on the plant, predict, check
by a small Monte Carlo, export, report; the output folder is laid out as ``stewartid design``'s.
"""

from __future__ import annotations

import dataclasses
import warnings
from collections.abc import Callable, Mapping
from pathlib import Path
from typing import Any

import numpy as np

from stewartid.design.candidates import Design
from stewartid.design.export import write_commands
from stewartid.design.limits import LIMIT_NAMES, resolve_limits
from stewartid.design.multisine import all_dofs_multisine
from stewartid.design.physical.information import (
    ParameterPrediction,
    played_states,
    predict_parameters,
)
from stewartid.design.physical.payload_accuracy import ACCURACY_COVERAGE, held_share, payload_criterion
from stewartid.design.physical.refine import FINAL_RATE, played_pick
from stewartid.design.physical.search import PLANT_EVALUATIONS, judged_against, search_design
from stewartid.design.prediction import (
    inverse_leg_jacobians,
    measured_plant_datasets,
    plant_records,
)
from stewartid.design.report import play_command, plot_limit_use, write_design_report
from stewartid.design.validation import write_validation_record
from stewartid.design.workflow import is_design_file
from stewartid.errors import ConfigError
from stewartid.files import check_output_folder, write_json_atomic
from stewartid.physical.estimator import PhysicalIdentifier
from stewartid.platform import Platform
from stewartid.simulation.sensors import SensorNoise

#: The payload's quantities in words.
QUANTITY_NAMES = {"mass": "mass", "com": "centre of mass", "inertia": "inertia"}


@dataclasses.dataclass(frozen=True)
class PhysicalDesignOutput:
    """What :func:`run_physical_design` produced.

    Attributes
    ----------
    design : Design
    prediction, baseline : ParameterPrediction
        The design's and the same-length all-DOF multisine's.
    check : dict
        :func:`monte_carlo_check`.
    commands : dict of str to str
        ``play`` (``simulate``) and ``identify`` commands.
    files : list of Path
    """

    design: Design
    prediction: ParameterPrediction
    baseline: ParameterPrediction
    check: dict[str, Any]
    commands: dict[str, str]
    files: list[Path]


#: Reported over predicted standard error above which the check names a parameter: beyond
#: what the fits' own errors scatter by over a couple of seeds.
UNDERPREDICTED = 1.5


def physical_identify_command(payload: bool, run: str = "RUN") -> str:
    """``stewartid identify`` command of the physical model (payload or full)."""
    return (f"stewartid identify {run} --platform PLATFORM --model physical"
            + (" --payload" if payload else ""))


def monte_carlo_check(platform: Platform, records: list, noise: SensorNoise,
                      prediction: ParameterPrediction, seeds: int) -> dict[str, Any]:
    """Fit the physical model to ``seeds`` noisy copies of the played design and compare with the
    prediction (errors known: the description is the plant's truth).

    Returns
    -------
    dict
        ``seeds``, ``ratio_median`` (predicted / reported), ``within_30_percent``, ``max_abs_z``,
        ``underpredicted`` (reported over :data:`UNDERPREDICTED` x predicted), and per parameter
        ``predicted``, ``reported``, ``errors``.
    """
    names = prediction.names
    if seeds == 0:
        return {"seeds": 0, "ratio_median": None, "within_30_percent": None,
                "max_abs_z": None, "underpredicted": [],
                "parameters": {n: {"predicted": None, "reported": None, "errors": []}
                               for n in names}}
    inverse = inverse_leg_jacobians(platform, [r.q for r in records])
    estimates, reported = [], []
    for seed in range(seeds):
        generators = [np.random.default_rng([seed, k]) for k in range(len(records))]
        data = measured_plant_datasets(platform, records, noise, generators, inverse)
        fitted = PhysicalIdentifier(payload=prediction.payload).fit(data, platform)
        estimates.append([fitted.parameters_[n] for n in names])
        reported.append([fitted.parameter_std_errors_[n] for n in names])
    estimates, reported = np.array(estimates), np.array(reported, dtype=float)
    with warnings.catch_warnings():  # a parameter the fits fixed has no standard error
        warnings.simplefilter("ignore", RuntimeWarning)
        mean_se = np.nanmean(reported, axis=0)
    expected = prediction.expected_std_errors
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = expected / mean_se
        z = (estimates - prediction.nominal) / reported
    finite = np.isfinite(ratio)
    return {"seeds": seeds,
            "ratio_median": float(np.median(ratio[finite])) if finite.any() else None,
            "within_30_percent": (float(np.mean(np.abs(ratio[finite] - 1) <= 0.3))
                                  if finite.any() else None),
            "max_abs_z": float(np.nanmax(np.abs(z))) if np.isfinite(z).any() else None,
            "underpredicted": [n for n, r in zip(names, ratio, strict=True)
                               if np.isfinite(r) and r * UNDERPREDICTED < 1.0],
            "parameters": {n: {"predicted": _number(expected[k]),
                               "reported": _number(mean_se[k]),
                               "errors": [_number(v) for v in estimates[:, k]
                                          - prediction.nominal[k]]}
                           for k, n in enumerate(names)}}


def _number(value: float) -> float | None:
    return float(value) if np.isfinite(value) else None


def run_physical_design(platform: Platform, budget_s: float, noise: SensorNoise,
                        out: str | Path, payload: bool = False, rate_hz: float = 500.0,
                        max_use: float = 0.7, check_seeds: int = 2, force: bool = False,
                        progress: Callable[[str], None] | None = None,
                        search: dict[str, int] | None = None,
                        accuracy: Mapping[str, float] | None = None) -> PhysicalDesignOutput:
    """Design records for the physical model and write them with their report to ``out``.

    Parameters
    ----------
    platform : Platform
        With the expected ``[payload]`` (required in payload mode).
    budget_s : float
        Total motion time (s).
    noise : SensorNoise
    out : str or Path
    payload : bool
        Design for the payload's ten parameters, else every base parameter.
    rate_hz : float
        Controller rate of the command files (Hz).
    max_use : float
        Largest fraction of every limit, on the plant's states.
    check_seeds : int
        Noisy copies for the Monte Carlo check (0: none).
    force : bool
        Overwrite an earlier design.
    progress : callable, optional
    search : dict, optional
        ``random_candidates``, ``local_evaluations``, ``plant_evaluations``.
    accuracy : mapping, optional
        Payload mode's required accuracies.

    Raises
    ------
    ConfigError
        Payload mode without ``[payload]``.
    """
    out = Path(out)
    if payload and platform.payload is None:
        raise ConfigError("--payload: the platform file has no [payload] section; give the "
                          "expected payload's mass, com and inertia there (the design is "
                          "judged against them; identify --payload fits it anew).")
    check_output_folder(out, force, is_design_file)
    search = dict(search or {})
    refinement = search.pop("plant_evaluations", PLANT_EVALUATIONS)
    best = search_design(platform, budget_s, noise, payload, max_use, progress=progress,
                         accuracy=accuracy, **search)
    best, design, records, uses, prediction, commanded = played_pick(
        platform, best, budget_s, noise, payload, max_use, refinement, progress, accuracy)
    baseline_design = all_dofs_multisine(budget_s)
    # predicted as the design is, along its motion on the plant: like for like
    baseline = judged_against(predict_parameters(
        platform, baseline_design, noise, payload, FINAL_RATE, filtered=True,
        states=played_states(plant_records(platform, baseline_design), baseline_design,
                             FINAL_RATE)), accuracy)
    if progress:
        progress(f"checking the prediction on {check_seeds} noisy copies")
    check = monte_carlo_check(platform, records, noise, prediction, check_seeds)
    out.mkdir(parents=True, exist_ok=True)
    files = write_commands(platform, design, out / "commands", rate_hz)
    files.append(write_validation_record(platform, out / "validation", rate_hz))
    files += plot_limit_use(uses, [r.name for r in design.records], out / "figures")
    peaks = [u.peak for u in uses]
    coulomb = platform.friction.coulomb
    commands = {"play": play_command(design, coulomb, str(out)),
                "identify": physical_identify_command(payload)}
    settings = {"platform": platform.name, "budget (s)": budget_s,
                "mode": "payload" if payload else "full",
                "Coulomb friction (N m)": coulomb, "force noise (N)": noise.force_noise,
                "largest limit use": max_use, "controller rate (Hz)": rate_hz,
                "search parameters": [round(float(v), 4) for v in best.parameters]}
    document = {"model": "physical", "design": design.to_dict(),
                "prediction": prediction.to_dict(),
                "prediction_commanded": commanded.to_dict(),
                "baseline": {"design": baseline_design.to_dict(), **baseline.to_dict()},
                "check": check, "limits": resolve_limits(platform).to_dict(),
                "limit_use": peaks, "limit_use_from": "the plant's simulated states",
                "settings": settings, "identify": commands,
                "validation": {"record": "validation/validation.csv"}}
    files.append(write_json_atomic(out / "design.json", document))
    files += write_design_report(out, render_physical_markdown(
        design, prediction, baseline, check, peaks, settings, commands, commanded))
    return PhysicalDesignOutput(design, prediction, baseline, check, commands, files)


def render_physical_markdown(design: Design, prediction: ParameterPrediction,
                             baseline: ParameterPrediction, check: dict,
                             peaks: list[dict[str, float]], settings: dict,
                             commands: dict[str, str],
                             commanded: ParameterPrediction | None = None) -> str:
    """Report text of a physical design (``commanded``: prediction along the commanded motion)."""
    lines = ["# Excitation design for the physical model", "",
             f"{design.label}; {design.duration:.1f} s of motion.", "", "## Settings", ""]
    lines += [f"- {key}: {value}" for key, value in settings.items()]
    lines += ["", "## Records", "", "| record | duration (s) | highest frequency (Hz) | "
              + " | ".join(LIMIT_NAMES) + " |", "|---" * (3 + len(LIMIT_NAMES)) + "|"]
    for record, peak in zip(design.records, peaks, strict=True):
        lines.append(f"| {record.name} | {record.duration:.1f} | {record.max_frequency:.3g} | "
                     + " | ".join(f"{peak[n]:.0%}" for n in LIMIT_NAMES) + " |")
    lines += ["", "Limit use: the largest over the legs and the record on the plant's "
              "simulated states, 100 % = the limit.", "", "![limit use](figures/limit_use.png)",
              "", "## Predicted standard errors", "", criterion_summary(prediction, baseline)
              + f" Fixed by the estimator (too uncertain): {', '.join(prediction.fixed) or 'none'}.",
              "",
              *_commanded_lines(prediction, commanded),
              "| parameter | nominal | design SE | relative (%) | multisine SE | fit's SE (check) |",
              "|---|---|---|---|---|---|"]
    for k, name in enumerate(prediction.names):
        rel = prediction.relative_std[k]
        reported = check["parameters"][name]["reported"]
        lines.append(f"| {name} | {prediction.nominal[k]:.5g} | "
                     f"{prediction.expected_std_errors[k]:.3g} | "
                     f"{'' if np.isnan(rel) else f'{rel:.3g}'} | "
                     f"{baseline.expected_std_errors[k]:.3g} | "
                     f"{'' if reported is None else f'{reported:.3g}'} |")
    if check["seeds"]:
        lines += ["", f"Check: the design played on the plant and fitted on {check['seeds']} "
                  f"noisy copies; predicted / reported standard error, median "
                  f"{check['ratio_median']:.2f}, within 30 % for "
                  f"{check['within_30_percent']:.0%} of the parameters."]
        if check["underpredicted"]:
            lines += ["", f"The fits' standard errors are over {UNDERPREDICTED:g} times the "
                      f"prediction for {', '.join(check['underpredicted'])}. Either the "
                      "prediction falls short (it counts the force noise and the pose noise "
                      "to first order, not the pose noise's share through the Coulomb signs "
                      "of joints that barely move) or the fits' own standard errors, taken "
                      "from the spread of a few records' sums over few seeds, are "
                      "conservative. Rely on the larger of the two for those."]
    lines += ["", "## Playing and identifying it", "", "On the plant first (PLATFORM: the "
              "platform file of the design), then on the machine's logs:", "", "```bash",
              commands["play"], commands["identify"], "```", "",
              "`validation/validation.csv` moves every DOF at once at frequencies of its own: "
              "motion the fit does not see (`identify --validate`).", ""]
    return "\n".join(lines)


def criterion_summary(prediction: ParameterPrediction, baseline: ParameterPrediction) -> str:
    """The design's criterion beside the all-DOF multisine's, in a sentence."""
    worst = (f"worst relative standard error of the "
             f"{'payload' if prediction.payload else 'moving body'}'s ten parameters "
             f"{prediction.worst_relative_std:.3g} % ({prediction.worst_parameter}; the "
             f"all-DOFs multisine at the paper's amplitudes, same length, "
             f"{baseline.worst_relative_std:.3g} %, ratio "
             f"{prediction.worst_relative_std / baseline.worst_relative_std:.2f})")
    if not prediction.payload:
        return f"Predicted {worst}."
    std, needed = prediction.payload_std_errors, prediction.accuracy
    ratio, quantity = payload_criterion(std, needed)
    share, held = held_share(std, needed)
    coverage = f"{100 * ACCURACY_COVERAGE:g} %"
    margin = (f"each within its accuracy in {coverage} of runs, and within that the search "
              "sharpened the ten parameters" if share <= 1 else
              f"the {QUANTITY_NAMES[held]} within its accuracy in fewer than the {coverage} of "
              "runs the search aims at: a longer budget or more of the limits (--max-use) "
              "sharpens it")
    return (f"Predicted standard errors of the payload: mass {100 * std['mass']:.3g} %, "
            f"centre of mass {1e3 * std['com']:.3g} mm along its least certain direction "
            f"(its error within {1e3 * std['com_distance']:.3g} mm in {coverage} of runs), "
            f"inertia about it "
            f"{100 * std['inertia']:.3g} % (needed: {100 * needed['mass']:g} %, "
            f"{1e3 * needed['com']:g} mm, {100 * needed['inertia']:g} %); the largest "
            f"share of its accuracy {ratio:.3g} ({quantity}; multisine {baseline.criterion:.3g}, "
            f"ratio {ratio / baseline.criterion:.2f}; {margin}). The {worst}.")


def _commanded_lines(prediction: ParameterPrediction,
                     commanded: ParameterPrediction | None) -> list[str]:
    if commanded is None:
        return []
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = commanded.expected_std_errors / prediction.expected_std_errors
    return [f"Predicted along the motion the plant played, whose servo adds motion of its own "
            f"at the higher frequencies. Along the commanded motion, as a machine that tracks "
            f"it exactly would move: worst {commanded.worst_relative_std:.3g} % "
            f"({commanded.worst_parameter}), each standard error up to "
            f"{np.nanmax(ratio):.2f} times the table's (`prediction_commanded` in "
            f"`design.json`).", ""]


__all__ = ["PhysicalDesignOutput", "QUANTITY_NAMES", "UNDERPREDICTED", "criterion_summary",
           "monte_carlo_check", "physical_identify_command", "render_physical_markdown",
           "run_physical_design"]
