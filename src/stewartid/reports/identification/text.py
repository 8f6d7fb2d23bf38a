"""The text of ``report.md``, every statement computed from the run's numbers."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from stewartid.comparison import MethodFit
from stewartid.datasets.dataset import Dataset
from stewartid.identification.consistency import consistency_metrics, is_consistent
from stewartid.identification.wavelet.noise import white_noise_covariance
from stewartid.platform import COORDINATES, Platform
from stewartid.reports.identification.friction_text import friction_section
from stewartid.reports.identification.physical_section import physical_lines
from stewartid.reports.identification.verdict_text import changed_text, verdict_lines
from stewartid.reports.identification.written import IdentificationReport
from stewartid.reports.tables import ResultTable, to_markdown
from stewartid.signals.differentiation import differentiate, estimate_frequency

_UNITS = ("mm",) * 3 + ("mrad",) * 3
#: The physical model's row in the validation tables.
_UNRANKED = "Physical model (full model; not ranked)"


def data_rows(datasets: Sequence[Dataset], platform: Platform) -> list[dict[str, Any]]:
    """Per-experiment summary for the data table and figures.

    Keys: ``name``, ``samples``, ``duration_s``, ``sample_rate_hz``, ``frequency_hz`` (dominant),
    ``excited`` (most excited coordinate, rotations weighted by the upper joint radius),
    ``amplitude`` (its half range, mm or mrad), ``pose_noise`` (m, rad) and ``force_noise`` (leg
    forces, N), shape (6,) each, estimated from the data."""
    rows = []
    lever = np.array([1.0] * 3 + [platform.geometry.upper_radius] * 3)
    for d in datasets:
        frequency = estimate_frequency(d.pose, d.sample_rate)
        window = 0.2 / frequency
        smooth_pose = differentiate(d.pose, d.sample_rate, window, derivatives=(0,))[0]
        smooth_force = differentiate(d.forces, d.sample_rate, window, derivatives=(0,))[0]
        spread = d.pose.std(axis=0) * lever
        excited = int(np.argmax(spread))
        rows.append({
            "name": d.name, "samples": len(d), "duration_s": d.duration,
            "sample_rate_hz": d.sample_rate, "frequency_hz": frequency, "excited": excited,
            "amplitude": 0.5 * float(np.ptp(d.pose[:, excited])) * 1e3,
            "pose_noise": np.sqrt(np.diag(white_noise_covariance(d.pose, smooth_pose))),
            "force_noise": np.sqrt(np.diag(white_noise_covariance(d.forces,
                                                                     smooth_force)))})
    return rows


def used_intervals(runs: Sequence[MethodFit], trusted: str, datasets: Sequence[Dataset]
                   ) -> tuple[str, list[np.ndarray], list[np.ndarray | None]]:
    """The intervals and (a, b) points per experiment, of the trusted method or else the first with them.

    Returns the method's display name ("" if none uses intervals), the intervals (shape (M_k, 2),
    [start, stop], s) and the (a, b) points (shape (K_k, 2), s; None for an experiment without)."""
    def recorded(run: MethodFit) -> list[dict]:
        experiments = [] if run.result is None else run.result.diagnostics.get("experiments")
        experiments = experiments or []
        ok = len(experiments) == len(datasets) and all("intervals" in e for e in experiments)
        return experiments if ok else []

    ordered = sorted(runs, key=lambda run: run.name != trusted)
    chosen = next((run for run in ordered if recorded(run)), None)
    if chosen is None:
        return "", [], []
    experiments = recorded(chosen)
    intervals = [np.asarray(e["intervals"], dtype=float).reshape(-1, 2) for e in experiments]
    points = [np.column_stack([np.asarray(e["scales"], dtype=float),
                               np.asarray(e["shifts"], dtype=float)])
              if "scales" in e and "shifts" in e else None for e in experiments]
    return chosen.display_name, intervals, points


def _number(value: float) -> str:
    if not np.isfinite(value):
        return "n/a"
    return f"{value:,.1f}" if abs(value) >= 100 else f"{value:.4g}"


def matrix_table(title: str, matrix: np.ndarray, std: np.ndarray | None = None) -> str:
    """A 6x6 matrix (± standard errors) as a Markdown table under a heading."""
    rows = []
    for name, values, errors in zip(COORDINATES, matrix,
                                    std if std is not None else [None] * 6, strict=True):
        cells = [_number(v) + ("" if errors is None else f" ± {errors:.2g}")
                 for v, errors in zip(values, errors if errors is not None else [None] * 6,
                                      strict=True)]
        rows.append((name, *cells))
    table = ResultTable("matrix", title, ("", *COORDINATES), ("text",) + ("value",) * 6,
                        tuple(rows))
    return to_markdown(table, heading_level=4)


def _figure(figures: Mapping[str, tuple[str, str]], key: str) -> list[str]:
    if key not in figures:
        return []
    path, caption = figures[key]
    svg = path[:-4] + ".svg"
    return [f"![{caption}]({path})", "", f"*{caption}* ([SVG]({svg}))", ""]


def _data_section(rows: Sequence[dict[str, Any]]) -> list[str]:
    table = ResultTable("data", "Experiments", (
        "experiment", "samples", "duration (s)", "rate (Hz)", "frequency (Hz)", "excited",
        "amplitude", "pose noise (µm, µrad)", "leg-force noise (N)"),
        ("text",) * 9, tuple(
            (r["name"], str(r["samples"]), f"{r['duration_s']:.3g}",
             f"{r['sample_rate_hz']:.4g}", f"{r['frequency_hz']:.4g}",
             COORDINATES[r["excited"]], f"{r['amplitude']:.3g} {_UNITS[r['excited']]}",
             " / ".join(f"{v * 1e6:.2g}" for v in r["pose_noise"]),
             " / ".join(f"{v:.2g}" for v in r["force_noise"])) for r in rows))
    return [to_markdown(table), "Noise is estimated from each record (second differences of "
            "what a smoothing filter leaves), per coordinate x / y / z / rx / ry / rz and per "
            "leg 1-6; values near zero mean noise-free data.", ""]


def render_report(report: IdentificationReport, datasets: Sequence[Dataset],
                  platform: Platform, nominal: tuple[np.ndarray, np.ndarray],
                  nominal_source: str, rows: Sequence[dict[str, Any]],
                  figures: Mapping[str, tuple[str, str]], sources: Sequence[str], folds: int,
                  seconds: float, records: Sequence[str] = (), notes: Sequence[str] = ()
                  ) -> str:
    """The text of ``report.md``, figures referenced by relative path.

    ``nominal``: reference (Mt, Bt); ``rows``: from :func:`data_rows`; ``figures``: key ->
    (relative PNG path, caption); ``sources``: data files; ``folds``: held-out segments per
    experiment; ``seconds``: wall time (s); ``records``: the ``--validate`` records; ``notes``:
    summary sentences."""
    from stewartid import __version__

    best = next(run for run in report.runs if run.name == report.trusted)
    ok = [run for run in report.runs if run.result is not None]
    several = len(report.runs) > 1
    lines = [f"# Identification report: {platform.name}", "",
             f"{len(datasets)} experiments identified with "
             + ", ".join(run.display_name for run in report.runs)
             + f" (stewartid {__version__}, {seconds:.1f} s).", ""]
    if sources:
        lines += ["Data: " + ", ".join(f"`{s}`" for s in sources) + ".", ""]
    verdict = [f"- {line}" for line in verdict_lines(report.verdict, report.runs)]
    lines += ["## Summary", "", *verdict, *(f"- {note}" for note in notes), ""]
    lines += ["## Data", ""] + _data_section(rows)
    lines += _figure(figures, "excitation") + _figure(figures, "spectrum")
    lines += ["## Joint rates and constant-direction intervals", ""]
    owner, intervals, points = used_intervals(report.runs, report.trusted, datasets)
    if intervals:
        counts = ", ".join(f"{d.name} {len(i)}" for d, i in zip(datasets, intervals,
                                                                strict=True))
        lines += [f"{owner} used {sum(len(i) for i in intervals)} intervals in "
                  f"which no active joint reverses ({counts}); "
                  + ("the (a, b) points are marked." if any(p is not None for p in points)
                     else "its test functions span each whole interval, so there are no "
                          "separate (a, b) points."), ""]
    lines += _figure(figures, "joint_rates") + _figure(figures, "intervals")
    lines += ["## Identified Mt and Bt", "",
              f"Nominal values: {nominal_source}. Standard errors as the method computes them "
              "from its residuals; a symmetric pair that disagrees by more than its standard "
              "errors shows they understate the error.", ""]
    for run in ok:
        lines += [f"### {run.display_name}", ""]
        lines += [matrix_table("Mt (kg, kg·m, kg·m²) ± standard error", run.result.M,
                               run.result.std_errors_M),
                  matrix_table("Bt (N·s/m, N·s, N·m·s) ± standard error", run.result.B,
                               run.result.std_errors_B)]
    lines += [matrix_table("Nominal Mt", nominal[0]), matrix_table("Nominal Bt", nominal[1])]
    lines += _figure(figures, "matrices")
    lines += ["## Residuals", "",
              f"Measured minus modelled generalized force of {best.display_name} fitted on all "
              "data (both filtered alike; one constant per segment removed). Peaks at the "
              "odd harmonics of the excitation are the signature of unmodelled Coulomb "
              "friction.", ""]
    lines += _figure(figures, "residuals")
    lines += (_validation_section(report, folds) + _figure(figures, "validation")
              + _records_section(report, records))
    lines += _consistency_section(ok)
    lines += ["## Friction", ""] + friction_section(ok, platform)
    lines += [""] + _figure(figures, "friction") + physical_lines(report.physical, figures,
                                                                    platform)
    if several:
        lines += ["## Methods compared", "", *verdict, ""]
        lines += _figure(figures, "methods")
    lines += _files_section(report)
    return "\n".join(lines).rstrip() + "\n"


def _validation_section(report: IdentificationReport, folds: int) -> list[str]:
    lines = ["## Validation on held-out data", "",
             f"Every experiment is cut into {folds} segments of equal length; each segment is "
             "predicted by the method refitted on all other segments. The prediction is "
             "Mt q̈ + Bt q̇, plus the Coulomb friction where the method estimates it; one "
             "constant per segment (static-load residual, sensor offsets) is not part of the "
             "model. Force and motion are filtered with the same zero-phase kernel of 0.2 "
             "excitation periods. VAF = 100 (1 − Σe² / Σy²) %, NRMSE = rms(e) / range(y), "
             "per DOF over all held-out segments.", ""]
    vaf_rows, nrmse_rows = [], []
    for run in report.runs:
        variants = [("", run.validation)]
        if run.validation_unconstrained is not None:
            variants = [(", consistent", run.validation),
                        (", unconstrained", run.validation_unconstrained)]
        for suffix, validation in variants:
            if validation is not None:
                vaf_rows.append((run.display_name + suffix,
                                 *(f"{v:.3f}" for v in validation.vaf_percent)))
                nrmse_rows.append((run.display_name + suffix,
                                   *(f"{v:.2g}" for v in validation.nrmse)))
    physical = report.physical
    if physical is not None and physical.validation is not None:
        vaf_rows.append((_UNRANKED, *(f"{v:.3f}" for v in physical.validation.vaf_percent)))
        nrmse_rows.append((_UNRANKED, *(f"{v:.2g}" for v in physical.validation.nrmse)))
    kinds = ("text",) + ("value",) * 6
    return lines + [
        to_markdown(ResultTable("vaf", "Held-out VAF per DOF (%)", ("method", *COORDINATES),
                                kinds, tuple(vaf_rows))),
        to_markdown(ResultTable("nrmse", "Held-out NRMSE per DOF", ("method", *COORDINATES),
                                kinds, tuple(nrmse_rows)))] + _residual_delay_lines(report)


def _residual_delay_lines(report: IdentificationReport) -> list[str]:
    """The force delay left in each method's held-out residuals, or why it cannot be seen."""
    found = [(run.display_name, run.validation.residual_delay) for run in report.runs
             if run.validation is not None and run.validation.residual_delay is not None]
    if not found:
        return []
    if not all(delay.identifiable for _, delay in found):
        return ["", "A force delay left in the data is not identifiable in the held-out "
                "residuals: a DOF moved at one frequency only, where a fit absorbs the delay "
                "into Bt and predicts the delayed force as well as the true one.", ""]
    values = ", ".join(f"{name} {1e3 * d.seconds:.3g} ± {1e3 * d.std_error:.2g}"
                       for name, d in found if np.isfinite(d.seconds))
    return ["", "Force delay left in the held-out residuals (ms ± standard error; positive: "
            "the measured force lags the prediction), once any other Mt, Bt per fold, Coulomb "
            f"levels and offsets have explained what they can: {values}.", ""]


def _records_section(report: IdentificationReport, records: Sequence[str]) -> list[str]:
    """Validation on records of another excitation, or what the segments cannot show."""
    if not records:
        return ["The held-out segments come from the same excitation as the fit: a model "
                "whose friction term compensates a wrong coupling predicts them as well as the "
                "right one. Records of another excitation (`identify --validate FILE`, e.g. "
                "the validation record `stewartid design` writes) would show it.", ""]
    rows = tuple((run.display_name, *(f"{v:.3f}" for v in run.records.vaf_percent))
                 for run in report.runs if run.records is not None)
    if report.physical is not None and report.physical.records is not None:
        rows += ((_UNRANKED, *(f"{v:.3f}" for v in report.physical.records.vaf_percent)),)
    lines = ["## Validation on other records", "",
             f"Each method's model, fitted on all experiments, predicts {len(records)} "
             f"record(s) of another excitation ({', '.join(records)}), filtered as the held-out "
             "segments are; the verdict judges the prediction on these.", ""]
    return lines + [to_markdown(ResultTable(
        "records", "VAF per DOF on the validation records (%)", ("method", *COORDINATES),
        ("text",) + ("value",) * 6, rows)), ""]


def _consistency_section(runs: Sequence[MethodFit]) -> list[str]:
    lines = ["## Physical consistency", "",
             "Mt must be symmetric positive definite and Bt symmetric positive semidefinite. "
             "Smallest eigenvalues are of the symmetric parts; asymmetry is the relative "
             "Frobenius norm of the antisymmetric part.", ""]
    rows = []
    for run in runs:
        for label, result in (("", run.unconstrained), (", consistent", run.result)):
            if label and run.projection is None:
                continue
            m = consistency_metrics(result.M, result.B)
            rows.append((run.display_name + label, _number(m["M_min_eigenvalue"]),
                         f"{m['M_asymmetry']:.2g}", _number(m["B_min_eigenvalue"]),
                         f"{m['B_asymmetry']:.2g}",
                         "yes" if is_consistent(result.M, result.B) else "no"))
    lines.append(to_markdown(ResultTable(
        "consistency", "Consistency", ("estimate", "Mt min eigenvalue", "Mt asymmetry",
                                       "Bt min eigenvalue", "Bt asymmetry", "consistent"),
        ("text",) + ("value",) * 5, tuple(rows))))
    for run in runs:
        if run.projection is None:
            continue
        before = run.validation_unconstrained.vaf_percent
        after = run.validation.vaf_percent
        lines += [f"`--consistent` ({run.display_name}, solver {run.projection.solver}): the "
                  "nearest consistent pair in standard errors of the estimate moves no entry "
                  f"by more than {changed_text(run.projection)} standard errors; held-out "
                  f"VAF in the worst DOF {np.min(before):.3f} % → {np.min(after):.3f} %.", ""]
    return lines


def _files_section(report: IdentificationReport) -> list[str]:
    lines = ["## Files", "",
             "- [result.json](result.json): the physical model's result with its `validation` "
             "and the compared methods' `verdict`" if report.physical_primary else
             f"- [result.json](result.json): {report.trusted}'s result with its `validation` "
             "and `consistency` objects",
             "- [identification.mat](identification.mat): every method's matrices, standard "
             "errors, validation and friction (MATLAB)"]
    for run in report.runs:
        if run.result is not None:
            links = ", ".join(f"[{run.name}_{key}.csv]({run.name}_{key}.csv)"
                              for key in ("M", "B", "std_errors_M", "std_errors_B"))
            lines.append(f"- {run.display_name}: {links}")
    if (report.physical is not None and report.physical.result is not None
            and not report.physical_primary):
        lines.append("- [physical.json](physical.json): the physical model's result")
    return lines + [""]


__all__ = ["data_rows", "matrix_table", "render_report", "used_intervals"]
