"""A study's report: error against each swept parameter per method (median and spread over the
seeds), the table behind every figure, sentences computed from the numbers."""

from __future__ import annotations

import math
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from stewartid.files import write_text_atomic
from stewartid.reports.drawing import STYLE, save_figure
from stewartid.reports.html import render_html
from stewartid.reports.methods import method_color, method_name, report_order
from stewartid.reports.tables import ResultTable, to_markdown, write_tables
from stewartid.studies.spec import PARAMETERS, StudySpec

#: Error columns summarised, with their labels.
METRICS = {"max_error_M_percent": "largest Mt error (%)",
           "max_error_B_percent": "largest Bt error (%)",
           "max_error_percent": "largest error, 20 entries (%)"}
#: Error column each parameter's sentences are about: the Bt error for Coulomb friction (the
#: paper's claim concerns Method A's Bt), the error over all 20 entries otherwise.
TREND_METRIC = {"coulomb": "max_error_B_percent"}
#: Errors below this (%) are drawn at it, to keep the logarithmic axes readable.
FLOOR_PERCENT = 1e-3
_STATISTICS = ("median", "q25", "q75", "min", "max")


def swept_parameters(spec: StudySpec) -> list[str]:
    """Parameters with two or more grid values: Coulomb friction and noise scale first."""
    order = ["coulomb", "noise_scale", *(name for name in PARAMETERS
                                         if name not in ("coulomb", "noise_scale"))]
    return [name for name in order if len(spec.grid.get(name, ())) > 1]


def _parameter_text(name: str, value: float) -> str:
    return f"{name} {value:g} {PARAMETERS[name].unit}".replace(" -", "")


def sweep_statistics(rows: Any, parameter: str, others: Sequence[str]) -> Any:
    """Median, quartiles, extremes and count over the seeds of every error metric (%).

    ``rows`` from :func:`~stewartid.studies.results.read_results` (failed rows left out);
    ``parameter`` on the horizontal axis, one panel row per combination of ``others``. One row per
    (others..., parameter, method); columns ``seeds`` and ``<metric>_<statistic>`` for each of
    :data:`METRICS` and median, q25, q75, min, max."""
    good = rows[rows["failure"].isna()]
    keys = [*others, parameter, "method"]
    groups = good.groupby(keys, sort=True)
    parts = {"seeds": groups["seed"].nunique()}
    for metric in METRICS:
        column = groups[metric]
        parts.update({f"{metric}_median": column.median(),
                      f"{metric}_q25": column.quantile(0.25),
                      f"{metric}_q75": column.quantile(0.75),
                      f"{metric}_min": column.min(), f"{metric}_max": column.max()})
    return pd.DataFrame(parts).reset_index()


def _panels(statistics: Any, others: Sequence[str]) -> list[tuple[tuple[float, ...], Any]]:
    if not others:
        return [((), statistics)]
    return [(values if isinstance(values, tuple) else (values,), frame)
            for values, frame in statistics.groupby(list(others), sort=True)]


def _panel_title(others: Sequence[str], values: Sequence[float]) -> str:
    return ", ".join(_parameter_text(n, v) for n, v in zip(others, values, strict=True))


def plot_sweep(statistics: Any, parameter: str, others: Sequence[str],
               methods: Sequence[str], directory: str | Path) -> list[Path]:
    """Figure ``error_vs_<parameter>`` (PNG and SVG) from :func:`sweep_statistics`."""
    import matplotlib
    from matplotlib.figure import Figure


    panels = _panels(statistics, others)
    with matplotlib.rc_context(STYLE):
        figure = Figure(figsize=(11, 3.3 * len(panels) + 0.6), layout="constrained")
        axes = figure.subplots(len(panels), 2, squeeze=False, sharex=True)
        for (values, frame), row in zip(panels, axes, strict=True):
            for axis, metric in zip(row, ("max_error_M_percent", "max_error_B_percent"),
                                    strict=True):
                for method in methods:
                    data = frame[frame["method"] == method].sort_values(parameter)
                    if data.empty:
                        continue
                    x = data[parameter].to_numpy()
                    band = {s: np.maximum(data[f"{metric}_{s}"].to_numpy(), FLOOR_PERCENT)
                            for s in _STATISTICS}
                    colour = method_color(method)
                    axis.fill_between(x, band["min"], band["max"], color=colour, alpha=0.12,
                                      lw=0)
                    axis.fill_between(x, band["q25"], band["q75"], color=colour, alpha=0.3,
                                      lw=0)
                    axis.plot(x, band["median"], color=colour, marker="o", lw=1.6,
                              label=method_name(method))
                axis.set_yscale("log")
                axis.set_ylabel(METRICS[metric])
                title = "Mt" if metric == "max_error_M_percent" else "Bt"
                if values:
                    title += f" ({_panel_title(others, values)})"
                axis.set_title(title)
            row[0].legend(loc="best", framealpha=0.9)
        for axis in axes[-1]:
            axis.set_xlabel(f"{parameter} ({PARAMETERS[parameter].unit})")
        figure.suptitle(f"Largest relative error against {PARAMETERS[parameter].doc}: median "
                        "over the seeds, interquartile range (dark) and range (light)")
        return save_figure(figure, directory, f"error_vs_{parameter}")


def sweep_table(statistics: Any, parameter: str, others: Sequence[str],
                methods: Sequence[str]) -> ResultTable:
    """The numbers behind :func:`plot_sweep`: median [q25, q75] of Mt, Bt and overall."""
    rank = {method: k for k, method in enumerate(methods)}
    ordered = statistics.assign(rank=statistics["method"].map(rank)).sort_values(
        [*others, "rank", parameter], kind="stable")
    columns = [*others, parameter, "method", "seeds"]
    kinds = ["text"] * len(columns)
    for metric in METRICS:
        columns += [f"{METRICS[metric][:-4]}: median (%)", "q25 (%)", "q75 (%)"]
        kinds += ["eps"] * 3
    rows = []
    for _, item in ordered.iterrows():
        cells: list[Any] = [f"{item[n]:g}" for n in (*others, parameter)]
        cells += [method_name(item["method"]), f"{int(item['seeds'])}"]
        for metric in METRICS:
            cells += [float(item[f"{metric}_{s}"]) for s in ("median", "q25", "q75")]
        rows.append(tuple(cells))
    return ResultTable(name=f"error_vs_{parameter}",
                       title=f"Error against {PARAMETERS[parameter].doc} "
                             f"({PARAMETERS[parameter].unit})",
                       columns=tuple(columns), kinds=tuple(kinds), rows=tuple(rows))


def _trend(medians: Sequence[float]) -> str:
    if any(not math.isfinite(m) for m in medians):
        return "not defined at every value"
    steps = [b > a for a, b in zip(medians, medians[1:], strict=False)]
    if all(steps):
        return "grows at every step"
    if medians[-1] > medians[0]:
        return "grows overall, not at every step"
    return "does not grow"


def trend_sentences(statistics: Any, parameter: str, others: Sequence[str],
                    methods: Sequence[str]) -> list[str]:
    """One Markdown sentence per method: median error at each ``parameter`` value and whether it grows."""
    metric = TREND_METRIC.get(parameter, "max_error_percent")
    label = METRICS[metric][:-4]
    lines = []
    for method in methods:
        parts = []
        for values, frame in _panels(statistics, others):
            data = frame[frame["method"] == method].sort_values(parameter)
            if len(data) < 2:
                continue
            medians = data[f"{metric}_median"].tolist()
            path = " → ".join(f"{m:.3g}" for m in medians)
            where = f"at {_panel_title(others, values)}: " if values else ""
            parts.append(f"{where}{path} % ({_trend(medians)})")
        if parts:
            grid = ", ".join(f"{v:g}" for v in sorted(statistics[parameter].unique()))
            unit = PARAMETERS[parameter].unit
            lines.append(f"**{method_name(method)}**, {label} against {parameter} ({grid}"
                         f"{'' if unit == '-' else ' ' + unit}), median over the seeds: "
                         + "; ".join(parts) + ".")
    return lines


def _settings_lines(spec: StudySpec, rows: Any, total_tasks: int, failed_tasks: int
                    ) -> list[str]:
    finished = rows["task"].nunique() if len(rows) else 0
    failed_rows = int(rows["failure"].notna().sum()) if len(rows) else 0
    lines = [f"- platform: {spec.platform}",
             "- methods: " + ", ".join(method_name(m) for m in spec.methods),
             f"- seeds per grid point: {len(spec.seeds)} ({spec.seeds[0]}…{spec.seeds[-1]})"]
    lines += [f"- grid: {name} = {', '.join(f'{v:g}' for v in values)} "
              f"({PARAMETERS[name].unit})" for name, values in spec.grid.items()]
    lines += [f"- fixed: {_parameter_text(name, value)}" for name, value in spec.fixed.items()]
    if spec.actuator is not None:
        lines.append(f"- actuator: {spec.actuator}")
    for method, settings in spec.method_settings.items():
        lines.append(f"- settings of {method}: "
                     + ", ".join(f"{k} = {v!r}" for k, v in settings.items()))
    lines += [f"- tasks finished: {finished} of {total_tasks} (one simulation of the six "
              f"experiments each), {len(rows)} rows; {failed_tasks} tasks crashed in the last "
              f"run, {failed_rows} rows record a failed simulation or identification"]
    if len(rows):
        seconds = rows.groupby("task")["task_cpu_time_s"].first().sum()
        lines.append(f"- CPU time summed over the tasks: {seconds / 60:.1f} min")
    return lines


def _failures_table(rows: Any) -> ResultTable | None:
    failed = rows[rows["failure"].notna()]
    if failed.empty:
        return None
    shown = failed.head(20)
    cells = tuple((method_name(item["method"]),
                   " ".join(f"{n}={item[n]:g}" for n in PARAMETERS) + f" seed={item['seed']}",
                   str(item["failure"])) for _, item in shown.iterrows())
    notes = (f"{len(failed) - len(shown)} more in results.parquet.",) if len(failed) > 20 else ()
    return ResultTable("failures", f"Failed simulations and identifications ({len(failed)})",
                       ("method", "point", "failure"), ("text",) * 3, cells, notes)


def write_study_report(rows: Any, spec: StudySpec, directory: str | Path,
                       total_tasks: int, failed_tasks: int = 0) -> list[Path]:
    """Write a study's figures (``figures/``), tables (``tables/``), ``report.md`` and ``report.html``.

    ``rows`` from :func:`~stewartid.studies.results.read_results`; ``total_tasks`` of the study,
    ``failed_tasks`` crashed in the last run. Returns every file written."""
    directory = Path(directory)
    methods = report_order(spec.methods)
    lines = [f"# {spec.title}", "",
             "Each task simulates the paper's six experiments (experiment k excites DOF k) at "
             "one grid point with one noise seed, and identifies Mt and Bt with every method "
             "on the same data. ε is |identified − nominal| / |nominal| in percent over the "
             "paper's 20 entries, the nominal matrices being those of the simulated plant. "
             "noise_scale multiplies the reference sensor noise (20 µm on the leg lengths, "
             "0.5 % of the static leg force on the forces).", "", "## What was run", ""]
    lines += _settings_lines(spec, rows, total_tasks, failed_tasks)
    sections, summary, tables, files = [], [], [], []
    swept = swept_parameters(spec)
    good = rows[rows["failure"].isna()] if len(rows) else rows
    for parameter in swept if len(good) else []:
        others = [name for name in swept if name != parameter]
        statistics = sweep_statistics(rows, parameter, others)
        summary += trend_sentences(statistics, parameter, others, methods)
        files += plot_sweep(statistics, parameter, others, methods, directory / "figures")
        table = sweep_table(statistics, parameter, others, methods)
        tables.append(table)
        sections += [f"![error against {parameter}](figures/error_vs_{parameter}.png)", "",
                     f"*Largest Mt and Bt error against {PARAMETERS[parameter].doc}, per "
                     "method: median over the seeds, interquartile range and range.*", "",
                     to_markdown(table, heading_level=3)]
    if len(good) and not swept:
        statistics = sweep_statistics(rows.assign(point=0.0), "point", [])
        summary += [f"**{method_name(item['method'])}**: largest error over the 20 entries, "
                    f"median {item['max_error_percent_median']:.3g} % (range "
                    f"{item['max_error_percent_min']:.3g}–{item['max_error_percent_max']:.3g} "
                    f"%) over {int(item['seeds'])} seeds."
                    for _, item in statistics.iterrows()]
    lines += ["", "## Summary", ""]
    lines += [f"- {line}" for line in summary] or ["- No finished row without failure yet."]
    if sections:
        lines += ["", "## Figures and their tables", "", *sections]
    failures = _failures_table(rows) if len(rows) else None
    if failures is not None:
        tables.append(failures)
        lines += ["", to_markdown(failures, heading_level=2)]
    files += write_tables(tables, directory / "tables")
    text = "\n".join(lines).rstrip() + "\n"
    files.append(write_text_atomic(directory / "report.md", text))
    files.append(write_text_atomic(directory / "report.html",
                                   render_html(text, directory, title=spec.title)))
    return files


__all__ = ["METRICS", "plot_sweep", "swept_parameters", "sweep_statistics", "sweep_table",
           "trend_sentences", "write_study_report"]
