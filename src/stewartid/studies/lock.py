"""One study run at a time per output folder: an ``fcntl.flock`` on a file in it, released when its
process dies (no stale-lock check)."""

from __future__ import annotations

import contextlib
import os
from collections.abc import Iterator
from pathlib import Path

from stewartid.errors import ConfigError

#: The lock file inside a study's output folder.
LOCK_NAME = ".study.lock"


def _holder(path: Path) -> str:
    try:
        found = path.read_text(encoding="ascii").strip()
    except (OSError, UnicodeDecodeError):
        return "another process"
    return f"process {found}" if found.isdigit() else "another process"


@contextlib.contextmanager
def study_lock(directory: str | Path) -> Iterator[Path]:
    """Hold a study folder's lock (folder created if missing) while the block runs; yields the lock file.

    Raises
    ------
    ConfigError
        Another live process, named, holds the lock.
    """
    import fcntl

    directory = Path(directory)
    directory.mkdir(parents=True, exist_ok=True)
    path = directory / LOCK_NAME
    fd = os.open(path, os.O_RDWR | os.O_CREAT, 0o644)
    try:
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            raise ConfigError(f"{directory} is being written by {_holder(path)} (another "
                              "'stewartid study' run); wait for it to finish, or give "
                              "another --out.") from None
        os.ftruncate(fd, 0)
        os.write(fd, f"{os.getpid()}\n".encode("ascii"))
        try:
            yield path
        finally:
            os.ftruncate(fd, 0)
            fcntl.flock(fd, fcntl.LOCK_UN)
    finally:
        os.close(fd)


__all__ = ["LOCK_NAME", "study_lock"]
