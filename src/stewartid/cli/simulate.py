"""``stewartid simulate``: the paper's six virtual experiments written to a folder."""

from __future__ import annotations

import dataclasses
import os
from pathlib import Path
from typing import TYPE_CHECKING, Annotated, Any

import typer

from stewartid.errors import ConfigError
from stewartid.files import check_output_folder
from stewartid.platform import load_platform

if TYPE_CHECKING:
    from stewartid.platform import Platform
    from stewartid.simulation.experiments import SimulationResult
    from stewartid.simulation.sensors import SensorNoise

#: The sensor imperfections set on the command line: flag -> (SensorNoise field, help).
IMPERFECTION_FLAGS = {
    "--force-delay": ("force_delay", "Log the forces this long after the motion (s, e.g. "
                      "0.002): f(t) = true f(t - delay), interpolated between samples."),
    "--length-delay": ("length_delay", "Log the leg lengths (and so the pose) this long "
                       "after the motion (s)."),
    "--force-lowpass": ("force_lowpass", "Colour the force noise: pass it through a causal "
                        "Butterworth low-pass filter with this cut-off (Hz), its standard "
                        "deviation kept."),
    "--force-lowpass-order": ("force_lowpass_order", "Order of that filter (default 4)."),
    "--hum": ("hum_amplitude", "Mains hum on every force channel: amplitude (N), a random "
              "phase per leg."),
    "--hum-frequency": ("hum_frequency", "Mains frequency of the hum (Hz, default 50)."),
    "--force-drift": ("force_drift", "Random-walk drift of each force channel from zero: its "
                      "standard deviation at the end of the record (N)."),
    "--length-drift": ("length_drift", "Random-walk drift of each leg-length channel: its "
                       "standard deviation at the end of the record (m)."),
    "--force-resolution": ("force_resolution", "Quantisation step of the forces (N); "
                           "default: [sensors] force_resolution."),
    "--length-resolution": ("length_resolution", "Quantisation step of the leg lengths (m, "
                            "e.g. 1e-6); default: [sensors] length_resolution."),
}
#: The metavar of each sensor-imperfection flag in ``--help``: what its value is.
IMPERFECTION_METAVARS = {"--force-delay": "SECONDS", "--length-delay": "SECONDS", "--force-lowpass": "HZ",
                         "--force-lowpass-order": "N", "--hum": "NEWTONS", "--hum-frequency": "HZ",
                         "--force-drift": "NEWTONS", "--length-drift": "METRES",
                         "--force-resolution": "NEWTONS", "--length-resolution": "METRES"}
#: A flag that only shapes the error another flag switches on: flag -> (that flag, field).
SHAPING_FLAGS = {"--force-lowpass-order": ("--force-lowpass", "force_lowpass"),
                 "--hum-frequency": ("--hum", "hum_amplitude")}


def imperfection_option(flag: str) -> Any:
    """The typer option of a sensor-imperfection flag, with its help."""
    return typer.Option(flag, metavar=IMPERFECTION_METAVARS[flag], help=IMPERFECTION_FLAGS[flag][1])


def simulate(
    out: Annotated[Path, typer.Option("--out", metavar="DIR", help="Output folder for exp1..exp6 and "
                                      "meta.json.")],
    platform: Annotated[str, typer.Option("--platform", metavar="NAME|FILE",
                                          help="'paper' for the preset, or a "
                                          "platform TOML file.")] = "paper",
    coulomb: Annotated[float | None, typer.Option("--coulomb", metavar="TORQUE", help="Coulomb friction per "
                                                  "joint axis (N m); default: the platform's.")
                       ] = None,
    viscous: Annotated[float | None, typer.Option("--viscous", metavar="DAMPING", help="Viscous friction per "
                                                  "gimbal axis (N m s/rad).")] = None,
    frequency: Annotated[float, typer.Option("--frequency", metavar="HZ", help="Excitation sine frequency "
                                             "(Hz).")] = 0.5,
    duration: Annotated[float, typer.Option("--duration", metavar="SECONDS", help="Record length of each "
                                            "experiment (s).")] = 20.0,
    noise_on: Annotated[bool, typer.Option(
        "--noise", help="Switch on the reference sensor noise: 20 um on the leg lengths and "
        "0.5 % of the static leg force on the forces (--length-noise/--force-noise override "
        "either); for electric legs 0.5 % of each motor current's RMS over the record, and "
        "no length noise beyond the encoders' counts.")] = False,
    length_noise: Annotated[float | None, typer.Option(
        "--length-noise", metavar="METRES", help="Leg-length sensor noise, standard deviation (m); default: "
        "[sensors] length_noise.")] = None,
    force_noise: Annotated[float | None, typer.Option(
        "--force-noise", metavar="NEWTONS", help="Force sensor noise, standard deviation (N); default: "
        "[sensors] force_noise.")] = None,
    actuator: Annotated[str | None, typer.Option(
        "--actuator", metavar="KIND",
        help="The legs' own model, 'hydraulic' (valves and cylinders) or 'electric' (servo "
        "motors with current loops, logging currents i1..i6), which must be the platform's "
        "[actuator] kind; or 'ideal' (the demanded forces applied exactly). Default: the "
        "platform's kind, or 'ideal' when [hydraulics] mode = \"ideal\".")] = None,
    seed: Annotated[int, typer.Option("--seed", metavar="N", help="Seed of the sensor noise.")] = 0,
    format: Annotated[str, typer.Option("--format", metavar="csv|parquet",
                                        help="'csv' or 'parquet'.")] = "csv",
    force: Annotated[bool, typer.Option("--force", help="Overwrite results already in "
                                        "--out.")] = False,
    excitation: Annotated[list[Path] | None, typer.Option(
        "--excitation", metavar="FILE", help="Play this excitation file instead of the paper's sines: CSV "
        "with t and the pose x..rz (m, rad) or t and l1..l6 (m), e.g. a command file of "
        "`stewartid design`; repeat for more experiments (exp1, exp2, ...).")] = None,
    engine: Annotated[str, typer.Option(
        "--engine", metavar="ours|mujoco", help="'ours' (the plant) or 'mujoco' (the "
        "same platform in MuJoCo, an independent engine: ideal leg actuators under the "
        "servo's PD law, or electric legs' motors under its PID law, MuJoCo's friction "
        "constraints; needs the [mujoco] extra). The sensor errors are the same on "
        "both.")] = "ours",
    sample_rate: Annotated[float | None, typer.Option(
        "--sample-rate", metavar="HZ", help="Sample rate of the logs (Hz); default: [sensors] "
        "sample_rate.")] = None,
    jobs: Annotated[int | None, typer.Option(
        "--jobs", metavar="N", help="Worker processes for the paper's experiments (default: every core); "
        "the data do not depend on it.")] = None,
    force_delay: Annotated[float | None, imperfection_option("--force-delay")] = None,
    length_delay: Annotated[float | None, imperfection_option("--length-delay")] = None,
    force_lowpass: Annotated[float | None, imperfection_option("--force-lowpass")] = None,
    force_lowpass_order: Annotated[int | None,
                                   imperfection_option("--force-lowpass-order")] = None,
    hum: Annotated[float | None, imperfection_option("--hum")] = None,
    hum_frequency: Annotated[float | None, imperfection_option("--hum-frequency")] = None,
    force_drift: Annotated[float | None, imperfection_option("--force-drift")] = None,
    length_drift: Annotated[float | None, imperfection_option("--length-drift")] = None,
    force_resolution: Annotated[float | None, imperfection_option("--force-resolution")] = None,
    length_resolution: Annotated[float | None,
                                 imperfection_option("--length-resolution")] = None,
) -> None:
    """Simulate the six experiments (experiment k excites DOF k) on the plant (hydraulic or
    electric legs), or with ``--engine mujoco`` on MuJoCo's model of the platform."""
    # imported when this command runs: every command's module is imported at start-up
    from rich.progress import Progress

    from stewartid.fields import Options, check, nonnegative, positive
    from stewartid.simulation import simulate_experiments, write_experiments
    from stewartid.simulation.experiments import is_experiment_file
    from stewartid.simulation.sensors import REFERENCE_CURRENT_NOISE, sensor_noise

    description = load_platform(platform)
    check("--format", format, [Options(("csv", "parquet"))])
    check("--engine", engine, [Options(("ours", "mujoco"))])
    if actuator is not None:
        check("--actuator", actuator, [Options(("hydraulic", "electric", "ideal"))])
    if engine == "mujoco" and actuator == "hydraulic":
        raise ConfigError("--actuator hydraulic: MuJoCo's legs are ideal force actuators; "
                          "leave --actuator out or use --engine ours.")
    if actuator is not None and actuator not in ("ideal", description.actuator.kind):
        fix = ("leave --actuator out" if description.actuator.kind == "electric" else
               'give the platform an [actuator] with kind = "electric" and its motor constants')
        raise ConfigError(f"--actuator {actuator}: platform '{description.name}' has "
                          f"{description.actuator.kind} legs ([actuator] kind = "
                          f'"{description.actuator.kind}"); {fix}, or use --actuator ideal.')
    if sample_rate is not None:
        check("--sample-rate", sample_rate, [positive()], "Hz")
        description = description.replace(sensors__sample_rate=sample_rate)
    electric = _overridden(description, None, None, actuator).electric_legs
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
    # an encoder has no white noise: for electric legs --noise is the current sensing's
    reference = "always" if noise_on and not electric else "never"
    current_noise = REFERENCE_CURRENT_NOISE if noise_on and electric else 0.0
    noise = with_imperfections(
        sensor_noise(description, reference, length_noise, force_noise),
        description.sensors.sample_rate,
        {"--force-delay": force_delay, "--length-delay": length_delay,
         "--force-lowpass": force_lowpass, "--force-lowpass-order": force_lowpass_order,
         "--hum": hum, "--hum-frequency": hum_frequency, "--force-drift": force_drift,
         "--length-drift": length_drift, "--force-resolution": force_resolution,
         "--length-resolution": length_resolution})
    with Progress(transient=True) as bar:
        task = bar.add_task("simulating", total=len(excitation) if excitation else 6)

        def progress(done: int, total: int, name: str) -> None:
            bar.update(task, completed=done, description=f"simulated {name}")

        workers = (os.cpu_count() or 1) if jobs is None else jobs
        if engine == "mujoco":
            result = _on_mujoco(description, coulomb, viscous, excitation, frequency, duration,
                                noise, seed, progress, workers, actuator, current_noise)
        elif excitation:
            from stewartid.design.export import read_excitation, simulate_excitations  # as above

            description = _overridden(description, coulomb, viscous, actuator)
            result = simulate_excitations(
                description, [read_excitation(path, description) for path in excitation],
                noise, seed, progress, current_noise)
        else:
            result = simulate_experiments(description, coulomb=coulomb, viscous=viscous,
                                          frequency_hz=frequency, duration_s=duration,
                                          noise=noise, seed=seed, actuator=actuator,
                                          progress=progress, jobs=workers,
                                          current_noise=current_noise)
    paths = write_experiments(result, out, format=format, force=force)
    engine_note = ""
    if engine == "mujoco":
        engine_note = (" (MuJoCo: electric legs)" if electric
                       else " (MuJoCo: ideal leg actuators, no hydraulics)")
    if electric:
        engine_note += ", currents i1..i6 (A) in place of forces"
    typer.echo(f"wrote {len(paths) - 1} experiments and meta.json to {out}{engine_note}")


def _overridden(description: Platform, coulomb: float | None, viscous: float | None,
                actuator: str | None) -> Platform:
    """The platform with the friction and actuator flags given on the command line."""
    mode = None if actuator is None else ("ideal" if actuator == "ideal" else "hydraulic")
    overrides = {key: value for key, value in (
        ("friction__coulomb", coulomb), ("friction__gimbal_viscous", viscous),
        ("hydraulics__mode", mode)) if value is not None}
    return description.replace(**overrides) if overrides else description


def _on_mujoco(description: Platform, coulomb: float | None, viscous: float | None,
               excitation: list[Path] | None, frequency: float, duration: float,
               noise: SensorNoise, seed: int, progress: Any, jobs: int,
               actuator: str | None = None, current_noise: float = 0.0) -> SimulationResult:
    """``simulate --engine mujoco``: the experiments or excitation files played on the MuJoCo model."""
    from stewartid.design.export import read_excitation
    from stewartid.simulation import paper_experiments

    try:
        from stewartid.mujoco.experiments import simulate_on_mujoco
        from stewartid.mujoco.model import require_mujoco

        require_mujoco()
    except ImportError as exc:
        raise ConfigError(f"--engine mujoco: {exc}.") from None
    description = _overridden(description, coulomb, viscous, actuator)
    if excitation:
        played = [read_excitation(path, description) for path in excitation]
        durations = [e.duration for e in played]
        meta = {"sources": [e.name for e in played]}
    else:
        played = paper_experiments(description, frequency)
        durations = [duration] * len(played)
        meta = {"frequency_hz": frequency, "duration_s": duration}
    return simulate_on_mujoco(description, played, durations, noise, seed, progress=progress,
                              jobs=jobs, excitation_meta=meta, current_noise=current_noise)


def with_imperfections(noise: SensorNoise, sample_rate: float,
                       given: dict[str, Any]) -> SensorNoise:
    """``noise`` with the command line's sensor imperfections.

    ``given``: flag of :data:`IMPERFECTION_FLAGS` -> value (None when not given); filter and hum
    frequencies must lie below half ``sample_rate`` (Hz).

    Raises
    ------
    ConfigError
        Naming the flag: a value out of range, a frequency at or above Nyquist, or a flag shaping an
        error not switched on.
    """
    from numbers import Real

    import numpy as np

    from stewartid.errors import ConfigError
    from stewartid.fields import Interval, check, field_spec
    from stewartid.simulation.sensors import SensorNoise

    fields = {f.name: f for f in dataclasses.fields(SensorNoise)}
    changes = {}
    for flag, value in given.items():
        if value is not None:  # an optional flag not given
            name = IMPERFECTION_FLAGS[flag][0]
            declared = field_spec(fields[name])
            check(flag, value, [declared.constraint], declared.unit)
            changes[name] = value
    noise = dataclasses.replace(noise, **changes)
    for flag, (switch, field) in SHAPING_FLAGS.items():
        if given.get(flag) is not None and not getattr(noise, field):
            raise ConfigError(f"{flag} has no effect without {switch}; add {switch} or leave "
                              f"{flag} out.")
    if noise.force_lowpass and not any(np.atleast_1d(noise.force_noise)):
        raise ConfigError("--force-lowpass colours the force noise, which is zero here; add "
                          "--noise or --force-noise N.")
    for flag, field, used in (("--force-lowpass", "force_lowpass", noise.force_lowpass > 0),
                              ("--hum-frequency", "hum_frequency", noise.hum_amplitude > 0)):
        if used:
            check(flag, getattr(noise, field), [Interval(Real, 0.0, sample_rate / 2, "neither")],
                  "Hz", f"sampling at {sample_rate:g} Hz")
    return noise
