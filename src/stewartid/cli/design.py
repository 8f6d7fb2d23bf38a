"""``stewartid design``: an excitation within the machine's limits, its predicted accuracy
and the command files to play it."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from stewartid.identification.registry import registered_methods
from stewartid.platform import load_platform


def design(
    out: Annotated[Path, typer.Option("--out", metavar="DIR", help="Output folder: design.json, commands/, "
                                      "figures/, report.md, report.html.")],
    budget: Annotated[float, typer.Option("--budget", metavar="SECONDS",
                                          help="Total motion time (s).")] = 120.0,
    platform: Annotated[str, typer.Option("--platform", metavar="NAME|FILE",
                                          help="'paper' for the preset, or a "
                                          "platform TOML file (with its [limits]).")] = "paper",
    method: Annotated[str, typer.Option("--method", metavar="NAME", help="Identification method the design "
                                        "is for.")] = "wavelet",
    coulomb: Annotated[float | None, typer.Option(
        "--coulomb", metavar="TORQUE", help="Coulomb friction per joint axis the machine is expected to have "
        "(N m); default: the platform's.")] = None,
    length_noise: Annotated[float | None, typer.Option(
        "--length-noise", metavar="METRES",
        help="Leg-length noise, standard deviation (m); default: [sensors] "
        "length_noise, or the reference 20 um when that is 0.")] = None,
    force_noise: Annotated[float | None, typer.Option(
        "--force-noise", metavar="NEWTONS", help="Force noise, standard deviation (N); default: [sensors] "
        "force_noise, or the reference 0.5 % of the static leg force when that is 0.")] = None,
    rate: Annotated[float, typer.Option("--rate", metavar="HZ", help="Controller rate of the command files "
                                        "(Hz).")] = 500.0,
    max_use: Annotated[float, typer.Option("--max-use", metavar="FRACTION",
                                           help="Largest fraction of every limit "
                                           "the design may use on the plant's simulated "
                                           "states.")] = 0.7,
    seeds: Annotated[int | None, typer.Option(
        "--seeds", metavar="N", help="Noise realisations of the Monte Carlo that checks the "
        "chosen design's predicted accuracy (its bias, and its spread beside the information "
        "matrix's standard errors), >= 2 (default 8); for a --method without an "
        "information-matrix prediction, of the prediction itself (default 120); with "
        "--model physical, the noisy copies of the played design the prediction is checked "
        "on, >= 0 (default 2).")] = None,
    workers: Annotated[int | None, typer.Option(
        "--workers", metavar="N", help="Processes the predictions are spread over (default: every "
        "available core).")] = None,
    model_data: Annotated[bool, typer.Option(
        "--model-data", help="Predict on rigid-body model data with perfect tracking (fast, "
        "optimistic) instead of the design played on the plant.")] = False,
    quick: Annotated[bool, typer.Option("--quick", help="One candidate and few realisations "
                                        "(a smoke test).")] = False,
    force: Annotated[bool, typer.Option("--force", help="Overwrite a design already in "
                                        "--out.")] = False,
    model: Annotated[str | None, typer.Option(
        "--model", metavar="NAME", help="'physical': records that move every DOF at once across "
        "the workspace, for the physical model (masses, first moments, inertias), chosen by "
        "the information matrix; --method, --model-data and --quick do not apply.")] = None,
    payload: Annotated[bool, typer.Option(
        "--payload", help="--model physical: design for payload mode (the payload's ten "
        "parameters; the platform file's [payload] is the expected one).")] = False,
    accuracy: Annotated[str | None, typer.Option(
        "--accuracy", metavar="ACCURACY", help="--payload: MASS,COM,INERTIA, the accuracy "
        "the payload's mass (%), centre of mass (mm, a distance) and inertia about it (% of "
        "its mean diagonal) are needed to; the design holds each within it in 95 % of runs "
        "and sharpens the ten parameters there. Default 0.2,2,2.")] = None,
) -> None:
    """Design an excitation for identification: records within the platform's [limits],
    chosen so that the predicted error of every Mt and Bt entry (|bias| + 2 standard errors)
    is smallest against the accuracy its group needs (Mt diagonal 0.5 %, Bt diagonal 2 %,
    couplings 8 %), written as command files (pose and leg lengths) with a report against
    the paper's set."""
    # imported when this command runs: every command's module is imported at start-up
    from numbers import Real

    from rich.progress import Progress

    from stewartid.design.report import identify_command
    from stewartid.design.workflow import run_design
    from stewartid.fields import Interval, Options, check, nonnegative, positive
    from stewartid.simulation.sensors import sensor_noise

    description = load_platform(platform)
    physical = model is not None
    # typer has parsed the types: integer flags are checked on their range (Real)
    for flag, value, constraint, unit in (
            ("--model", model, Options(("physical",)), ""),
            ("--method", method, Options(tuple(m.name for m in registered_methods())), ""),
            ("--budget", budget, positive(), "s"),
            ("--rate", rate, positive(), "Hz"),
            ("--max-use", max_use, Interval(Real, 0, 1, closed="right"), ""),
            # a spread needs two realisations; the physical check none
            ("--seeds", seeds, Interval(Real, 0 if physical else 2, None), ""),
            ("--workers", workers, Interval(Real, 1, None), ""),
            ("--coulomb", coulomb, nonnegative(), "N m"),
            ("--length-noise", length_noise, nonnegative(), "m"),
            ("--force-noise", force_noise, nonnegative(), "N")):
        if value is not None:  # an optional flag not given
            check(flag, value, [constraint], unit)
    if coulomb is not None:
        description = description.replace(friction__coulomb=coulomb)
    noise = sensor_noise(description, "where_zero", length_noise, force_noise)
    if physical or payload or accuracy is not None:
        _design_physical(description, budget, noise, out, payload, rate, max_use, seeds, force,
                         {"--model": physical, "--method": method != "wavelet",
                          "--model-data": model_data, "--quick": quick}, accuracy)
        return
    with Progress(transient=True) as bar:
        task = bar.add_task("noise realisations", total=None)

        def realisations(done: int, total: int) -> None:
            bar.update(task, completed=done, total=total,
                       description=f"noise realisations {done}/{total}")

        def say(text: str) -> None:  # above the bar, as plain text
            bar.console.print(text, markup=False, highlight=False, soft_wrap=True)

        output = run_design(description, budget, noise, out, method=method, rate_hz=rate,
                            max_use=max_use, seeds=min(seeds or 4, 4) if quick else seeds,
                            source="model" if model_data else "plant", quick=quick,
                            force=force, workers=workers, progress=say,
                            realisations=realisations)
    p, b = output.prediction, output.baseline
    typer.echo(f"design: {output.design.label}")
    typer.echo(f"predicted worst relative standard error {p.worst_relative_std:.2f} % "
               f"(paper's set {b.worst_relative_std:.2f} %, ratio "
               f"{p.worst_relative_std / b.worst_relative_std:.2f})")
    checked = p.relative_monte_carlo_std
    if checked is not None:
        ratios = sorted(p.relative_std / checked)
        typer.echo(f"Monte Carlo check ({p.seeds} noise realisations): predicted over "
                   f"observed standard error {ratios[0]:.2f}-{ratios[-1]:.2f}, median "
                   f"{ratios[len(ratios) // 2]:.2f}")
    typer.echo(f"identify its logs with: {identify_command(method)}")
    typer.echo(f"wrote {len(output.files)} files to {out}; report: {out / 'report.md'}")


def _design_physical(description, budget: float, noise, out: Path, payload: bool, rate: float,
                     max_use: float, seeds: int | None, force: bool, given: dict,
                     accuracy: str | None) -> None:
    """``design --model physical``: run it and print its summary."""
    from rich.console import Console

    from stewartid.design.physical.payload_accuracy import parse_accuracy
    from stewartid.design.physical.workflow import criterion_summary, run_physical_design
    from stewartid.errors import ConfigError

    if not given.pop("--model"):
        raise ConfigError(f"{'--payload' if payload else '--accuracy'} needs --model physical.")
    if accuracy is not None and not payload:
        raise ConfigError("--accuracy applies to payload mode: add --payload (full mode "
                          "judges the moving body's parameters by their relative errors).")
    needed = None if accuracy is None else parse_accuracy(accuracy)
    wrong = [flag for flag, value in given.items() if value]
    if wrong:
        raise ConfigError(f"{', '.join(wrong)} do not apply to --model physical; leave "
                          f"{'them' if len(wrong) > 1 else 'it'} out.")
    console = Console(stderr=True)
    output = run_physical_design(
        description, budget, noise, out, payload=payload, rate_hz=rate, max_use=max_use,
        check_seeds=2 if seeds is None else seeds, force=force, accuracy=needed,
        progress=lambda text: console.print(text, markup=False, highlight=False))
    p, b = output.prediction, output.baseline
    typer.echo(f"design: {output.design.label}")
    typer.echo(criterion_summary(p, b))
    if output.check["seeds"]:
        typer.echo(f"check on {output.check['seeds']} noisy copies: predicted / fitted standard "
                   f"error, median {output.check['ratio_median']:.2f}")
    typer.echo(f"play it with: {output.commands['play']}")
    typer.echo(f"identify its logs with: {output.commands['identify']}")
    typer.echo(f"wrote {len(output.files)} files to {out}; report: {out / 'report.md'}")
