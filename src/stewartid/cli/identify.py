"""``stewartid identify``: Mt and Bt from measured experiments by a registered method."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Annotated

import typer

from stewartid.errors import ConfigError


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
                                        help="wavelet (Zhang 2020), fourier (Tian), ls, or "
                                             "another name that 'stewartid methods' lists.")]
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
    from stewartid.identification.registry import create_identifier, method_spec
    from stewartid.linearization import nominal_matrices
    from stewartid.platform import load_platform
    from stewartid.reporting.terminal import print_comparison

    spec = method_spec(method)
    accepted = spec.estimator_class._param_names()
    options = {"--no-gravity": ("gravity", not no_gravity, no_gravity),
               "--symmetric": ("symmetric", symmetric, symmetric),
               "--frequency": ("frequency_hz", frequency or None, bool(frequency)),
               "--stiffness": ("stiffness", stiffness, stiffness)}
    settings = {}
    for flag, (name, value, given) in options.items():
        if name in accepted:
            settings[name] = value
        elif given:
            raise ConfigError(f"{flag} does not apply to --method {method}; it has the "
                              f"settings {', '.join(accepted)}.")
    description = load_platform(platform)
    paths = expand_paths(files)
    datasets = read_datasets(paths, description)
    estimator = create_identifier(method, **settings).fit(datasets, description)
    result = estimator.result_

    meta = nominal_from_meta(paths)
    if meta is not None:
        M_nom, B_nom, source = meta
    else:
        M_nom, B_nom = nominal_matrices(description)
        source = f"platform '{description.name}' at neutral"
    table = result.comparison_table(M_nom, B_nom)
    print_comparison(table, f"{method}: identified vs nominal ({source})")
    typer.echo(f"condition number {result.condition_number:.3g}; largest error "
               f"{np.nanmax(table['error_percent']):.2f} % ({len(datasets)} experiments)")
    if out is not None:
        result.to_json(out)
        typer.echo(f"wrote {out}")
