"""Method B: wavelet transform on constant-direction intervals (Zhang 2020).

In a constant-direction interval (no joint reverses, :mod:`.intervals`) the Coulomb friction
of every joint is constant, and so is what remains of gravity after the pose-dependent G(q)
has been subtracted. The linearised equation of motion

    Mt q_ddot + Bt q_dot + c = y,        y = J_lq(q)^T f_a - G(q),   c constant,

transformed with a wavelet psi whose moments of order 0 and 1 vanish and whose support lies
inside the interval, loses the constant:

    [Mt Bt] [W_psi q_ddot ; W_psi q_dot](a, b) = W_psi y (a, b).

Stacking the equations of many (a, b) points from all intervals of all experiments gives a
least-squares problem for the 72 entries of Mt and Bt.

Variants (``variant``):

``"position"`` (default)
    No numerical differentiation: integration by parts moves both derivatives onto the
    wavelet, W_psi q_ddot = W_psi'' q / a^2 and W_psi q_dot = -W_psi' q / a.
``"paper"``
    Zhang's equations: W_psi q_ddot and W_psi q_dot = -a W_psi1 q_ddot, with the
    acceleration from a Savitzky-Golay differentiator (``differentiation_window``).
``"derivative"``
    W_psi q_ddot and W_psi q_dot with both signals from the Savitzky-Golay differentiator.

Wavelets (``wavelet``): ``"polynomial"`` (default), psi = g'' with g = (1 - x^2)^p on [-1, 1],
compactly supported, so the largest scale spans a whole interval (the modulating-function
idea); ``"mexican_hat"``, the paper's Gaussian wavelet, truncated at +-``truncation`` scales,
so its scales are limited to a tenth of the interval at the default truncation of 5. Measured
on the independent example data set (docs/benchmarks.md), the polynomial wavelet with the
position-only variant is the most accurate; it is the default.

Scales and shifts are chosen per interval: for every fraction s of ``scale_fractions`` the
scale is a = s T / (2 h) (T the interval length, h the wavelet's half-width in scales), and
``shifts_per_scale`` shifts spread evenly over the positions that keep the support inside the
interval.

Couplings (the paper's Mt(2,4) case): an off-diagonal entry and its transpose are estimated
from different equations (Mt(5,1) from the pitch equation under surge, Mt(1,5) from the surge
equation under pitch). The rotational equations under translational excitation are the
sensitive ones, because joints that barely move (and so are left out of the interval
detection) switch friction at odd times. With ``pair_selection="std_error"`` (default) both
entries of every symmetric pair take the estimate with the smaller standard error, computed
from the data alone; ``symmetric=True`` imposes symmetry in the least-squares solve instead.

Standard errors are cluster-robust over intervals: the equations of one interval share
samples (overlapping wavelets) and the same friction state, so their residuals are
correlated; treating them as independent would understate the uncertainty.

References
----------
Zhang, C. "A Parameter Identification Method for Stewart Manipulator Based on Wavelet
Transform." Mathematics 8(2), 257 (2020). doi:10.3390/math8020257
"""

from __future__ import annotations

import numpy as np
from scipy import sparse
from scipy.signal import savgol_filter

from stewartid.dataset import Dataset
from stewartid.errors import IdentificationError
from stewartid.identification.base import (
    COORDINATES,
    BaseIdentifier,
    Experiment,
    check_parameter,
    prepare,
    regressor_names,
    solve_least_squares,
)
from stewartid.identification.intervals import constant_direction_intervals, joint_rates
from stewartid.identification.results import IdentificationResult
from stewartid.identification.signals import (
    DEFAULT_ORDER,
    default_window,
    differentiate,
    estimate_frequency,
    window_samples,
)
from stewartid.identification.wavelets import (
    MotherWavelet,
    PolynomialWavelet,
    make_wavelet,
    transform_matrix,
)
from stewartid.platform import Platform

VARIANTS = ("position", "paper", "derivative")
#: Polynomial degree up to which every transform row integrates exactly (moment-corrected
#: quadrature, see :func:`~stewartid.identification.wavelets.transform_matrix`).
EXACT_DEGREE = 5
#: Default interval margin, in periods of the estimated excitation frequency.
MARGIN_PERIODS = 0.05
PAIR_SELECTIONS = ("std_error", "none")


def rate_noise(rates: np.ndarray, period: float, window: float) -> np.ndarray:
    """Noise level of each joint rate: robust standard deviation of what a four times wider
    Savitzky-Golay smoother removes.

    Parameters
    ----------
    rates : ndarray, shape (N, J)
    period, window : float
        Sample period and the differentiation window (s).

    Returns
    -------
    ndarray, shape (J,)
        1.4826 * median absolute deviation (units of ``rates``).
    """
    n = max(7, int(round(4 * window / period)) | 1)
    if n > len(rates):
        n = len(rates) if len(rates) % 2 else len(rates) - 1
    residual = rates - savgol_filter(rates, n, 3, axis=0, mode="interp")
    return 1.4826 * np.median(np.abs(residual - np.median(residual, axis=0)), axis=0)


def position_noise_covariance(q: np.ndarray, smooth: np.ndarray | None = None) -> np.ndarray:
    """Covariance of white measurement noise on the pose, from second differences.

    For a smooth motion, q[n+1] - 2 q[n] + q[n-1] is the noise e[n+1] - 2 e[n] + e[n-1]
    (covariance 6 Sigma for white noise) plus q_ddot dt^2. The latter is removed by taking
    the differences of q minus a smoothed copy (a low-pass smoother leaves the noise's second
    differences almost untouched), so noise-free data give a covariance near zero. The pose
    of a hexapod is the forward kinematics of the measured leg lengths, so its noise is
    correlated across the six coordinates; the full covariance is returned.

    Parameters
    ----------
    q : ndarray, shape (N, 6)
        Measured poses (m, rad).
    smooth : ndarray, shape (N, 6), optional
        A low-pass smoothed copy of ``q`` (e.g. the Savitzky-Golay output); None: raw
        second differences.

    Returns
    -------
    ndarray, shape (6, 6)
        Sigma (m^2, m rad, rad^2) per sample.
    """
    r = q if smooth is None else q - smooth
    d2 = r[2:] - 2.0 * r[1:-1] + r[:-2]
    d2 = d2 - np.median(d2, axis=0)
    return d2.T @ d2 / (6.0 * max(len(d2), 1))


def joint_rate_noise(covariance: np.ndarray, sample_rate: float, window: float,
                     joint_jacobians: np.ndarray, leg_jacobian: np.ndarray) -> np.ndarray:
    """Standard deviation of each Savitzky-Golay joint rate caused by pose noise.

    The velocity filter is a linear combination of samples with coefficients c, so white
    pose noise of covariance Sigma gives q_dot noise of covariance |c|^2 Sigma, and the joint
    rates J q_dot the standard deviations |c| sqrt(diag(J Sigma J^T)) (Jacobians averaged over
    the record; the motion is small).

    Parameters
    ----------
    covariance : ndarray, shape (6, 6)
        Pose noise per sample (:func:`position_noise_covariance`).
    sample_rate, window : float
        Hz and the differentiation window (s).
    joint_jacobians : ndarray, shape (N, 6, 5, 6)
    leg_jacobian : ndarray, shape (N, 6, 6)

    Returns
    -------
    ndarray, shape (36,)
        Columns as :data:`~stewartid.identification.intervals.JOINT_RATE_NAMES`.
    """
    from scipy.signal import savgol_coeffs

    n = window_samples(window, sample_rate, DEFAULT_ORDER)
    gain = np.linalg.norm(savgol_coeffs(n, DEFAULT_ORDER, deriv=1, delta=1.0 / sample_rate))
    jac = np.concatenate([joint_jacobians.mean(axis=0).reshape(30, 6),
                          leg_jacobian.mean(axis=0)], axis=0)
    variance = np.einsum("ij,jk,ik->i", jac, covariance, jac)
    return gain * np.sqrt(np.clip(variance, 0.0, None))


def generalized_force_sensitivity(platform: Platform, q: np.ndarray, forces: np.ndarray,
                                  gravity: bool = True, step: float = 1e-6) -> np.ndarray:
    """K = d(J_lq(q)^T f - G(q)) / dq at the mean pose and mean leg forces, shape (6, 6).

    Pose noise enters the generalized force through the Jacobian (the static leg load times
    the change of the leg directions) and through G(q); K maps it there, so the
    errors-in-variables correction can account for noise shared by regressors and targets.
    Central differences of ``step`` (m, rad).
    """
    from stewartid.dynamics import ModelTerms

    q0, f0 = q.mean(axis=0), forces.mean(axis=0)
    poses = np.repeat(q0[None], 12, axis=0)
    for j in range(6):
        poses[2 * j, j] += step
        poses[2 * j + 1, j] -= step
    terms = ModelTerms(platform, poses)
    y = np.einsum("nji,j->ni", terms.leg_jacobian, f0)
    if gravity:
        y = y - terms.gravity
    return ((y[0::2] - y[1::2]) / (2 * step)).T


def wavelet_points(intervals: np.ndarray, wavelet: MotherWavelet,
                   scale_fractions: tuple[float, ...], shifts_per_scale: int,
                   ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(a, b) points whose wavelet support lies inside an interval.

    Parameters
    ----------
    intervals : ndarray, shape (M, 2)
        [start, stop] (s).
    wavelet : MotherWavelet
    scale_fractions : tuple of float
        Support length as a fraction of the interval length, each in (0, 1].
    shifts_per_scale : int
        Shifts per scale and interval (one if the support fills the interval).

    Returns
    -------
    scales, shifts : ndarray, shape (K,)
        a and b (s).
    interval_index : ndarray of int, shape (K,)
        Row of ``intervals`` each point belongs to.
    """
    scales, shifts, owner = [], [], []
    for m, (start, stop) in enumerate(intervals):
        length = stop - start
        for fraction in scale_fractions:
            a = fraction * length / (2.0 * wavelet.half_width)
            free = length - 2.0 * a * wavelet.half_width
            count = shifts_per_scale if free > 1e-9 * length else 1
            b = start + a * wavelet.half_width + np.linspace(0.0, max(free, 0.0), count)
            scales.append(np.full(count, a))
            shifts.append(b)
            owner.append(np.full(count, m))
    if not scales:
        return np.zeros(0), np.zeros(0), np.zeros(0, dtype=int)
    return np.concatenate(scales), np.concatenate(shifts), np.concatenate(owner)


class WaveletIdentifier(BaseIdentifier):
    """Identify Mt and Bt by the wavelet method of Zhang (2020) (Method B).

    Parameters
    ----------
    wavelet : {"polynomial", "mexican_hat"}
        Mother wavelet (see the module docstring).
    wavelet_order : int
        Exponent p of the polynomial wavelet, 5..20.
    truncation : float
        Half-width (scales) at which the Mexican hat is cut.
    variant : {"position", "paper", "derivative"}
        How W q_ddot and W q_dot are obtained (see the module docstring).
    scale_fractions : tuple of float
        Wavelet support as fractions of each interval's length, each in (0, 1].
    shifts_per_scale : int
        Shifts per scale and interval.
    margin : float or None
        Time (s) cut from both ends of every constant-direction interval. None (default):
        :data:`MARGIN_PERIODS` periods of the estimated excitation frequency (0.1 s at
        0.5 Hz): with large Coulomb friction the friction of joints that barely move
        reverses somewhat after the measured zero crossings (measured on the paper's
        platform at 30 N m: Mt(1,5) off by 1.5 % with 0.02 s, 0.5 % with 0.1 s).
    ignore_below : float
        Joints whose rate RMS is below this fraction of the largest of their kind are left
        out of the interval detection (they barely move, and their sign flips at odd times).
    min_interval : float or None
        Shortest usable interval (s); None: half the median interval of each experiment.
    min_support_samples : int
        Fewest samples the smallest wavelet's support may cover; intervals too short for it
        are dropped.
    differentiation_window : float or None
        Savitzky-Golay window (s) for the joint rates of the interval detection and, in the
        ``"paper"`` and ``"derivative"`` variants, for q_dot and q_ddot. None (default): a
        fifth of the period of the experiment's dominant frequency, estimated from the data,
        which keeps measurement noise out of the joint rates without moving their zeros.
    hysteresis : float
        A joint's direction counts as known only while its rate exceeds this many times the
        rate's noise level (estimated from the data, :func:`rate_noise`); reversals inside the
        noise band are kept out of every interval (see
        :func:`~stewartid.identification.intervals.constant_direction_intervals`).
    odd_companion : bool
        With the polynomial wavelet, also use its odd companion g''' at every (a, b) (see
        :class:`~stewartid.identification.wavelets.PolynomialWavelet`); use with
        ``wavelet_order`` >= 8.
    noise_correction : bool
        Errors-in-variables correction of the least squares (position variant, not with
        ``symmetric``): the pose noise covariance is estimated from the data
        (:func:`position_noise_covariance`) and its contribution to the normal equations
        removed (:func:`bias_compensated_least_squares`); standard errors from the
        corrected sandwich.
    symmetric : bool
        Impose Mt = Mt^T and Bt = Bt^T in the solve.
    pair_selection : {"std_error", "none"}
        For each symmetric pair of off-diagonal entries, use the estimate with the smaller
        standard error for both (ignored with ``symmetric``).
    gravity : bool
        Subtract the model's pose-dependent gravity G(q) before identification.

    Attributes
    ----------
    M_, B_ : ndarray, shape (6, 6)
    std_errors_ : dict of ndarray (6, 6)
    condition_number_ : float
    result_ : IdentificationResult
        ``diagnostics`` holds, per experiment, the intervals and the (a, b) points used, the
        joints left out, and which member of each symmetric pair was taken.

    References
    ----------
    Zhang, C. "A Parameter Identification Method for Stewart Manipulator Based on Wavelet
    Transform." Mathematics 8(2), 257 (2020). doi:10.3390/math8020257
    """

    method = "wavelet"

    def __init__(self, wavelet: str = "polynomial", wavelet_order: int = 6,
                 truncation: float = 5.0, variant: str = "position",
                 scale_fractions: tuple[float, ...] = (1.0, 0.8, 0.6),
                 shifts_per_scale: int = 5, margin: float | None = None, ignore_below: float = 0.01,
                 min_interval: float | None = None, min_support_samples: int = 32,
                 differentiation_window: float | None = None, hysteresis: float = 4.0,
                 odd_companion: bool = False, noise_correction: bool = True,
                 symmetric: bool = False,
                 pair_selection: str = "std_error", gravity: bool = True):
        self.wavelet = wavelet
        self.wavelet_order = wavelet_order
        self.truncation = truncation
        self.variant = variant
        self.scale_fractions = scale_fractions
        self.shifts_per_scale = shifts_per_scale
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

    # ------------------------------------------------------------------ settings
    def _validate_params(self) -> None:
        name = type(self).__name__
        check_parameter(name, "wavelet", self.wavelet,
                        self.wavelet in ("polynomial", "mexican_hat"),
                        "'polynomial' or 'mexican_hat'")
        check_parameter(name, "variant", self.variant, self.variant in VARIANTS,
                        f"one of {VARIANTS}")
        fractions = np.atleast_1d(np.asarray(self.scale_fractions, dtype=float))
        check_parameter(name, "scale_fractions", self.scale_fractions,
                        fractions.size > 0 and bool(np.all((fractions > 0) & (fractions <= 1))),
                        "a non-empty sequence of fractions in (0, 1]")
        check_parameter(name, "shifts_per_scale", self.shifts_per_scale,
                        isinstance(self.shifts_per_scale, int | np.integer)
                        and 1 <= self.shifts_per_scale <= 1000, "an integer in [1, 1000]")
        check_parameter(name, "margin", self.margin,
                        self.margin is None
                        or (isinstance(self.margin, int | float) and self.margin >= 0),
                        "None or a float in [0, inf) (s)")
        check_parameter(name, "ignore_below", self.ignore_below,
                        isinstance(self.ignore_below, int | float)
                        and 0 <= self.ignore_below < 1, "a float in [0, 1)")
        check_parameter(name, "min_interval", self.min_interval,
                        self.min_interval is None or (isinstance(self.min_interval, int | float)
                                                      and self.min_interval > 0),
                        "None or a float in (0, inf) (s)")
        check_parameter(name, "min_support_samples", self.min_support_samples,
                        isinstance(self.min_support_samples, int | np.integer)
                        and self.min_support_samples >= 8, "an integer >= 8")
        check_parameter(name, "differentiation_window", self.differentiation_window,
                        self.differentiation_window is None
                        or (isinstance(self.differentiation_window, int | float)
                            and self.differentiation_window > 0),
                        "None or a float in (0, inf) (s)")
        check_parameter(name, "hysteresis", self.hysteresis,
                        isinstance(self.hysteresis, int | float) and self.hysteresis >= 0,
                        "a float in [0, inf)")
        check_parameter(name, "pair_selection", self.pair_selection,
                        self.pair_selection in PAIR_SELECTIONS, f"one of {PAIR_SELECTIONS}")
        make_wavelet(self.wavelet, **self._wavelet_options())

    def _wavelet_options(self) -> dict:
        if self.wavelet == "polynomial":
            return {"order": self.wavelet_order}
        return {"truncation": self.truncation}

    # ------------------------------------------------------------------ equations
    def _experiment_equations(self, experiment: Experiment, wavelet: MotherWavelet,
                              platform: Platform):
        """Wavelet equations of one experiment: regressors (K, 12), targets (K, 6), info."""
        t, q, period = experiment.t, experiment.q, experiment.period
        rate = 1.0 / period
        window, margin = self.differentiation_window, self.margin
        if window is None or margin is None:
            frequency = estimate_frequency(q, rate)
            window = default_window(frequency) if window is None else window
            margin = MARGIN_PERIODS / frequency if margin is None else margin
        q_smooth, q_dot, q_ddot = differentiate(q, rate, window)
        rates = joint_rates(platform, q, q_dot, experiment.joint_jacobians,
                            experiment.leg_jacobian)
        noise = position_noise_covariance(q, q_smooth)
        thresholds = self.hysteresis * joint_rate_noise(
            noise, rate, window, experiment.joint_jacobians, experiment.leg_jacobian)
        found = constant_direction_intervals(t, rates, margin=margin,
                                             ignore_below=self.ignore_below,
                                             hysteresis=thresholds)
        lengths = found[:, 1] - found[:, 0]
        shortest = (self.min_interval if self.min_interval is not None
                    else 0.5 * float(np.median(lengths)) if len(lengths) else 0.0)
        smallest = min(self.scale_fractions)
        # the smallest wavelet support must cover min_support_samples samples
        needed = self.min_support_samples * period / smallest
        intervals = found[lengths >= max(shortest, needed)]
        info = {"name": experiment.name, "intervals_found": int(len(found)),
                "longest_interval": float(lengths.max()) if len(lengths) else 0.0,
                "shortest_usable": float(max(shortest, needed)),
                "intervals": intervals, "differentiation_window": float(window)}
        scales, shifts, owner = wavelet_points(intervals, wavelet,
                                               tuple(self.scale_fractions),
                                               int(self.shifts_per_scale))
        info["scales"], info["shifts"] = scales, shifts
        info["noise_covariance"] = noise
        if len(scales) == 0:
            return np.zeros((0, 12)), np.zeros((0, 6)), owner, np.zeros((0, 3, 3)), info
        wavelets = [wavelet]
        if self.odd_companion and isinstance(wavelet, PolynomialWavelet):
            wavelets.append(PolynomialWavelet(wavelet.order, odd=True))
        a = scales[:, None]
        qc = q - q.mean(axis=0)
        rows, targets, products = [], [], []
        for psi in wavelets:
            def matrix(derivative, psi=psi):
                return transform_matrix(t, scales, shifts, psi, derivative,
                                        exact_degree=EXACT_DEGREE)

            w0 = matrix(0)
            targets.append(w0 @ experiment.generalized_force)
            if self.variant == "position":
                # constants vanish analytically (and, with the moment correction, to
                # rounding); removing the mean also keeps the Mexican hat's truncation error
                # proportional to the motion, not the offset
                w2 = sparse.diags(1.0 / scales ** 2) @ matrix(2)
                w1 = sparse.diags(-1.0 / scales) @ matrix(1)
                w_acc, w_vel = w2 @ qc, w1 @ qc
                # inner products of the rows acting on q (acc, vel) and on y (target): the
                # covariances of the transformed white pose noise
                operators = (w2, w1, w0)
                products.append(np.stack([
                    np.stack([np.asarray(u.multiply(v).sum(axis=1)).ravel()
                              for v in operators], axis=-1) for u in operators], axis=-2))
            else:
                w_acc = w0 @ q_ddot
                w_vel = (-a * (matrix(-1) @ q_ddot) if self.variant == "paper"
                         else w0 @ q_dot)
                products.append(np.zeros((len(scales), 3, 3)))
            rows.append(np.hstack([w_acc, w_vel]))
        owner = np.tile(owner, len(wavelets))
        return (np.vstack(rows), np.vstack(targets), owner, np.concatenate(products),
                info)

    def _fit(self, datasets: list[Dataset], platform: Platform) -> IdentificationResult:
        wavelet = make_wavelet(self.wavelet, **self._wavelet_options())
        experiments = prepare(datasets, platform, gravity=self.gravity)
        phi, target, cluster, infos, noise_xx, noise_xy = [], [], [], [], [], []
        offset = 0
        for dataset, experiment in zip(datasets, experiments, strict=True):
            x, y, owner, products, info = self._experiment_equations(experiment, wavelet,
                                                                     platform)
            phi.append(x)
            target.append(y)
            cluster.append(owner + offset)
            offset += len(info["intervals"])
            infos.append(info)
            if len(x) and self.noise_correction and self.variant == "position":
                sigma = info["noise_covariance"]
                sens = generalized_force_sensitivity(platform, dataset.pose, dataset.forces,
                                                     self.gravity)
                # per row: E[e_x e_x^T] (12, 12) and E[e_x e_y^T] (12, 6)
                noise_xx.append(np.einsum("kuv,ij->kuivj", products[:, :2, :2], sigma
                                          ).reshape(len(x), 12, 12))
                noise_xy.append(np.einsum("ku,ij->kuij", products[:, :2, 2],
                                          sigma @ sens.T).reshape(len(x), 12, 6))
            else:
                noise_xx.append(np.zeros((len(x), 12, 12)))
                noise_xy.append(np.zeros((len(x), 12, 6)))
        phi, target, cluster = np.vstack(phi), np.vstack(target), np.concatenate(cluster)
        noise_xx, noise_xy = np.concatenate(noise_xx), np.concatenate(noise_xy)
        if len(phi) == 0:
            longest = max(info["longest_interval"] for info in infos)
            needed = min(info["shortest_usable"] for info in infos)
            raise IdentificationError(
                f"no constant-direction interval long enough for the smallest wavelet scale "
                f"in any experiment (longest {longest:.3g} s, at least {needed:.3g} s needed); "
                "excite with a slower single-frequency sine, lower 'margin' or "
                "'min_support_samples', raise 'ignore_below' to leave idle joints out, or "
                "record at a higher sample rate.")
        names = regressor_names("q_ddot", "q_dot")
        solution = solve_least_squares(phi, target, symmetric=bool(self.symmetric),
                                       regressor_names=names)
        theta = solution.theta
        std = solution.theta_std
        if not self.symmetric:
            theta, std = bias_compensated_least_squares(phi, target, cluster, noise_xx,
                                                        noise_xy)
        M, B = theta[:, :6].copy(), theta[:, 6:12].copy()
        std_M, std_B = std[:, :6].copy(), std[:, 6:12].copy()
        chosen = {}
        if not self.symmetric and self.pair_selection == "std_error":
            chosen["M"] = select_symmetric_pairs(M, std_M)
            chosen["B"] = select_symmetric_pairs(B, std_B)
        residual = target - phi @ theta.T
        noise = [info["noise_covariance"] for info in infos]
        diagnostics = {
            "position_noise_std": [np.sqrt(np.diag(c)).tolist() for c in noise],
            "wavelet": wavelet.to_dict(),
            "n_equations": int(len(phi)),
            "n_intervals": int(offset),
            "experiments": [
                {"name": info["name"], "intervals_found": info["intervals_found"],
                 "intervals": info["intervals"].tolist(),
                 "scales": info["scales"].tolist(), "shifts": info["shifts"].tolist()}
                for info in infos],
            "pair_choice": chosen,
            "coordinates": list(COORDINATES),
        }
        return IdentificationResult(
            M=M, B=B, std_errors_M=std_M, std_errors_B=std_B,
            condition_number=solution.condition_number,
            residual_rms=np.sqrt(np.mean(residual ** 2, axis=0)), method=self.method,
            settings={k: (list(v) if isinstance(v, tuple) else v)
                      for k, v in self.get_params().items()},
            diagnostics=diagnostics)


def bias_compensated_least_squares(phi: np.ndarray, target: np.ndarray, cluster: np.ndarray,
                                   noise_xx: np.ndarray, noise_xy: np.ndarray
                                   ) -> tuple[np.ndarray, np.ndarray]:
    """Errors-in-variables least squares with cluster-robust standard errors.

    With measured regressors X = X0 + E and targets Y = Y0 + E_y, ordinary least squares
    is biased towards zero by E[E^T E] (attenuation) and shifted by E[E^T E_y]. With the
    noise second moments known per row, the bias-compensated estimator (Stoica &
    Soderstrom 1982, "Bias correction in least-squares identification")

        theta_i = (X^T X - sum_k C_k)^-1 (X^T y_i - sum_k D_k[:, i])

    is consistent. Its covariance is the sandwich A^-1 (sum_c s_c s_c^T) A^-1 with the
    mean-zero estimating-equation scores of each cluster
    s_c = X_c^T (y_c - X_c theta) + C_c theta - D_c, clusters being the intervals (their
    equations share samples; intervals do not overlap, so clusters are independent).

    Parameters
    ----------
    phi : ndarray, shape (K, p)
    target : ndarray, shape (K, C)
    cluster : ndarray of int, shape (K,)
    noise_xx : ndarray, shape (K, p, p)
        E[e_k e_k^T] of each row's regressor noise (C_k).
    noise_xy : ndarray, shape (K, p, C)
        E[e_k e_y,k^T] between regressor and target noise (D_k).

    Returns
    -------
    theta : ndarray, shape (C, p)
    std : ndarray, shape (C, p)
        Cluster-robust standard errors with the small-sample factor G / (G - 1).
    """
    K, p = phi.shape
    scale = np.linalg.norm(phi, axis=0)
    scale = np.where(scale > 0, scale, 1.0)
    xs = phi / scale
    cxx = noise_xx / np.outer(scale, scale)
    cxy = noise_xy / scale[None, :, None]
    labels, index = np.unique(cluster, return_inverse=True)
    groups = len(labels)
    cluster_xx = np.zeros((groups, p, p))
    cluster_xy = np.zeros((groups, p, target.shape[1]))
    np.add.at(cluster_xx, index, cxx)
    np.add.at(cluster_xy, index, cxy)
    normal = xs.T @ xs - cluster_xx.sum(axis=0)
    bread = np.linalg.inv(normal)
    theta_s = (bread @ (xs.T @ target - cluster_xy.sum(axis=0))).T       # (C, p)
    residual = target - xs @ theta_s.T
    std = np.empty_like(theta_s)
    factor = groups / max(groups - 1, 1) * (K - 1) / max(K - p, 1)
    for c in range(target.shape[1]):
        scores = np.zeros((groups, p))
        np.add.at(scores, index, xs * residual[:, c:c + 1])
        scores += cluster_xx @ theta_s[c] - cluster_xy[:, :, c]
        cov = factor * bread @ (scores.T @ scores) @ bread.T
        std[c] = np.sqrt(np.clip(np.diag(cov), 0.0, None))
    return theta_s / scale, std / scale


def cluster_robust_std(phi: np.ndarray, residual: np.ndarray, cluster: np.ndarray
                       ) -> np.ndarray:
    """Cluster-robust standard errors of per-channel ordinary least squares.

    Parameters
    ----------
    phi : ndarray, shape (K, p)
        Regressors.
    residual : ndarray, shape (K, C)
        Residuals of each channel.
    cluster : ndarray of int, shape (K,)
        Cluster (interval) of each row; residuals may correlate within a cluster.

    Returns
    -------
    ndarray, shape (C, p)
        Standard error of each coefficient, with the small-sample factor G / (G - 1).
    """
    K, p = phi.shape
    scale = np.linalg.norm(phi, axis=0)
    scale = np.where(scale > 0, scale, 1.0)
    xs = phi / scale
    bread = np.linalg.pinv(xs.T @ xs)
    labels, index = np.unique(cluster, return_inverse=True)
    groups = len(labels)
    out = np.empty((residual.shape[1], p))
    for c in range(residual.shape[1]):
        scores = np.zeros((groups, p))
        np.add.at(scores, index, xs * residual[:, c:c + 1])
        meat = scores.T @ scores
        factor = groups / max(groups - 1, 1) * (K - 1) / max(K - p, 1)
        cov = factor * bread @ meat @ bread
        out[c] = np.sqrt(np.clip(np.diag(cov), 0.0, None)) / scale
    return out


def select_symmetric_pairs(matrix: np.ndarray, std: np.ndarray) -> list[dict]:
    """For every off-diagonal pair, copy the estimate with the smaller standard error.

    Both ``matrix`` and ``std`` are modified in place (6, 6). Returns, per pair, which entry
    was kept (1-based), as a list of {"pair": [[i, j], [j, i]], "kept": [i, j]}.
    """
    choice = []
    n = matrix.shape[0]
    for i in range(n):
        for j in range(i + 1, n):
            keep, drop = ((i, j), (j, i)) if std[i, j] <= std[j, i] else ((j, i), (i, j))
            matrix[drop] = matrix[keep]
            std[drop] = std[keep]
            choice.append({"pair": [[i + 1, j + 1], [j + 1, i + 1]],
                           "kept": [keep[0] + 1, keep[1] + 1]})
    return choice


__all__ = ["EXACT_DEGREE", "MARGIN_PERIODS", "PAIR_SELECTIONS", "VARIANTS", "WaveletIdentifier",
           "bias_compensated_least_squares", "cluster_robust_std",
           "generalized_force_sensitivity", "joint_rate_noise", "position_noise_covariance",
           "rate_noise", "select_symmetric_pairs", "wavelet_points"]
