"""The published results of Zhang (2020), Tables 3-6 (``stewartid/data/published.json``, Table 6's
sign typos corrected, printed values kept); entries keyed ``(matrix, row, column)``, 0-based.
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass, field
from importlib import resources
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from stewartid.errors import DataError

#: One matrix entry: ("M" or "B", row, column), 0-based indices.
EntryKey = tuple[str, int, int]

_PAIRS = ((0, 0), (1, 1), (2, 2), (3, 3), (4, 4), (5, 5), (0, 4), (1, 3), (3, 1), (4, 0))

#: The 20 entries of Mt and Bt the paper tabulates, in its row order (diagonal, then couplings).
PAPER_ENTRIES: tuple[EntryKey, ...] = tuple(
    (matrix, row, col) for matrix in ("M", "B") for row, col in _PAIRS
)

_UNITS = {
    "M": ("kg", "kg", "kg", "kg·m²", "kg·m²", "kg·m²"),
    "B": ("N·s/m", "N·s/m", "N·s/m", "N·m·s/rad", "N·m·s/rad", "N·m·s/rad"),
}


def entry_label(key: EntryKey) -> str:
    """Paper-style name of an entry, e.g. ``("M", 0, 4)`` -> ``"Mt(1,5)"``."""
    matrix, row, col = key
    return f"{matrix}t({row + 1},{col + 1})"


def entry_unit(key: EntryKey) -> str:
    """SI unit of an entry of Mt or Bt (couplings carry kg·m or N·s)."""
    matrix, row, col = key
    if row == col:
        return _UNITS[matrix][row]
    # a coupling between a translation and a rotation: kg·m (Mt) or N·s (Bt)
    return "kg·m" if matrix == "M" else "N·s"


def relative_error_percent(value: ArrayLike, nominal: ArrayLike) -> Any:
    """ε = |value − nominal| / |nominal| · 100 (%), the paper's relative error (the package's one definition).

    Element-wise; NaN, silently, where the nominal is zero.
    """
    value = np.asarray(value, dtype=float)
    nominal = np.asarray(nominal, dtype=float)
    with np.errstate(divide="ignore", invalid="ignore"):
        eps = np.abs(value - nominal) / np.where(nominal == 0, np.nan, np.abs(nominal)) * 100.0
    return float(eps) if eps.ndim == 0 else eps


@dataclass(frozen=True)
class PublishedEntry:
    """One published identified value.

    Attributes
    ----------
    key : tuple
        ``(matrix, row, column)``, 0-based.
    value : float
        SI, known typos corrected.
    eps : float
        ε (%) as printed.
    printed : float
        As printed.
    note : str or None
        Why a value was corrected or does not match its ε.
    """

    key: EntryKey
    value: float
    eps: float
    printed: float
    note: str | None = None

    @property
    def label(self) -> str:
        """Paper-style entry name, e.g. ``"Bt(2,4)"``."""
        return entry_label(self.key)

    @property
    def corrected(self) -> bool:
        """True where the printed value was corrected (a sign typo)."""
        return self.printed != self.value


@dataclass(frozen=True)
class PublishedTable:
    """One of the paper's result tables.

    Attributes
    ----------
    number : int
        3-6.
    title : str
    coulomb : float
        Coulomb level of the experiment (N·m per joint axis).
    frequency_hz : float
    results : dict
        ``{method letter: {entry key: PublishedEntry}}``.
    """

    number: int
    title: str
    coulomb: float
    frequency_hz: float
    results: dict[str, dict[EntryKey, PublishedEntry]] = field(repr=False)

    @property
    def methods(self) -> tuple[str, ...]:
        """Method letters reported in this table, e.g. ``("A", "B")``."""
        return tuple(self.results)

    @property
    def matrices(self) -> tuple[str, ...]:
        """Matrices ("M", "B") reported in this table."""
        found = {key[0] for entries in self.results.values() for key in entries}
        return tuple(m for m in ("M", "B") if m in found)


@dataclass(frozen=True)
class PublishedResults:
    """All of the paper's published results (Tables 3-6) and its nominal column.

    Attributes
    ----------
    tables : dict
        ``{table number: PublishedTable}``.
    nominal : dict
        ``{entry key: nominal value}`` as printed (SI).
    citation, doi : str
    """

    tables: dict[int, PublishedTable] = field(repr=False)
    nominal: dict[EntryKey, float] = field(repr=False)
    citation: str
    doi: str

    def table(self, number: int) -> PublishedTable:
        """The paper's Table ``number`` (3, 4, 5 or 6)."""
        try:
            return self.tables[number]
        except KeyError:
            raise DataError(
                f"the paper has no result table {number}; expected one of "
                f"{sorted(self.tables)}") from None

    def entry(self, method: str, coulomb: float, key: EntryKey) -> PublishedEntry | None:
        """The published entry of method ``method`` ("A"/"B") at ``coulomb`` N·m, if any."""
        for table in self.tables.values():
            if math.isclose(table.coulomb, coulomb) and key in table.results.get(method, {}):
                return table.results[method][key]
        return None

    def cases(self) -> list[tuple[str, float]]:
        """All (method letter, Coulomb level) combinations the paper reports, sorted."""
        found = {(method, table.coulomb) for table in self.tables.values()
                 for method in table.results}
        return sorted(found, key=lambda item: (item[1], item[0]))


def _parse_key(text: str, where: str) -> tuple[int, int]:
    try:
        row, col = (int(part) for part in text.split(","))
    except ValueError:
        raise DataError(f"{where}: entry key {text!r} is not 'row,column' (1-based), "
                        "e.g. '1,5'") from None
    if not (1 <= row <= 6 and 1 <= col <= 6):
        raise DataError(f"{where}: entry {text!r} is outside a 6x6 matrix; rows and "
                        "columns run from 1 to 6")
    return row - 1, col - 1


def _number(value: Any, where: str) -> float:
    if isinstance(value, bool) or not isinstance(value, int | float) or not math.isfinite(value):
        raise DataError(f"{where}: expected a finite number, got {value!r}")
    return float(value)


def _parse_entries(matrix: str, mapping: Any, where: str) -> dict[EntryKey, PublishedEntry]:
    if not isinstance(mapping, dict):
        raise DataError(f"{where}: expected an object of entries, got {type(mapping).__name__}")
    entries = {}
    for text, item in mapping.items():
        row, col = _parse_key(text, where)
        here = f"{where}[{text!r}]"
        if not isinstance(item, dict) or not {"value", "eps"} <= set(item):
            raise DataError(f"{here}: expected {{'value': ..., 'eps': ...}}, got {item!r}")
        value = _number(item["value"], f"{here}.value")
        printed = _number(item.get("printed", item["value"]), f"{here}.printed")
        key = (matrix, row, col)
        entries[key] = PublishedEntry(key, value, _number(item["eps"], f"{here}.eps"),
                                      printed, item.get("note"))
    return entries


def parse_published(document: dict[str, Any], where: str = "published.json"
                    ) -> PublishedResults:
    """Build :class:`PublishedResults` from the decoded JSON document."""
    try:
        nominal_doc, tables_doc, source = (document["nominal"], document["tables"],
                                           document["source"])
    except (KeyError, TypeError):
        raise DataError(f"{where}: expected top-level keys 'source', 'nominal' and 'tables'"
                        ) from None
    nominal = {}
    for matrix in ("M", "B"):
        for text, value in nominal_doc.get(matrix, {}).items():
            row, col = _parse_key(text, f"{where}: nominal.{matrix}")
            nominal[(matrix, row, col)] = _number(value, f"{where}: nominal.{matrix}[{text!r}]")
    tables = {}
    for number_text, table_doc in tables_doc.items():
        here = f"{where}: tables[{number_text!r}]"
        results = {}
        for method, matrices in table_doc.get("results", {}).items():
            entries: dict[EntryKey, PublishedEntry] = {}
            for matrix, mapping in matrices.items():
                if matrix not in ("M", "B"):
                    raise DataError(f"{here}.{method}: unknown matrix {matrix!r}; "
                                    "expected 'M' or 'B'")
                entries.update(_parse_entries(matrix, mapping, f"{here}.{method}.{matrix}"))
            results[method] = entries
        tables[int(number_text)] = PublishedTable(
            number=int(number_text), title=str(table_doc.get("title", "")),
            coulomb=_number(table_doc.get("coulomb"), f"{here}.coulomb"),
            frequency_hz=_number(table_doc.get("frequency_hz"), f"{here}.frequency_hz"),
            results=results)
    return PublishedResults(tables=tables, nominal=nominal,
                            citation=str(source.get("citation", "")),
                            doi=str(source.get("doi", "")))


def load_published(path: str | Path | None = None) -> PublishedResults:
    """Load the paper's Tables 3-6 from ``path`` (the package's copy by default)."""
    if path is None:
        text = resources.files("stewartid").joinpath("data/published.json").read_text("utf-8")
        where = "stewartid/data/published.json"
    else:
        where = str(path)
        text = Path(path).read_text(encoding="utf-8")
    try:
        document = json.loads(text)
    except json.JSONDecodeError as exc:
        raise DataError(f"{where}: not valid JSON ({exc})") from None
    return parse_published(document, where)


__all__ = [
    "PAPER_ENTRIES",
    "EntryKey",
    "PublishedEntry",
    "PublishedResults",
    "PublishedTable",
    "entry_label",
    "entry_unit",
    "load_published",
    "parse_published",
    "relative_error_percent",
]
