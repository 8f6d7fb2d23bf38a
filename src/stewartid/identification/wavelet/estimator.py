"""Method B: wavelet transform on constant-direction intervals (Zhang 2020, doi:10.3390/math8020257).

A zero-mean psi removes an interval's constant friction: [Mt Bt] [W q_ddot ; W q_dot](a, b) = W y (a, b).
"""

from __future__ import annotations

from numbers import Integral, Real

import numpy as np

from stewartid.datasets.dataset import Dataset
from stewartid.fields import BOOLEAN, Interval, ListOf, Options, nonnegative, positive, validate_parameters
from stewartid.identification.base import BaseIdentifier
from stewartid.identification.pairs import combine_pairs
from stewartid.identification.preparation import Experiment, prepare_experiment
from stewartid.identification.registry import Preset, register_method
from stewartid.identification.result import IdentificationResult
from stewartid.identification.sampling import check_sampling
from stewartid.identification.solvers import (
    bias_compensated_least_squares,
    regressor_names,
    solve_least_squares,
)
from stewartid.identification.wavelet.detection import (
    Detection,
    check_coverage,
    detect_intervals,
    excitation_scales,
    raise_no_interval,
)
from stewartid.identification.wavelet.friction_models import (
    choose_friction_fit,
    chosen_models,
    constants_floor,
    friction_models,
    law_floor,
    model_equations,
    one_sine,
    patterns_with_half_window,
    solve_models,
)
from stewartid.identification.wavelet.gls import WeakFormSolution
from stewartid.identification.wavelet.noise import estimate_noise
from stewartid.identification.wavelet.point_equations import EXACT_DEGREE, point_equations
from stewartid.model.joints import JOINT_TYPES
from stewartid.parallel import WorkerPool, inheriting_workers
from stewartid.platform import COORDINATES, Platform
from stewartid.signals.wavelets import MotherWavelet, PolynomialWavelet, make_wavelet

#: Citation of the method.
REFERENCE = ("Zhang, C. A Parameter Identification Method for Stewart Manipulator Based on "
             "Wavelet Transform. Mathematics 8(2), 257 (2020). doi:10.3390/math8020257")
VARIANTS = ("position", "paper", "derivative")
#: Default interval margin, in periods of the estimated excitation frequency.
MARGIN_PERIODS = 0.015
PAIR_SELECTIONS = ("pooled", "std_error", "none")
FRICTION_MODELS = ("auto", "free", "shared", "uniform", "coulomb")


@register_method(
    name="wavelet", letter="B", color="#d62728",
    display_name="Method B (wavelet)",
    description="wavelet transform on constant-direction intervals, derivatives moved onto "
                "compact polynomial wavelets (the package's Method B)",
    reference=REFERENCE,
    presets={"wavelet-paper": Preset(
        settings={"variant": "paper", "wavelet": "mexican_hat", "test_functions": None},
        display_name="Method B, paper's equations (Mexican hat)",
        description="Method B with the paper's own equations: Mexican hat, W q_ddot and "
                    "a W1 q_ddot from a Savitzky-Golay acceleration",
        color="#ff7f0e")})
class WaveletIdentifier(BaseIdentifier):
    """Identify Mt and Bt by the wavelet method of Zhang (2020) (Method B).

    Parameters
    ----------
    wavelet : {"polynomial", "mexican_hat"}
        psi = g'', g = (1 - x^2)^p on [-1, 1]; or the paper's Mexican hat.
    wavelet_order : int
        Exponent p, 5..20.
    truncation : float
        Mexican hat half-width, scales.
    variant : {"position", "paper", "derivative"}
        "position": both derivatives moved onto the wavelet; "paper": Savitzky-Golay q_ddot and
        W q_dot = -a W_psi1 q_ddot; "derivative": Savitzky-Golay q_ddot and q_dot.
    test_functions : int or None
        Orthonormal zero-mean test functions per interval, 1..12 (polynomial, position); None: the
        paper's (a, b) points.
    friction : {"auto", "free", "shared", "uniform", "coulomb"}
        "coulomb": windows across reversals with per-type Coulomb forces (electric legs, without
        "free" beside it: their stops' friction left free, the windows shortened to leave rows
        beside it); "free": every interval constant free; "shared": per-experiment offsets and
        per-type levels; "uniform": one level; "auto": "coulomb", or on one sine per experiment
        the better of it and "free".
    scale_fractions : tuple of float
        Wavelet supports as fractions of the interval, in (0, 1].
    shifts_per_scale : int
    margin : float or None
        Cut from both ends of every interval, s; None: :data:`MARGIN_PERIODS` periods.
    ignore_below : float
        Joints slower than this fraction of the fastest of their kind are left out.
    min_interval : float or None
        Shortest usable interval, s; None: half the median.
    min_support_samples : int
        Fewest samples the smallest wavelet may cover.
    differentiation_window : float or None
        Savitzky-Golay window, s; None: a fifth of the period of the pose's line of
        largest acceleration (the fastest of a multi-sine's falling amplitudes).
    hysteresis : float
        A direction is known only while the rate exceeds this many noise levels.
    odd_companion : bool
        Also use the odd companion g''' (``test_functions=None``, order >= 8).
    noise_correction : bool
        Weight by and remove the pose noise's errors-in-variables bias (position variant).
    symmetric : bool
        Impose Mt = Mt^T, Bt = Bt^T.
    pair_selection : {"pooled", "std_error", "none"}
        Symmetric pairs: inverse-variance mean within 3 standard errors, else the translational one;
        or the better-determined member.
    gravity : bool
        Subtract the model's G(q).
    remainder : bool
        Subtract the model's departure from its linearisation.
    sampling_check : bool
        Widen standard errors where the log's sampling limits them.
    sign_window_check : bool
        Where pose noise lengthened the Coulomb signs' window, refit with the signs from half of
        it and widen the standard errors by the distance
        (:mod:`~stewartid.identification.sign_window`).
    jobs : int or None
        Worker processes preparing the experiments' equations side by side, then solving the
        friction models (or one model's soft-sign rates) side by side (None: every core; one
        where workers cannot start by fork, :func:`~stewartid.parallel.inheriting_workers`); the
        results do not depend on it.

    Attributes
    ----------
    M_, B_ : ndarray, shape (6, 6)
    std_errors_ : dict of ndarray (6, 6)
    condition_number_ : float
    result_ : IdentificationResult
        Diagnostics: intervals, (a, b) points, joints left out, symmetric pairs taken.
    """

    def __init__(self, wavelet: str = "polynomial", wavelet_order: int = 6,
                 truncation: float = 5.0, variant: str = "position",
                 scale_fractions: tuple[float, ...] = (1.0, 0.8, 0.6),
                 shifts_per_scale: int = 5, test_functions: int | None = 8,
                 friction: str = "auto", margin: float | None = None, ignore_below: float = 0.01,
                 min_interval: float | None = None, min_support_samples: int = 32,
                 differentiation_window: float | None = None, hysteresis: float = 4.0,
                 odd_companion: bool = False, noise_correction: bool = True,
                 symmetric: bool = False,
                 pair_selection: str = "pooled", gravity: bool = True, remainder: bool = True,
                 sampling_check: bool = True,
                 sign_window_check: bool = True, jobs: int | None = 1):
        self.wavelet = wavelet
        self.wavelet_order = wavelet_order
        self.truncation = truncation
        self.variant = variant
        self.scale_fractions = scale_fractions
        self.shifts_per_scale = shifts_per_scale
        self.test_functions = test_functions
        self.friction = friction
        self.margin = margin
        self.ignore_below = ignore_below
        self.min_interval = min_interval
        self.min_support_samples = min_support_samples
        self.differentiation_window = differentiation_window
        self.hysteresis = hysteresis
        self.odd_companion = odd_companion
        self.noise_correction = noise_correction
        self.symmetric = symmetric
        self.pair_selection = pair_selection
        self.gravity = gravity
        self.remainder = remainder
        self.sampling_check = sampling_check
        self.sign_window_check = sign_window_check
        self.jobs = jobs

    # ------------------------------------------------------------------ settings
    _parameter_constraints = {
        "wavelet": [Options(("polynomial", "mexican_hat"))],
        "variant": [Options(VARIANTS)],
        "scale_fractions": [Interval(Real, 0, 1, "right"), ListOf(Interval(Real, 0, 1, "right"))],
        "shifts_per_scale": [Interval(Integral, 1, 1000, "both")],
        "margin": [nonnegative(), None],
        "ignore_below": [Interval(Real, 0, 1, "left")],
        "min_interval": [positive(), None],
        "min_support_samples": [Interval(Integral, 8, None)],
        "differentiation_window": [positive(), None],
        "hysteresis": [nonnegative()],
        "test_functions": [Interval(Integral, 1, 12, "both"), None],
        "friction": [Options(FRICTION_MODELS)],
        "sampling_check": [BOOLEAN],
        "sign_window_check": [BOOLEAN],
        "pair_selection": [Options(PAIR_SELECTIONS)],
        "jobs": [Interval(Integral, 1, None), None],
    }

    def _validate_params(self) -> None:
        super()._validate_params()
        owner, params = type(self).__name__, self.get_params()
        if self.test_functions is None:  # the point equations have no interval constants
            validate_parameters({"friction": [Options(("auto", "free"))]}, params, owner,
                                condition="test_functions is None")
        else:
            validate_parameters({"wavelet": [Options(("polynomial",))],
                                 "variant": [Options(("position",))],
                                 "wavelet_order": [Interval(Integral, 3, None)]}, params, owner,
                                condition="test_functions is set (use test_functions=None "
                                          "for the paper's equations or the Mexican hat)")
        make_wavelet(self.wavelet, **self._wavelet_options())

    def _wavelet_options(self) -> dict:
        if self.wavelet == "polynomial":
            return {"order": self.wavelet_order}
        return {"truncation": self.truncation}

    # ------------------------------------------------------------------ steps
    def _noise_and_intervals(self, experiment: Experiment, smallest: float) -> Detection:
        """The noise model, then the usable intervals, of one prepared experiment."""
        window, margin = excitation_scales(experiment, self.differentiation_window,
                                           self.margin, MARGIN_PERIODS)
        noise = estimate_noise(experiment, window)
        return detect_intervals(
            experiment, noise, margin=margin, hysteresis=self.hysteresis,
            ignore_below=self.ignore_below, min_interval=self.min_interval,
            min_support_samples=self.min_support_samples, smallest=smallest)

    def _fit_weak_form(self, datasets: list[Dataset], platform: Platform,
                       wavelet: MotherWavelet) -> tuple[IdentificationResult, dict]:
        """Test-function families per interval, one experiment at a time (long logs fit in memory)."""
        # a ball screw's Coulomb friction along each leg: one more level, in N
        legs = platform.actuator.kind == "electric"
        workers = inheriting_workers(self.jobs, len(datasets))
        # the same workers build the experiments' equations, then solve at the soft-sign rates
        with WorkerPool(workers, len(datasets), (self, datasets, platform,
                                                 friction_models(self.friction), legs)) as pool:
            # each experiment tells whether it is one sine beside its equations (its dominant
            # frequency is its detection's), and the models follow from all of them
            parts = pool.map_shared(_experiment_equations, range(len(datasets)))
            models = chosen_models(self.friction, [part[4] for part in parts])
            equations: dict[str, list] = {model: [] for model in models}
            for part in parts:
                for model in models:
                    equations[model] += part[0][model]
            infos, sensitivities, motion = ([part[k] for part in parts] for k in (1, 2, 3))
            noise = ({"pose_covariance": [i["noise_covariance"] for i in infos],
                      "force_variance": [i["force_noise_variance"] for i in infos],
                      "force_sensitivity": sensitivities} if self.noise_correction else {})
            solved, refused = solve_models(models, equations, infos, motion, noise, pool)

        def result_of(model: str) -> tuple[IdentificationResult, dict]:
            solution, rate = solved[model]
            return self._weak_form_result(solution, infos, len(equations[model]), wavelet,
                                          model, rate, legs and model in ("free", "coulomb"))

        fits = {model: result_of(model) for model in solved}
        if "free" in fits and "coulomb" in fits:
            # before the choice: the law's bias, as the free constants' fit measures it, then
            # that fit's own, from the Coulomb torques it leaves out at the law's levels
            fits["coulomb"] = (law_floor(fits["coulomb"][0], fits["free"][0]), fits["coulomb"][1])
            floored = constants_floor(solved["free"][0], *solved["coulomb"])
            if floored is not solved["free"][0]:
                solved["free"] = (floored, solved["free"][1])
                fits["free"] = result_of("free")
        chosen, why = choose_friction_fit({model: fit[0] for model, fit in fits.items()},
                                          {model: solution for model, (solution, _) in
                                           solved.items()})
        result, learned = fits[chosen]
        self.pair_calibration_ = result.diagnostics["pair_calibration"]
        result.diagnostics.update(why, **({"friction_refused": refused} if refused else {}))
        return result, learned

    def _weak_form_result(self, solution: WeakFormSolution, infos: list[dict],
                          n_intervals: int, wavelet: MotherWavelet, friction: str,
                          rate: float, legs: bool = False) -> tuple[IdentificationResult, dict]:
        """The result and the learned Coulomb levels of :meth:`_fit_weak_form`; ``legs``: the last
        level is the legs' (N)."""
        M, B = solution.theta[:, :6].copy(), solution.theta[:, 6:12].copy()
        std_M, std_B = solution.theta_std[:, :6].copy(), solution.theta_std[:, 6:12].copy()
        chosen = self._combine_pairs(M, B, std_M, std_B, clip=friction == "free")
        joint_levels = (solution.coulomb[:-1], solution.coulomb_std[:-1]) if legs else (
            solution.coulomb, solution.coulomb_std)
        levels, levels_std = (dict(zip(JOINT_TYPES, np.resize(v, 3).tolist(), strict=True))
                              for v in joint_levels)  # uniform: 1
        leg_levels = ({"leg_coulomb": float(solution.coulomb[-1]),
                       "leg_coulomb_std": float(solution.coulomb_std[-1])} if legs else {})
        diagnostics = {
            "position_noise_std": [np.sqrt(np.diag(i["noise_covariance"])).tolist()
                                   for i in infos],
            "wavelet": wavelet.to_dict(), "test_functions": int(self.test_functions),
            "n_equations": solution.n_equations, "n_intervals": n_intervals,
            "experiments": [{"name": i["name"], "intervals_found": i["intervals_found"],
                             "intervals": i["intervals"].tolist(),
                             **{key: i[key] for key in ("stopped_share", "stop_window_s")
                                if key in i}} for i in infos],
            "pair_choice": chosen, "pair_calibration": self.pair_calibration_,
            "coordinates": list(COORDINATES), "friction_model": friction,
            "soft_sign_rate": rate, "soft_sign_weights": solution.rate_weights,
            "coulomb": levels, "coulomb_std": levels_std, **leg_levels,
            "offsets": solution.offsets, "noise_std": solution.noise_std,
            "constant_scatter": solution.constant_scatter,
            "pose_noise_share": solution.pose_noise_share}
        result = IdentificationResult(
            M=M, B=B, std_errors_M=std_M, std_errors_B=std_B,
            condition_number=solution.condition_number, residual_rms=solution.noise_std,
            method=self.method, settings=self._settings(), diagnostics=diagnostics)
        return result, {"coulomb_": levels, "coulomb_std_": levels_std}

    def _check_sampling(self, datasets: list[Dataset], platform: Platform,
                        result: IdentificationResult, learned: dict
                        ) -> tuple[IdentificationResult, dict]:
        """The sampling check, its thinned fits under the friction model the full-rate fit chose."""
        chosen = result.diagnostics.get("friction_model")
        if self.friction != "auto" or chosen is None:
            return super()._check_sampling(datasets, platform, result, learned)
        fixed = type(self)(**{**self.get_params(), "friction": chosen})
        return check_sampling(lambda part: fixed._fit(part, platform)[0], datasets,
                              result), learned

    def _point_equations(self, experiment: Experiment, wavelet: MotherWavelet):
        """Wavelet equations at (a, b) points with per-row pose-noise moments (12, 12), (12, 6)."""
        found = self._noise_and_intervals(experiment, min(self.scale_fractions))
        wavelets = [wavelet]
        if self.odd_companion and isinstance(wavelet, PolynomialWavelet):
            wavelets.append(PolynomialWavelet(wavelet.order, odd=True))
        x, y, owner, products, info = point_equations(
            experiment, found, wavelets, tuple(self.scale_fractions),
            int(self.shifts_per_scale), self.variant)
        if len(x) and self.noise_correction and self.variant == "position":
            sigma, sens = info["noise_covariance"], experiment.force_sensitivity
            noise_xx = np.einsum("kuv,ij->kuivj", products[:, :2, :2], sigma
                                 ).reshape(len(x), 12, 12)
            noise_xy = np.einsum("ku,ij->kuij", products[:, :2, 2],
                                 sigma @ sens.T).reshape(len(x), 12, 6)
        else:
            noise_xx, noise_xy = np.zeros((len(x), 12, 12)), np.zeros((len(x), 12, 6))
        return x, y, owner, noise_xx, noise_xy, info

    def _combine_pairs(self, M: np.ndarray, B: np.ndarray, std_M: np.ndarray,
                       std_B: np.ndarray, clip: bool = False) -> dict:
        """Symmetric pairs, in place; ``clip`` for the free interval constants."""
        chosen, self.pair_calibration_ = combine_pairs(
            M, B, std_M, std_B, bool(self.symmetric), self.pair_selection, clip)
        return chosen

    def _fit(self, datasets: list[Dataset], platform: Platform
             ) -> tuple[IdentificationResult, dict]:
        wavelet = make_wavelet(self.wavelet, **self._wavelet_options())
        if self.test_functions is not None:
            return self._fit_weak_form(datasets, platform, wavelet)
        phi, target, cluster, infos, noise_xx, noise_xy, motion = [], [], [], [], [], [], []
        offset = 0
        for dataset in datasets:
            experiment = prepare_experiment(dataset, platform, self.gravity, joints=True,
                                            remainder=self.remainder)
            x, y, owner, xx, xy, info = self._point_equations(experiment, wavelet)
            phi.append(x)
            target.append(y)
            cluster.append(owner + offset)
            noise_xx.append(xx)
            noise_xy.append(xy)
            infos.append(info)
            motion.append(np.std(experiment.q, axis=0))
            offset += len(info["intervals"])
            del experiment
        phi, target, cluster = np.vstack(phi), np.vstack(target), np.concatenate(cluster)
        noise_xx, noise_xy = np.concatenate(noise_xx), np.concatenate(noise_xy)
        if len(phi) == 0:
            raise_no_interval(infos)
        check_coverage([i["name"] for i in infos], np.array(motion),
                       [len(i["intervals"]) for i in infos])
        names = regressor_names("q_ddot", "q_dot")
        solution = solve_least_squares(phi, target, symmetric=bool(self.symmetric),
                                       regressor_names=names)
        theta, std = solution.theta, solution.theta_std
        if not self.symmetric:
            theta, std = bias_compensated_least_squares(phi, target, cluster, noise_xx,
                                                        noise_xy)
        M, B = theta[:, :6].copy(), theta[:, 6:12].copy()
        std_M, std_B = std[:, :6].copy(), std[:, 6:12].copy()
        self.pair_calibration_ = {}
        chosen = {} if self.symmetric else self._combine_pairs(M, B, std_M, std_B)
        residual = target - phi @ theta.T
        diagnostics = {
            "position_noise_std": [np.sqrt(np.diag(i["noise_covariance"])).tolist()
                                   for i in infos],
            "wavelet": wavelet.to_dict(), "n_equations": int(len(phi)),
            "n_intervals": int(offset),
            "experiments": [
                {"name": info["name"], "intervals_found": info["intervals_found"],
                 "intervals": info["intervals"].tolist(),
                 "scales": info["scales"].tolist(), "shifts": info["shifts"].tolist()}
                for info in infos],
            "pair_choice": chosen, "pair_calibration": self.pair_calibration_,
            "coordinates": list(COORDINATES)}
        return IdentificationResult(
            M=M, B=B, std_errors_M=std_M, std_errors_B=std_B,
            condition_number=solution.condition_number,
            residual_rms=np.sqrt(np.mean(residual ** 2, axis=0)), method=self.method,
            settings=self._settings(),
            diagnostics=diagnostics), {}


def _experiment_equations(work: tuple, k: int) -> tuple[dict[str, list], dict, np.ndarray,
                                                        np.ndarray, bool]:
    """Experiment ``k``'s weak-form equations under each friction model, its detection info,
    force sensitivity (6, 6), pose spread (6,) and whether it is one sine: one task of
    :meth:`WaveletIdentifier._fit_weak_form` (``work``: the estimator, the data sets, the platform,
    the friction models and whether the legs carry a Coulomb level). Under "auto" an experiment
    of more than one sine builds no "free" equations: :func:`chosen_models` drops them."""
    estimator, datasets, platform, models, legs = work
    single = estimator.friction != "auto" or one_sine(datasets[k])
    models = [model for model in models if single or model != "free"]
    experiment = prepare_experiment(datasets[k], platform, estimator.gravity, joints=True,
                                    remainder=estimator.remainder)
    found = estimator._noise_and_intervals(experiment, 1.0)
    patterns = (patterns_with_half_window(experiment, found, legs, estimator.sign_window_check)
                if {"free", "coulomb"} & set(models) else None)
    if patterns is not None and len(models) > 1:  # intervals and windows overlap: all at once
        patterns = patterns[:]
    # the legs' stops in the law's windows, unless the free interval constants are fitted
    # beside them (one sine per experiment: the stops fall between the intervals)
    stops = legs and "free" not in models
    equations = {model: model_equations(model, experiment, found, int(estimator.wavelet_order),
                                        int(estimator.test_functions), k, patterns, stops)
                 for model in models}
    return (equations, found.info, experiment.force_sensitivity, np.std(experiment.q, axis=0),
            single)


__all__ = ["EXACT_DEGREE", "FRICTION_MODELS", "MARGIN_PERIODS", "PAIR_SELECTIONS", "VARIANTS",
           "WaveletIdentifier"]
