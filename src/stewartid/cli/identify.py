"""``stewartid identify``: Mt and Bt from measured experiments by a registered method."""

from __future__ import annotations

import json
import warnings
from pathlib import Path
from typing import Annotated

import typer

from stewartid.errors import ConfigError

#: Suffixes of data and description files, which a JSON result must not be named like.
INPUT_SUFFIXES = (".csv", ".parquet", ".pq", ".toml")


def platform_from_meta(files: list[Path]):
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
    from stewartid.platform import load_platform, platform_from_mapping

    found = []
    for folder in dict.fromkeys(f.parent for f in files):
        path = folder / "meta.json"
        try:
            document = json.loads(path.read_text()) if path.is_file() else {}
        except (OSError, ValueError):
            continue
        named = document.get("platform") if isinstance(document, dict) else None
        if isinstance(named, dict):
            sections = {section: {k: v for k, v in table.items() if v is not None}
                        for section, table in named.items() if isinstance(table, dict)}
            name = str(document.get("platform_name", "meta"))
            found.append((platform_from_mapping(sections, name), path))
        elif isinstance(named, str):
            found.append((load_platform(named if named == "paper" else folder / named), path))
    if len({json.dumps(p.to_dict(), sort_keys=True) for p, _ in found}) > 1:
        raise ConfigError(f"{found[0][1]} and {found[-1][1]} name different platforms; identify "
                          "one platform's data at a time, or pass --platform.")
    return found[0] if found else None


def _is_result(path: Path) -> bool:
    """True for a JSON file that ``identify --out`` wrote (overwritten without --force)."""
    try:
        document = json.loads(path.read_text())
    except (OSError, ValueError):
        return False
    return isinstance(document, dict) and {"M", "B", "method"} <= set(document)


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
    platform: Annotated[str | None, typer.Option(
        "--platform", help="'paper' for the preset, or a platform TOML file; required unless "
                           "a meta.json beside the data names the platform.")] = None,
    out: Annotated[Path | None, typer.Option("--out", help="Write the result as JSON.")]
    = None,
    force: Annotated[bool, typer.Option(
        "--force", help="Overwrite an existing --out file that is not an earlier result.")]
    = False,
    columns: Annotated[str | None, typer.Option(
        "--columns", help="Column mapping of the logs with units: a TOML file or entries "
                          "such as 't=Time:ms,l1..l6=Leg{k}:mm' (docs/logs.md).")] = None,
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
    friction: Annotated[str | None, typer.Option(
        "--friction", help="wavelet: the interval constants: 'free' (default; immune to the "
                           "friction law), 'shared' (Coulomb level per joint type), 'uniform' "
                           "(one level for every joint axis; what 'stewartid design' "
                           "predicts for).")] = None,
    report: Annotated[Path | None, typer.Option(
        "--report", help="Write a report into this folder: data, intervals, matrices with "
                         "standard errors, residuals, validation on held-out data, "
                         "consistency, friction, CSV and MATLAB exports, result.json.")] = None,
    consistent: Annotated[bool, typer.Option(
        "--consistent", help="Replace Mt, Bt by the nearest symmetric pair with Mt positive "
                             "definite and Bt positive semidefinite (needs the 'convex' "
                             "extra).")] = False,
    folds: Annotated[int | None, typer.Option(
        "--folds", help="--report: time segments per experiment for the validation "
                        "(default 3).")] = None,
) -> None:
    """Identify Mt and Bt from experiments; print the paper-style table when nominal values are
    known (platform description, or meta.json/truth.json beside the data) and write JSON."""
    import numpy as np

    from stewartid.datasets.dataset import expand_paths, read_datasets
    from stewartid.datasets.log_format import load_log_format
    from stewartid.datasets.plausibility import check_identified
    from stewartid.files import check_output_file
    from stewartid.identification.registry import create_identifier, method_spec
    from stewartid.identification.result import comparison_rows
    from stewartid.model.linearization import nominal_matrices
    from stewartid.platform import load_platform
    from stewartid.reporting.terminal import print_comparison
    from stewartid.reports.identification.report import methods_for

    names = methods_for(method)
    accepted = {name for each in names
                for name in method_spec(each).estimator_class.param_names()}
    options = {"--no-gravity": ("gravity", not no_gravity, no_gravity),
               "--symmetric": ("symmetric", symmetric, symmetric),
               "--frequency": ("frequency_hz", frequency or None, bool(frequency)),
               "--stiffness": ("stiffness", stiffness, stiffness),
               "--friction": ("friction", friction, friction is not None)}
    settings = {}
    for flag, (name, value, given) in options.items():
        if name in accepted and (given or name != "friction"):
            settings[name] = value
        elif given:
            raise ConfigError(f"{flag} does not apply to --method {method}; it has the "
                              f"settings {', '.join(accepted)}.")
    paths = expand_paths(files)
    try:
        named = platform_from_meta(paths)
    except ConfigError:
        if platform is None:
            raise
        named = None  # --platform decides; a broken meta.json does not matter then
    if platform is None and named is None:
        raise ConfigError("--platform is required (a platform TOML file, or 'paper' for the "
                          "preset): masses and geometry decide the result and its checks.")
    description = load_platform(platform) if platform is not None else named[0]
    if platform is not None and named is not None:
        # friction is what the data measure; geometry and inertia must be the platform's
        differing = [f"[{section}]" for section in ("geometry", "inertia")
                     if named[0].to_dict()[section] != description.to_dict()[section]]
        if differing:
            warnings.warn(f"{named[1]} describes platform '{named[0].name}' with another "
                          f"{' and '.join(differing)} than --platform {platform}; using "
                          "--platform.", stacklevel=1)
    if out is not None:
        inputs = [*paths, *(p for p in (platform, columns) if p and Path(p).is_file())]
        check_output_file(out, force, inputs, is_result=_is_result)
        if out.suffix.lower() in INPUT_SUFFIXES:
            raise ConfigError(f"--out {str(out)!r}: the result is JSON; give a .json file name.")
    if report is not None:
        from stewartid.files import check_output_folder

        inside = [p for p in paths if report.resolve() in p.resolve().parents]
        if inside:
            raise ConfigError(f"--report {str(report)!r} holds the input {str(inside[0])!r}; "
                              "choose another folder for the report.")
        check_output_folder(report, force)
    elif len(names) > 1:
        raise ConfigError(f"--method {method} compares the methods in a report; add "
                          "--report DIR.")
    elif folds is not None:
        raise ConfigError("--folds sets the report's validation; add --report DIR.")
    folds = 3 if folds is None else folds
    log_format = load_log_format(columns) if columns is not None else None
    datasets = read_datasets(paths, description, log_format)
    if report is not None or consistent or len(names) > 1:
        from stewartid.reports.identification.report import identify_for_command

        result, written = identify_for_command(
            datasets, description, method, settings, report, consistent, folds,
            nominal_from_meta(paths), [str(p) for p in paths],
            check=lambda found: check_identified(found.M, found.B, description))
        if written is not None:
            typer.echo(f"wrote the report to {report}/report.html; trusted: {written.trusted}")
    else:
        result = create_identifier(method, **settings).fit(datasets, description).result_
    check_identified(result.M, result.B, description)

    meta = nominal_from_meta(paths)
    if meta is not None:
        M_nom, B_nom, source = meta
    else:
        M_nom, B_nom = nominal_matrices(description)
        source = f"platform '{description.name}' at neutral"
    rows = comparison_rows(result.M, result.B, M_nom, B_nom, result.std_errors_M,
                           result.std_errors_B)
    print_comparison(rows, f"{method}: identified vs nominal ({source})")
    largest = np.nanmax([row["error_percent"] for row in rows])
    typer.echo(f"condition number {result.condition_number:.3g}; largest error "
               f"{largest:.2f} % ({len(datasets)} experiments)")
    if out is not None:
        result.to_json(out)
        typer.echo(f"wrote {out}")
