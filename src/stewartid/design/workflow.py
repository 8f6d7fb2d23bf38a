"""``stewartid design`` end to end: optimise, predict the baseline, export, report
(``design.json``, ``commands/``, ``validation/``, ``figures/``, ``report.md``/``.html``).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable
from pathlib import Path

from stewartid.design.candidates import Design, paper_design, schedule_label
from stewartid.design.export import write_commands
from stewartid.design.limits import resolve_limits
from stewartid.design.optimise import (
    DEFAULT_FREQUENCIES,
    DEFAULT_SCHEDULES,
    optimise_design,
)
from stewartid.design.prediction import DESIGN_SETTINGS, Prediction, predict_accuracy
from stewartid.design.report import (
    identify_command,
    play_command,
    plot_accuracy,
    plot_limit_use,
    render_markdown,
    validation_commands,
    write_design_report,
)
from stewartid.design.validation import write_validation_record
from stewartid.design.weak_information import has_information, information_prediction
from stewartid.files import check_output_folder, write_json_atomic
from stewartid.platform import Platform
from stewartid.simulation.sensors import SensorNoise

#: Noise realisations of the Monte Carlo that checks the chosen design's information-matrix
#: prediction.
CHECK_SEEDS = 8


@dataclasses.dataclass(frozen=True)
class DesignOutput:
    """What :func:`run_design` produced.

    Attributes
    ----------
    design : Design
    prediction, baseline : Prediction
        The design's and the same-length paper set's.
    files : list of Path
    """

    design: Design
    prediction: Prediction
    baseline: Prediction
    files: list[Path]


def is_design_file(path: Path) -> bool:
    """True for what :func:`run_design` writes."""
    return path.name in ("design.json", "report.md", "report.html", "commands", "figures",
                         "validation")


def run_design(platform: Platform, budget_s: float, noise: SensorNoise, out: str | Path,
               method: str = "wavelet", rate_hz: float = 500.0, max_use: float = 0.7,
               seeds: int | None = None, source: str = "plant", quick: bool = False,
               force: bool = False, workers: int | None = None,
               progress: Callable[[str], None] | None = None,
               realisations: Callable[[int, int], None] | None = None) -> DesignOutput:
    """Design an excitation for ``platform`` and write it with its report to ``out``.

    Parameters
    ----------
    platform : Platform
    budget_s : float
        Total motion time (s).
    noise : SensorNoise
    out : str or Path
    method : str
        Method the design is for.
    rate_hz : float
        Controller rate of the command files (Hz).
    max_use : float
        Fraction of every limit used on the plant's states.
    seeds : int, optional
        Monte Carlo realisations: check of the information matrix (default :data:`CHECK_SEEDS`),
        or the prediction itself for other methods (default 120).
    source : {"plant", "model"}
        Noise-free data from the plant or the rigid-body model (faster, optimistic).
    quick : bool
        One candidate, no screening (tests).
    force : bool
        Overwrite an earlier design.
    workers : int, optional
        Default: every core.
    progress : callable, optional
        One line per step.
    realisations : callable, optional
        Called with (done, total) per realisation.
    """
    out = Path(out)
    check_output_folder(out, force, is_design_file)
    limits = resolve_limits(platform)
    analytic = has_information(method)
    if seeds is None:
        seeds = CHECK_SEEDS if analytic else 120
    grid = {"frequencies": ((1.0,),) * 3, "schedules": ((1.0, 0.5),)} if quick \
        else {"frequencies": DEFAULT_FREQUENCIES, "schedules": DEFAULT_SCHEDULES}
    best, screened = optimise_design(platform, budget_s, noise, method, max_use=max_use,
                                     seeds=seeds, source=source, progress=progress,
                                     workers=workers, realisations=realisations, **grid)
    baseline_design = paper_design(duration_s=budget_s / 6)
    if progress:
        progress("predicting the paper's set of the same length")
    if analytic:
        baseline = information_prediction(platform, baseline_design, noise, method,
                                          source=source)
    else:
        baseline = predict_accuracy(platform, baseline_design, noise, method, seeds,
                                    source=source, workers=workers, progress=realisations)
    if progress:
        progress(f"paper's set: predicted worst relative SE {baseline.worst_relative_std:.2f} %")
    design, prediction = best.design, best.prediction
    out.mkdir(parents=True, exist_ok=True)
    uses = list(best.plant_use)
    use_source = ("the plant's true states" if source == "plant"
                  else "commanded motion, rigid-body model forces")
    files = write_commands(platform, design, out / "commands", rate_hz)
    files.append(write_validation_record(platform, out / "validation", rate_hz))
    files += plot_limit_use(uses, [r.name for r in design.records], out / "figures")
    files += plot_accuracy(prediction, baseline, out / "figures")
    settings = {"platform": platform.name, "budget (s)": budget_s, "method": prediction.method,
                "Coulomb friction (N m)": platform.friction.coulomb,
                "length noise (m)": noise.length_noise, "force noise (N)": noise.force_noise,
                "largest limit use": max_use, "controller rate (Hz)": rate_hz,
                "prediction data": source,
                "frequencies tried (Hz)": dict(zip(("x and y", "z", "rotations"),
                                                   map(list, grid["frequencies"]), strict=True)),
                "schedules tried": [schedule_label(s if isinstance(s[0], tuple) else [s])
                                    for s in grid["schedules"]],
                "required accuracy (%)": dict(best.required),
                "criterion (worst (|bias| + 2 SE) / required)": round(best.score, 3)}
    intervals = [0.5 / r.frequency_hz for r in design.records]
    text = render_markdown(design, prediction, baseline, [u.peak for u in uses], intervals,
                           settings, use_source, method, platform.friction.coulomb, str(out))
    files += write_design_report(out, text)
    document = {"design": design.to_dict(), "prediction": prediction.to_dict(),
                "baseline": {"design": baseline_design.to_dict(), **baseline.to_dict()},
                "limits": limits.to_dict(), "limit_use": [u.peak for u in uses],
                "limit_use_from": use_source,
                "screened": [{"label": c.design.label, "criterion": c.score,
                              "worst_relative_std_percent": c.prediction.worst_relative_std,
                              "seeds": c.prediction.seeds} for c in screened],
                "settings": settings,
                "identify": {"method": method, "settings": DESIGN_SETTINGS.get(method, {}),
                             "command": identify_command(method),
                             "play": play_command(design, platform.friction.coulomb, str(out))},
                "validation": {"record": "validation/validation.csv",
                               "commands": validation_commands(
                                   method, platform.friction.coulomb, str(out))}}
    files.append(write_json_atomic(out / "design.json", document))
    return DesignOutput(design, prediction, baseline, files)
