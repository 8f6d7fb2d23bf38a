"""Virtual experiments: run the closed-loop plant along excitations, record data sets and write
them as ``exp1.csv`` to ``exp6.csv`` with ``meta.json``.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

import numpy as np

import stewartid
from stewartid.datasets.dataset import Dataset, write_dataset
from stewartid.errors import ConfigError, StewartidError
from stewartid.files import check_output_folder, write_json_atomic
from stewartid.model.dynamics import COULOMB_SMOOTHING
from stewartid.model.linearization import gravity_stiffness, nominal_matrices
from stewartid.parallel import WORKERS_INHERIT, run_in_order, worker_count
from stewartid.platform import Platform
from stewartid.platform.sections import ACTUATOR_KINDS
from stewartid.simulation import plant
from stewartid.simulation.controller import command_tables, controller_parameters
from stewartid.simulation.electric import (
    current_bandwidth,
    electric_parameters,
    encoder_resolution,
    largest_step,
)
from stewartid.simulation.excitation import (
    DEFAULT_AMPLITUDES,
    DEFAULT_FADE_IN,
    Excitation,
    excitation_to_dict,
    paper_experiments,
)
from stewartid.simulation.hydraulics import hydraulic_parameters
from stewartid.simulation.sensors import (
    SensorNoise,
    measure_electric_legs,
    measure_legs,
    measured_pose,
)
from stewartid.simulation.stability import initial_state, leg_drive, loop_poles, require_stable

#: Default integration step (s).
DEFAULT_STEP = 5e-4


@dataclasses.dataclass(frozen=True)
class ExperimentRecord:
    """True signals of one simulated experiment, at the recorded samples.

    Attributes
    ----------
    name : str
    t : ndarray, shape (N,)
        s.
    q, q_dot, q_ddot : ndarray, shape (N, 6)
        m, rad and derivatives.
    lengths, length_rates, command_lengths : ndarray, shape (N, 6)
        m, m/s, m.
    forces, demands : ndarray, shape (N, 6)
        Actual actuator forces and controller demands (N).
    pressures : ndarray, shape (N, 6, 2)
        Chamber pressures p_A, p_B (Pa); constant in ideal actuator mode.
    spools : ndarray, shape (N, 6)
        Valve spool positions (fraction of full opening).
    currents : ndarray, shape (N, 6), or None
        Motor currents (A) of electric legs (``forces`` = force_constant currents); None otherwise.
    """

    name: str
    t: np.ndarray
    q: np.ndarray
    q_dot: np.ndarray
    q_ddot: np.ndarray
    lengths: np.ndarray
    length_rates: np.ndarray
    forces: np.ndarray
    demands: np.ndarray
    command_lengths: np.ndarray
    pressures: np.ndarray
    spools: np.ndarray
    currents: np.ndarray | None = None

    def tracking_error(self) -> np.ndarray:
        """RMS of the leg-length tracking error per leg (m), shape (6,)."""
        return np.sqrt(np.mean((self.command_lengths - self.lengths) ** 2, axis=0))


@dataclasses.dataclass(frozen=True)
class SimulationResult:
    """Output of :func:`simulate_experiments`.

    Attributes
    ----------
    datasets : list of Dataset
        Measured data, one per experiment.
    meta : dict
        Configuration, seed, nominal matrices, package version (JSON-ready).
    states : list of ExperimentRecord
        True signals, one per experiment.
    force_constant : float, optional
        N/A; when given (electric legs), :func:`write_experiments` logs the motor currents
        ``i1..i6`` = forces / force_constant (A) in place of ``f1..f6``.
    """

    datasets: list[Dataset]
    meta: dict
    states: list[ExperimentRecord]
    force_constant: float | None = None


def check_timing(duration_s: float, sample_rate: float, max_frequency: float) -> None:
    """Raise ConfigError on a non-positive record length or a frequency not below Nyquist."""
    if not (math.isfinite(duration_s) and duration_s > 0):
        raise ConfigError(f"duration must be > 0 s; got {duration_s!r}.")
    nyquist = sample_rate / 2
    if not max_frequency < nyquist:
        raise ConfigError(
            f"excitation frequency {max_frequency!r} Hz is not below the Nyquist limit "
            f"{nyquist:g} Hz of the {sample_rate:g} Hz sampling; lower the frequency or raise "
            "[sensors] sample_rate."
        )


def integration_substeps(platform: Platform, step: float) -> int:
    """RK4 steps per sample: the sample period over ``step`` (s) rounded up, the step no longer than
    the current loop of electric legs resolves (:func:`~stewartid.simulation.electric.largest_step`).
    """
    if platform.electric_legs:
        step = min(step, largest_step(platform.actuator))
    fs = platform.sensors.sample_rate
    return max(1, math.ceil(1.0 / (fs * step) - 1e-9))


def simulate_experiment(platform: Platform, excitation: Excitation, duration_s: float,
                        noise: SensorNoise | None = None,
                        rng: np.random.Generator | None = None,
                        step: float = DEFAULT_STEP,
                        coulomb_smoothing: float = COULOMB_SMOOTHING,
                        current_noise: float = 0.0,
                        ) -> tuple[Dataset, ExperimentRecord]:
    """Run the closed-loop plant along one excitation; returns the measured data set and the true
    :class:`ExperimentRecord`.

    ``duration_s`` in s, sampled at ``platform.sensors.sample_rate``; ``noise`` defaults to
    ``[sensors]``, ``rng`` to ``default_rng(0)``; ``step`` (s) is rounded down to divide the sample
    period (and, for electric legs, to resolve their current loop); ``coulomb_smoothing`` in rad/s.
    Electric legs (:attr:`~stewartid.platform.Platform.electric_legs`) log their encoders' lengths
    and the force equivalent of their currents, with ``current_noise`` (-) times each channel's
    RMS as further noise (see :func:`~stewartid.simulation.sensors.measure_electric_legs`).

    Raises
    ------
    ConfigError
        On a non-positive duration, a frequency not below Nyquist, an actuator that cannot hold the
        platform, or a servo loop unstable at the start pose.
    StewartidError
        If a leg leaves its stroke, an electric leg exceeds its screw speed, or the integration
        diverges.
    """
    fs = platform.sensors.sample_rate
    check_timing(duration_s, fs, excitation.max_frequency)
    if not (step > 0 and math.isfinite(step)):
        raise ConfigError(f"integration step must be > 0 s; got {step!r}.")
    if not (math.isfinite(current_noise) and current_noise >= 0):
        raise ConfigError(f"current_noise must be a fraction >= 0 of each current's RMS; got "
                          f"{current_noise!r}.")
    noise = SensorNoise.from_sensors(platform.sensors) if noise is None else noise
    rng = np.random.default_rng(0) if rng is None else rng
    noise.check_sampling(fs)
    n_out = int(math.floor(duration_s * fs + 1e-9)) + 1
    substeps = integration_substeps(platform, step)
    h = 1.0 / (fs * substeps)
    t_half = np.arange(2 * substeps * (n_out - 1) + 1) * (h / 2)
    q_cmd, qd_cmd, _ = excitation.evaluate(t_half)
    params = platform.parameters()
    upper = np.ascontiguousarray(platform.upper_joints)
    base = np.ascontiguousarray(platform.base_joints)
    cmd_len, cmd_rate, cmd_force = command_tables(
        params, upper, base, q_cmd, qd_cmd, bool(platform.controller.gravity_feedforward))
    hp = hydraulic_parameters(platform.hydraulics, platform.neutral_leg_length)
    cp = controller_parameters(platform)
    ep = electric_parameters(platform.actuator)
    y0 = initial_state(platform, q_cmd[0], cmd_force[0], hp, cp)
    drive = leg_drive(platform)
    require_stable(loop_poles(y0, cmd_len[0], cmd_rate[0], cmd_force[0], params, upper, base,
                              hp, cp, drive, float(coulomb_smoothing), ep),
                   platform, excitation.name)
    status, where, leg, states, qdd, lengths, rates, forces, demands = plant.integrate(
        y0, h, substeps, n_out, cmd_len, cmd_rate, cmd_force, params, upper, base, hp, cp,
        ep, drive, float(coulomb_smoothing))
    if status == plant.STATUS_STROKE:
        raise StewartidError(
            f"{excitation.name}: leg {leg + 1} left its {platform.hydraulics.stroke} m stroke "
            f"at t = {where / fs:.3f} s; lower the excitation amplitude or lengthen [hydraulics] "
            "stroke.")
    if status == plant.STATUS_NONFINITE:
        raise StewartidError(
            f"{excitation.name}: the closed loop diverged at t = {where / fs:.3f} s; lower "
            "the integration step or the controller gains.")
    electric = drive == plant.DRIVE_ELECTRIC
    if electric:
        _require_screw_speed(platform, rates, excitation.name)
    t = np.arange(n_out) / fs
    record = ExperimentRecord(
        name=excitation.name, t=t, q=states[:, plant.S_Q:plant.S_Q + 6],
        q_dot=states[:, plant.S_QD:plant.S_QD + 6], q_ddot=qdd, lengths=lengths,
        length_rates=rates, forces=forces, demands=demands,
        command_lengths=cmd_len[::2 * substeps],
        pressures=np.stack([states[:, plant.S_PA:plant.S_PA + 6],
                            states[:, plant.S_PB:plant.S_PB + 6]], axis=-1),
        spools=states[:, plant.S_XV:plant.S_XV + 6],
        currents=states[:, plant.S_I:plant.S_I + 6] if electric else None)
    if electric:
        measured_lengths, measured_forces = measure_electric_legs(
            lengths, forces, noise, rng, t, encoder_resolution(platform.actuator), current_noise)
    else:
        measured_lengths, measured_forces = measure_legs(lengths, forces, noise, rng, t)
    # Newton started at the true pose: the same solution as from the commanded one, in fewer
    # iterations
    pose = measured_pose(platform, measured_lengths, record.q)
    dataset = Dataset(t=t, pose=pose, lengths=measured_lengths, forces=measured_forces,
                      name=excitation.name)
    return dataset, record


def _require_screw_speed(platform: Platform, rates: np.ndarray, where: str) -> None:
    """Raise if a leg moved faster than its motor's screw_speed allows (when given)."""
    a = platform.actuator
    if a.screw_speed is None or a.screw_lead is None:
        return
    limit = a.screw_speed * a.screw_lead
    fastest = np.abs(rates).max(axis=0)
    if fastest.max() > limit:
        leg = int(np.argmax(fastest))
        raise StewartidError(
            f"{where}: leg {leg + 1} moved at {fastest[leg]:.4g} m/s, faster than its motor "
            f"allows ([actuator] screw_speed x screw_lead = {limit:.4g} m/s); lower the "
            "excitation amplitude or frequency.")


def noise_generator(seed: int, experiment: int, count: int = 6) -> np.random.Generator:
    """Generator of experiment ``experiment`` of ``count``: that child of ``SeedSequence(seed)``, the
    same whether experiments run together or one per worker.
    """
    return np.random.default_rng(np.random.SeedSequence(int(seed)).spawn(count)[experiment])


def simulate_experiments(platform: Platform, coulomb: float | None = None,
                         viscous: float | None = None, frequency_hz: float = 0.5,
                         duration_s: float = 20.0,
                         amplitudes: Sequence[float] = DEFAULT_AMPLITUDES,
                         noise: SensorNoise | None = None, seed: int = 0,
                         actuator: str | None = None, fade_in: float = DEFAULT_FADE_IN,
                         step: float = DEFAULT_STEP,
                         progress: Callable[[int, int, str], Any] | None = None,
                         jobs: int = 1, current_noise: float = 0.0,
                         ) -> SimulationResult:
    """The paper's six virtual experiments (experiment k excites DOF k with a sine).

    Parameters
    ----------
    platform : Platform
    coulomb, viscous : float, optional
        Override the Coulomb (N m per joint axis) and gimbal viscous (N m s/rad) friction.
    frequency_hz : float
        Sine frequency (Hz), 0.5 in the paper.
    duration_s : float
        Length of each record (s).
    amplitudes : sequence of 6 float
        Per DOF (m, rad).
    noise : SensorNoise, optional
        Sensor errors; ``[sensors]`` by default.
    seed : int
        Seed of the sensor noise, one stream per experiment.
    actuator : {"hydraulic", "electric", "ideal"}, optional
        "ideal" applies the demanded forces exactly; "hydraulic" or "electric", the platform's own
        ``[actuator]`` kind, drives the legs by their valves or motors. Default: the kind, or
        "ideal" when ``[hydraulics] mode = "ideal"``.
    fade_in : float
        s.
    step : float
        Largest integration step (s).
    progress : callable, optional
        ``progress(done, total, name)`` after each experiment.
    jobs : int
        Worker processes; the data are the same for any number.
    current_noise : float
        Electric legs: noise of each motor current as a fraction of its RMS over the record
        (0.005 for ``simulate --noise``).

    Raises
    ------
    ConfigError
        On an actuator other than the platform's kind or "ideal", and as
        :func:`simulate_experiment`.
    """
    updates: dict[str, Any] = {}
    if coulomb is not None:
        updates["friction__coulomb"] = float(coulomb)
    if viscous is not None:
        updates["friction__gimbal_viscous"] = float(viscous)
    if actuator is not None:
        updates["hydraulics__mode"] = actuator_mode(platform, actuator)
    if updates:
        platform = platform.replace(**updates)
    noise = SensorNoise.from_sensors(platform.sensors) if noise is None else noise
    check_timing(duration_s, platform.sensors.sample_rate, frequency_hz)
    noise.check_sampling(platform.sensors.sample_rate)
    if not (isinstance(seed, int | np.integer) and seed >= 0):
        raise ConfigError(f"seed must be an integer >= 0; got {seed!r}.")
    if isinstance(jobs, bool) or not isinstance(jobs, int | np.integer) or jobs < 1:
        raise ConfigError(f"jobs must be a positive integer (worker processes); got {jobs!r}.")
    excitations = paper_experiments(platform, frequency_hz, amplitudes, fade_in)
    runs = [(platform, excitation, duration_s, noise, seed, k, len(excitations), step,
             current_noise) for k, excitation in enumerate(excitations)]
    datasets, records = zip(*run_experiments(runs, jobs, progress), strict=True)
    datasets, records = list(datasets), list(records)
    M, B = nominal_matrices(platform)
    meta = {
        "platform": platform.to_dict(),
        "platform_name": platform.name,
        "excitation": {
            "frequency_hz": frequency_hz, "duration_s": duration_s,
            "amplitudes": list(map(float, amplitudes)), "fade_in": fade_in,
            "experiments": [excitation_to_dict(e) for e in excitations],
        },
        "integration": {"method": "RK4", "step": 1.0 / (platform.sensors.sample_rate
                                                         * integration_substeps(platform, step)),
                        "coulomb_smoothing": COULOMB_SMOOTHING},
        "noise": dataclasses.asdict(noise),
        "seed": int(seed),
        "tracking_error_rms": [r.tracking_error().tolist() for r in records],
        "nominal": {"M": M.tolist(), "B": B.tolist()},
        "K_G": gravity_stiffness(platform).tolist(),
        "version": stewartid.__version__,
    }
    meta.update(electric_meta(platform, current_noise))
    return SimulationResult(datasets, meta, records, logged_force_constant(platform))


def actuator_mode(platform: Platform, actuator: str) -> str:
    """``[hydraulics] mode`` for the legs ``actuator`` ("hydraulic", "electric" or "ideal").

    Raises
    ------
    ConfigError
        If ``actuator`` is neither "ideal" nor the platform's ``[actuator] kind``.
    """
    kind = platform.actuator.kind
    if actuator == "ideal":
        return "ideal"
    if actuator in ACTUATOR_KINDS and actuator != kind:
        fix = ('give the platform an [actuator] with kind = "electric" and its motor constants'
               if actuator == "electric" else "leave the actuator out")
        raise ConfigError(f"actuator {actuator!r}: platform '{platform.name}' has {kind} legs "
                          f"([actuator] kind = \"{kind}\"); {fix}, or use 'ideal'.")
    if actuator != kind:
        raise ConfigError(f"actuator must be one of 'hydraulic', 'electric', 'ideal'; got "
                          f"{actuator!r}.")
    return "hydraulic"


def logged_force_constant(platform: Platform) -> float | None:
    """N/A by which logs of the platform's legs give currents instead of forces; None unless electric."""
    return platform.actuator.force_constant if platform.electric_legs else None


def electric_meta(platform: Platform, current_noise: float) -> dict:
    """The ``electric`` entry of a simulation's metadata (motor model and sensors); empty for
    other legs, whose metadata stay as they were.
    """
    if not platform.electric_legs:
        return {}
    a = platform.actuator
    return {"electric": {
        "current_loop": "first order, i' = 2 pi f_c (i_cmd - i), i_cmd within +-peak_current",
        "current_bandwidth_hz": current_bandwidth(a), "peak_current": a.peak_current,
        "force_constant": a.force_constant, "encoder_resolution": encoder_resolution(a),
        "current_noise_fraction_of_rms": float(current_noise),
        "logged": "i1..i6 (A) = f / force_constant"}}


def _simulate_run(run: tuple) -> tuple[Dataset, ExperimentRecord]:
    platform, excitation, duration_s, noise, seed, k, count, step, current_noise = run
    return simulate_experiment(platform, excitation, duration_s, noise,
                               noise_generator(seed, k, count), step,
                               current_noise=current_noise)


def run_experiments(runs: Sequence[tuple], jobs: int | None = 1,
                    progress: Callable[[int, int, str], Any] | None = None,
                    ) -> list[tuple[Dataset, ExperimentRecord]]:
    """Simulate ``runs`` in order on up to ``jobs`` workers (every core when None); results in order.

    Each run is ``(platform, excitation, duration_s, noise, seed, k, count, step, current_noise)``,
    its noise stream :func:`noise_generator` ``(seed, k, count)``; ``progress(done, total, name)``
    as they finish.
    """
    def finished(done: int, total: int, index: int) -> None:
        progress(done, total, runs[index][1].name)

    if WORKERS_INHERIT and worker_count(jobs, len(runs)) > 1:
        # load the compiled kernels here, once: the workers inherit them
        platform, excitation, *_ = runs[0]
        simulate_experiment(platform, excitation, 2.0 / platform.sensors.sample_rate)

    return run_in_order(_simulate_run, runs, jobs, finished if progress is not None else None)


def write_experiments(result: SimulationResult, out: str | Path, format: str = "csv",
                      force: bool = False) -> list[Path]:
    """Write ``exp1..expN.<format>`` and ``meta.json`` into the folder ``out``; the motor currents
    ``i1..i6`` in place of ``f1..f6`` when ``result.force_constant`` is set.

    Raises
    ------
    OutputExistsError
        If ``out`` already holds results and not ``force``.
    ConfigError
        If ``format`` is unknown.
    """
    if format not in ("csv", "parquet"):
        raise ConfigError(f"format must be 'csv' or 'parquet'; got {format!r}.")
    out = Path(out)
    check_output_folder(out, force, is_experiment_file)
    out.mkdir(parents=True, exist_ok=True)
    paths = [write_dataset(d, out / f"{d.name}.{format}", format=format,
                           force_constant=result.force_constant)
             for d in result.datasets]
    return [*paths, write_json_atomic(out / "meta.json", result.meta)]


def is_experiment_file(path: Path) -> bool:
    """True for the files :func:`write_experiments` writes (``exp*`` and ``meta.json``)."""
    return path.name == "meta.json" or path.name.startswith("exp")
