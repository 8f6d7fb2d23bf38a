"""``meta.json`` (and ``truth.json``) beside the data files: the platform the data come from
and the nominal Mt, Bt they should give.

``stewartid simulate`` writes ``meta.json`` with the whole platform description under
``"platform"`` and the plant's nominal matrices; a hand-written one may name a preset or a
TOML file instead. A file that cannot be read as JSON is skipped.
"""

from __future__ import annotations

import json
import warnings
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from stewartid.errors import ConfigError
from stewartid.platform import Platform, load_platform, platform_from_mapping


def _documents(files: Sequence[Path], names: Sequence[str]):
    """(path, JSON document) of every readable file named ``names`` beside ``files``, folder by
    folder in the order of ``files``."""
    for folder in dict.fromkeys(f.parent for f in files):
        for name in names:
            path = folder / name
            if not path.is_file():
                continue
            try:
                document = json.loads(path.read_text())
            except (OSError, ValueError):
                continue
            yield path, document


def platform_from_meta(files: Sequence[Path]) -> tuple[Platform, Path] | None:
    """The platform description that a ``meta.json`` beside the data names, if any.

    ``stewartid simulate`` writes the whole description under ``"platform"``; a hand-written
    ``meta.json`` may name a preset or a TOML file instead (``{"platform": "paper"}`` or
    ``{"platform": "hexapod.toml"}``, relative to the ``meta.json``).

    Returns
    -------
    (Platform, Path) or None
        The description and the ``meta.json`` that names it.

    Raises
    ------
    ConfigError
        The data folders name different platforms, or a named description is invalid.
    """
    found = []
    for path, document in _documents(files, ("meta.json",)):
        named = document.get("platform") if isinstance(document, dict) else None
        if isinstance(named, dict):
            sections = {section: {k: v for k, v in table.items() if v is not None}
                        for section, table in named.items() if isinstance(table, dict)}
            name = str(document.get("platform_name", "meta"))
            found.append((platform_from_mapping(sections, name), path))
        elif isinstance(named, str):
            found.append((load_platform(named if named == "paper" else path.parent / named),
                          path))
    if len({json.dumps(p.to_dict(), sort_keys=True) for p, _ in found}) > 1:
        raise ConfigError(f"{found[0][1]} and {found[-1][1]} name different platforms; identify "
                          "one platform's data at a time, or pass --platform.")
    return found[0] if found else None


def platform_for_data(files: Sequence[Path], platform: str | Path | None) -> Platform:
    """The platform description of the data: ``platform`` (``"paper"`` or a TOML file) if
    given, else the one a ``meta.json`` beside the data names.

    When both are there, ``platform`` decides (a broken ``meta.json`` does not matter then);
    a ``meta.json`` with another geometry or inertia draws a warning. Friction may differ: it
    is what the data measure.

    Raises
    ------
    ConfigError
        Neither is there, or (without ``platform``) the ``meta.json`` files are inconsistent.
    """
    try:
        named = platform_from_meta(files)
    except ConfigError:
        if platform is None:
            raise
        named = None
    if platform is None and named is None:
        raise ConfigError("--platform is required (a platform TOML file, or 'paper' for the "
                          "preset): masses and geometry decide the result and its checks.")
    if platform is None:
        return named[0]
    description = load_platform(platform)
    if named is not None:
        differing = [f"[{section}]" for section in ("geometry", "inertia")
                     if named[0].to_dict()[section] != description.to_dict()[section]]
        if differing:
            warnings.warn(f"{named[1]} describes platform '{named[0].name}' with another "
                          f"{' and '.join(differing)} than --platform {platform}; using "
                          "--platform.", stacklevel=1)
    return description


def nominal_from_meta(files: Sequence[Path]) -> tuple[np.ndarray, np.ndarray, str] | None:
    """Nominal (Mt, Bt) from a ``meta.json`` or ``truth.json`` beside the data files.

    Accepted layouts: ``{"nominal": {"M": ..., "B": ...}}`` or ``{"Mt": ..., "Bt": ...}``.

    Returns
    -------
    (M, B, source) or None
        The matrices, shape (6, 6) each (kg, kg m, kg m^2 and N s/m, N s, N m s blocks), and
        the file they come from; None when no such file holds them.
    """
    for path, document in _documents(files, ("meta.json", "truth.json")):
        nominal: Any = document.get("nominal", document) if isinstance(document, dict) else {}
        M = nominal.get("M", nominal.get("Mt")) if isinstance(nominal, dict) else None
        B = nominal.get("B", nominal.get("Bt")) if isinstance(nominal, dict) else None
        if M is not None and B is not None:
            M, B = np.asarray(M, dtype=float), np.asarray(B, dtype=float)
            if M.shape == (6, 6) and B.shape == (6, 6):
                return M, B, str(path)
    return None


__all__ = ["nominal_from_meta", "platform_for_data", "platform_from_meta"]
