"""``meta.json`` (and ``truth.json``) beside the data: the platform the data come from and the
nominal Mt, Bt; unreadable JSON is skipped.
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
    """(path, document) of every readable ``names`` file beside ``files``, folder by folder."""
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
    """The description a ``meta.json`` beside the data names, and that file; None without.

    Under ``"platform"``: the whole description, a preset or a TOML path relative to the file.

    Raises
    ------
    ConfigError
        Folders name different platforms, or a named description is invalid.
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
    """The data's platform: ``platform`` (preset or TOML) if given, else the ``meta.json``'s.
    With both, ``platform`` decides and differing geometry or inertia warns (friction may differ).

    Raises
    ------
    ConfigError
        Neither given, or inconsistent ``meta.json`` files.
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
    """Nominal (M, B, source file) from a ``meta.json`` or ``truth.json`` beside the data, or None.

    Layouts: ``{"nominal": {"M": ..., "B": ...}}`` or ``{"Mt": ..., "Bt": ...}``.
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
