"""Terminal tables (rich): a 6x6 matrix, a six-vector, identified versus nominal values."""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from typing import Any

import numpy as np
from rich.console import Console
from rich.table import Table

from stewartid.platform import COORDINATES


def matrix_table(matrix: np.ndarray, title: str, digits: int = 1) -> Table:
    """A rich table of a 6x6 matrix, coordinate labels; entries below 1e-9 of the largest shown as 0."""
    table = Table(title=title, title_justify="left")
    table.add_column("")
    for name in COORDINATES:
        table.add_column(name, justify="right")
    scale = float(np.max(np.abs(matrix))) or 1.0
    for name, row in zip(COORDINATES, matrix, strict=True):
        cells = [f"{0.0 if abs(v) < 1e-9 * scale else v:,.{digits}f}" for v in row]
        table.add_row(name, *cells)
    return table


def print_matrix(matrix: np.ndarray, title: str, digits: int = 1,
                 console: Console | None = None) -> None:
    """Print a 6x6 matrix as a labelled table."""
    (console or Console()).print(matrix_table(matrix, title, digits))


def print_vector(vector: np.ndarray, title: str, digits: int = 1,
                 console: Console | None = None) -> None:
    """Print a six-coordinate vector as a one-row table, small entries as 0 (:func:`matrix_table`)."""
    table = Table(title=title, title_justify="left")
    for name in COORDINATES:
        table.add_column(name, justify="right")
    scale = float(np.max(np.abs(vector))) or 1.0
    table.add_row(*(f"{0.0 if abs(v) < 1e-9 * scale else v:,.{digits}f}" for v in vector))
    (console or Console()).print(table)


def print_comparison(rows: Iterable[Mapping[str, Any]], title: str,
                     console: Console | None = None) -> None:
    """Print identified versus nominal values of the paper's 20 entries.

    ``rows`` as :func:`~stewartid.identification.result.comparison_rows` returns them."""
    view = Table(title=title, title_justify="left")
    for column, justify in (("entry", "left"), ("identified", "right"), ("± std", "right"),
                            ("nominal", "right"), ("ε (%)", "right")):
        view.add_column(column, justify=justify)
    for row in rows:
        view.add_row(row["entry"], f"{row['identified']:,.1f}", f"{row['std_error']:,.2g}",
                     f"{row['nominal']:,.1f}", f"{row['error_percent']:.2f}")
    (console or Console()).print(view)


__all__ = ["matrix_table", "print_comparison", "print_matrix", "print_vector"]
