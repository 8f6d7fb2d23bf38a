"""Every report's tables, built once as a :class:`ResultTable` and written as CSV (full precision)
and Markdown (rounded)."""

from __future__ import annotations

import csv
import io
import math
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

#: A table cell: a number, text, or None where there is no value.
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
        Per column: ``"text"``, ``"value"``, ``"eps"`` (%) or ``"published"`` (as the paper prints).
    rows : tuple of tuple
    notes : tuple of str
        Footnotes under the Markdown table.
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
    """Markdown text of a cell by ``kind``: values to 1 decimal, ε to 2, published as printed;
    "—" for none, "n/a" for non-finite."""
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
    """The table as CSV, full precision, empty cells for missing values."""
    buffer = io.StringIO()
    writer = csv.writer(buffer, lineterminator="\n")
    writer.writerow(table.columns)
    for row in table.rows:
        writer.writerow(["" if v is None else (repr(v) if isinstance(v, float) else v)
                         for v in row])
    return buffer.getvalue()


def write_tables(tables: Sequence[ResultTable], directory: str | Path) -> list[Path]:
    """Write each table as ``<name>.md`` and ``<name>.csv``; returns the paths."""
    from stewartid.files import write_text_atomic

    directory = Path(directory)
    paths = []
    for table in tables:
        paths.append(write_text_atomic(directory / f"{table.name}.md", to_markdown(table)))
        paths.append(write_text_atomic(directory / f"{table.name}.csv", to_csv(table)))
    return paths


__all__ = [
    "Cell",
    "ResultTable",
    "format_cell",
    "to_csv",
    "to_markdown",
    "write_tables",
]
