"""Predicted accuracy of a design before any test: the chosen estimator fitted to the design's
noise-free data (plant or rigid-body model) and to ``seeds`` noisy copies; their spread is
the standard error, the mean's shift from nominal the bias.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable, Sequence

import numpy as np

from stewartid.datasets.dataset import Dataset
from stewartid.design.candidates import Design
from stewartid.design.export import simulate_excitations
from stewartid.errors import ConfigError
from stewartid.identification.registry import create_identifier, estimates_only
from stewartid.model.dynamics import inverse_dynamics
from stewartid.model.kinematics import inverse_kinematics, leg_jacobian
from stewartid.model.linearization import nominal_matrices
from stewartid.parallel import run_in_order
from stewartid.platform import Platform
from stewartid.reference.published import PAPER_ENTRIES, entry_label
from stewartid.simulation.sensors import SensorNoise, measure_legs, measured_pose


def model_datasets(platform: Platform, design: Design) -> list[Dataset]:
    """Noise-free data of a design from the rigid-body model with perfect tracking, one per
    record at ``[sensors] sample_rate``, forces including the platform's friction.
    """
    rate = platform.sensors.sample_rate
    out = []
    for playable in design.playable(platform):
        t = np.arange(int(math.floor(playable.record.duration * rate + 1e-9)) + 1) / rate
        q, q_dot, q_ddot = playable.evaluate(t)
        forces = inverse_dynamics(platform, q, q_dot, q_ddot)
        out.append(Dataset(t=t, pose=q, lengths=inverse_kinematics(platform, q).lengths,
                           forces=forces, name=playable.name))
    return out


def add_noise(platform: Platform, dataset: Dataset, noise: SensorNoise,
              rng: np.random.Generator, inverse_jacobian: np.ndarray | None = None) -> Dataset:
    """Noisy copy of noise-free data: white noise on lengths (m) and forces (N), pose to first
    order (true pose + J_lq^-1 length noise); biases and resolutions not modelled.

    ``inverse_jacobian`` (N, 6, 6) is :func:`inverse_leg_jacobians`, worth keeping over many copies.
    """
    n = len(dataset.t)
    d_lengths = rng.normal(0.0, noise.length_noise, size=(n, 6))
    d_forces = rng.normal(0.0, noise.force_noise, size=(n, 6))
    if inverse_jacobian is None:
        (inverse_jacobian,) = inverse_leg_jacobians(platform, [dataset.pose])
    d_pose = np.einsum("nij,nj->ni", inverse_jacobian, d_lengths)
    return Dataset(t=dataset.t, pose=dataset.pose + d_pose, lengths=dataset.lengths + d_lengths,
                   forces=dataset.forces + d_forces, name=dataset.name)


def inverse_leg_jacobians(platform: Platform, poses: list[np.ndarray]) -> list[np.ndarray]:
    """J_lq^-1 (N, 6, 6) at each array of poses (N, 6)."""
    return [np.linalg.inv(leg_jacobian(platform, q)) for q in poses]


@dataclasses.dataclass(frozen=True)
class Prediction:
    """Predicted accuracy of a design; matrices in Mt, Bt units.

    Attributes
    ----------
    nominal_M, nominal_B : ndarray, shape (6, 6)
        At the neutral pose.
    bias_M, bias_B : ndarray, shape (6, 6)
        Mean estimate minus nominal (without seeds, the information fit's expected estimate).
    noise_free_bias_M, noise_free_bias_B : ndarray, shape (6, 6), or None
        Noise-free estimate minus nominal; None when not fitted.
    std_M, std_B : ndarray, shape (6, 6)
        Predicted standard errors.
    seeds : int
        Monte Carlo realisations (0: none).
    method : str
        Estimator name with its settings.
    monte_carlo_std_M, monte_carlo_std_B : ndarray, shape (6, 6), or None
        Monte Carlo spread checking information-matrix standard errors.
    """

    nominal_M: np.ndarray
    nominal_B: np.ndarray
    bias_M: np.ndarray
    bias_B: np.ndarray
    noise_free_bias_M: np.ndarray | None
    noise_free_bias_B: np.ndarray | None
    std_M: np.ndarray
    std_B: np.ndarray
    seeds: int
    method: str
    monte_carlo_std_M: np.ndarray | None = None
    monte_carlo_std_B: np.ndarray | None = None

    def _entries(self, prefix: str) -> np.ndarray:
        values = {"M": getattr(self, f"{prefix}_M"), "B": getattr(self, f"{prefix}_B")}
        nominal = {"M": self.nominal_M, "B": self.nominal_B}
        return np.array([100 * abs(values[m][i, j]) / abs(nominal[m][i, j])
                         for m, i, j in PAPER_ENTRIES])

    @property
    def relative_std(self) -> np.ndarray:
        """Standard error of the paper's 20 entries, % of nominal, shape (20,)."""
        return self._entries("std")

    @property
    def relative_bias(self) -> np.ndarray:
        """|bias| of the paper's 20 entries, % of nominal, shape (20,)."""
        return self._entries("bias")

    @property
    def relative_noise_free_bias(self) -> np.ndarray | None:
        """|noise-free bias| of the 20 entries, % of nominal; None without a noise-free fit."""
        return None if self.noise_free_bias_M is None else self._entries("noise_free_bias")

    @property
    def relative_monte_carlo_std(self) -> np.ndarray | None:
        """Monte Carlo spread of the 20 entries, % of nominal; None without."""
        return None if self.monte_carlo_std_M is None else self._entries("monte_carlo_std")

    @property
    def worst_relative_std(self) -> float:
        """Design criterion: largest relative standard error of the 20 entries (%)."""
        return float(self.relative_std.max())

    @property
    def worst_relative_error(self) -> float:
        """Largest sqrt(bias^2 + SE^2) over the 20 entries (%)."""
        return float(np.hypot(self.relative_std, self.relative_bias).max())

    def scaled(self, factor: float) -> Prediction:
        """The same design run ``factor`` times longer: standard errors / sqrt(factor)."""
        return dataclasses.replace(self, std_M=self.std_M / math.sqrt(factor),
                                   std_B=self.std_B / math.sqrt(factor))

    def to_dict(self) -> dict:
        """JSON-ready summary, the 20 entries by their paper names."""
        checked = self.relative_monte_carlo_std
        entries = {entry_label(k): {"std_percent": float(s), "bias_percent": float(b)}
                   for k, s, b in zip(PAPER_ENTRIES, self.relative_std, self.relative_bias,
                                      strict=True)}
        for k, value in enumerate(() if checked is None else checked):
            entries[entry_label(PAPER_ENTRIES[k])]["monte_carlo_std_percent"] = float(value)
        return {"method": self.method, "seeds": self.seeds,
                "worst_relative_std_percent": self.worst_relative_std,
                "worst_relative_error_percent": self.worst_relative_error,
                "entries": entries,
                "std_M": self.std_M.tolist(), "std_B": self.std_B.tolist(),
                "bias_M": self.bias_M.tolist(), "bias_B": self.bias_B.tolist(),
                **{f"noise_free_bias_{m}": (None if getattr(self, f"noise_free_bias_{m}") is None
                                            else getattr(self, f"noise_free_bias_{m}").tolist())
                   for m in "MB"}}


#: Settings of the estimator a design is made for, per method (the rest: its defaults).
#: Method B with one Coulomb level for every joint axis, so that intervals of different speeds
#: separate viscous from Coulomb friction.
DESIGN_SETTINGS = {"wavelet": {"friction": "uniform"}}


def default_estimator(method: str = "wavelet"):
    """The estimator a design is made for: ``method`` with :data:`DESIGN_SETTINGS`."""
    return create_identifier(method, **DESIGN_SETTINGS.get(method, {}))


def _monte_carlo_estimator(method: str):
    """:func:`default_estimator` for the Monte Carlo (reads the estimates only)."""
    return estimates_only(method, **DESIGN_SETTINGS.get(method, {}))


def identify_options(method: str = "wavelet") -> list[str]:
    """``stewartid identify`` options matching :func:`default_estimator`."""
    options = ["--method", method]
    for name, value in DESIGN_SETTINGS.get(method, {}).items():
        options += [f"--{name}", str(value)]
    return options


#: Entropy that keeps the prediction's noise streams apart from ``simulate``'s seeds.
PREDICTION_STREAM = 0x5D1

#: Where the noise-free data of a prediction come from.
SOURCES = ("plant", "model")


def measured_plant_datasets(platform: Platform, records: list, noise: SensorNoise,
                            generators: list[np.random.Generator],
                            inverse_jacobians: list[np.ndarray] | None = None) -> list[Dataset]:
    """Measured data ``exp1..expN`` of noise-free plant records, noise drawn as ``simulate`` does.

    ``generators`` has one per record. With ``inverse_jacobians`` (:func:`inverse_leg_jacobians`)
    the pose is one Newton step of forward kinematics from the true pose, else full forward
    kinematics.
    """
    out = []
    for k, (record, rng) in enumerate(zip(records, generators, strict=True)):
        lengths, forces = measure_legs(record.lengths, record.forces, noise, rng, record.t)
        if inverse_jacobians is None:
            pose = measured_pose(platform, lengths, record.q)
        else:
            pose = record.q + np.einsum("nij,nj->ni", inverse_jacobians[k],
                                        lengths - record.lengths)
        out.append(Dataset(t=record.t, pose=pose, lengths=lengths, forces=forces,
                           name=f"exp{k + 1}"))
    return out


def plant_records(platform: Platform, design: Design, workers: int | None = None) -> list:
    """True signals of the design played once on the plant, noise-free, over ``workers`` processes."""
    return run_in_order(_play, design.playable(platform), workers, shared=platform)


def _play(platform: Platform, playable) -> object:
    return simulate_excitations(platform, [playable], SensorNoise()).states[0]


def predict_accuracy(platform: Platform, design: Design, noise: SensorNoise,
                     method: str = "wavelet", seeds: int = 120, seed: int = 0,
                     source: str = "plant", records: list | None = None,
                     workers: int | None = None,
                     progress: Callable[[int, int], None] | None = None) -> Prediction:
    """Predicted bias and standard errors of Mt and Bt for a design.

    Parameters
    ----------
    platform : Platform
        With the machine's expected friction.
    design : Design
    noise : SensorNoise
        Standard deviations (m, N).
    method : str
        Registered method (:func:`default_estimator`).
    seeds : int
        Noise realisations, >= 2.
    seed : int
        First realisation's seed (streams differ from ``simulate --seed``'s).
    source : {"plant", "model"}
        Noise-free data from the plant (honest, slower) or the rigid-body model (fast, optimistic).
    records : list of ExperimentRecord, optional
        :func:`plant_records`, for ``source="plant"``.
    workers : int, optional
        Processes; None: every core from :data:`PARALLEL_SEEDS` realisations on. Result independent.
    progress : callable, optional
        Called with (done, total).
    """
    if source not in SOURCES:
        raise ConfigError(f"source must be one of {', '.join(SOURCES)}; got {source!r}.")
    if workers is not None and int(workers) < 1:
        raise ConfigError(f"workers must be >= 1; got {workers!r}.")
    M0, B0 = nominal_matrices(platform)
    if source == "plant":
        records = plant_records(platform, design) if records is None else list(records)
        runs = NoiseRuns(platform, noise, method, int(seed), records=records,
                         inverse_jacobians=inverse_leg_jacobians(platform,
                                                                 [r.q for r in records]))
    else:
        clean = model_datasets(platform, design)
        runs = NoiseRuns(platform, noise, method, int(seed), datasets=clean,
                         inverse_jacobians=inverse_leg_jacobians(platform,
                                                                 [d.pose for d in clean]))
    estimator = _monte_carlo_estimator(method).fit(runs.clean(), platform)
    M_clean, B_clean = estimator.M_.copy(), estimator.B_.copy()
    fits = runs.estimates(range(int(seeds)), workers, progress)         # (seeds, 2, 6, 6)
    settings = estimator.get_params()
    label = method + ("" if method != "wavelet" else f" (friction={settings['friction']})")
    # the noise's shift of the mean belongs to the bias, the spread about it to the SE
    mean, std = fits.mean(axis=0), fits.std(axis=0, ddof=1)
    return Prediction(
        nominal_M=M0, nominal_B=B0, bias_M=mean[0] - M0, bias_B=mean[1] - B0,
        noise_free_bias_M=M_clean - M0, noise_free_bias_B=B_clean - B0, std_M=std[0],
        std_B=std[1], seeds=int(seeds), method=f"{label}, {source} data")


#: Realisations from which a prediction is spread over processes (fewer: not worth starting
#: them).
PARALLEL_SEEDS = 16


@dataclasses.dataclass(frozen=True)
class NoiseRuns:
    """Noisy copies of a design's noise-free data and the estimator fitted to each: from plant
    ``records`` (noise as ``simulate``) or model ``datasets`` (white noise), with J_lq^-1 at the poses.
    """

    platform: Platform
    noise: SensorNoise
    method: str
    seed: int
    records: list | None = None
    datasets: list[Dataset] | None = None
    inverse_jacobians: list[np.ndarray] | None = None

    def clean(self) -> list[Dataset]:
        """The noise-free data."""
        if self.records is None:
            return list(self.datasets)
        return measured_plant_datasets(self.platform, self.records, SensorNoise(),
                                       [np.random.default_rng(0)] * len(self.records),
                                       self.inverse_jacobians)

    def noisy(self, k: int) -> list[Dataset]:
        """Realisation ``k``: one stream per record, apart from ``simulate --seed``'s."""
        if self.records is None:
            rng = np.random.default_rng(np.random.SeedSequence([self.seed, k]))
            return [add_noise(self.platform, d, self.noise, rng, inverse_jacobian=j)
                    for d, j in zip(self.datasets, self.inverse_jacobians, strict=True)]
        streams = np.random.SeedSequence([PREDICTION_STREAM, self.seed, k]).spawn(
            len(self.records))
        return measured_plant_datasets(self.platform, self.records, self.noise,
                                       [np.random.default_rng(s) for s in streams],
                                       self.inverse_jacobians)

    def fit(self, ks: Sequence[int], progress: Callable[[int, int], None] | None = None
            ) -> np.ndarray:
        """``[M_, B_]`` on realisations ``ks``, shape (len(ks), 2, 6, 6); ``progress(done, total)`` each."""
        estimator = _monte_carlo_estimator(self.method)
        out = np.empty((len(ks), 2, 6, 6))
        for i, k in enumerate(ks):
            estimator.fit(self.noisy(int(k)), self.platform)
            out[i] = estimator.M_, estimator.B_
            if progress:
                progress(i + 1, len(ks))
        return out

    def estimates(self, ks: Sequence[int], workers: int | None = None,
                  progress: Callable[[int, int], None] | None = None) -> np.ndarray:
        """:meth:`fit` over ``workers`` processes, in the order of ``ks``."""
        ks = [int(k) for k in ks]
        if workers is None:
            workers = None if len(ks) >= PARALLEL_SEEDS else 1

        def finished(done: int, total: int, index: int) -> None:
            progress(done, total)

        fits = run_in_order(_fit_realisation, ks, workers,
                            finished if progress is not None else None, shared=self)
        return np.array(fits).reshape(len(ks), 2, 6, 6)


def _fit_realisation(runs: NoiseRuns, k: int) -> np.ndarray:
    return runs.fit([k])[0]
