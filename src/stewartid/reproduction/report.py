"""A reproduction's ``report.md`` and self-contained ``report.html``; the summary derived from the numbers."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

from stewartid.files import write_text_atomic
from stewartid.reference.published import PAPER_ENTRIES, EntryKey, entry_label
from stewartid.reports.html import render_html
from stewartid.reports.methods import method_name
from stewartid.reports.tables import ResultTable, to_markdown
from stewartid.reproduction.comparison import ComparisonResults, MethodRun

#: The 1 % target of the wavelet method over the 20 entries.
TARGET_PERCENT = 1.0


@dataclass(frozen=True)
class FigureEntry:
    """A figure as the report shows it.

    Attributes
    ----------
    path : str
        PNG path relative to the report's folder.
    caption : str
    """

    path: str
    caption: str


def _max_eps(results: ComparisonResults, run: MethodRun, keys: Sequence[EntryKey]
             ) -> tuple[float, str]:
    errors = {k: results.eps(run, k) for k in keys}
    key = max(errors, key=errors.__getitem__)
    return errors[key], entry_label(key)


def _paper_max(results: ComparisonResults, method: str, coulomb: float,
               keys: Sequence[EntryKey]) -> tuple[float, str] | None:
    entries = {k: results.published_entry(method, coulomb, k) for k in keys}
    if any(e is None for e in entries.values()):
        return None
    key = max(entries, key=lambda k: entries[k].eps)
    return entries[key].eps, entry_label(key)


_GROUPS = {
    "diagonal Mt": [k for k in PAPER_ENTRIES if k[0] == "M" and k[1] == k[2]],
    "Mt couplings": [k for k in PAPER_ENTRIES if k[0] == "M" and k[1] != k[2]],
    "Bt": [k for k in PAPER_ENTRIES if k[0] == "B"],
}


def _compare(ours: float, paper: float) -> str:
    if ours < paper:
        ratio = paper / max(ours, 1e-9)
        return f"{ratio:.0f}× smaller than" if ratio >= 2 else "smaller than"
    return "larger than" if ours > paper else "equal to"


def wavelet_summary(results: ComparisonResults) -> list[str]:
    """Sentences on Method B at each Coulomb level: largest ε and the paper's."""
    lines = []
    for level in results.coulomb_levels:
        run = results.run("wavelet", level)
        if run is None:
            continue
        eps, label = _max_eps(results, run, PAPER_ENTRIES)
        paper = _paper_max(results, "wavelet", level, PAPER_ENTRIES)
        verdict = "within" if eps <= TARGET_PERCENT else "above"
        text = (f"**Method B (wavelet), {level:g} N·m**: largest ε over the 20 entries "
                f"{eps:.2f} % ({label}), {verdict} the {TARGET_PERCENT:g} % target")
        if paper is not None:
            text += (f"; the paper's largest is {paper[0]:.1f} % ({paper[1]}), ours is "
                     f"{_compare(eps, paper[0])} it")
        lines.append(text + ".")
    return lines


def fourier_summary(results: ComparisonResults) -> list[str]:
    """Sentences on Method A: errors by group with and without Coulomb friction, vs the paper's pattern."""
    lines = []
    for level in results.coulomb_levels:
        run = results.run("fourier", level)
        if run is None:
            continue
        parts = []
        group_max = {}
        for group, keys in _GROUPS.items():
            eps, label = _max_eps(results, run, keys)
            group_max[group] = eps
            paper = _paper_max(results, "fourier", level, keys)
            paper_text = "" if paper is None else f"; paper {paper[0]:.1f} %"
            parts.append(f"{group} up to {eps:.2f} % ({label}{paper_text})")
        text = f"**Method A (Fourier), {level:g} N·m**: " + ", ".join(parts)
        if level > 0:
            biased = max(group_max["Mt couplings"], group_max["Bt"])
            if group_max["diagonal Mt"] < biased:
                text += (f". The paper's pattern holds: the diagonal of Mt stays accurate "
                         f"({group_max['diagonal Mt']:.2f} %) while the first harmonic of the "
                         f"Coulomb square wave biases Bt and the couplings (up to "
                         f"{biased:.2f} %, {biased / max(group_max['diagonal Mt'], 1e-9):.0f}×"
                         " larger)")
            else:
                text += (". The paper's pattern does not show here: the diagonal of Mt is "
                         "not more accurate than Bt and the couplings")
        lines.append(text + ".")
    return lines


def others_summary(results: ComparisonResults) -> list[str]:
    """One sentence per remaining method: its largest ε at each Coulomb level."""
    lines = []
    for method in results.methods:
        if method in ("wavelet", "fourier"):
            continue
        parts = []
        for level in results.coulomb_levels:
            run = results.run(method, level)
            if run is not None:
                eps, label = _max_eps(results, run, PAPER_ENTRIES)
                parts.append(f"{eps:.2f} % at {level:g} N·m ({label})")
        if parts:
            lines.append(f"**{method_name(method)}**: largest ε " + ", ".join(parts) + ".")
    return lines


def summary_lines(results: ComparisonResults) -> list[str]:
    """The automatic summary, one Markdown bullet each."""
    noisy = results.settings.get("noise_case_summary")
    return (wavelet_summary(results) + fourier_summary(results) + others_summary(results)
            + ([str(noisy)] if noisy else []))


def _settings_lines(results: ComparisonResults) -> list[str]:
    settings = results.settings
    lines = []
    described = {
        "platform": "platform",
        "coulomb_levels": "Coulomb levels (N·m per joint axis)",
        "frequency_hz": "excitation frequency (Hz)",
        "duration_s": "record length per experiment (s)",
        "experiments": "experiments per level",
        "noise": "measurement noise",
        "seed": "seed",
        "jobs": "worker processes",
        "quick": "quick mode",
        "version": "stewartid version",
        "runtime_s": "run time (s)",
    }
    for key, label in described.items():
        if key in settings:
            value = settings[key]
            if isinstance(value, float):
                value = f"{value:.3g}"
            elif isinstance(value, list | tuple):
                value = ", ".join(f"{v:g}" if isinstance(v, float) else str(v) for v in value)
            lines.append(f"- {label}: {value}")
    return lines


def _published_notes(results: ComparisonResults) -> list[str]:
    notes = []
    for table in results.published.tables.values():
        for letter, entries in table.results.items():
            for entry in entries.values():
                if entry.note:
                    notes.append(f"- Table {table.number}, Method {letter}, {entry.label}: "
                                 f"{entry.note}.")
    return notes


def render_markdown(results: ComparisonResults, tables: Sequence[ResultTable],
                    figures: Sequence[FigureEntry], title: str | None = None) -> str:
    """The report as Markdown (figures referenced by relative path)."""
    settings = results.settings
    title = title or "Zhang (2020), Section 5, regenerated"
    lines = [f"# {title}", ""]
    mode = "quick run (shortened records)" if settings.get("quick") else "full run"
    lines += [
        f"{mode.capitalize()} of the paper's identification comparison on the simulated "
        "hydraulic plant of this package, with the paper's published values beside ours. "
        "ε is the relative absolute error |identified − nominal| / |nominal| in percent; our "
        "nominal values are computed from the platform description (Tables 1-2), the "
        "paper's are its printed ones.",
        "",
        f"Source: {results.published.citation} doi:{results.published.doi}",
        "",
        "## What was run",
        "",
    ]
    lines += _settings_lines(results)
    lines += ["- methods: " + ", ".join(method_name(m) for m in results.methods), ""]
    lines += ["## Summary", ""]
    lines += [f"- {line}" for line in summary_lines(results)]
    lines.append("")
    for table in tables:
        lines.append(to_markdown(table, heading_level=3 if table.name != "summary" else 3))
    if figures:
        lines += ["## Figures", ""]
        for figure in figures:
            lines += [f"![{figure.caption}]({figure.path})", "", f"*{figure.caption}*", ""]
    notes = _published_notes(results)
    if notes:
        lines += ["## Notes on the published values", ""] + notes + [""]
    return "\n".join(lines).rstrip() + "\n"


def write_report(results: ComparisonResults, tables: Sequence[ResultTable],
                 figures: Sequence[FigureEntry], directory: str | Path
                 ) -> tuple[Path, Path]:
    """Write ``report.md`` and ``report.html`` into ``directory``; returns both paths."""
    directory = Path(directory)
    text = render_markdown(results, tables, figures)
    markdown_path = write_text_atomic(directory / "report.md", text)
    html_path = write_text_atomic(directory / "report.html", render_html(text, directory))
    return markdown_path, html_path


__all__ = [
    "FigureEntry",
    "TARGET_PERCENT",
    "fourier_summary",
    "others_summary",
    "render_markdown",
    "summary_lines",
    "wavelet_summary",
    "write_report",
]
