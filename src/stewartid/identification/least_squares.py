"""Time-domain least squares with Coulomb friction: the inverse-dynamics model of robotics.

y = Mt q_ddot + Bt q_dot + c_e + sum_types Fc_type S_type, S_type = sum J_j^T sign(J_j q_dot)
(Khalil and Dombre 2002, ch. 12); with friction along the legs (an electric leg's screw and
nut) one more level Fc_leg S_leg, S_leg = sum_legs J_l^T sign(J_l q_dot), J_l a row of J_lq.
The viscous friction along the legs, J_lq^T c J_lq q_dot, is part of Bt.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from numbers import Integral
from typing import NamedTuple

import numpy as np

from stewartid.datasets.dataset import Dataset
from stewartid.fields import BOOLEAN, Interval, Options, nonnegative
from stewartid.identification.base import DIFFERENTIATION_CONSTRAINTS, BaseIdentifier
from stewartid.identification.friction_shape import (
    COULOMB_SHAPES,
    EXACT_SIGN,
    akaike_weights,
    average_solutions,
    shaped_sign,
    widened_by_exact_sign,
)
from stewartid.identification.pairs import calibrate_by_pairs
from stewartid.identification.preparation import Experiment, prepare_experiment
from stewartid.identification.registry import register_method
from stewartid.identification.result import IdentificationResult
from stewartid.identification.sign_window import widened_by_sign_window
from stewartid.identification.solvers import regressor_names, solve_least_squares
from stewartid.identification.stops import find_stops, project_out, stop_basis
from stewartid.identification.wavelet.noise import sign_pose_noise
from stewartid.model.joints import JOINT_TYPES
from stewartid.model.kinematics import joint_axis_rates, joint_type_forces
from stewartid.parallel import inheriting_workers, run_in_order
from stewartid.platform import Platform
from stewartid.signals.differentiation import (
    DEFAULT_ORDER,
    default_window,
    differentiate,
    estimate_frequency,
    kernel_taps,
    trim,
)
from stewartid.signals.filtered_rows import kernel_filter_rows
from stewartid.signals.sign_rates import (
    coulomb_sign_rates,
    lengthened_by_noise,
    shorter_sign_window,
    sign_rates,
)


def pose_noise_gram(q: np.ndarray, sample_rate: float, window: float) -> np.ndarray:
    """Covariance (12, 12) of the pose noise a row [q * h'', q * h'] carries."""
    from stewartid.identification.wavelet.noise import white_noise_covariance

    smooth = differentiate(q, sample_rate, window, derivatives=(0,))[0]
    sigma = white_noise_covariance(q, smooth)
    _, first, second = kernel_taps(sample_rate, window, derivatives=2)
    block = np.zeros((12, 12))
    block[:6, :6] = sigma * np.sum(second ** 2)
    block[6:, 6:] = sigma * np.sum(first ** 2)
    return block


def coulomb_regressors(joint_jacobians: np.ndarray, q_dot: np.ndarray, smoothing: float,
                       shape: str = "algebraic") -> np.ndarray:
    """Generalized Coulomb force per unit level S_type (N, 3, 6), one per :data:`JOINT_TYPES`.

    ``joint_jacobians`` (N, 6, 5, 6); ``smoothing`` s, rad/s, and ``shape`` as
    :func:`~stewartid.identification.friction_shape.shaped_sign`.
    """
    return shaped_coulomb_regressors(joint_jacobians, [q_dot], smoothing, (shape,))[:, 0]


def shaped_coulomb_regressors(joint_jacobians: np.ndarray, q_dots: Sequence[np.ndarray],
                              smoothing: float, shapes: Sequence[str],
                              out: np.ndarray | None = None) -> np.ndarray:
    """:func:`coulomb_regressors` (N, R, 3, 6) of R sets of signs: the rates ``q_dots[r]`` (N, 6)
    under the sign shape ``shapes[r]``.

    The joint-axis rates once per run of the same rate array, and one product for every set;
    ``out`` (N, R, 3, 6), written and returned when given.
    """
    n = len(joint_jacobians)
    if out is None:
        out = np.empty((n, len(shapes), len(JOINT_TYPES), 6))
    signs = np.empty((min(n, COULOMB_CHUNK), len(shapes), 6, 5))
    for lo in range(0, n, COULOMB_CHUNK):  # blocks keep the temporaries in cache
        hi = min(n, lo + COULOMB_CHUNK)
        jacobians = joint_jacobians[lo:hi]
        for r, (q_dot, shape) in enumerate(zip(q_dots, shapes, strict=True)):
            if r == 0 or q_dot is not q_dots[r - 1]:
                rates = joint_axis_rates(jacobians, q_dot[lo:hi])
            signs[:hi - lo, r] = shaped_sign(rates, smoothing, shape)
        joint_type_forces(signs[:hi - lo], jacobians, out=out[lo:hi])
    return out


#: Samples per block of :func:`shaped_coulomb_regressors`.
COULOMB_CHUNK = 1000


#: Filtered rows kept per filter window by default (``decimate``): fewer change the estimates by
#: a fraction of their standard errors (docs/benchmarks.md), more only cost time and memory.
ROWS_PER_WINDOW = 40


def leg_coulomb_regressor(leg_jacobian: np.ndarray, q_dot: np.ndarray, smoothing: float,
                          shape: str = "algebraic", stopped: np.ndarray | None = None
                          ) -> np.ndarray:
    """Generalized force per newton of Coulomb friction along every leg, S_leg (N, 1, 6).

    S_leg = sum_legs J_l^T sign(J_l q_dot), J_l (N, 6, 6) the rows of the leg Jacobian
    ``leg_jacobian``; ``smoothing`` s in m/s of leg rate, ``shape`` as
    :func:`~stewartid.identification.friction_shape.shaped_sign`; ``stopped`` (N, 6), the legs'
    stops (:func:`~stewartid.identification.stops.find_stops`), where the law gives nothing.
    """
    rates = np.einsum("nlc,nc->nl", leg_jacobian, q_dot)
    signs = shaped_sign(rates, smoothing, shape)
    if stopped is not None:
        signs = np.where(stopped, 0.0, signs)
    return np.einsum("nl,nlc->nc", signs, leg_jacobian)[:, None]


def uses_leg_coulomb(setting: bool | None, platform: Platform) -> bool:
    """Whether to fit the Coulomb friction along the legs: ``setting``, or when None, for an
    electric ``[actuator]`` (a ball screw's friction is of the order of its inertial force;
    a hydraulic cylinder's seals are in its measured pressures' force)."""
    return platform.actuator.kind == "electric" if setting is None else bool(setting)


class _Rows(NamedTuple):
    """One experiment's rows: times, support, decimation, force, rates (K, 6), Coulomb regressors,
    pose-noise Gram, the offset's regressor (K,), the rows the legs' stops took and, where noise
    lengthened the signs' window, the first shape's Coulomb regressors from half of it."""

    t: np.ndarray
    window: float
    decimate: int
    y: np.ndarray
    q_dot: np.ndarray
    q_ddot: np.ndarray
    coulomb: list[np.ndarray]
    noise: np.ndarray | None
    offset: np.ndarray
    absorbed: int = 0
    half_window: np.ndarray | None = None


@register_method(
    name="ls", color="#2ca02c",
    display_name="Time-domain least squares",
    description="time-domain least squares of the inverse-dynamics model with Coulomb "
                "regressors and per-experiment offsets",
    reference="Khalil, W., Dombre, E. Modeling, Identification and Control of Robots, "
              "ch. 12 (2002)")
class LeastSquaresIdentifier(BaseIdentifier):
    """Time-domain least squares for Mt, Bt, per-experiment offsets and Coulomb levels.

    Parameters
    ----------
    window : float, optional
        Filter window, s; default 0.2 periods of each experiment's dominant frequency.
    order : int
        Savitzky-Golay polynomial order.
    gravity : bool
        Subtract the model's G(q).
    remainder : bool
        Subtract the model's nonlinear remainder.
    sampling_check : bool
        Widen standard errors where the log's sampling limits them.
    sign_window_check : bool
        Where pose noise lengthened the Coulomb signs' window, refit with the signs from half of
        it and widen the standard errors by the distance
        (:mod:`~stewartid.identification.sign_window`).
    coulomb : bool
        Include the three Coulomb regressors.
    leg_coulomb : bool, optional
        With ``coulomb``, also the Coulomb friction along the legs (one level for the six
        identical legs, N); default: when ``[actuator] kind`` is electric.
    coulomb_smoothing : float
        Rate below which a Coulomb sign is attenuated: rad/s of a joint, m/s of a leg.
    coulomb_shape : {'average', 'algebraic', 'erf'}
        Sign shape, or the Akaike-weighted average of both (default). With a smoothing above
        zero, the standard errors also count a fit with the exact sign
        (:func:`~stewartid.identification.friction_shape.widened_by_exact_sign`).
    leg_stops : bool
        With the legs' Coulomb friction, leave the legs' stops out of its sign law and fit their
        friction freely (:mod:`~stewartid.identification.stops`; kernel only).
    symmetric : bool
        Impose Mt = Mt^T, Bt = Bt^T.
    differentiation : {'kernel', 'savgol'}
        Filter both sides with a smooth kernel, or differentiate with Savitzky-Golay.
    decimate : int, optional
        Keep every ``decimate``-th filtered row; default: :data:`ROWS_PER_WINDOW` rows per filter
        window (the filtered rows are smooth over the window: more of them add no information).
    noise_correction : bool
        Remove the errors-in-variables bias of pose noise (kernel only).
    jobs : int or None
        Worker processes building the experiments' rows side by side (None: every core; one
        where workers cannot start by fork, :func:`~stewartid.parallel.inheriting_workers`); the
        results do not depend on it.

    Attributes
    ----------
    M_, B_ : ndarray, shape (6, 6)
    std_errors_ : dict of ndarray (6, 6)
    coulomb_, coulomb_std_ : dict
        Coulomb level per joint type and its standard error, N m.
    leg_coulomb_, leg_coulomb_std_ : float
        Coulomb friction along each leg and its standard error, N; NaN when not fitted.
    coulomb_shape_weights_ : dict
    offsets_ : ndarray, shape (n_experiments, 6)
    condition_number_ : float
    result_ : IdentificationResult
    """

    def __init__(self, window: float | None = None, order: int = DEFAULT_ORDER,
                 gravity: bool = True, coulomb: bool = True, leg_coulomb: bool | None = None,
                 coulomb_smoothing: float = 1e-4,
                 coulomb_shape: str = "average", leg_stops: bool = True,
                 symmetric: bool = False,
                 decimate: int | None = None,
                 differentiation: str = "kernel", noise_correction: bool = True,
                 remainder: bool = True, sampling_check: bool = True,
                 sign_window_check: bool = True, jobs: int | None = 1):
        self.window = window
        self.order = order
        self.gravity = gravity
        self.remainder = remainder
        self.coulomb = coulomb
        self.leg_coulomb = leg_coulomb
        self.coulomb_smoothing = coulomb_smoothing
        self.coulomb_shape = coulomb_shape
        self.leg_stops = leg_stops
        self.symmetric = symmetric
        self.decimate = decimate
        self.differentiation = differentiation
        self.noise_correction = noise_correction
        self.sampling_check = sampling_check
        self.sign_window_check = sign_window_check
        self.jobs = jobs

    _parameter_constraints = {
        **DIFFERENTIATION_CONSTRAINTS,
        "leg_coulomb": [BOOLEAN, None],
        "coulomb_smoothing": [nonnegative()],
        "coulomb_shape": [Options(("average", *COULOMB_SHAPES))],
        "leg_stops": [BOOLEAN],
        "differentiation": [Options(("kernel", "savgol"))],
        "decimate": [Interval(Integral, 1, None), None],
        "noise_correction": [BOOLEAN],
        "sampling_check": [BOOLEAN],
        "sign_window_check": [BOOLEAN],
        "jobs": [Interval(Integral, 1, None), None],
    }

    def _coulomb_units(self, exp: Experiment, rows: slice, q_dots: Sequence[np.ndarray],
                       shapes: Sequence[str], legs: bool, stopped: np.ndarray | None = None,
                       out: np.ndarray | None = None) -> np.ndarray:
        """Coulomb regressors (K, R, 3 or 4, 6) of ``rows`` of an experiment, R sets of signs as
        :func:`shaped_coulomb_regressors`; ``stopped`` as :func:`leg_coulomb_regressor`; ``out``
        written and returned when given."""
        if out is None:
            out = np.empty((len(exp.t[rows]), len(shapes), len(JOINT_TYPES) + legs, 6))
        if not shapes:
            return out
        shaped_coulomb_regressors(exp.joint_jacobians[rows], q_dots, self.coulomb_smoothing,
                                  shapes, out=out[:, :, :len(JOINT_TYPES)])
        if legs:
            for r, (q_dot, shape) in enumerate(zip(q_dots, shapes, strict=True)):
                out[:, r, -1] = leg_coulomb_regressor(exp.leg_jacobian[rows], q_dot,
                                                      self.coulomb_smoothing, shape, stopped)[:, 0]
        return out

    def _experiment_rows(self, exp: Experiment, shapes: tuple[str, ...], legs: bool) -> _Rows:
        """One prepared experiment's rows; ``legs`` adds the legs' Coulomb regressor."""
        window = self.window or default_window(estimate_frequency(exp.q, exp.sample_rate))
        decimate = self.decimate or max(1, int(window * exp.sample_rate) // ROWS_PER_WINDOW)
        if self.differentiation == "savgol":
            _, qd, qdd = differentiate(exp.q, exp.sample_rate, window, self.order)
            cut = trim(window, exp.sample_rate, self.order)
            sl = slice(cut, len(exp.t) - cut, decimate)
            units = self._coulomb_units(exp, sl, [qd[sl]] * len(shapes), shapes, legs)
            return _Rows(exp.t[sl], window, decimate, exp.generalized_force[sl], qd[sl],
                         qdd[sl], list(units.transpose(1, 0, 2, 3)), None, np.ones(len(qd[sl])))
        # the Coulomb signs need the rates at every sample, from a window the noise allows
        # (the physical model's rule), so that they do not chatter
        stops, qd_sign, refit = None, None, False
        if shapes:
            pose_noise = sign_pose_noise(exp.q, exp.sample_rate, window)
            if legs and self.leg_stops:
                stops = find_stops(exp.q, exp.leg_jacobian, exp.sample_rate, window, pose_noise)
                qd_sign = stops.q_dot
            else:
                qd_sign, sign_window = coulomb_sign_rates(exp.q, exp.sample_rate, window,
                                                          pose_noise)
                refit = self.sign_window_check and lengthened_by_noise(window, sign_window)
        # the signs of every shape, then the first shape's from the half window (the refit of
        # the signs' window), filtered with the force in one buffer
        q_dots, sets = [qd_sign] * len(shapes), list(shapes)
        if refit:
            q_dots.append(sign_rates(exp.q, exp.sample_rate,
                                     shorter_sign_window(window, sign_window)))
            sets.append(shapes[0])
        levels = len(JOINT_TYPES) + legs
        width = 6 * levels
        signals = np.empty((len(exp.t), 6 + width * len(sets)))
        signals[:, :6] = exp.generalized_force
        self._coulomb_units(exp, slice(None), q_dots, sets, legs,
                            None if stops is None else stops.stopped,
                            out=signals[:, 6:].reshape(len(exp.t), len(sets), levels, 6))
        # only every decimate-th row is kept: direct sums cost less than FFTs of every row
        filtered = kernel_filter_rows(signals, exp.sample_rate, window, decimate)
        qd, qdd = (kernel_filter_rows(exp.q, exp.sample_rate, window, decimate, derivative=k)
                   for k in (1, 2))
        cut = len(kernel_taps(exp.sample_rate, window)[0]) // 2
        sl = slice(cut, len(exp.t) - cut, decimate)
        y = filtered[:, :6]
        coulomb = [filtered[:, 6 + width * k:6 + width * (k + 1)].reshape(len(y), -1, 6)
                   for k in range(len(sets))]
        coulomb, half = coulomb[:len(shapes)], coulomb[len(shapes):]
        noise = (pose_noise_gram(exp.q, exp.sample_rate, window) if self.noise_correction
                 else None)
        offset = np.ones(len(y))
        absorbed = 0
        if stops is not None:  # the stops' free friction out of every row
            basis = stop_basis(stops, exp.sample_rate, window, decimate, exp.name)
            y, qd, qdd, offset, *coulomb = project_out(basis, y, qd, qdd, offset, *coulomb)
            absorbed = basis.shape[1]
        return _Rows(exp.t[sl], window, decimate, y, qd, qdd, coulomb, noise, offset, absorbed,
                     half[0] if half else None)

    def _fit(self, datasets: list[Dataset], platform: Platform
             ) -> tuple[IdentificationResult, dict]:
        n_exp = len(datasets)
        shapes = (() if not self.coulomb else COULOMB_SHAPES if self.coulomb_shape == "average"
                  else (self.coulomb_shape,))
        # the exact sign beside the soft ones: how far the band's law moves the estimates
        exact = bool(shapes) and self.coulomb_smoothing > 0
        variants = shapes + (EXACT_SIGN,) * exact
        legs = bool(shapes) and uses_leg_coulomb(self.leg_coulomb, platform)
        shared: list[list[np.ndarray]] = [[] for _ in variants]
        # the first shape's regressors with the signs from half their window, where noise
        # lengthened it (elsewhere the window's own)
        half: list[np.ndarray] = []
        lengthened = False
        phis, ys, used, noise, segments = [], [], [], [], []
        absorbed = 0
        workers = inheriting_workers(self.jobs, n_exp)
        built = run_in_order(_experiment_rows, range(n_exp), workers,
                             shared=(self, datasets, platform, variants, legs))
        for e, (rows, name, rate) in enumerate(built):
            k = len(rows.y)
            offsets = np.zeros((k, n_exp))
            offsets[:, e] = rows.offset
            phis.append(np.concatenate([rows.q_ddot, rows.q_dot, offsets], axis=1))
            ys.append(rows.y)
            for per_shape, regressors in zip(shared, rows.coulomb, strict=True):
                per_shape.append(regressors)
            if rows.coulomb:
                half.append(rows.coulomb[0] if rows.half_window is None else rows.half_window)
            lengthened |= rows.half_window is not None
            if rows.noise is not None:  # the noise the projected rows keep
                noise.append((k - rows.absorbed, rows.noise))
            absorbed += rows.absorbed
            # the filters' support: rows further apart share no noise sample
            segments.append((k, math.ceil(rows.window * rate / rows.decimate) + 1))
            used.append({"name": name, "window_s": rows.window, "decimate": rows.decimate,
                         "samples": k, "stop_rows": rows.absorbed,
                         "t_start": float(rows.t[0]), "t_stop": float(rows.t[-1])})
        names = regressor_names("q_ddot", "q_dot") + [f"offset[{x['name']}]" for x in used]
        regressor_noise = None
        if noise:
            regressor_noise = np.zeros((12 + n_exp, 12 + n_exp))
            for count, block in noise:
                regressor_noise[:12, :12] += count * block
        phi, y = np.concatenate(phis), np.concatenate(ys)

        def solve(per_shape: list[np.ndarray] | None, standard_errors: bool = True):
            return solve_least_squares(
                phi, y, None if per_shape is None else np.concatenate(per_shape),
                symmetric=self.symmetric, regressor_names=names,
                shared_names=([f"coulomb[{t}]" for t in JOINT_TYPES]
                              + ["coulomb[actuator]"] * legs if shapes else None),
                autocorrelated=True, regressor_noise=regressor_noise, segments=segments,
                absorbed=absorbed, standard_errors=standard_errors)

        # the exact sign's fit (the last) and the half window's refit only move the shapes'
        # errors: their estimates suffice
        solutions = ([solve(per_shape, standard_errors=k < len(shapes))
                      for k, per_shape in enumerate(shared)] if shared else [solve(None)])
        exact_solution = solutions.pop() if exact else None
        weights = akaike_weights(solutions)
        solution = average_solutions(solutions, weights)
        exact_weight = None
        if exact_solution is not None:
            solution, exact_weight = widened_by_exact_sign(
                solution, solutions[int(np.argmax(weights))], exact_solution)
        if lengthened:  # the long window's rounding of the reversals, as the half window sees it
            solution = widened_by_sign_window(
                solution, solutions[0], solve(half, standard_errors=False), "shared")
        shape_weights = ({shape: float(w) for shape, w in zip(shapes, weights, strict=True)}
                         if shapes else {})
        theta, std = solution.theta, solution.theta_std.copy()
        # residual autocorrelation is in theta_std; model error (friction the joint model
        # lacks) shows as symmetric pairs that disagree beyond it
        calibration = {} if self.symmetric else calibrate_by_pairs(
            theta[:, :6], theta[:, 6:12], std[:, :6], std[:, 6:12])
        offsets = theta[:, 12:].T.copy()
        levels = dict(zip(JOINT_TYPES, solution.shared.tolist(), strict=False))
        levels_std = dict(zip(JOINT_TYPES, solution.shared_std.tolist(), strict=False))
        # N along a leg, kept apart from the joints' N m levels
        leg_level, leg_std = ((float(solution.shared[-1]), float(solution.shared_std[-1]))
                              if legs else (math.nan, math.nan))
        diagnostics = {"experiments": used, "offsets": offsets,
                       "coulomb": levels, "coulomb_std": levels_std,
                       "leg_coulomb": leg_level, "leg_coulomb_std": leg_std,
                       "coulomb_shape_weights": shape_weights,
                       "exact_sign_weight": exact_weight,
                       "n_equations": int(solution.n_equations),
                       "pair_calibration": calibration}
        return IdentificationResult(
            M=theta[:, :6], B=theta[:, 6:12], std_errors_M=std[:, :6], std_errors_B=std[:, 6:12],
            condition_number=solution.condition_number, residual_rms=solution.residual_rms,
            method=self.method, settings=self._settings(), diagnostics=diagnostics), {
            "offsets_": offsets, "coulomb_": levels, "coulomb_std_": levels_std,
            "leg_coulomb_": leg_level, "leg_coulomb_std_": leg_std,
            "coulomb_shape_weights_": shape_weights}


def _experiment_rows(work: tuple, e: int) -> tuple[_Rows, str, float]:
    """Experiment ``e``'s rows, name and sample rate (Hz): one task of
    :meth:`LeastSquaresIdentifier._fit` (``work``: the estimator, the data sets, the platform,
    the Coulomb sign shapes and whether the legs carry a Coulomb level). Its joint-axis
    Jacobians go when its rows are built."""
    estimator, datasets, platform, shapes, legs = work
    exp = prepare_experiment(datasets[e], platform, gravity=estimator.gravity,
                             joints=estimator.coulomb, remainder=estimator.remainder)
    return estimator._experiment_rows(exp, shapes, legs), exp.name, exp.sample_rate


__all__ = ["ROWS_PER_WINDOW", "LeastSquaresIdentifier", "coulomb_regressors",
           "leg_coulomb_regressor", "shaped_coulomb_regressors", "uses_leg_coulomb"]
