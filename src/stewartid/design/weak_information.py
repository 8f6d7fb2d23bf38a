"""Predicted standard errors of Method B's Mt and Bt from its weak-form equations' information,
without a Monte Carlo: Cov(z) = N^-1 (sum_n D_n^T W_n C_n W_n D_n) N^-1, N = sum_n D_n^T W_n D_n,
on the design's noise-free data with the noise model known.
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
    """Pose noise J_lq^-1 Sigma_l J_lq^-T and generalized force noise J_lq^T Sigma_f J_lq + K pose K^T
    per sample, each (6, 6), averaged over one noise-free experiment.
    """
    forces = np.broadcast_to(np.asarray(noise.force_noise, dtype=float), 6) ** 2
    jacobian = experiment.leg_jacobian
    pose = pose_noise.pose_covariance(noise, jacobian).mean(axis=0)
    force = np.einsum("nji,j,njk->ik", jacobian, forces, jacobian) / len(jacobian)
    sensitivity = experiment.force_sensitivity
    return pose, force + sensitivity @ pose @ sensitivity.T


def expected_detection(experiment: Experiment, pose: np.ndarray, force: np.ndarray,
                       settings: dict) -> Detection:
    """Intervals Method B finds in a noisy copy of a noise-free experiment (with joint-axis
    Jacobians); ``pose, force`` from :func:`known_noise`, ``settings`` the estimator's ``get_params()``.
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
    """Weak-form equations of noise-free data as the estimator forms them from a noisy copy, with
    each experiment's known noise; and the force noise covariance per experiment (n, 6, 6).
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
    """tau (6,) the estimator's chi-square match gives on average (N, N m), from ``theta`` (6, 12)
    and per-interval row noise ``variance`` (n, 6).
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
    """Expected estimate z (u,) and covariance (u, u) of every unknown of the joint weak-form fit:
    [Mt Bt] row-major, then offsets and the Coulomb level.

    Parameters
    ----------
    stacked : StackedEquations
    force : ndarray, shape (n_experiments, 6, 6)
        Generalized force noise per sample.
    theta : ndarray, shape (6, 12)
        [Mt Bt] for the pose noise's coefficients.
    model_error : ndarray, shape (n, 6)
        Model-error variance per row.
    scatter : ndarray, shape (6,)
        tau per channel.
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
    """M, B, std_M, std_B (6, 6) once symmetric pairs are pooled as the estimator does
    (inverse-variance mean, correlation kept).
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
    """Method B's expected Mt, Bt and standard errors (6, 6 each) on noisy copies of noise-free data.

    Parameters
    ----------
    platform : Platform
    datasets : list of Dataset
        Noise-free data.
    noise : SensorNoise
        White noise on lengths (m) and forces (N).
    settings : dict
        Estimator's ``get_params()`` (``friction`` "shared" or "uniform").
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
    """Whether ``method``'s design estimator has an information-matrix prediction (else Monte Carlo only)."""
    return method == "wavelet" and DESIGN_SETTINGS.get(method, {}).get("friction") in (
        "shared", "uniform")


def information_prediction(platform: Platform, design: Design, noise: SensorNoise,
                           method: str = "wavelet", check_seeds: int = 0, seed: int = 0,
                           source: str = "plant", records: list | None = None,
                           workers: int | None = None,
                           progress: Callable[[int, int], None] | None = None) -> Prediction:
    """Predicted bias and standard errors of Mt and Bt for a design, standard errors from the
    information matrix (:func:`information_estimate`).

    Parameters
    ----------
    platform : Platform
        With the machine's expected friction.
    design : Design
    noise : SensorNoise
        Standard deviations (m, N).
    method : str
        A method with :func:`has_information`.
    check_seeds : int
        0: bias from the expected estimate; >= 2: a Monte Carlo gives the bias and a spread check.
    seed : int
        Monte Carlo's first seed.
    source : {"plant", "model"}
    records : list of ExperimentRecord, optional
        Design already played on the plant.
    workers : int, optional
    progress : callable, optional
        Called with (done, total).
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
    """Information-matrix prediction with the Monte Carlo's spread beside its standard errors and
    the Monte Carlo's bias (what first order leaves out).
    """
    return dataclasses.replace(monte_carlo, std_M=prediction.std_M, std_B=prediction.std_B,
                               monte_carlo_std_M=monte_carlo.std_M,
                               monte_carlo_std_B=monte_carlo.std_B,
                               method=f"{prediction.method}, checked by {monte_carlo.seeds} "
                                      "noise realisations")


__all__ = ["checked_prediction", "expected_detection", "expected_equations", "expected_scatter",
           "has_information", "information_covariance", "information_estimate",
           "information_prediction", "known_noise", "pooled"]
