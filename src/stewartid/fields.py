"""Validation of TOML sections into frozen dataclasses.

A section is a frozen dataclass whose fields carry their unit, a one-line description and a
constraint in ``dataclasses.field(metadata=...)``. :func:`section_from_mapping` turns a TOML
table into such a dataclass and refuses unknown keys, missing keys, wrong types and values
out of range with one message naming the key, so every section of a platform description
is checked by the same code.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping
from pathlib import Path
from typing import Any, TypeVar

from stewartid.errors import ConfigError

T = TypeVar("T")

#: Constraint names understood in field metadata under ``"check"``.
_CHECKS = {
    "positive": (lambda v: v > 0, "> 0"),
    "nonnegative": (lambda v: v >= 0, ">= 0"),
    "fraction": (lambda v: 0 <= v < 1, "in [0, 1)"),
    "any": (lambda v: True, "any finite value"),
}


def spec(unit: str, doc: str, check: str = "positive", default: Any = dataclasses.MISSING,
         length: int | None = None) -> Any:
    """Declare a section field.

    Parameters
    ----------
    unit : str
        SI unit of the value, shown in error messages and documentation.
    doc : str
        One-line description.
    check : {"positive", "nonnegative", "fraction", "any"}
        Range constraint applied to the value (to every element for arrays).
    default : optional
        Default value; fields without one are required in TOML.
    length : int, optional
        For array-valued fields, the required number of elements.
    """
    metadata = {"unit": unit, "doc": doc, "check": check, "length": length}
    if default is dataclasses.MISSING:
        return dataclasses.field(metadata=metadata)
    if isinstance(default, list | tuple):
        value = tuple(default)
        return dataclasses.field(default=value, metadata=metadata)
    return dataclasses.field(default=default, metadata=metadata)


def _coerce(name: str, value: Any, field: dataclasses.Field, where: str) -> Any:
    meta = field.metadata
    length = meta.get("length")
    ok, expected = _CHECKS[meta.get("check", "any")]
    kind = field.type if isinstance(field.type, str) else getattr(field.type, "__name__", "")

    def number(v: Any, label: str) -> float:
        if isinstance(v, bool) or not isinstance(v, int | float):
            raise ConfigError(
                f"[{where}] {label} must be a number in {meta['unit']}; got {v!r} "
                f"({type(v).__name__}). Write it as e.g. {label} = 1.0"
            )
        v = float(v)
        if not math.isfinite(v) or not ok(v):
            raise ConfigError(
                f"[{where}] {label} must be {expected} ({meta['unit']}); got {v!r}."
            )
        return v

    if "bool" in kind:
        if not isinstance(value, bool):
            raise ConfigError(f"[{where}] {name} must be true or false; got {value!r}.")
        return value
    if "int" in kind and "tuple" not in kind:
        if isinstance(value, bool) or not isinstance(value, int):
            raise ConfigError(f"[{where}] {name} must be an integer; got {value!r}.")
        if not ok(value):
            raise ConfigError(f"[{where}] {name} must be {expected}; got {value!r}.")
        return value
    if "str" in kind:
        if not isinstance(value, str):
            raise ConfigError(f"[{where}] {name} must be a string; got {value!r}.")
        return value
    if length is not None:
        if not isinstance(value, list | tuple) or len(value) != length:
            raise ConfigError(
                f"[{where}] {name} must be a list of {length} numbers in {meta['unit']}; "
                f"got {value!r}."
            )
        return tuple(number(v, f"{name}[{i}]") for i, v in enumerate(value))
    return number(value, name)


def section_from_mapping(cls: type[T], table: Any, where: str) -> T:
    """Build the section dataclass ``cls`` from a TOML table.

    Parameters
    ----------
    cls : type
        Frozen dataclass declared with :func:`spec` fields.
    table : Mapping
        The parsed TOML table.
    where : str
        Section name used in error messages.

    Raises
    ------
    ConfigError
        On an unknown key, a missing required key, a wrong type or a value out of range.
    """
    if not isinstance(table, Mapping):
        raise ConfigError(f"[{where}] must be a TOML table; got {type(table).__name__}.")
    fields = {f.name: f for f in dataclasses.fields(cls)}
    unknown = sorted(set(table) - set(fields))
    if unknown:
        raise ConfigError(
            f"[{where}] has unknown key {unknown[0]!r}; valid keys are: {', '.join(fields)}."
        )
    values = {}
    for name, field in fields.items():
        if name in table:
            values[name] = _coerce(name, table[name], field, where)
        elif field.default is dataclasses.MISSING:
            raise ConfigError(
                f"[{where}] is missing required key {name!r} ({field.metadata['doc']}, "
                f"{field.metadata['unit']})."
            )
    return cls(**values)


def read_toml_text(path: str | Path) -> str:
    """The text of a TOML file, which must be UTF-8 (a byte-order mark is allowed).

    Raises
    ------
    ConfigError
        Naming the file and the line of the first byte that is not UTF-8, with the fix.
    """
    data = Path(path).read_bytes()
    try:
        return data.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        line = data[:exc.start].count(b"\n") + 1
        raise ConfigError(f"{path}: not UTF-8 (byte 0x{data[exc.start]:02x} on line {line}); "
                          "TOML files are UTF-8: re-save it as UTF-8.") from None


def section_to_mapping(section: Any) -> dict[str, Any]:
    """Inverse of :func:`section_from_mapping`: plain values ready for TOML or JSON."""
    out = {}
    for f in dataclasses.fields(section):
        value = getattr(section, f.name)
        out[f.name] = list(value) if isinstance(value, tuple) else value
    return out
