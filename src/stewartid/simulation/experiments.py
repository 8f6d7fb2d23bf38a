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
from stewartid.simulation import plant
from stewartid.simulation.controller import command_tables, controller_parameters
from stewartid.simulation.excitation import (
    DEFAULT_AMPLITUDES,
    DEFAULT_FADE_IN,
    Excitation,
    excitation_to_dict,
    paper_experiments,
)
from stewartid.simulation.hydraulics import hydraulic_parameters
from stewartid.simulation.sensors import SensorNoise, measure_legs, measured_pose
from stewartid.simulation.stability import initial_state, loop_poles, require_stable

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
    """

    datasets: list[Dataset]
    meta: dict
    states: list[ExperimentRecord]


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


def simulate_experiment(platform: Platform, excitation: Excitation, duration_s: float,
                        noise: SensorNoise | None = None,
                        rng: np.random.Generator | None = None,
                        step: float = DEFAULT_STEP,
                        coulomb_smoothing: float = COULOMB_SMOOTHING,
                        ) -> tuple[Dataset, ExperimentRecord]:
    """Run the closed-loop plant along one excitation; returns the measured data set and the true
    :class:`ExperimentRecord`.

    ``duration_s`` in s, sampled at ``platform.sensors.sample_rate``; ``noise`` defaults to
    ``[sensors]``, ``rng`` to ``default_rng(0)``; ``step`` (s) is rounded down to divide the sample
    period; ``coulomb_smoothing`` in rad/s.

    Raises
    ------
    ConfigError
        On a non-positive duration, a frequency not below Nyquist, an actuator that cannot hold the
        platform, or a servo loop unstable at the start pose.
    StewartidError
        If a leg leaves its stroke or the integration diverges.
    """
    fs = platform.sensors.sample_rate
    check_timing(duration_s, fs, excitation.max_frequency)
    if not (step > 0 and math.isfinite(step)):
        raise ConfigError(f"integration step must be > 0 s; got {step!r}.")
    noise = SensorNoise.from_sensors(platform.sensors) if noise is None else noise
    rng = np.random.default_rng(0) if rng is None else rng
    noise.check_sampling(fs)
    n_out = int(math.floor(duration_s * fs + 1e-9)) + 1
    substeps = max(1, math.ceil(1.0 / (fs * step) - 1e-9))
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
    y0 = initial_state(platform, q_cmd[0], cmd_force[0], hp, cp)
    hydraulic = platform.hydraulic_legs
    require_stable(loop_poles(y0, cmd_len[0], cmd_rate[0], cmd_force[0], params, upper, base,
                              hp, cp, hydraulic, float(coulomb_smoothing)),
                   platform, excitation.name)
    status, where, leg, states, qdd, lengths, rates, forces, demands = plant.integrate(
        y0, h, substeps, n_out, cmd_len, cmd_rate, cmd_force, params, upper, base, hp, cp,
        hydraulic, float(coulomb_smoothing))
    if status == plant.STATUS_STROKE:
        raise StewartidError(
            f"{excitation.name}: leg {leg + 1} left its {platform.hydraulics.stroke} m stroke "
            f"at t = {where / fs:.3f} s; lower the excitation amplitude or lengthen [hydraulics] "
            "stroke.")
    if status == plant.STATUS_NONFINITE:
        raise StewartidError(
            f"{excitation.name}: the closed loop diverged at t = {where / fs:.3f} s; lower "
            "the integration step or the controller gains.")
    t = np.arange(n_out) / fs
    record = ExperimentRecord(
        name=excitation.name, t=t, q=states[:, plant.S_Q:plant.S_Q + 6],
        q_dot=states[:, plant.S_QD:plant.S_QD + 6], q_ddot=qdd, lengths=lengths,
        length_rates=rates, forces=forces, demands=demands,
        command_lengths=cmd_len[::2 * substeps],
        pressures=np.stack([states[:, plant.S_PA:plant.S_PA + 6],
                            states[:, plant.S_PB:plant.S_PB + 6]], axis=-1),
        spools=states[:, plant.S_XV:plant.S_XV + 6])
    measured_lengths, measured_forces = measure_legs(lengths, forces, noise, rng, t)
    # Newton started at the true pose: the same solution as from the commanded one, in fewer
    # iterations
    pose = measured_pose(platform, measured_lengths, record.q)
    dataset = Dataset(t=t, pose=pose, lengths=measured_lengths, forces=measured_forces,
                      name=excitation.name)
    return dataset, record


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
                         jobs: int = 1,
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
    actuator : {"hydraulic", "ideal"}, optional
        Override ``[hydraulics] mode``.
    fade_in : float
        s.
    step : float
        Largest integration step (s).
    progress : callable, optional
        ``progress(done, total, name)`` after each experiment.
    jobs : int
        Worker processes; the data are the same for any number.
    """
    updates: dict[str, Any] = {}
    if coulomb is not None:
        updates["friction__coulomb"] = float(coulomb)
    if viscous is not None:
        updates["friction__gimbal_viscous"] = float(viscous)
    if actuator is not None:
        updates["hydraulics__mode"] = actuator
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
    runs = [(platform, excitation, duration_s, noise, seed, k, len(excitations), step)
            for k, excitation in enumerate(excitations)]
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
        "integration": {"method": "RK4", "step": 1.0 / (platform.sensors.sample_rate * max(
            1, math.ceil(1.0 / (platform.sensors.sample_rate * step) - 1e-9))),
            "coulomb_smoothing": COULOMB_SMOOTHING},
        "noise": dataclasses.asdict(noise),
        "seed": int(seed),
        "tracking_error_rms": [r.tracking_error().tolist() for r in records],
        "nominal": {"M": M.tolist(), "B": B.tolist()},
        "K_G": gravity_stiffness(platform).tolist(),
        "version": stewartid.__version__,
    }
    return SimulationResult(datasets, meta, records)


def _simulate_run(run: tuple) -> tuple[Dataset, ExperimentRecord]:
    platform, excitation, duration_s, noise, seed, k, count, step = run
    return simulate_experiment(platform, excitation, duration_s, noise,
                               noise_generator(seed, k, count), step)


def run_experiments(runs: Sequence[tuple], jobs: int | None = 1,
                    progress: Callable[[int, int, str], Any] | None = None,
                    ) -> list[tuple[Dataset, ExperimentRecord]]:
    """Simulate ``runs`` in order on up to ``jobs`` workers (every core when None); results in order.

    Each run is ``(platform, excitation, duration_s, noise, seed, k, count, step)``, its noise stream
    :func:`noise_generator` ``(seed, k, count)``; ``progress(done, total, name)`` as they finish.
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
    """Write ``exp1..expN.<format>`` and ``meta.json`` into the folder ``out``.

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
    paths = [write_dataset(d, out / f"{d.name}.{format}", format=format)
             for d in result.datasets]
    return [*paths, write_json_atomic(out / "meta.json", result.meta)]


def is_experiment_file(path: Path) -> bool:
    """True for the files :func:`write_experiments` writes (``exp*`` and ``meta.json``)."""
    return path.name == "meta.json" or path.name.startswith("exp")
