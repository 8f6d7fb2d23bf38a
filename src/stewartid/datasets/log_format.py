"""Controller logs into the interchange format: column mapping with units (``docs/logs.md``),
delimiter and encoding detection, actuator forces f = pa * piston_area - pb * annulus_area, leg
lengths of electric legs from motor angles, l = length_at_zero_angle + screw_lead angle / (2 pi).
"""

from __future__ import annotations

import math
import re
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from stewartid.datasets.columns import (
    Columns,
    read_csv_columns,
    read_parquet_columns,
    to_numbers,
)
from stewartid.errors import ConfigError, DataError
from stewartid.files import read_toml
from stewartid.platform import COORDINATES

#: Interchange columns a log format may map, in order, with the chamber pressures.
PRESSURE_COLUMNS = tuple(f"pa{k}" for k in range(1, 7)) + tuple(f"pb{k}" for k in range(1, 7))
#: Motor currents of electric legs (A): forces through [actuator] force_constant.
CURRENT_COLUMNS = tuple(f"i{k}" for k in range(1, 7))
#: Motor angles of electric legs (rad): leg lengths through [actuator] screw_lead.
MOTOR_ANGLE_COLUMNS = tuple(f"motor{k}" for k in range(1, 7))
_TIME, _POSITIONS, _ANGLES = ("t",), COORDINATES[:3], COORDINATES[3:]
_LENGTHS = tuple(f"l{k}" for k in range(1, 7))
_FORCES = tuple(f"f{k}" for k in range(1, 7))
MAPPABLE = (*_TIME, *_POSITIONS, *_ANGLES, *_LENGTHS, *_FORCES, *PRESSURE_COLUMNS,
            *CURRENT_COLUMNS, *MOTOR_ANGLE_COLUMNS)

#: Units understood for each quantity, as factors to SI (keys are matched case-insensitively).
UNITS: dict[str, dict[str, float]] = {
    "time": {"s": 1.0, "ms": 1e-3, "us": 1e-6, "µs": 1e-6},
    "length": {"m": 1.0, "cm": 1e-2, "mm": 1e-3, "um": 1e-6, "µm": 1e-6},
    "angle": {"rad": 1.0, "mrad": 1e-3, "deg": math.pi / 180.0},
    "force": {"n": 1.0, "kn": 1e3},
    "pressure": {"pa": 1.0, "kpa": 1e3, "mpa": 1e6, "bar": 1e5, "psi": 6894.757293168},
    "current": {"a": 1.0, "ma": 1e-3},
    "motor angle": {"rad": 1.0, "deg": math.pi / 180.0, "rev": 2.0 * math.pi},
}
_QUANTITY = {**dict.fromkeys(_TIME, "time"), **dict.fromkeys(_POSITIONS + _LENGTHS, "length"),
             **dict.fromkeys(_ANGLES, "angle"), **dict.fromkeys(_FORCES, "force"),
             **dict.fromkeys(PRESSURE_COLUMNS, "pressure"),
             **dict.fromkeys(CURRENT_COLUMNS, "current"),
             **dict.fromkeys(MOTOR_ANGLE_COLUMNS, "motor angle")}

#: Keys of the ``[log]`` section (inline: the same names).
LOG_KEYS = ("delimiter", "encoding", "decimal", "skip_rows")
#: Keys of the ``[pressures]`` section (m^2).
AREA_KEYS = ("piston_area", "annulus_area")
#: Keys of the ``[motors]`` section: the leg length (m) at which a motor angle reads zero, one
#: for all legs or six.
MOTOR_KEYS = ("length_at_zero_angle",)
DELIMITERS = (",", ";", "\t")


@dataclass(frozen=True)
class ColumnSource:
    """Where one interchange column comes from.

    Attributes
    ----------
    name : str
        Log column ("" keeps the interchange name).
    unit : str
        A key of :data:`UNITS` for its quantity.
    scale : float
        Multiplier after conversion (-1 flips a sign).
    offset : float
        Added after conversion and scale, SI units.
    """

    name: str = ""
    unit: str = ""
    scale: float = 1.0
    offset: float = 0.0


@dataclass(frozen=True)
class LogFormat:
    """How to read a controller's log: columns with units, delimiter, encoding, areas.

    Attributes
    ----------
    columns : mapping of str to ColumnSource
        Interchange column (:data:`MAPPABLE`) to its source.
    delimiter, encoding, decimal : str or None
        Detected when None.
    skip_rows : int
        Lines before the header.
    piston_area, annulus_area : float or None
        m^2, needed for pressures.
    length_at_zero_angle : tuple of 6 floats or None
        Leg lengths (m) at which the motor angles read zero, needed for motor angles.
    source : str
        Named in error messages.
    """

    columns: Mapping[str, ColumnSource] = field(default_factory=dict)
    delimiter: str | None = None
    encoding: str | None = None
    decimal: str | None = None
    skip_rows: int = 0
    piston_area: float | None = None
    annulus_area: float | None = None
    length_at_zero_angle: tuple[float, ...] | None = None
    source: str = "--columns"

    def to_interchange(self, columns: Columns, where: str,
                       screw_lead: float | None = None) -> Columns:
        """The log's ``columns`` with interchange names in SI units; unmapped columns unchanged,
        ``f1..f6`` from pressures when there are no forces, ``l1..l6`` from motor angles when
        there are no leg lengths.

        Parameters
        ----------
        columns : mapping of str to ndarray of shape (N,)
        where : str
            Named in messages.
        screw_lead : float, optional
            Leg travel per motor revolution (m, ``[actuator] screw_lead``), needed for motor angles.

        Raises
        ------
        DataError
            A mapped column missing or not numeric, pressures without areas, motor angles
            without a screw lead or a length at zero angle.
        """
        out = dict(columns)
        for target, source in self.columns.items():
            name = source.name or target
            if name not in columns:
                raise DataError(f"{where}: no column {name!r} (mapped to {target} by "
                                f"{self.source}); the file has {_listing(columns)}.")
            values = to_numbers(columns[name])
            bad = [row for row in np.flatnonzero(np.isnan(values))
                   if not _missing(columns[name][row])]
            if bad:
                row = int(bad[0])
                raise DataError(f"{where}: column {name!r} has the non-numeric value "
                                f"{columns[name][row]!r} at row {row}; clean that row or "
                                "set the decimal mark / delimiter (docs/logs.md).")
            factor = UNITS[_QUANTITY[target]][source.unit.lower()] if source.unit else 1.0
            out[target] = values * factor * source.scale + source.offset
        if not all(f in out for f in _FORCES) and all(p in out for p in PRESSURE_COLUMNS):
            if self.piston_area is None or self.annulus_area is None:
                raise DataError(f"{where}: forces from chamber pressures need piston_area and "
                                f"annulus_area (m^2) in {self.source} (docs/logs.md).")
            for k in range(1, 7):
                out[f"f{k}"] = (to_numbers(out[f"pa{k}"]) * self.piston_area
                                - to_numbers(out[f"pb{k}"]) * self.annulus_area)
        if not all(c in out for c in _LENGTHS) and all(c in out for c in MOTOR_ANGLE_COLUMNS):
            if screw_lead is None:
                raise DataError(f"{where}: leg lengths from motor angles motor1..motor6 need "
                                "the screw lead; add screw_lead (m per motor revolution) to "
                                "[actuator] of the platform description (docs/logs.md).")
            if self.length_at_zero_angle is None:
                raise DataError(f"{where}: leg lengths from motor angles need "
                                "length_at_zero_angle (m, the leg length where a motor angle "
                                f"reads 0) in [motors] of {self.source} (docs/logs.md).")
            for k, reference in enumerate(self.length_at_zero_angle, start=1):
                out[f"l{k}"] = (reference + screw_lead / (2.0 * math.pi)
                                * to_numbers(out[f"motor{k}"]))
        return out


def _missing(value: Any) -> bool:
    return value is None or (isinstance(value, float) and math.isnan(value))


def _listing(columns: Any, limit: int = 8) -> str:
    names = [str(c) for c in columns]
    shown = ", ".join(repr(n) for n in names[:limit])
    return shown + (f" and {len(names) - limit} more" if len(names) > limit else "")


# -- building a LogFormat -------------------------------------------------------------------

def _expand(key: str, source: str) -> list[str]:
    """Interchange columns named by ``key``: one name, or a range ``first..last``."""
    if ".." in key:
        first, _, last = key.partition("..")
        if first in MAPPABLE and last in MAPPABLE and MAPPABLE.index(first) <= MAPPABLE.index(
                last):
            return list(MAPPABLE[MAPPABLE.index(first):MAPPABLE.index(last) + 1])
    elif key in MAPPABLE:
        return [key]
    raise ConfigError(f"{source}: unknown column {key!r}; map one of {', '.join(MAPPABLE)} "
                      "or a range such as l1..l6.")


def _column_source(target: str, value: Any, source: str, index: int | None) -> ColumnSource:
    """One :class:`ColumnSource` from "NAME", "NAME:UNIT", ":UNIT" or a table; ``{k}`` is the leg
    number of ``target``.
    """
    if isinstance(value, str):
        name, unit = value, ""
        head, colon, tail = value.rpartition(":")
        if colon and any(tail.lower() in units for units in UNITS.values()):
            name, unit = head, tail
        value = {"name": name, "unit": unit}
    if not isinstance(value, Mapping):
        raise ConfigError(f"{source}: {target} must be \"NAME\", \"NAME:UNIT\" or a table "
                          f"{{name = ..., unit = ..., scale = ..., offset = ...}}; got {value!r}.")
    unknown = sorted(set(value) - {"name", "unit", "scale", "offset"})
    if unknown:
        raise ConfigError(f"{source}: {target} has unknown key {unknown[0]!r}; valid keys are "
                          "name, unit, scale, offset.")
    name, unit = str(value.get("name", "")), str(value.get("unit", ""))
    units = UNITS[_QUANTITY[target]]
    if unit and unit.lower() not in units:
        raise ConfigError(f"{source}: unit {unit!r} does not fit {target} "
                          f"({_QUANTITY[target]}); use one of {', '.join(units)}.")
    if "{k}" in name:
        if index is None:
            raise ConfigError(f"{source}: {{k}} in {name!r} needs a range key such as l1..l6.")
        leg = re.search(r"\d$", target)
        name = name.replace("{k}", leg.group() if leg else str(index))
    numbers = {}
    for key, default in (("scale", 1.0), ("offset", 0.0)):
        number = value.get(key, default)
        if isinstance(number, bool) or not isinstance(number, int | float) or not math.isfinite(
                number):
            raise ConfigError(f"{source}: {target} {key} must be a finite number; got "
                              f"{number!r}.")
        numbers[key] = float(number)
    return ColumnSource(name=name, unit=unit, **numbers)


def log_format_from_mapping(document: Mapping[str, Any], source: str) -> LogFormat:
    """A :class:`LogFormat` from a parsed TOML document (``[log]``, ``[columns]``, ``[pressures]``,
    ``[motors]``).

    Raises
    ------
    ConfigError
        Unknown section, key or unit, or a value of the wrong type.
    """
    sections = {"log": LOG_KEYS, "columns": None, "pressures": AREA_KEYS, "motors": MOTOR_KEYS}
    unknown = sorted(set(document) - set(sections))
    if unknown:
        raise ConfigError(f"{source}: unknown section [{unknown[0]}]; valid sections are "
                          "[log], [columns], [pressures], [motors].")
    settings: dict[str, Any] = {}
    for section, keys in (("log", LOG_KEYS), ("pressures", AREA_KEYS), ("motors", MOTOR_KEYS)):
        table = document.get(section, {})
        bad = sorted(set(table) - set(keys))
        if bad:
            raise ConfigError(f"{source}: [{section}] has unknown key {bad[0]!r}; valid keys "
                              f"are {', '.join(keys)}.")
        settings.update(table)
    columns: dict[str, ColumnSource] = {}
    for key, value in document.get("columns", {}).items():
        targets = _expand(key, source)
        for index, target in enumerate(targets, start=1):
            columns[target] = _column_source(target, value, source,
                                             index if len(targets) > 1 else None)
    return LogFormat(columns=columns, source=source, **_checked_settings(settings, source))


def _checked_settings(settings: dict[str, Any], source: str) -> dict[str, Any]:
    delimiter = settings.get("delimiter")
    if delimiter is not None:
        delimiter = {"tab": "\t", "\\t": "\t"}.get(delimiter, delimiter)
        if delimiter not in DELIMITERS:
            raise ConfigError(f"{source}: delimiter must be ',', ';' or 'tab'; got "
                              f"{settings['delimiter']!r}.")
        settings["delimiter"] = delimiter
    if settings.get("decimal") not in (None, ".", ","):
        raise ConfigError(f"{source}: decimal must be '.' or ','; got {settings['decimal']!r}.")
    encoding = settings.get("encoding")
    if encoding is not None:
        try:
            "".encode(str(encoding))
        except LookupError:
            raise ConfigError(f"{source}: unknown encoding {encoding!r}; use e.g. 'utf-8', "
                              "'latin-1' or 'cp1252'.") from None
    rows = settings.get("skip_rows", 0)
    try:
        rows = int(rows)
    except (TypeError, ValueError):
        rows = -1
    if rows < 0:
        raise ConfigError(f"{source}: skip_rows must be an integer >= 0; got "
                          f"{settings['skip_rows']!r}.")
    settings["skip_rows"] = rows
    for key in AREA_KEYS:
        area = settings.get(key)
        if area is not None:
            try:
                area = float(area)
            except (TypeError, ValueError):
                area = math.nan
            if not 1e-6 <= area <= 10.0:
                raise ConfigError(f"{source}: {key} must be a cylinder area in m^2 between "
                                  f"1e-6 and 10; got {settings[key]!r} (mm^2 or cm^2?).")
            settings[key] = area
    if settings.get("length_at_zero_angle") is not None:
        settings["length_at_zero_angle"] = _lengths_at_zero_angle(
            settings["length_at_zero_angle"], source)
    return settings


def _lengths_at_zero_angle(value: Any, source: str) -> tuple[float, ...]:
    """Six leg lengths (m) from one number or a list of six, each a leg length of 1 cm to 100 m."""
    values = value if isinstance(value, list | tuple) else [value] * 6
    try:
        lengths = tuple(float(v) for v in values)
    except (TypeError, ValueError):
        lengths = ()
    if len(lengths) != 6 or not all(0.01 <= v <= 100.0 for v in lengths):
        raise ConfigError(f"{source}: length_at_zero_angle must be a leg length in m (0.01 to "
                          "100), or a list of six, where each motor angle reads 0; got "
                          f"{value!r} (mm?).")
    return lengths


def load_log_format(spec: str | Path) -> LogFormat:
    """A :class:`LogFormat` from a ``.toml`` file or an inline string such as
    ``"t=Time:ms,l1..l6=Leg{k}:mm,delimiter=;"``.

    Raises
    ------
    ConfigError
        File missing, not UTF-8 or not TOML, or an entry invalid.
    """
    text = str(spec)
    if isinstance(spec, Path) or text.lower().endswith(".toml") or Path(text).is_file():
        path = Path(spec)
        if not path.is_file():
            raise ConfigError(f"column mapping file {text!r} not found; give a TOML file "
                              "(docs/logs.md) or inline entries such as t=Time:ms.")
        return log_format_from_mapping(read_toml(path, "column mapping file"), str(path))
    document: dict[str, dict[str, Any]] = {"log": {}, "columns": {}, "pressures": {},
                                           "motors": {}}
    for entry in filter(None, (e.strip() for e in text.split(","))):
        key, equals, value = (part.strip() for part in entry.partition("="))
        if not equals:
            raise ConfigError(f"--columns: entry {entry!r} must read KEY=VALUE, e.g. t=Time:ms "
                              "or l1..l6=:mm.")
        section = ("log" if key in LOG_KEYS else "pressures" if key in AREA_KEYS
                   else "motors" if key in MOTOR_KEYS else "columns")
        document[section][key] = value
    return log_format_from_mapping(document, "--columns")


# -- reading a log ---------------------------------------------------------------------------

def decode_text(data: bytes, where: str, encoding: str | None = None) -> str:
    """Text of a log: the given encoding, else by byte-order mark, else strict UTF-8.

    Raises
    ------
    DataError
        Naming the file, the line of the first undecodable byte and the fix.
    """
    if encoding is None:
        if data.startswith((b"\xff\xfe", b"\xfe\xff")):
            encoding = "utf-16"
        else:
            encoding = "utf-8-sig"
    try:
        return data.decode(encoding)
    except UnicodeDecodeError as exc:
        line = data[:exc.start].count(b"\n") + 1
        raise DataError(f"{where}: not {encoding.removesuffix('-sig')} text (byte "
                        f"0x{data[exc.start]:02x} on line {line}); name its encoding, e.g. "
                        "--columns encoding=latin-1.") from None


def detect_delimiter(lines: list[str]) -> str:
    """The delimiter (``,`` ``;`` tab) splitting header and next lines alike into most fields; else ``,``."""
    best, best_count = ",", 0
    for delimiter in DELIMITERS:
        counts = {line.count(delimiter) for line in lines if line.strip()}
        count = counts.pop() if len(counts) == 1 else 0
        if count > best_count:
            best, best_count = delimiter, count
    return best


_DECIMAL_COMMA = re.compile(r"^\s*[+-]?\d+,\d+([eE][+-]?\d+)?\s*$")


def read_table(path: Path, kind: str, log_format: LogFormat | None = None,
               screw_lead: float | None = None) -> Columns:
    """Read a CSV or Parquet log into interchange columns (N,) in SI units.

    Parameters
    ----------
    path : Path
    kind : {'csv', 'parquet'}
    log_format : LogFormat, optional
        Detection and identity mapping otherwise.
    screw_lead : float, optional
        m per motor revolution, for motor angles (:meth:`LogFormat.to_interchange`).

    Raises
    ------
    DataError
        File cannot be decoded or parsed, or the mapping does not fit.
    """
    log_format = log_format or LogFormat()
    where = str(path)
    if kind == "parquet":
        return log_format.to_interchange(read_parquet_columns(str(path), where), where,
                                         screw_lead)
    try:
        text = decode_text(path.read_bytes(), where, log_format.encoding)
    except OSError as exc:
        raise DataError(f"{path}: cannot be read as {kind}: {exc}") from exc
    lines = _head_lines(text, log_format.skip_rows + 6)[log_format.skip_rows:]
    delimiter = log_format.delimiter or detect_delimiter(lines)
    decimal = log_format.decimal
    if decimal is None:
        fields = lines[1].split(delimiter) if len(lines) > 1 else []
        decimal = "," if delimiter != "," and any(
            _DECIMAL_COMMA.match(f) for f in fields) else "."
    columns = read_csv_columns(text, where, delimiter, decimal, log_format.skip_rows)
    return log_format.to_interchange(columns, where, screw_lead)


def _head_lines(text: str, count: int) -> list[str]:
    size = 4096
    while True:
        lines = text[:size].splitlines()
        if size >= len(text):
            return lines[:count]
        if len(lines) > count:  # the last line of the prefix may be cut short
            return lines[:count]
        size *= 4


__all__ = ["CURRENT_COLUMNS", "MAPPABLE", "MOTOR_ANGLE_COLUMNS", "MOTOR_KEYS", "PRESSURE_COLUMNS",
           "UNITS", "ColumnSource", "LogFormat",
           "decode_text", "detect_delimiter", "load_log_format", "log_format_from_mapping",
           "read_table"]
