"""The identification report (``stewartid identify --report DIR``): ``report.md``, a self-contained
``report.html``, figures, ``result.json``, ``physical.json`` and every method's CSV/MATLAB matrices."""

from __future__ import annotations

import time
from collections.abc import Sequence
from pathlib import Path

from stewartid.comparison import Comparison
from stewartid.files import write_text_atomic
from stewartid.reports.exports import ExportedModel, write_exports
from stewartid.reports.html import render_html
from stewartid.reports.identification.figures import (
    FigureDrawer,
    data_figures,
    physical_figures,
    result_figures,
)
from stewartid.reports.identification.text import data_rows, render_report
from stewartid.reports.identification.written import IdentificationReport


def write_report(comparison: Comparison, directory: str | Path, *, sources: Sequence[str] = (),
                 notes: Sequence[str] = (), jobs: int | None = 1) -> IdentificationReport:
    """Write the identification report of ``comparison`` into ``directory``.

    Parameters
    ----------
    comparison : Comparison
        From :func:`~stewartid.comparison.compare_methods`.
    directory : str or Path
        Output folder (created; its files replaced; see
        :func:`stewartid.files.check_output_folder`).
    sources : sequence of str
        The data files, listed in the report.
    notes : sequence of str
        Sentences added to the summary.
    jobs : int or None
        Worker processes drawing the figures (None: every core; one where workers cannot start
        by fork); the files do not depend on it.
    """
    started = time.perf_counter()
    directory = Path(directory)
    datasets, platform = list(comparison.experiments), comparison.platform
    nominal = (comparison.nominal_M, comparison.nominal_B)
    rows = data_rows(datasets, platform)
    drawer = FigureDrawer(directory / "figures")
    data_figures(drawer, datasets, platform, rows)
    result_figures(drawer, comparison.runs, datasets, platform, nominal, comparison.trusted,
                   rows)
    physical_figures(drawer, comparison.physical)
    drawer.draw(jobs)
    models = [ExportedModel(run.name, run.result, *run.coulomb) for run in comparison.runs
              if run.result is not None]
    files = drawer.files + write_exports(models, directory, comparison.trusted)
    report = IdentificationReport(comparison, directory)
    files.append(comparison.result.to_json(directory / "result.json"))
    physical = comparison.physical
    if physical is not None and physical.result is not None and not comparison.physical_primary:
        files.append(physical.result.to_json(directory / "physical.json"))
    text = render_report(report, datasets, platform, nominal, comparison.nominal_source, rows,
                         drawer.entries, sources, comparison.folds,
                         comparison.seconds + time.perf_counter() - started,
                         [d.name for d in comparison.records], notes)
    files.append(write_text_atomic(directory / "report.md", text))
    files.append(write_text_atomic(directory / "report.html", render_html(
        text, directory, title=f"stewartid identification report: {platform.name}")))
    return IdentificationReport(comparison, directory, files)


__all__ = ["IdentificationReport", "write_report"]
