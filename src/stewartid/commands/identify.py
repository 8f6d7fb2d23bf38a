"""``stewartid identify``: Mt and Bt from measured experiments by one of three methods."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Annotated

import typer

METHODS = {
    "wavelet": ("stewartid.identification.wavelet", "WaveletIdentifier"),
    "fourier": ("stewartid.identification.fourier", "FourierIdentifier"),
    "ls": ("stewartid.identification.least_squares", "LeastSquaresIdentifier"),
}


def make_identifier(method: str, **settings):
    """The identifier class of ``method`` built with ``settings`` (imported lazily)."""
    import importlib

    from stewartid.errors import ConfigError

    if method not in METHODS:
        raise ConfigError(f"unknown method {method!r}; expected one of {', '.join(METHODS)}.")
    module, name = METHODS[method]
    try:
        cls = getattr(importlib.import_module(module), name)
    except (ModuleNotFoundError, AttributeError) as exc:
        raise ConfigError(f"method {method!r} is not available in this installation ({exc}); "
                          f"use one of {', '.join(m for m in METHODS if m != method)}.") from exc
    return cls(**settings)


def nominal_from_meta(files: list[Path]):
    """Nominal (Mt, Bt) from a ``meta.json`` or ``truth.json`` beside the data files.

    Accepted layouts: ``{"nominal": {"M": ..., "B": ...}}`` or ``{"Mt": ..., "Bt": ...}``.
    Returns None when no such file holds them.
    """
    import numpy as np

    for folder in dict.fromkeys(f.parent for f in files):
        for name in ("meta.json", "truth.json"):
            path = folder / name
            if not path.is_file():
                continue
            try:
                document = json.loads(path.read_text())
            except (OSError, ValueError):
                continue
            nominal = document.get("nominal", document) if isinstance(document, dict) else {}
            M = nominal.get("M", nominal.get("Mt")) if isinstance(nominal, dict) else None
            B = nominal.get("B", nominal.get("Bt")) if isinstance(nominal, dict) else None
            if M is not None and B is not None:
                M, B = np.asarray(M, dtype=float), np.asarray(B, dtype=float)
                if M.shape == (6, 6) and B.shape == (6, 6):
                    return M, B, str(path)
    return None


def identify(
    files: Annotated[list[Path], typer.Argument(
        help="Data files (CSV/Parquet, one experiment each) or folders of them.")],
    method: Annotated[str, typer.Option("--method",
                                        help="wavelet (Zhang 2020), fourier (Tian) or ls.")]
    = "wavelet",
    platform: Annotated[str, typer.Option(
        "--platform", help="'paper' for the preset, or a platform TOML file.")] = "paper",
    out: Annotated[Path | None, typer.Option("--out", help="Write the result as JSON.")]
    = None,
    no_gravity: Annotated[bool, typer.Option(
        "--no-gravity", help="Do not subtract the model's gravity term G(q).")] = False,
    symmetric: Annotated[bool, typer.Option(
        "--symmetric", help="Impose symmetric Mt and Bt.")] = False,
    frequency: Annotated[list[float] | None, typer.Option(
        "--frequency", help="Excitation frequency (Hz) for --method fourier; repeat for "
                            "several. Detected from the data by default.")] = None,
    stiffness: Annotated[bool, typer.Option(
        "--stiffness", help="fourier: identify a stiffness matrix too (needs >= 2 "
                            "frequencies).")] = False,
) -> None:
    """Identify Mt and Bt from experiments; print the paper-style table when nominal values are
    known (platform description, or meta.json/truth.json beside the data) and write JSON."""
    import numpy as np

    from stewartid.dataset import expand_paths, read_datasets
    from stewartid.errors import ConfigError
    from stewartid.linearization import nominal_matrices
    from stewartid.platform import load_platform

    description = load_platform(platform)
    paths = expand_paths(files)
    datasets = read_datasets(paths, description)
    settings: dict = {}
    if method in ("fourier", "ls", "wavelet"):
        settings["gravity"] = not no_gravity
        settings["symmetric"] = symmetric
    if frequency or stiffness:
        if method != "fourier":
            raise ConfigError("--frequency and --stiffness apply to --method fourier only.")
        if frequency:
            settings["frequency_hz"] = frequency
        settings["stiffness"] = stiffness
    estimator = make_identifier(method, **settings)
    try:
        estimator.fit(datasets, description)
    except TypeError as exc:  # a method without some setting
        raise ConfigError(f"--method {method} does not accept these options: {exc}") from exc
    result = estimator.result_

    meta = nominal_from_meta(paths)
    if meta is not None:
        M_nom, B_nom, source = meta
    else:
        M_nom, B_nom = nominal_matrices(description)
        source = f"platform '{description.name}' at neutral"
    table = result.comparison_table(M_nom, B_nom)
    _print_table(table, f"{method}: identified vs nominal ({source})")
    typer.echo(f"condition number {result.condition_number:.3g}; largest error "
               f"{np.nanmax(table['error_percent']):.2f} % ({len(datasets)} experiments)")
    if out is not None:
        result.to_json(out)
        typer.echo(f"wrote {out}")


def _print_table(table, title: str) -> None:
    from rich.console import Console
    from rich.table import Table

    view = Table(title=title, title_justify="left")
    for column, justify in (("entry", "left"), ("identified", "right"), ("± std", "right"),
                            ("nominal", "right"), ("ε (%)", "right")):
        view.add_column(column, justify=justify)
    for row in table.itertuples():
        view.add_row(row.entry, f"{row.identified:,.1f}", f"{row.std_error:,.2g}",
                     f"{row.nominal:,.1f}", f"{row.error_percent:.2f}")
    Console().print(view)
