"""A study's results: one row per (grid point, seed, method) in ``DIR/results.parquet/``, one
atomically written ``part-<task key>.parquet`` per finished task (a rerun task replaces its
rows, a killed run leaves whole files). Columns: ``docs/studies.md``, :func:`columns`."""

from __future__ import annotations

import io
from collections.abc import Iterable, Mapping, Sequence
from pathlib import Path
from typing import Any

import pyarrow as pa
import pyarrow.parquet as pq

from stewartid.files import write_bytes_atomic
from stewartid.reference.published import PAPER_ENTRIES, entry_label
from stewartid.studies.spec import PARAMETERS

#: Folder of the data set inside the output folder.
RESULTS_NAME = "results.parquet"

#: Column of each of the paper's 20 entries, in PAPER_ENTRIES order.
ENTRY_COLUMNS = tuple(f"error_{entry_label(key)}" for key in PAPER_ENTRIES)

_PREFIX, _SUFFIX = "part-", ".parquet"


def _schema() -> Any:

    text, number = pa.string(), pa.float64()
    return pa.schema(
        [("task", text), *((name, number) for name in PARAMETERS), ("seed", pa.int64()),
         ("method", text), ("max_error_percent", number), ("max_error_entry", text),
         ("max_error_M_percent", number), ("max_error_B_percent", number),
         *((name, number) for name in ENTRY_COLUMNS), ("run_time_s", number),
         ("simulation_time_s", number), ("task_cpu_time_s", number), ("failure", text),
         ("worker", text)])


def columns() -> tuple[str, ...]:
    """Every column of the data set, in order."""
    return tuple(_schema().names)


def part_path(directory: str | Path, task_key: str) -> Path:
    """The file of task ``task_key`` in output folder ``directory``."""
    return Path(directory) / RESULTS_NAME / f"{_PREFIX}{task_key}{_SUFFIX}"


def write_part(directory: str | Path, task_key: str, rows: Sequence[Mapping[str, Any]]
               ) -> Path:
    """Write one task's rows as its own Parquet file, atomically; returns the path.

    Raises
    ------
    ValueError
        A row misses a column or belongs to another task.
    """

    schema = _schema()
    for row in rows:
        missing = [name for name in schema.names if name not in row]
        if missing or row["task"] != task_key:
            raise ValueError(f"row of task {row.get('task')!r} for {task_key!r} misses "
                             f"columns {missing}")
    table = pa.Table.from_pylist([dict(row) for row in rows], schema=schema)
    buffer = io.BytesIO()
    pq.write_table(table, buffer)
    return write_bytes_atomic(part_path(directory, task_key), buffer.getvalue())


def finished_tasks(directory: str | Path) -> set[str]:
    """Keys of the tasks stored in output folder ``directory``."""
    folder = Path(directory) / RESULTS_NAME
    if not folder.is_dir():
        return set()
    return {path.name[len(_PREFIX):-len(_SUFFIX)]
            for path in folder.glob(f"{_PREFIX}*{_SUFFIX}")}


def read_results(directory: str | Path, tasks: Iterable[str] | None = None) -> Any:
    """Every row in output folder ``directory`` (only ``tasks`` if given) as a pandas DataFrame.

    Sorted by parameters, seed and method; empty, with the :func:`columns`, before any task ends."""

    folder = Path(directory) / RESULTS_NAME
    paths = sorted(folder.glob(f"{_PREFIX}*{_SUFFIX}")) if folder.is_dir() else []
    schema = _schema()
    tables = [pq.read_table(path, schema=schema) for path in paths]
    frame = pa.concat_tables(tables or [schema.empty_table()]).to_pandas()
    if tasks is not None:
        frame = frame[frame["task"].isin(set(tasks))]
    frame = frame.drop_duplicates(["task", "method"], keep="last")
    order = [*PARAMETERS, "seed", "method"]
    return frame.sort_values(order, kind="stable").reset_index(drop=True)


__all__ = ["ENTRY_COLUMNS", "RESULTS_NAME", "columns", "finished_tasks", "part_path",
           "read_results", "write_part"]
