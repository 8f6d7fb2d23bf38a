"""The experiments of one identification read from their files."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

from stewartid.datasets.dataset import Dataset, expand_paths, read_datasets
from stewartid.datasets.log_format import LogFormat, load_log_format
from stewartid.datasets.meta import platform_for_data
from stewartid.datasets.plausibility import CARRIED_WEIGHT, PHYSICAL_CARRIED_WEIGHT
from stewartid.platform import Platform


def read_experiments(paths: str | Path | Sequence[str | Path],
                     platform: Platform | str | Path | None = None,
                     columns: LogFormat | str | Path | None = None,
                     payload_unknown: bool = False) -> list[Dataset]:
    """Read logged experiments, checked against their platform description.

    Parameters
    ----------
    paths : str, Path or sequence of them
        Data files (CSV or Parquet, one experiment each) or folders of them.
    platform : Platform, ``"paper"``, a TOML file, optional
        The hexapod the logs come from; by default the one a ``meta.json`` beside the data
        names.
    columns : LogFormat, TOML file or mapping string, optional
        The layout and units of a controller's own log (docs/logs.md); the interchange format
        by default.
    payload_unknown : bool
        The logs are to identify the payload (``identify --model physical``): the forces may
        carry half to five times the file's weight, the payload's evidence, without a warning.

    Returns
    -------
    list of Dataset
        In the order given, a folder's files sorted by name.
    """
    files = expand_paths([paths] if isinstance(paths, str | Path) else paths)
    if not isinstance(platform, Platform):
        platform = platform_for_data(files, platform)
    if columns is not None and not isinstance(columns, LogFormat):
        columns = load_log_format(columns)
    carried = PHYSICAL_CARRIED_WEIGHT if payload_unknown else CARRIED_WEIGHT
    return read_datasets(files, platform, columns, carried)
