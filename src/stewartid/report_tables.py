"""Readable terminal tables of matrices (rich)."""

from __future__ import annotations

import numpy as np
from rich.console import Console
from rich.table import Table

#: Names of the six generalized coordinates, paper order.
COORDINATES = ("x", "y", "z", "rx", "ry", "rz")


def matrix_table(matrix: np.ndarray, title: str, digits: int = 1) -> Table:
    """A rich table of a 6x6 matrix with coordinate labels; entries below 1e-9 of the largest
    are shown as 0 (rounding noise of symmetric terms)."""
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
