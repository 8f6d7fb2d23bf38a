"""``stewartid identify``: Mt and Bt from measured experiments by a registered method."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer


def identify(
    files: Annotated[list[Path], typer.Argument(
        metavar="FILE", help="Data files (CSV/Parquet, one experiment each) or folders of them.")],
    method: Annotated[str, typer.Option("--method", metavar="NAME",
                                        help="wavelet (Zhang 2020), fourier (Tian), ls, "
                                             "another name that 'stewartid methods' lists, or "
                                             "'all': every registered method of the comparison "
                                             "(with --report, which to trust; the physical "
                                             "model runs by name).")]
    = "wavelet",
    platform: Annotated[str | None, typer.Option(
        "--platform", metavar="NAME|FILE",
        help="'paper' for the preset, or a platform TOML file; required unless "
                           "a meta.json beside the data names the platform.")] = None,
    out: Annotated[Path | None, typer.Option("--out", metavar="FILE", help="Write the result as JSON.")]
    = None,
    force: Annotated[bool, typer.Option(
        "--force", help="Overwrite an existing --out file that is not an earlier result.")]
    = False,
    columns: Annotated[str | None, typer.Option(
        "--columns", metavar="MAPPING", help="Column mapping of the logs with units: a TOML file or entries "
                          "such as 't=Time:ms,l1..l6=Leg{k}:mm' (docs/logs.md).")] = None,
    no_gravity: Annotated[bool, typer.Option(
        "--no-gravity", help="Do not subtract the model's gravity term G(q).")] = False,
    no_remainder: Annotated[bool, typer.Option(
        "--no-remainder", help="Do not subtract the model's departure from its linearisation "
                               "along the motion (the matrices then average M(q) over the "
                               "poses reached).")] = False,
    symmetric: Annotated[bool, typer.Option(
        "--symmetric", help="Impose symmetric Mt and Bt.")] = False,
    frequency: Annotated[list[float] | None, typer.Option(
        "--frequency", metavar="HZ", help="Excitation frequency (Hz) for --method fourier; repeat for "
                            "several. Detected from the data by default.")] = None,
    stiffness: Annotated[bool, typer.Option(
        "--stiffness", help="fourier: identify a stiffness matrix too (needs >= 2 "
                            "frequencies).")] = False,
    friction: Annotated[str | None, typer.Option(
        "--friction", metavar="NAME",
        help="wavelet: the interval constants: 'auto' (default: 'free' for one "
                           "sine per experiment, else 'coulomb'), 'free' (immune to the "
                           "friction law), 'coulomb' (windows across reversals, Coulomb level "
                           "per joint type), 'shared' (Coulomb level per joint type), 'uniform' "
                           "(one level for every joint axis; what 'stewartid design' "
                           "predicts for).")] = None,
    report: Annotated[Path | None, typer.Option(
        "--report", metavar="DIR", help="Write a report into this folder: data, intervals, matrices with "
                         "standard errors, residuals, validation on held-out data, "
                         "consistency, friction, CSV and MATLAB exports, result.json.")] = None,
    consistent: Annotated[bool, typer.Option(
        "--consistent", help="Replace Mt, Bt by the nearest symmetric pair with Mt positive "
                             "definite and Bt positive semidefinite; with --model physical, "
                             "the physically consistent parameters (pseudo-inertia positive "
                             "semidefinite, friction nonnegative). Needs the 'convex' "
                             "extra.")] = False,
    jobs: Annotated[int | None, typer.Option(
        "--jobs", metavar="N", help="Worker processes: the methods fitted side by side with "
        "--report, the experiments prepared side by side by Method B and least squares, and "
        "Method B's friction models solved side by side (default: every core, where workers "
        "start by fork); the results do not depend on it.")] = None,
    folds: Annotated[int | None, typer.Option(
        "--folds", metavar="N", help="--report: time segments per experiment for the validation "
                        "(default 3).")] = None,
    delay: Annotated[str | None, typer.Option(
        "--delay", metavar="SECONDS|auto",
        help="Delay of the force channels behind the motion, in seconds (0.002 for 2 ms; "
             "negative when the forces lead; 0: as logged): every method works on the forces "
             "aligned by it. By default it is estimated where the motion tells it from damping "
             "(two or more frequencies per DOF) and applied when beyond three standard errors "
             "of zero; 'auto' estimates and applies it, and refuses one-frequency motion "
             "(docs/logs.md).")] = None,
    average: Annotated[bool, typer.Option(
        "--average", help="Average records sampled well above what the fits need (2 kHz and "
                          "more) over blocks of samples first, down to no less than 1 kHz and "
                          "400 samples per period of the fastest excitation: about a 1 kHz "
                          "log's cost. The paper platform's logs keep their estimates within "
                          "0.15 standard errors; an electric platform's may move further "
                          "(docs/user-guide.md).")] = False,
    validate: Annotated[list[Path] | None, typer.Option(
        "--validate", metavar="FILE",
        help="--report: a record of another excitation (e.g. the validation record of "
             "'stewartid design'), not fitted: every method predicts it and the verdict "
             "judges the methods by it. Repeat for several.")] = None,
    model: Annotated[str | None, typer.Option(
        "--model", metavar="NAME",
        help="'physical': identify the physical parameters of the rigid-body model (masses, "
             "first moments, inertias, friction per joint type, sensor offsets) and Mt, Bt "
             "from them (docs/physical-model.md); with --report, beside every compared "
             "method.")] = None,
    payload: Annotated[bool, typer.Option(
        "--payload", help="--model physical: identify only the payload on the platform "
                          "file's known platform.")] = False,
    platform_out: Annotated[Path | None, typer.Option(
        "--platform-out", metavar="FILE",
        help="--model physical: write the identified platform description (TOML).")] = None,
) -> None:
    """Identify Mt and Bt from experiments; print the paper-style table when nominal values are
    known (platform description, or meta.json/truth.json beside the data) and write JSON."""
    import numpy as np

    from stewartid.cli.identify_run import FlagSetting, identify_files, model_method
    from stewartid.reports.terminal import print_comparison

    flags = {"--no-gravity": FlagSetting("gravity", not no_gravity, no_gravity),
             "--no-remainder": FlagSetting("remainder", not no_remainder, no_remainder),
             "--symmetric": FlagSetting("symmetric", symmetric, symmetric),
             "--frequency": FlagSetting("frequency_hz", frequency or None, bool(frequency)),
             "--stiffness": FlagSetting("stiffness", stiffness, stiffness),
             "--friction": FlagSetting("friction", friction, friction is not None)}
    method = model_method(model, method, payload, platform_out)
    found = identify_files(files, method, platform, flags=flags, columns=columns, out=out,
                           force=force, report=report, consistent=consistent, folds=folds,
                           delay=delay, validate=validate or (), model=model,
                           payload=payload, platform_out=platform_out, jobs=jobs,
                           average=average)
    if found.averaging is not None:
        from stewartid.identification.averaging import describe_averaging

        typer.echo(describe_averaging(found.averaging))
    if found.delay is not None:
        entry = found.delay
        if entry["source"] == "given":
            typer.echo(f"force delay {entry['seconds'] * 1e3:.3f} ms, given; forces aligned")
        elif entry["seconds"] is None:
            typer.echo(f"force delay not estimated: {entry.get('reason', '')}")
        else:
            typer.echo(f"force delay {entry['seconds'] * 1e3:.3f} ms (standard error "
                       f"{entry['std_error'] * 1e3:.3f} ms), estimated; "
                       + ("forces aligned" if entry["applied"] else
                          "within noise of zero, forces used as logged"))
    if found.delay_sensitivity is not None:
        from stewartid.comparison import delay_note

        typer.echo(f"note: {delay_note(found.delay_sensitivity)}")
    if found.report is not None:
        typer.echo(f"wrote the report to {report}/report.html; trusted: {found.report.trusted}")
    rows = found.comparison()
    print_comparison(rows, f"{method}: identified vs nominal ({found.nominal_source})")
    largest = np.nanmax([row["error_percent"] for row in rows])
    typer.echo(f"condition number {found.result.condition_number:.3g}; largest error "
               f"{largest:.2f} % ({found.experiments} experiments)")
    if out is not None:
        typer.echo(f"wrote {out}")
