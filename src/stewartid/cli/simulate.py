"""``stewartid simulate``: the paper's six virtual experiments written to a folder."""

from __future__ import annotations

import os
from pathlib import Path
from typing import Annotated

import typer

from stewartid.files import check_output_folder
from stewartid.platform import load_platform


def simulate(
    out: Annotated[Path, typer.Option("--out", help="Output folder for exp1..exp6 and "
                                      "meta.json.")],
    platform: Annotated[str, typer.Option("--platform", help="'paper' for the preset, or a "
                                          "platform TOML file.")] = "paper",
    coulomb: Annotated[float | None, typer.Option("--coulomb", help="Coulomb friction per "
                                                  "joint axis (N m); default: the platform's.")
                       ] = None,
    viscous: Annotated[float | None, typer.Option("--viscous", help="Viscous friction per "
                                                  "gimbal axis (N m s/rad).")] = None,
    frequency: Annotated[float, typer.Option("--frequency", help="Excitation sine frequency "
                                             "(Hz).")] = 0.5,
    duration: Annotated[float, typer.Option("--duration", help="Record length of each "
                                            "experiment (s).")] = 20.0,
    noise_on: Annotated[bool, typer.Option(
        "--noise", help="Switch on the reference sensor noise: 20 um on the leg lengths and "
        "0.5 % of the static leg force on the forces (--length-noise/--force-noise override "
        "either).")] = False,
    length_noise: Annotated[float | None, typer.Option(
        "--length-noise", help="Leg-length sensor noise, standard deviation (m); default: "
        "[sensors] length_noise.")] = None,
    force_noise: Annotated[float | None, typer.Option(
        "--force-noise", help="Force sensor noise, standard deviation (N); default: "
        "[sensors] force_noise.")] = None,
    actuator: Annotated[str | None, typer.Option(
        "--actuator", help="'hydraulic' or 'ideal'; default: [hydraulics] mode.")] = None,
    seed: Annotated[int, typer.Option("--seed", help="Seed of the sensor noise.")] = 0,
    format: Annotated[str, typer.Option("--format", help="'csv' or 'parquet'.")] = "csv",
    force: Annotated[bool, typer.Option("--force", help="Overwrite results already in "
                                        "--out.")] = False,
    excitation: Annotated[list[Path] | None, typer.Option(
        "--excitation", help="Play this excitation file instead of the paper's sines: CSV "
        "with t and the pose x..rz (m, rad) or t and l1..l6 (m), e.g. a command file of "
        "`stewartid design`; repeat for more experiments (exp1, exp2, ...).")] = None,
    jobs: Annotated[int | None, typer.Option(
        "--jobs", help="Worker processes for the paper's experiments (default: every core); "
        "the data do not depend on it.")] = None,
) -> None:
    """Simulate the six experiments (experiment k excites DOF k) on the hydraulic plant."""
    # simulation, design and rich.progress load in 0.4-0.5 s; every command's module is
    # imported when the command line starts, so they are imported when this one runs
    from rich.progress import Progress

    from stewartid.fields import Options, check, nonnegative, positive
    from stewartid.simulation import simulate_experiments, write_experiments
    from stewartid.simulation.experiments import is_experiment_file
    from stewartid.simulation.sensors import sensor_noise

    description = load_platform(platform)
    check("--format", format, [Options(("csv", "parquet"))])
    # before the simulation, which takes a while; write_experiments checks again
    check_output_folder(out, force, is_experiment_file)
    for flag, value, constraint, unit in (
            ("--coulomb", coulomb, nonnegative(), "N m"),
            ("--viscous", viscous, nonnegative(), "N m s/rad"),
            ("--length-noise", length_noise, nonnegative(), "m"),
            ("--force-noise", force_noise, nonnegative(), "N"),
            ("--duration", duration, positive(), "s")):
        if value is not None:  # an optional flag not given
            check(flag, value, [constraint], unit)
    noise = sensor_noise(description, "always" if noise_on else "never", length_noise,
                         force_noise)
    with Progress(transient=True) as bar:
        task = bar.add_task("simulating", total=len(excitation) if excitation else 6)

        def progress(done: int, total: int, name: str) -> None:
            bar.update(task, completed=done, description=f"simulated {name}")

        if excitation:
            from stewartid.design.export import read_excitation, simulate_excitations  # as above

            overrides = {key: value for key, value in (
                ("friction__coulomb", coulomb), ("friction__gimbal_viscous", viscous),
                ("hydraulics__mode", actuator)) if value is not None}
            description = description.replace(**overrides) if overrides else description
            result = simulate_excitations(
                description, [read_excitation(path, description) for path in excitation],
                noise, seed, progress)
        else:
            result = simulate_experiments(description, coulomb=coulomb, viscous=viscous,
                                          frequency_hz=frequency, duration_s=duration,
                                          noise=noise, seed=seed, actuator=actuator,
                                          progress=progress,
                                          jobs=(os.cpu_count() or 1) if jobs is None else jobs)
    paths = write_experiments(result, out, format=format, force=force)
    typer.echo(f"wrote {len(paths) - 1} experiments and meta.json to {out}")
