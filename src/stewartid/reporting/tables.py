"""Result tables in the paper's layout, ours beside the published values (Markdown and CSV).

Each table is built once as a :class:`ResultTable` (column names and rows of numbers or text)
and written both ways: CSV keeps full precision, Markdown rounds for reading. ε is the
relative absolute error in percent against the nominal value of the simulated plant; the
paper's ε column is reprinted as published.
"""

from __future__ import annotations

import csv
import io
import math
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

from stewartid.reference.published import PAPER_ENTRIES, EntryKey, entry_label, entry_unit
from stewartid.reporting.comparison import ComparisonResults, method_name, paper_methods

Cell = float | str | None


@dataclass(frozen=True)
class ResultTable:
    """A titled table; cells are numbers (formatted by column kind) or text.

    Attributes
    ----------
    name : str
        File stem, e.g. ``"table4"``.
    title : str
    columns : tuple of str
    kinds : tuple of str
        Per column: ``"text"``, ``"value"`` (an identified or nominal value), ``"eps"`` (%)
        or ``"published"`` (a number reprinted as the paper prints it).
    rows : tuple of tuple
    notes : tuple of str
        Footnotes printed under the Markdown table.
    """

    name: str
    title: str
    columns: tuple[str, ...]
    kinds: tuple[str, ...]
    rows: tuple[tuple[Cell, ...], ...]
    notes: tuple[str, ...] = ()

    def column(self, name: str) -> list[Cell]:
        """All cells of one column."""
        index = self.columns.index(name)
        return [row[index] for row in self.rows]


def format_cell(value: Cell, kind: str) -> str:
    """Markdown text of a cell: values to 1 decimal with thousands separators, ε to 2."""
    if value is None:
        return "—"
    if isinstance(value, str):
        return value
    if not math.isfinite(value):
        return "n/a"
    if kind == "eps":
        return f"{value:.2f}"
    if kind == "published":
        # as printed in the paper: no added decimals
        return format(value, ",.10g")
    return f"{value:,.1f}"


def to_markdown(table: ResultTable, heading_level: int = 3) -> str:
    """The table as GitHub-flavoured Markdown with a heading and its footnotes."""
    align = ["---" if kind == "text" else "---:" for kind in table.kinds]
    lines = [f"{'#' * heading_level} {table.title}", "",
             "| " + " | ".join(table.columns) + " |", "| " + " | ".join(align) + " |"]
    for row in table.rows:
        cells = (format_cell(v, k).replace("|", "\\|") for v, k in zip(row, table.kinds,
                                                                        strict=True))
        lines.append("| " + " | ".join(cells) + " |")
    if table.notes:
        lines.append("")
        lines.extend(f"{note}  " for note in table.notes)
    return "\n".join(lines) + "\n"


def to_csv(table: ResultTable) -> str:
    """The table as CSV with full-precision numbers and empty cells for missing values."""
    buffer = io.StringIO()
    writer = csv.writer(buffer, lineterminator="\n")
    writer.writerow(table.columns)
    for row in table.rows:
        writer.writerow(["" if v is None else (repr(v) if isinstance(v, float) else v)
                         for v in row])
    return buffer.getvalue()


def _entry_cells(key: EntryKey) -> list[Cell]:
    return [entry_label(key), entry_unit(key)]


def paper_table(results: ComparisonResults, number: int) -> ResultTable:
    """The paper's Table ``number`` (3-6) with our identified values and ε beside its own.

    Rows are the entries the paper's table reports; for each of its methods the columns are
    our identified value and ε, then the paper's; the nominal columns close the row (ours,
    computed from the platform description, and the paper's printed one).
    """
    published = results.published.table(number)
    letters = paper_methods()
    methods = [name for name, letter in letters.items() if letter in published.methods]
    columns = ["Parameter", "Unit"]
    kinds = ["text", "text"]
    for method in methods:
        letter = letters[method]
        columns += [f"{letter}: ours", f"{letter}: ε ours (%)",
                    f"{letter}: paper", f"{letter}: ε paper (%)"]
        kinds += ["value", "eps", "published", "published"]
    columns += ["Nominal (ours)", "Nominal (paper)"]
    kinds += ["value", "published"]
    rows = []
    notes = []
    keys = [k for k in PAPER_ENTRIES if k[0] in published.matrices]
    for key in keys:
        row = _entry_cells(key)
        for method in methods:
            ours = results.run(method, published.coulomb)
            entry = published.results[letters[method]][key]
            row += [None, None] if ours is None else [ours.value(key), results.eps(ours, key)]
            row += [entry.value, entry.eps]
            if entry.note:
                notes.append(f"{letters[method]}, {entry.label}: {entry.note}.")
        row += [results.nominal(key), results.published.nominal[key]]
        rows.append(tuple(row))
    missing = [method_name(m) for m in methods if results.run(m, published.coulomb) is None]
    if missing:
        notes.append(f"Not run here: {', '.join(missing)} (— in the table).")
    label = " and ".join(f"Method {letters[m]}" for m in methods)
    title = (f"Table {number}: {label}, Coulomb friction {published.coulomb:g} N·m "
             f"({published.frequency_hz:g} Hz sine excitation)")
    return ResultTable(f"table{number}", title, tuple(columns), tuple(kinds), tuple(rows),
                       tuple(notes))


def comparison_table(results: ComparisonResults, coulomb: float) -> ResultTable:
    """Every method at one Coulomb level: identified value and ε per entry, with the paper's
    values for the methods it reports at that level."""
    columns = ["Parameter", "Unit", "Nominal"]
    kinds = ["text", "text", "value"]
    runs = [r for r in (results.run(m, coulomb) for m in results.methods) if r is not None]
    for run in runs:
        columns += [method_name(run.method), "ε (%)"]
        kinds += ["value", "eps"]
    letters = paper_methods()
    reported = [run.method for run in runs
                if results.published_entry(run.method, coulomb, PAPER_ENTRIES[0])]
    for method in reported:
        columns += [f"paper {letters[method]}", "ε paper (%)"]
        kinds += ["published", "published"]
    rows = []
    for key in PAPER_ENTRIES:
        row = [*_entry_cells(key), results.nominal(key)]
        for run in runs:
            row += [run.value(key), results.eps(run, key)]
        for method in reported:
            entry = results.published_entry(method, coulomb, key)
            row += [entry.value, entry.eps]
        rows.append(tuple(row))
    title = f"All methods, Coulomb friction {coulomb:g} N·m"
    return ResultTable(f"comparison_coulomb{coulomb:g}", title, tuple(columns), tuple(kinds),
                       tuple(rows))


def summary_table(results: ComparisonResults) -> ResultTable:
    """Largest ε (%) over the 20 entries, per method and Coulomb level, ours and the paper's."""
    columns = ["Method", "Coulomb (N·m)", "max ε Mt (%)", "entry", "max ε Bt (%)", "entry",
               "paper max ε (%)", "paper entry"]
    kinds = ["text", "text", "eps", "text", "eps", "text", "published", "text"]
    rows = []
    for method in results.methods:
        for level in results.coulomb_levels:
            run = results.run(method, level)
            if run is None:
                continue
            key_m, eps_m = results.worst(run, "M")
            key_b, eps_b = results.worst(run, "B")
            paper = results.published_worst(method, level)
            rows.append((method_name(method), f"{level:g}", eps_m, entry_label(key_m),
                         eps_b, entry_label(key_b),
                         None if paper is None else paper[1],
                         None if paper is None else entry_label(paper[0])))
    return ResultTable("summary", "Largest error per method and Coulomb level",
                       tuple(columns), tuple(kinds), tuple(rows))


def build_tables(results: ComparisonResults) -> list[ResultTable]:
    """All tables of a run: the summary, the paper's Tables 3-6, one comparison per level."""
    tables = [summary_table(results)]
    tables += [paper_table(results, n) for n in sorted(results.published.tables)]
    tables += [comparison_table(results, level) for level in results.coulomb_levels]
    return tables


def write_tables(tables: Sequence[ResultTable], directory: str | Path) -> list[Path]:
    """Write each table as ``<name>.md`` and ``<name>.csv`` in ``directory``; return the paths."""
    from stewartid.files import write_text_atomic

    directory = Path(directory)
    paths = []
    for table in tables:
        paths.append(write_text_atomic(directory / f"{table.name}.md", to_markdown(table)))
        paths.append(write_text_atomic(directory / f"{table.name}.csv", to_csv(table)))
    return paths


__all__ = [
    "ResultTable",
    "build_tables",
    "comparison_table",
    "format_cell",
    "paper_table",
    "summary_table",
    "to_csv",
    "to_markdown",
    "write_tables",
]
