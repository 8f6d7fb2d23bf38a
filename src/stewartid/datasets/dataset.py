"""Measured experiments in the interchange format (``t, x..rz, l1..l6, f1..f6``; the motor currents
``i1..i6`` in place of ``f1..f6`` for electric legs): reading, validation at the boundary, writing.
"""

from __future__ import annotations

import dataclasses
import warnings
import weakref
from collections.abc import Callable, Hashable, Iterable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
import pyarrow as pa
import pyarrow.csv

from stewartid.arrays import median
from stewartid.datasets import plausibility as checks
from stewartid.datasets.columns import shown_value, to_numbers
from stewartid.datasets.distinct import check_distinct_experiments, check_distinct_paths
from stewartid.datasets.log_format import CURRENT_COLUMNS, LogFormat, read_table
from stewartid.errors import ConfigError, DataError, DataWarning, KinematicsError
from stewartid.files import write_bytes_atomic
from stewartid.model.kinematics import forward_kinematics, leg_lengths
from stewartid.platform import COORDINATES, Platform

if TYPE_CHECKING:
    import pandas as pd

#: All columns of the interchange format, in order.
COLUMNS = ("t", *COORDINATES, "l1", "l2", "l3", "l4", "l5", "l6",
           "f1", "f2", "f3", "f4", "f5", "f6")
POSE_COLUMNS = COLUMNS[1:7]
LENGTH_COLUMNS = COLUMNS[7:13]
FORCE_COLUMNS = COLUMNS[13:19]

#: Fewest samples an experiment may have (a handful of periods of the slowest method's window).
MIN_SAMPLES = 64

#: Largest relative deviation of a sample period from the median before the time base counts
#: as non-uniform (tolerates the rounding of t in text files written with enough digits).
UNIFORM_TOLERANCE = 1e-3

#: Plausible sample rates of a hexapod log (Hz); outside, the time column is in another unit.
SAMPLE_RATE_RANGE_HZ = (10.0, 1e6)

SUFFIXES = {".csv": "csv", ".parquet": "parquet", ".pq": "parquet"}


@dataclass(frozen=True)
class Dataset:
    """One experiment on a uniform time base.

    Attributes
    ----------
    t : ndarray, shape (N,)
        s, uniform period.
    pose : ndarray, shape (N, 6)
        [x, y, z, rx, ry, rz] of the reference point, paper frame, absolute, z down (m, rad).
    lengths : ndarray, shape (N, 6)
        Leg lengths (m).
    forces : ndarray, shape (N, 6)
        Actuator forces along the legs (N, positive extends).
    name : str
        File stem when read from a file.

    Notes
    -----
    The arrays are read-only views: what is derived from a record (:meth:`derived`) is computed
    once, so the data must not change after the record is built.
    """

    t: np.ndarray
    pose: np.ndarray
    lengths: np.ndarray
    forces: np.ndarray
    name: str = "exp"
    _derived: dict = dataclasses.field(default_factory=dict, init=False, repr=False,
                                       compare=False)

    def __post_init__(self) -> None:
        n = np.shape(self.t)[0] if np.ndim(self.t) == 1 else -1
        if n < 0:
            raise DataError(f"{self.name}: t must be one-dimensional; got shape {np.shape(self.t)}.")
        for field in ("pose", "lengths", "forces"):
            value = np.asarray(getattr(self, field), dtype=float)
            if value.shape != (n, 6):
                raise DataError(f"{self.name}: {field} must have shape ({n}, 6) to match t; "
                                f"got {value.shape}.")
            object.__setattr__(self, field, _read_only(value))
        object.__setattr__(self, "t", _read_only(np.asarray(self.t, dtype=float)))

    def __reduce__(self) -> tuple:
        # a copy sent to another process starts without what was derived here
        return (Dataset, tuple(getattr(self, f.name) for f in dataclasses.fields(self) if f.init))

    def derived(self, key: Hashable, compute: Callable[[Dataset], Any]) -> Any:
        """``compute(self)``, computed once per ``key`` for this record (leg terms, frequencies,
        thinned copies: what every method derives from the same record)."""
        if key not in self._derived:
            self._derived[key] = compute(self)
        return self._derived[key]

    def part(self, rows: slice, name: str | None = None,
             forces: np.ndarray | None = None) -> Dataset:
        """The samples ``rows`` of this record as a new record (views of its arrays), which
        takes what :meth:`pointwise` derives from this one's; named ``name`` (default: its own);
        ``forces`` (n, 6) in place of its own (channels aligned with the motion), if given."""
        record = Dataset(t=self.t[rows], pose=self.pose[rows], lengths=self.lengths[rows],
                         forces=self.forces[rows] if forces is None else forces,
                         name=self.name if name is None else name)
        record._derived[_SOURCE] = (weakref.ref(self), rows)
        return record

    def averaged(self, samples: int) -> Dataset:
        """The record at 1/``samples`` of its rate: every signal and the time stamps averaged over
        consecutive blocks of ``samples`` samples (an incomplete last block dropped).

        A block mean of a signal s is s at the block's mean time up to
        max|s''| T^2 (k^2 - 1) / 24 (T the period, k = ``samples``): for a sine of frequency f
        a gain sin(k w T / 2) / (k sin(w T / 2)) = 1 - (w T)^2 (k^2 - 1) / 24 + ..., w = 2 pi f,
        and no phase. White noise of variance s^2 per sample becomes white noise of s^2 / k per
        sample at the lower rate: the same density at the frequencies below the new Nyquist's.

        Raises
        ------
        ConfigError
            ``samples`` is not a whole number >= 1, or leaves fewer than :data:`MIN_SAMPLES`.
        """
        if not (isinstance(samples, int | np.integer) and samples >= 1):
            raise ConfigError(f"{self.name}: samples averaged must be a whole number >= 1; got "
                              f"{samples!r}.")
        if samples == 1:
            return self
        blocks = len(self) // samples
        if blocks < MIN_SAMPLES:
            raise ConfigError(f"{self.name}: averaging {samples} samples leaves {blocks} of "
                              f"{len(self)} (at least {MIN_SAMPLES} needed); average fewer.")

        def mean(array: np.ndarray) -> np.ndarray:
            return array[:blocks * samples].reshape(blocks, samples, *array.shape[1:]).mean(axis=1)

        return Dataset(t=mean(self.t), pose=mean(self.pose), lengths=mean(self.lengths),
                       forces=mean(self.forces), name=self.name)

    def clear_derived(self) -> None:
        """Drop what was derived from this record (:meth:`derived`), and the memory it holds;
        it is computed again when asked."""
        source = self._derived.get(_SOURCE)
        self._derived.clear()
        if source is not None:
            self._derived[_SOURCE] = source

    def pointwise(self, key: Hashable, compute: Callable[[Dataset], tuple[np.ndarray, ...]]
                  ) -> tuple[np.ndarray, ...]:
        """:meth:`derived` for arrays computed sample by sample along their first axis (terms of
        the pose): a :meth:`part` of a record takes the rows of the record's, C-contiguous."""
        source = self._derived.get(_SOURCE)
        record = None if source is None else source[0]()
        if record is None:
            return self.derived(key, compute)
        rows = source[1]
        return self.derived(key, lambda _: tuple(
            np.ascontiguousarray(array[rows]) for array in record.pointwise(key, compute)))

    @property
    def sample_rate(self) -> float:
        """Hz, from the mean period."""
        return float((len(self.t) - 1) / (self.t[-1] - self.t[0]))

    @property
    def duration(self) -> float:
        """t[-1] - t[0] (s)."""
        return float(self.t[-1] - self.t[0])

    def __len__(self) -> int:
        return len(self.t)

    def to_frame(self) -> pd.DataFrame:
        """Table with the interchange columns."""
        import pandas as pd  # slow to import: reading and writing data never need it

        data = np.column_stack([self.t, self.pose, self.lengths, self.forces])
        return pd.DataFrame(data, columns=list(COLUMNS))


#: Key of :attr:`Dataset._derived` holding the record and rows a :meth:`Dataset.part` came from.
_SOURCE = ("part of",)


def _read_only(array: np.ndarray) -> np.ndarray:
    """A read-only view of ``array`` (the caller's array stays writable)."""
    view = array.view()
    view.flags.writeable = False
    return view


def _format_of(path: Path, format: str | None) -> str:
    if format is not None:
        if format not in ("csv", "parquet"):
            raise DataError(f"unknown data format {format!r} for {path}; expected 'csv' or "
                            "'parquet'.")
        return format
    try:
        return SUFFIXES[path.suffix.lower()]
    except KeyError:
        raise DataError(f"{path}: unknown file type {path.suffix!r}; expected one of "
                        f"{', '.join(SUFFIXES)} (or pass format='csv'|'parquet').") from None


def _check_time(t: np.ndarray, where: str) -> bool:
    """Validate the time column; True when uniform."""
    if len(t) < MIN_SAMPLES:
        raise DataError(f"{where}: only {len(t)} samples; at least {MIN_SAMPLES} are needed "
                        "(record a longer experiment).")
    dt = np.diff(t)
    if np.any(dt <= 0):
        bad = int(np.argmax(dt <= 0)) + 1
        raise DataError(f"{where}: column 't' must be strictly increasing; row {bad} has "
                        f"t = {float(t[bad])!r} after t = {float(t[bad - 1])!r} (sort the rows "
                        "and drop duplicate time stamps).")
    period = median(dt)
    low, high = SAMPLE_RATE_RANGE_HZ
    if not low <= 1.0 / period <= high:
        units = [unit for unit, factor in (("ms", 1e-3), ("us", 1e-6))
                 if low <= 1.0 / (period * factor) <= high]
        fix = f"map it with --columns t=:{units[0]}" if units else "give it in seconds"
        raise DataError(f"{where}: column 't' has a sample period of {period:.6g} s "
                        f"({1.0 / period:.3g} Hz), implausible for a hexapod log; is it in "
                        f"another unit? {fix}.")
    return bool(np.max(np.abs(dt - period)) <= UNIFORM_TOLERANCE * period)


def _uniform_clock(t: np.ndarray, where: str) -> np.ndarray | None:
    """Least-squares uniform clock t0 + T i of jittery time stamps; None when a sample is half a
    period off its slot or a slot is skipped.
    """
    index = np.arange(len(t), dtype=float)
    index -= index.mean()
    period = float(index @ (t - t.mean()) / (index @ index))
    clock = t.mean() + period * index
    deviation = np.abs(t - clock)
    if np.max(deviation) >= 0.5 * period or np.max(np.diff(t)) >= 1.9 * period:
        return None
    warnings.warn(f"{where}: time stamps jitter by up to {np.max(deviation) * 1e3:.3g} ms "
                  f"around a uniform {1.0 / period:.6g} Hz clock; read as timing noise and "
                  "replaced by that clock.", DataWarning, stacklevel=4)
    return clock


def _resample(t: np.ndarray, columns: dict[str, np.ndarray], where: str
              ) -> tuple[np.ndarray, dict[str, np.ndarray]]:
    period = median(np.diff(t))
    n = int(np.floor((t[-1] - t[0]) / period + 1e-9)) + 1
    grid = t[0] + period * np.arange(n)
    warnings.warn(f"{where}: time base is not uniform (sample periods from "
                  f"{np.min(np.diff(t)):.6g} s to {np.max(np.diff(t)):.6g} s); resampled "
                  f"linearly onto {n} samples at the median period {period:.6g} s.",
                  DataWarning, stacklevel=4)
    return grid, {k: np.interp(grid, t, v) for k, v in columns.items()}


def dataset_from_frame(frame: Mapping[str, np.ndarray] | pd.DataFrame,
                       platform: Platform | None = None, name: str = "exp",
                       where: str | None = None,
                       carried: tuple[float, float] = checks.CARRIED_WEIGHT) -> Dataset:
    """Validate a table in the interchange format into a :class:`Dataset`.

    Parameters
    ----------
    frame : mapping of str to ndarray of shape (N,), or DataFrame
        ``t``, ``f1..f6`` (or the motor currents ``i1..i6``, A) and ``x..rz`` or ``l1..l6``;
        extra columns ignored.
    platform : Platform, optional
        Needed when pose or lengths are missing, and for currents: f = force_constant i with
        ``[actuator] force_constant`` (N/A).
    name : str
    where : str, optional
        Source named in errors; ``name`` by default.
    carried : (float, float)
        Allowed weight in multiples of the file's.

    Raises
    ------
    DataError
        Missing columns, non-finite values, non-increasing time, too few samples.
    ConfigError
        Currents without a platform whose ``[actuator]`` has a force constant.
    """
    where = where or name
    present = set(frame.keys())
    currents = (not all(c in present for c in FORCE_COLUMNS)
                and all(c in present for c in CURRENT_COLUMNS))
    force_constant = _force_constant(platform, where) if currents else None
    force_columns = CURRENT_COLUMNS if currents else FORCE_COLUMNS
    missing = [c for c in ("t", *force_columns) if c not in present]
    if missing:
        electric = platform is not None and platform.actuator.force_constant is not None
        alternative = " (or the motor currents i1..i6, A)" if electric else ""
        raise DataError(f"{where}: missing required column(s) {', '.join(missing)}{alternative}; "
                        f"expected columns {', '.join(COLUMNS)} (other names or units: "
                        "--columns, docs/logs.md).")
    has_pose = all(c in present for c in POSE_COLUMNS)
    has_lengths = all(c in present for c in LENGTH_COLUMNS)
    if not (has_pose or has_lengths):
        lacking = [c for c in POSE_COLUMNS + LENGTH_COLUMNS if c not in present]
        raise DataError(f"{where}: needs either the pose columns x, y, z, rx, ry, rz or the leg "
                        f"lengths l1..l6; missing {', '.join(lacking)}.")
    wanted = ["t", *(POSE_COLUMNS if has_pose else ()), *(LENGTH_COLUMNS if has_lengths else ()),
              *force_columns]
    columns: dict[str, np.ndarray] = {}
    for c in wanted:
        column = np.asarray(frame[c])
        values = to_numbers(column)
        finite = np.isfinite(values)
        if not np.all(finite):
            row = int(np.argmin(finite))
            raise DataError(f"{where}: column {c!r} has a missing, non-numeric or non-finite "
                            f"value at row {row} ({shown_value(column, row)!r}); clean or drop "
                            "that row.")
        columns[c] = values
    t = columns.pop("t")
    if not _check_time(t, where):
        clock = _uniform_clock(t, where)
        if clock is None:
            t, columns = _resample(t, columns, where)
        else:
            t = clock
    forces = np.column_stack([columns[c] for c in force_columns])
    if force_constant is not None:
        forces = force_constant * forces
    pose = np.column_stack([columns[c] for c in POSE_COLUMNS]) if has_pose else None
    lengths = np.column_stack([columns[c] for c in LENGTH_COLUMNS]) if has_lengths else None
    if platform is not None:
        if pose is not None:
            checks.check_pose(pose, platform, where)
        if lengths is not None:
            checks.check_leg_lengths(lengths, platform, where)
    if pose is None or lengths is None:
        if platform is None:
            group = "pose (x..rz)" if pose is None else "leg lengths (l1..l6)"
            raise DataError(f"{where}: the {group} is missing and no platform description was "
                            "given to compute it; pass platform=... (CLI: --platform).")
        if pose is None:
            try:
                pose = _forward_kinematics_tracked(platform, lengths, forward_kinematics)
            except KinematicsError as exc:
                raise DataError(f"{where}: cannot compute the pose from l1..l6: {exc}") from exc
        else:
            lengths = leg_lengths(platform, pose)
    if platform is not None:
        checks.check_dataset(pose, lengths, forces, platform, where,
                             both_logged=has_pose and has_lengths, carried=carried,
                             currents=currents)
    return Dataset(t=t, pose=pose, lengths=lengths, forces=forces, name=name)


def _force_constant(platform: Platform | None, where: str) -> float:
    """[actuator] force_constant (N/A) that turns a log's currents into forces.

    Raises
    ------
    ConfigError
        No platform, or one without a force constant.
    """
    if platform is None:
        raise ConfigError(f"{where}: the motor currents i1..i6 become leg forces through the "
                          "force constant of the platform's [actuator]; pass platform=... "
                          "(CLI: --platform).")
    if platform.actuator.force_constant is None:
        raise ConfigError(f"{where}: the log has motor currents i1..i6 but platform "
                          f"'{platform.name}' has no force constant; add force_constant (N/A, "
                          'leg force per motor current) and kind = "electric" to its [actuator].')
    return platform.actuator.force_constant


def _forward_kinematics_tracked(platform: Platform, lengths: np.ndarray, solve) -> np.ndarray:
    # refined from the previous block's solution: consecutive samples are close, so Newton
    # converges even for large excursions that would stall from neutral
    pose = np.empty_like(lengths)
    block = 2048
    start = platform.neutral_pose
    for i in range(0, len(lengths), block):
        chunk = lengths[i:i + block]
        pose[i:i + block] = solve(platform, chunk, initial=start)
        start = pose[i + len(chunk) - 1]
    return pose


def read_dataset(path: str | Path, platform: Platform | None = None,
                 format: str | None = None, log_format: LogFormat | None = None,
                 carried: tuple[float, float] = checks.CARRIED_WEIGHT) -> Dataset:
    """Read and validate one experiment, named after the file stem.

    Parameters
    ----------
    path : str or Path
        ``.csv`` or ``.parquet``, interchange format or as ``log_format`` describes.
    platform : Platform, optional
        Fills in missing pose or lengths; checks the data
        (:mod:`stewartid.datasets.plausibility`).
    format : {'csv', 'parquet'}, optional
        Overrides the suffix.
    log_format : LogFormat, optional
    carried : (float, float)
        See :func:`~stewartid.datasets.plausibility.check_static_balance`.

    Raises
    ------
    DataError
        Unparsable or invalid file; the message names file and column.
    """
    path = Path(path)
    kind = _format_of(path, format)
    if not path.is_file():
        raise DataError(f"{path}: no such data file.")
    lead = platform.actuator.screw_lead if platform is not None else None
    frame = read_table(path, kind, log_format, lead)
    return dataset_from_frame(frame, platform, name=path.stem, where=str(path),
                              carried=carried)


def expand_paths(paths: Iterable[str | Path]) -> list[Path]:
    """Data files named by ``paths``; a directory stands for its ``*.csv`` and ``*.parquet``."""
    out: list[Path] = []
    for p in map(Path, paths):
        if p.is_dir():
            found = sorted(f for f in p.iterdir() if f.suffix.lower() in SUFFIXES)
            if not found:
                raise DataError(f"{p}: directory holds no .csv or .parquet data files.")
            out.extend(found)
        else:
            out.append(p)
    return out


def read_datasets(paths: str | Path | Sequence[str | Path],
                  platform: Platform | None = None,
                  log_format: LogFormat | None = None,
                  carried: tuple[float, float] = checks.CARRIED_WEIGHT) -> list[Dataset]:
    """Read several experiments in the given order (directories sorted by name), settings as
    :func:`read_dataset`.
    """
    if isinstance(paths, str | Path):
        paths = [paths]
    files = expand_paths(paths)
    if not files:
        raise DataError("no data files given; pass one or more .csv/.parquet files.")
    check_distinct_paths(files)
    datasets = [read_dataset(f, platform, log_format=log_format, carried=carried)
                for f in files]
    check_distinct_experiments(datasets, [str(f) for f in files])
    return datasets


def write_dataset(dataset: Dataset, path: str | Path, format: str | None = None,
                  force_constant: float | None = None) -> Path:
    """Write an experiment in the interchange format atomically; return the path.

    ``format`` defaults to the suffix of ``path``. With ``force_constant`` (N/A, electric legs) the
    forces are written as the motor currents ``i1..i6`` = f / force_constant (A), which reading with
    the platform's ``[actuator] force_constant`` turns back into the forces to 2 eps.
    """
    path = Path(path)
    kind = _format_of(path, format)
    forces = dataset.forces if force_constant is None else dataset.forces / force_constant
    columns = COLUMNS if force_constant is None else (*COLUMNS[:13], *CURRENT_COLUMNS)
    data = np.column_stack([dataset.t, dataset.pose, dataset.lengths, forces]).T
    table = pa.table(dict(zip(columns, data, strict=True)))
    buffer = pa.BufferOutputStream()
    if kind == "csv":
        # Arrow writes the shortest decimal that reads back to the same double: a bit-exact round trip
        pyarrow.csv.write_csv(table, buffer, pyarrow.csv.WriteOptions(quoting_style="none"))
    else:
        from pyarrow import parquet  # here: writing CSV files never needs it

        parquet.write_table(table, buffer)
    return write_bytes_atomic(path, buffer.getvalue().to_pybytes())


__all__ = [
    "COLUMNS",
    "FORCE_COLUMNS",
    "LENGTH_COLUMNS",
    "MIN_SAMPLES",
    "POSE_COLUMNS",
    "Dataset",
    "dataset_from_frame",
    "expand_paths",
    "read_dataset",
    "read_datasets",
    "write_dataset",
]
