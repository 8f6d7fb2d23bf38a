"""The one reader of data files: CSV and Parquet into NumPy columns via pyarrow (no pandas at
start-up), float64 where numeric, else as read; names cleaned as pandas' ``read_csv`` does.
"""

from __future__ import annotations

import numpy as np
import pyarrow as pa
import pyarrow.csv

from stewartid.errors import DataError

#: A table as read: column name to values, shape (N,) each.
Columns = dict[str, np.ndarray]


def read_csv_columns(text: str, where: str, delimiter: str = ",", decimal: str = ".",
                     skip_rows: int = 0) -> Columns:
    """Columns of a decoded CSV log: ``skip_rows`` preamble lines, a header, one line per sample.

    Raises
    ------
    DataError
        Not a table (a row with more or fewer fields than the header).
    """
    options = dict(
        read_options=pyarrow.csv.ReadOptions(skip_rows=skip_rows, use_threads=False),
        parse_options=pyarrow.csv.ParseOptions(delimiter=delimiter),
        # 0 and 1 are numbers here, not booleans
        convert_options=pyarrow.csv.ConvertOptions(decimal_point=decimal, true_values=[],
                                                   false_values=[]))
    try:
        table = pyarrow.csv.read_csv(pa.py_buffer(text.encode("utf-8")), **options)
    except (pa.ArrowException, ValueError) as exc:
        raise DataError(f"{where}: cannot be read as csv: {exc}") from exc
    return _columns(table)


def read_parquet_columns(path: str, where: str) -> Columns:
    """Columns of a Parquet file.

    Raises
    ------
    DataError
        Not Parquet.
    """
    from pyarrow import parquet  # here: a command line reading CSV never needs it

    try:
        # ParquetFile, not read_table: read_table imports pyarrow.dataset and pandas (0.2 s)
        with parquet.ParquetFile(path) as file:
            table = file.read()
    except (pa.ArrowException, ValueError, OSError) as exc:
        raise DataError(f"{where}: cannot be read as parquet: {exc}") from exc
    return _columns(table)


def _columns(table: pa.Table) -> Columns:
    out: Columns = {}
    for index, (name, column) in enumerate(zip(table.column_names, table.columns, strict=True)):
        name = name.strip().strip('"') or f"Unnamed: {index}"
        unique, count = name, 0
        while unique in out:
            count += 1
            unique = f"{name}.{count}"
        out[unique] = _values(column)
    return out


def _values(column: pa.ChunkedArray) -> np.ndarray:
    """float64 of a numeric column (NaN where missing), else the values as read."""
    kind = column.type
    if not (pa.types.is_floating(kind) or pa.types.is_integer(kind)):
        return np.array(column.to_pylist(), dtype=object)
    # read from the buffers: Array.to_numpy would import pandas, and cast or fill_null
    # pyarrow.compute
    code = "f" if pa.types.is_floating(kind) else "i" if pa.types.is_signed_integer(kind) else "u"
    dtype = np.dtype(f"<{code}{kind.bit_width // 8}")
    return np.concatenate([_chunk_values(chunk, dtype) for chunk in column.chunks]
                          or [np.empty(0)])


def _chunk_values(chunk: pa.Array, dtype: np.dtype) -> np.ndarray:
    validity, data = chunk.buffers()[:2]
    values = np.frombuffer(data, dtype=dtype, count=len(chunk),
                           offset=chunk.offset * dtype.itemsize).astype(float)
    if chunk.null_count:
        bits = np.unpackbits(np.frombuffer(validity, dtype=np.uint8), bitorder="little")
        values[bits[chunk.offset:chunk.offset + len(chunk)] == 0] = np.nan
    return values


def to_numbers(values: np.ndarray) -> np.ndarray:
    """Values as float64, NaN where missing or not a number."""
    values = np.asarray(values)
    if values.dtype != object:
        return values.astype(float)
    out = np.empty(values.shape)
    for k, value in enumerate(values):
        try:
            out[k] = float(value)
        except (TypeError, ValueError):
            out[k] = np.nan
    return out


def shown_value(values: np.ndarray, row: int) -> object:
    """Value at ``row`` for a message, as a number when it reads as one."""
    value = values[row]
    try:
        return float(value)
    except (TypeError, ValueError):
        return value


__all__ = ["Columns", "read_csv_columns", "read_parquet_columns", "shown_value", "to_numbers"]
