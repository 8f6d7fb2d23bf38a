"""Every file the package writes (atomically: a temporary file renamed over the target) and every
TOML file it reads; JSON gets plain values, NaN and ±infinity as ``null``.
"""

from __future__ import annotations

import json
import math
import os
import tempfile
import tomllib
from collections.abc import Callable, Iterable
from pathlib import Path
from typing import Any

import numpy as np

from stewartid.errors import ConfigError, OutputExistsError


def write_bytes_atomic(path: str | Path, data: bytes) -> Path:
    """Write ``data`` to ``path`` through a temporary file in its folder (created if missing) and a rename."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    handle, temporary = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".tmp")
    try:
        with os.fdopen(handle, "wb") as stream:
            stream.write(data)
        # mkstemp creates the file private (0600); give it the usual permissions
        umask = os.umask(0)
        os.umask(umask)
        os.chmod(temporary, 0o666 & ~umask)
        os.replace(temporary, path)
    except BaseException:
        Path(temporary).unlink(missing_ok=True)
        raise
    return path


def write_text_atomic(path: str | Path, text: str) -> Path:
    """Write UTF-8 ``text`` to ``path`` atomically."""
    return write_bytes_atomic(path, text.encode("utf-8"))


def to_jsonable(value: Any) -> Any:
    """``value`` as plain JSON: arrays and tuples as lists, NumPy scalars as numbers, paths and keys
    as strings, NaN or ±infinity as None.

    Raises
    ------
    TypeError
        For any other object.
    """
    if isinstance(value, np.ndarray):
        return to_jsonable(value.tolist())
    if isinstance(value, dict):
        return {str(k): to_jsonable(v) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return [to_jsonable(v) for v in value]
    if isinstance(value, np.generic):
        return to_jsonable(value.item())
    if isinstance(value, float):
        return value if math.isfinite(value) else None
    if isinstance(value, str | int | bool) or value is None:
        return value
    if isinstance(value, Path):
        return str(value)
    raise TypeError(f"cannot write a {type(value).__name__} as JSON: {value!r}")


def write_json_atomic(path: str | Path, document: Any) -> Path:
    """Write ``document`` (converted by :func:`to_jsonable`) as indented JSON, atomically."""
    text = json.dumps(to_jsonable(document), indent=1, allow_nan=False)
    return write_text_atomic(path, text + "\n")


def check_output_folder(directory: str | Path, force: bool,
                        is_result: Callable[[Path], bool] | None = None) -> None:
    """Refuse to write into a folder that holds results (``is_result``; by default any entry), unless
    ``force``, which replaces files one by one and deletes nothing.

    Raises
    ------
    OutputExistsError
        If ``directory`` is a file, or holds results and not ``force``.
    """
    directory = Path(directory)
    if directory.exists() and not directory.is_dir():
        raise OutputExistsError(f"output path {str(directory)!r} exists and is not a folder; "
                                "choose another folder.")
    if force or not directory.is_dir():
        return
    existing = sorted(p.name for p in directory.iterdir() if is_result is None or is_result(p))
    if existing:
        what = "is not empty" if is_result is None else "already holds results"
        raise OutputExistsError(f"output folder {str(directory)!r} {what} ({existing[0]}); "
                                "choose another folder or pass --force to overwrite.")


def check_output_file(path: str | Path, force: bool, inputs: Iterable[str | Path] = (),
                      is_result: Callable[[Path], bool] | None = None,
                      option: str = "--out") -> None:
    """Check, before any computation, that ``path`` can take an output file.

    Earlier results (``is_result``; none by default) are overwritten, other files only with
    ``force``, ``inputs`` never; ``option`` is named in messages.

    Raises
    ------
    OutputExistsError
        ``path`` is a folder, an input, an existing non-result file without ``force``, or lies where
        nothing can be written.
    """
    path = Path(path)
    if path.is_dir():
        raise OutputExistsError(f"{option} {str(path)!r} is a folder; give a file name, e.g. "
                                f"{str(path / 'result.json')!r}.")
    target = path.resolve()
    for source in inputs:
        if Path(source).resolve() == target:
            raise OutputExistsError(f"{option} {str(path)!r} is one of the input files; give "
                                    "another file name.")
    if path.exists() and not force and not (is_result is not None and is_result(path)):
        raise OutputExistsError(f"{option} {str(path)!r} exists and is not an earlier result; "
                                "give another file name or pass --force to overwrite it.")
    folder = next(p for p in target.parents if p.exists())
    if not folder.is_dir() or not os.access(folder, os.W_OK):
        raise OutputExistsError(f"{option} {str(path)!r}: {str(folder)!r} is not a writable "
                                "folder; give another file name.")


def read_toml(path: str | Path, what: str) -> dict[str, Any]:
    """The parsed TOML file ``path`` (UTF-8, a byte-order mark allowed); ``what`` names it in messages.

    Raises
    ------
    ConfigError
        Naming the file and the line of the first non-UTF-8 byte, with the fix, or the line and
        column of a TOML syntax error.
    """
    data = Path(path).read_bytes()
    try:
        text = data.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        line = data[:exc.start].count(b"\n") + 1
        raise ConfigError(f"{what} {path}: not UTF-8 (byte 0x{data[exc.start]:02x} on line "
                          f"{line}); TOML files are UTF-8: re-save it as UTF-8.") from None
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:  # the message ends "(at line L, column C)"
        raise ConfigError(f"{what} {path} is not valid TOML: {exc}.") from None


__all__ = ["check_output_file", "check_output_folder", "read_toml", "to_jsonable",
           "write_bytes_atomic", "write_json_atomic", "write_text_atomic"]
