"""Predicted standard errors of Method B's Mt and Bt from the information of its weak-form
equations, without a Monte Carlo.

To first order the generalized least squares of the design's estimator errs by
dz = N^-1 sum_n D_n^T W_n e_n, N = sum_n D_n^T W_n D_n, so that

    Cov(z) = N^-1 (sum_n D_n^T W_n C_n W_n D_n) N^-1,

with D_n the noise-free design of interval n, W_n its weights and C_n the true covariance of
its rows' force and pose noise. Everything is computed on the design's noise-free data with
the noise model known; the Monte Carlo check measures what first order leaves out.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable

import numpy as np

from stewartid.datasets.dataset import Dataset
from stewartid.design import pose_noise
from stewartid.design.candidates import Design
from stewartid.design.prediction import (
    DESIGN_SETTINGS,
    SOURCES,
    NoiseRuns,
    Prediction,
    default_estimator,
    inverse_leg_jacobians,
    model_datasets,
    plant_records,
    predict_accuracy,
)
from stewartid.errors import ConfigError
from stewartid.identification.preparation import Experiment, prepare_experiment
from stewartid.identification.wavelet.detection import (
    Detection,
    detect_intervals,
    excitation_scales,
)
from stewartid.identification.wavelet.estimator import MARGIN_PERIODS
from stewartid.identification.wavelet.gls import N_THETA, channel_systems, fit_invariant_rows
from stewartid.identification.wavelet.noise import NoiseModel, joint_rate_noise
from stewartid.identification.wavelet.variance_components import (
    chi2_excess,
    pose_coefficients,
    pose_covariance,
)
from stewartid.identification.wavelet.weak_form import (
    StackedEquations,
    experiment_equations,
    stack_equations,
)
from stewartid.model.linearization import nominal_matrices
from stewartid.parallel import worker_count
from stewartid.platform import Platform
from stewartid.signals.differentiation import differentiate
from stewartid.simulation.sensors import SensorNoise


def known_noise(experiment: Experiment, noise: SensorNoise) -> tuple[np.ndarray, np.ndarray]:
    """The pose noise and the generalized force's noise per sample of one noise-free experiment,
    from the sensor noise (white on lengths and forces).

    Returns
    -------
    pose : ndarray, shape (6, 6)
        J_lq^-1 Sigma_l J_lq^-T averaged over the samples (m^2, m rad, rad^2).
    force : ndarray, shape (6, 6)
        J_lq^T Sigma_f J_lq + K pose K^T averaged over the samples (N^2, N^2 m, N^2 m^2).
    """
    forces = np.broadcast_to(np.asarray(noise.force_noise, dtype=float), 6) ** 2
    jacobian = experiment.leg_jacobian
    pose = pose_noise.pose_covariance(noise, jacobian).mean(axis=0)
    force = np.einsum("nji,j,njk->ik", jacobian, forces, jacobian) / len(jacobian)
    sensitivity = experiment.force_sensitivity
    return pose, force + sensitivity @ pose @ sensitivity.T


def expected_detection(experiment: Experiment, pose: np.ndarray, force: np.ndarray,
                       settings: dict) -> Detection:
    """The intervals Method B finds in a noisy copy of a noise-free experiment.

    Parameters
    ----------
    experiment : Experiment
        Noise-free, with its joint-axis Jacobians.
    pose, force : ndarray, shape (6, 6)
        :func:`known_noise`.
    settings : dict
        The estimator's ``get_params()``.
    """
    window, margin = excitation_scales(experiment, settings["differentiation_window"],
                                       settings["margin"], MARGIN_PERIODS)
    rate = experiment.sample_rate
    _, q_dot, q_ddot = differentiate(experiment.q, rate, window)
    model = NoiseModel(window=window, q_dot=q_dot, q_ddot=q_ddot, pose_covariance=pose,
                       force_variance=np.diag(force).copy(),
                       rate_noise=joint_rate_noise(pose, rate, window,
                                                   experiment.joint_jacobians,
                                                   experiment.leg_jacobian))
    return detect_intervals(experiment, model, margin=margin, hysteresis=settings["hysteresis"],
                            ignore_below=settings["ignore_below"],
                            min_interval=settings["min_interval"],
                            min_support_samples=settings["min_support_samples"], smallest=1.0)


def expected_equations(platform: Platform, datasets: list[Dataset], noise: SensorNoise,
                       settings: dict) -> tuple[StackedEquations, np.ndarray]:
    """The weak-form equations of noise-free data, as the estimator forms them from a noisy
    copy, with the known noise of each experiment.

    Returns
    -------
    stacked : StackedEquations
        Pose noise, force sensitivity and white force variance per interval filled in.
    force : ndarray, shape (n_experiments, 6, 6)
        The full covariance of the generalized force's noise per sample of each experiment.
    """
    equations, poses, forces, sensitivities = [], [], [], []
    for k, dataset in enumerate(datasets):
        experiment = prepare_experiment(dataset, platform, settings["gravity"], joints=True)
        pose, force = known_noise(experiment, noise)
        found = expected_detection(experiment, pose, force, settings)
        equations += experiment_equations(experiment, found, int(settings["wavelet_order"]),
                                          int(settings["test_functions"]), k,
                                          settings["friction"])
        poses.append(pose)
        forces.append(force)
        sensitivities.append(experiment.force_sensitivity)
    stacked = stack_equations(equations, np.array(poses), np.array(sensitivities),
                              np.array([np.diag(f) for f in forces]))
    return stacked, np.array(forces)


def expected_scatter(stacked: StackedEquations, designs: list[np.ndarray], theta: np.ndarray,
                     variance: np.ndarray) -> np.ndarray:
    """tau (6,) the estimator's chi-square match gives on average (N, N m).

    Parameters
    ----------
    theta : ndarray, shape (6, 12)
        Invariant-row estimate on the noise-free data.
    variance : ndarray, shape (n, 6)
        Noise variance of every interval's mean row per channel.
    """
    base = stacked.mean_targets - stacked.mean_regressors @ theta.T
    nuisance = np.stack([d[:, -1, N_THETA:] for d in designs], axis=1)       # (n, 6, u)
    scaled = nuisance / np.sqrt(variance)[:, :, None]
    fitted = np.linalg.lstsq(scaled.reshape(-1, nuisance.shape[-1]),
                             (base / np.sqrt(variance)).ravel(), rcond=None)[0]
    residual = base - nuisance @ fitted
    weight = stacked.weights
    return np.sqrt([chi2_excess(variance[:, i] / weight ** 2,
                                (residual[:, i] ** 2 + variance[:, i]) / weight ** 2,
                                len(weight))
                    for i in range(6)])


def information_covariance(stacked: StackedEquations, force: np.ndarray, theta: np.ndarray,
                           model_error: np.ndarray, scatter: np.ndarray
                           ) -> tuple[np.ndarray, np.ndarray]:
    """The expected estimate and the covariance of every unknown of the joint weak-form fit
    (module docstring).

    Parameters
    ----------
    stacked : StackedEquations
    force : ndarray, shape (n_experiments, 6, 6)
        Generalized force noise per sample of each experiment.
    theta : ndarray, shape (6, 12)
        [Mt Bt] the pose noise's coefficients are taken at.
    model_error : ndarray, shape (n, 6)
        Variance per row the estimator adds for model error.
    scatter : ndarray, shape (6,)
        tau per channel.

    Returns
    -------
    z : ndarray, shape (u,)
        The fit of the noise-free equations with the weights of the noise: the mean of the
        noisy fits to first order.
    covariance : ndarray, shape (u, u)
        [Mt Bt] row-major, then the offsets and the Coulomb level.
    """
    n_experiments = int(stacked.owner.max()) + 1
    designs, targets = channel_systems(stacked, n_experiments, True)
    n, rows, n_unknowns = designs[0].shape
    gram = stacked.gram[..., :rows, :rows]
    coefficients = [pose_coefficients(stacked.sensitivity[:, i], theta[i]) for i in range(6)]
    weighted = []
    normal = np.zeros((n_unknowns, n_unknowns))
    rhs = np.zeros(n_unknowns)
    for i in range(6):
        assumed = ((stacked.white[:, i] + model_error[:, i])[:, None, None] * np.eye(rows)
                   + pose_covariance(gram, stacked.sigma, coefficients[i]))
        assumed[:, -1, -1] += (scatter[i] * stacked.weights) ** 2
        w_d = np.linalg.solve(assumed, designs[i])                           # (n, R, u)
        weighted.append(w_d)
        normal += np.einsum("nru,nrv->uv", designs[i], w_d, optimize=True)
        rhs += np.einsum("nru,nr->u", w_d, targets[i])
    # the true noise of the rows of channels i and j: force noise and pose noise, correlated
    meat = np.zeros((n_unknowns, n_unknowns))
    owner_force = force[stacked.owner]                                       # (n, 6, 6)
    for i in range(6):
        for j in range(i, 6):
            c = np.einsum("naj,njk,nbk->nab", coefficients[i], stacked.sigma, coefficients[j])
            cross = (np.einsum("nab,nabrs->nrs", c, gram)
                     + owner_force[:, i, j, None, None] * gram[:, 0, 0])
            part = np.einsum("nru,nrs,nsv->uv", weighted[i], cross, weighted[j], optimize=True)
            meat += part if i == j else part + part.T
    scale = np.sqrt(np.diag(normal))
    scale = np.where(scale > 0, scale, 1.0)
    bread = np.linalg.inv(normal / np.outer(scale, scale)) / np.outer(scale, scale)
    return bread @ rhs, bread @ meat @ bread


def pooled(z: np.ndarray, covariance: np.ndarray) -> tuple[np.ndarray, ...]:
    """Mt, Bt and their standard errors once every symmetric pair is pooled as the estimator
    pools it (inverse-variance mean, correlation kept), from [Mt Bt] row-major (the first 72
    unknowns) and their covariance.

    Returns
    -------
    M, B, std_M, std_B : ndarray, shape (6, 6)
    """
    variance = np.diag(covariance)[:N_THETA].reshape(6, 12)
    values = z[:N_THETA].reshape(6, 12)
    out = []
    for block in (0, 6):
        value = values[:, block:block + 6].copy()
        std = np.sqrt(np.clip(variance[:, block:block + 6], 0.0, None))
        for i in range(6):
            for j in range(i + 1, 6):
                a, b = 12 * i + block + j, 12 * j + block + i
                w_a, w_b = 1.0 / covariance[a, a], 1.0 / covariance[b, b]
                mean = (w_a * z[a] + w_b * z[b]) / (w_a + w_b)
                spread = (w_a ** 2 * covariance[a, a] + w_b ** 2 * covariance[b, b]
                          + 2 * w_a * w_b * covariance[a, b]) / (w_a + w_b) ** 2
                value[i, j] = value[j, i] = mean
                std[i, j] = std[j, i] = math.sqrt(max(spread, 0.0))
        out.append((value, std))
    (M, std_M), (B, std_B) = out
    return M, B, std_M, std_B


def information_estimate(platform: Platform, datasets: list[Dataset], noise: SensorNoise,
                         settings: dict) -> tuple[np.ndarray, ...]:
    """Method B's expected Mt and Bt and their standard errors on noisy copies of noise-free data.

    Parameters
    ----------
    platform : Platform
    datasets : list of Dataset
        Noise-free data, e.g. the design played on the plant.
    noise : SensorNoise
        White noise on lengths (m) and forces (N); biases and resolutions are left out.
    settings : dict
        The estimator's ``get_params()`` (``friction`` "shared" or "uniform").

    Returns
    -------
    M, B : ndarray, shape (6, 6)
        The mean estimate to first order (kg, kg m, kg m^2; N s/m, N s, N m s).
    std_M, std_B : ndarray, shape (6, 6)
        Standard errors (same units).
    """
    stacked, force = expected_equations(platform, datasets, noise, settings)
    designs, _ = channel_systems(stacked, len(datasets), True)
    invariant = fit_invariant_rows(stacked, 5)
    M0, B0 = nominal_matrices(platform)
    theta = np.hstack([M0, B0])
    model_error = np.clip(invariant.noise - stacked.white, 0.0, None)
    variance = np.stack([
        stacked.white[:, i] + model_error[:, i]
        + pose_covariance(stacked.gram, stacked.sigma,
                          pose_coefficients(stacked.sensitivity[:, i], theta[i]))[:, -1, -1]
        for i in range(6)], axis=1)
    scatter = expected_scatter(stacked, designs, invariant.theta, variance)
    return pooled(*information_covariance(stacked, force, theta, model_error, scatter))


def has_information(method: str) -> bool:
    """Whether the design's estimator for ``method`` has an information-matrix prediction
    (Method B with its interval constants tied to the friction); the others have the Monte Carlo
    alone.
    """
    return method == "wavelet" and DESIGN_SETTINGS.get(method, {}).get("friction") in (
        "shared", "uniform")


def information_prediction(platform: Platform, design: Design, noise: SensorNoise,
                           method: str = "wavelet", check_seeds: int = 0, seed: int = 0,
                           source: str = "plant", records: list | None = None,
                           workers: int | None = None,
                           progress: Callable[[int, int], None] | None = None) -> Prediction:
    """Predicted bias and standard errors of Mt and Bt for a design, the standard errors from
    the information matrix (:func:`information_estimate`).

    Parameters
    ----------
    platform : Platform
        With the friction the machine is expected to have.
    design : Design
    noise : SensorNoise
        Sensor noise standard deviations (m, N).
    method : str
        Registered method with :func:`has_information`.
    check_seeds : int
        0: the bias is the expected estimate's. >= 2: a Monte Carlo of as many realisations
        (:func:`~stewartid.design.prediction.predict_accuracy`) gives the bias and its spread,
        kept beside the standard errors as their check.
    seed : int
        Seed of the Monte Carlo's first realisation.
    source : {"plant", "model"}
        Noise-free data from the design played on the plant or from the rigid-body model.
    records : list of ExperimentRecord, optional
        The design already played on the plant, ``source="plant"``.
    workers : int, optional
        Processes the Monte Carlo is spread over.
    progress : callable, optional
        Called with (done, total) after each realisation of the Monte Carlo.

    Returns
    -------
    Prediction
        ``seeds`` = ``check_seeds``; ``monte_carlo_std_*`` set when checked.
    """
    if not has_information(method):
        raise ConfigError(f"method {method!r} has no information-matrix prediction; use "
                          "predict_accuracy (Monte Carlo).")
    if source not in SOURCES:
        raise ConfigError(f"source must be one of {', '.join(SOURCES)}; got {source!r}.")
    if check_seeds == 1 or check_seeds < 0:
        raise ConfigError(f"check_seeds must be 0 or >= 2; got {check_seeds!r}.")
    if source == "plant":
        records = plant_records(platform, design) if records is None else list(records)
        runs = NoiseRuns(platform, noise, method, int(seed), records=records,
                         inverse_jacobians=inverse_leg_jacobians(platform,
                                                                 [r.q for r in records]))
    else:
        runs = NoiseRuns(platform, noise, method, int(seed),
                         datasets=model_datasets(platform, design))
    clean = runs.clean()
    estimator = default_estimator(method)
    M, B, std_M, std_B = information_estimate(platform, clean, noise, estimator.get_params())
    M0, B0 = nominal_matrices(platform)
    label = f"{method} (friction={estimator.friction}), {source} data, information matrix"
    # no noise-free fit: on noise-free data the estimator's weights and intervals are not
    # those of a noisy fit
    prediction = Prediction(nominal_M=M0, nominal_B=B0, bias_M=M - M0, bias_B=B - B0,
                            noise_free_bias_M=None, noise_free_bias_B=None, std_M=std_M,
                            std_B=std_B, seeds=0, method=label)
    if not check_seeds:
        return prediction
    return checked_prediction(prediction, predict_accuracy(
        platform, design, noise, method, check_seeds, seed, source, records,
        worker_count(workers, check_seeds), progress))


def checked_prediction(prediction: Prediction, monte_carlo: Prediction) -> Prediction:
    """An information-matrix prediction checked by the Monte Carlo of the same design.

    The standard errors stay the information matrix's, with the Monte Carlo's spread beside them;
    the bias becomes the Monte Carlo's, which holds what first order leaves out.
    """
    return dataclasses.replace(monte_carlo, std_M=prediction.std_M, std_B=prediction.std_B,
                               monte_carlo_std_M=monte_carlo.std_M,
                               monte_carlo_std_B=monte_carlo.std_B,
                               method=f"{prediction.method}, checked by {monte_carlo.seeds} "
                                      "noise realisations")


__all__ = ["checked_prediction", "expected_detection", "expected_equations", "expected_scatter",
           "has_information", "information_covariance", "information_estimate",
           "information_prediction", "known_noise", "pooled"]
