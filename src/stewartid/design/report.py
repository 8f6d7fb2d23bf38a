"""Design report: limit use, interval lengths, predicted accuracy vs the paper's set (Markdown, HTML)."""

from __future__ import annotations

import shlex
from collections.abc import Sequence
from pathlib import Path

import numpy as np

from stewartid.design.candidates import Design
from stewartid.design.limits import LIMIT_NAMES, LimitUse
from stewartid.design.prediction import Prediction, identify_options
from stewartid.files import write_text_atomic
from stewartid.reference.published import PAPER_ENTRIES, entry_label
from stewartid.reports.drawing import STYLE, save_figure
from stewartid.reports.html import render_html


def plot_limit_use(uses: Sequence[LimitUse], names: Sequence[str], directory: str | Path
                   ) -> list[Path]:
    """Use of every limit (1 = the limit) over time, one panel per record."""
    import matplotlib
    from matplotlib.figure import Figure


    with matplotlib.rc_context(STYLE):
        figure = Figure(figsize=(9, 1.6 * len(uses) + 0.6))
        axes = figure.subplots(len(uses), 1, sharex=False, squeeze=False)[:, 0]
        for axis, use, name in zip(axes, uses, names, strict=True):
            every = slice(None, None, max(1, len(use.t) // 3000))
            for k, limit in enumerate(LIMIT_NAMES):
                axis.plot(use.t[every], use.use[every, k], lw=0.8, label=limit)
            axis.axhline(1.0, color="k", lw=0.8, ls="--")
            axis.set_ylim(0, 1.1)
            axis.set_ylabel(f"{name}\nuse (-)")
        axes[-1].set_xlabel("t (s)")
        axes[0].legend(ncol=5, fontsize="small", loc="lower center", bbox_to_anchor=(0.5, 1.0))
        return save_figure(figure, directory, "limit_use")


def plot_accuracy(design: Prediction, baseline: Prediction, directory: str | Path
                  ) -> list[Path]:
    """Relative standard error of the 20 entries, design beside the paper's set."""
    import matplotlib
    from matplotlib.figure import Figure


    labels = [entry_label(k) for k in PAPER_ENTRIES]
    x = np.arange(len(labels))
    with matplotlib.rc_context(STYLE):
        figure = Figure(figsize=(10, 3.6))
        axis = figure.subplots()
        axis.bar(x - 0.2, baseline.relative_std, 0.4, label="paper's set", color="#7f7f7f")
        axis.bar(x + 0.2, design.relative_std, 0.4, label="design", color="#d62728")
        axis.set_yscale("log")
        axis.set_xticks(x, labels, rotation=60, fontsize="small")
        axis.set_ylabel("predicted standard error (%)")
        axis.legend()
        return save_figure(figure, directory, "predicted_accuracy")


def render_markdown(design: Design, prediction: Prediction, baseline: Prediction,
                    peaks: Sequence[dict[str, float]], intervals: Sequence[float],
                    settings: dict, use_source: str = "the plant's true states",
                    method: str = "wavelet", coulomb: float = 0.0, folder: str = "DIR"
                    ) -> str:
    """The report text.

    Parameters
    ----------
    design : Design
    prediction, baseline : Prediction
        The design's and the paper set's at the same budget.
    peaks : sequence of dict
        Peak use of every limit per record.
    intervals : sequence of float
        Half period of each record (s).
    settings : dict
        Budget, noise, method, grid.
    use_source : str
        What limit use was measured on.
    method : str
    coulomb : float
        Assumed Coulomb friction (N m).
    folder : str
        Output folder.
    """
    lines = ["# Excitation design", "", f"{design.label}; {design.duration:.1f} s of motion.",
             "", "## Settings", ""]
    lines += [f"- {key}: {value}" for key, value in settings.items()]
    lines += ["", "## Records", "",
              "| record | direction (m, rad) | frequency (Hz) | levels | duration (s) | "
              "interval (s) | " + " | ".join(LIMIT_NAMES) + " |",
              "|---" * (6 + len(LIMIT_NAMES)) + "|"]
    for record, peak, interval in zip(design.records, peaks, intervals, strict=True):
        direction = ", ".join(f"{v:.4g}" for v in record.direction if v)
        lines.append(f"| {record.name} | {direction} | {record.frequency_hz:g} | "
                     + "/".join(f"{v:g}" for v in record.levels)
                     + f" | {record.duration:.1f} | {interval:.2f} | "
                     + " | ".join(f"{peak[n]:.0%}" for n in LIMIT_NAMES) + " |")
    lines += ["", "Limit use is the largest over the legs and the record, 100 % = the limit "
              f"({use_source}).", "",
              "![limit use](figures/limit_use.png)", "", "## Predicted accuracy", "",
              f"Method: {prediction.method}; {prediction.seeds} noise realisations "
              f"(paper's set: {baseline.seeds}). Worst relative standard error: "
              f"**{prediction.worst_relative_std:.2f} %** (paper's set "
              f"{baseline.worst_relative_std:.2f} %, ratio "
              f"{prediction.worst_relative_std / baseline.worst_relative_std:.2f}).", ""]
    checked = prediction.relative_monte_carlo_std
    extra = "" if checked is None else " Monte Carlo SE (%) |"
    lines += ["| entry | design SE (%) | design bias (%) | paper's set SE (%) |" + extra,
              "|---|---|---|---|" + ("---|" if extra else "")]
    for k, (key, s, b, s0) in enumerate(zip(PAPER_ENTRIES, prediction.relative_std,
                                            prediction.relative_bias, baseline.relative_std,
                                            strict=True)):
        lines.append(f"| {entry_label(key)} | {s:.3f} | {b:.3f} | {s0:.3f} |"
                     + ("" if checked is None else f" {checked[k]:.3f} |"))
    lines += ["", "![predicted accuracy](figures/predicted_accuracy.png)", "",
              "## Playing and identifying it", "",
              "The prediction holds for the estimator it was made with. On the plant first "
              "(with the sensor noise; `--seed` for another realisation), then on the "
              "machine's logs (PLATFORM: the platform file of the design):", "", "```bash",
              play_command(design, coulomb, folder), identify_command(method), "```", "",
              "`validation/validation.csv` moves every DOF at once at frequencies of its own, "
              "within half the limits: motion the fit does not see. Identified with it held "
              "out, the report judges each model by its prediction of it:", "", "```bash",
              *validation_commands(method, coulomb, folder), "```", ""]
    return "\n".join(lines)


def play_command(design: Design, coulomb: float, folder: str = "DIR", run: str = "RUN"
                 ) -> str:
    """``stewartid simulate`` command playing the exported records with the assumed Coulomb friction."""
    files = " ".join(f"--excitation {shlex.quote(f'{folder}/commands/{r.name}.csv')}"
                     for r in design.records)
    return (f"stewartid simulate --platform PLATFORM --coulomb {coulomb:g} {files} --noise "
            f"--out {run}")


def identify_command(method: str, run: str = "RUN") -> str:
    """``stewartid identify`` command of the design's estimator."""
    return f"stewartid identify {run} --platform PLATFORM {' '.join(identify_options(method))}"


def validation_commands(method: str, coulomb: float, folder: str = "DIR", run: str = "RUN"
                        ) -> list[str]:
    """Commands playing the validation record and identifying with it held out."""
    record = shlex.quote(f"{folder}/validation/validation.csv")
    return [f"stewartid simulate --platform PLATFORM --coulomb {coulomb:g} --excitation "
            f"{record} --noise --seed 1 --out {run}_validation",
            f"{identify_command(method, run)} --report {run}_report --validate "
            f"{run}_validation/exp1.csv"]


def write_design_report(directory: str | Path, markdown_text: str) -> list[Path]:
    """Write ``report.md`` and self-contained ``report.html`` into ``directory``."""
    directory = Path(directory)
    return [write_text_atomic(directory / "report.md", markdown_text),
            write_text_atomic(directory / "report.html",
                              render_html(markdown_text, directory, "stewartid design"))]
