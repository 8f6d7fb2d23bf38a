"""Method A: first-harmonic Fourier identification over whole periods (Tian et al., in Zhang 2020).

y_c = Mt qdd_c + Bt qd_c, y_s = Mt qdd_s + Bt qd_s: constants drop out, Coulomb friction lands in Bt.
"""

from __future__ import annotations

from collections.abc import Sequence
from numbers import Integral

import numpy as np

from stewartid.datasets.dataset import Dataset
from stewartid.datasets.excitation import LINE_FRACTION, leg_space_motion, spectral_lines
from stewartid.errors import ConfigError, DataError, IdentificationError
from stewartid.fields import BOOLEAN, Interval, ListOf, positive
from stewartid.identification.base import DIFFERENTIATION_CONSTRAINTS, BaseIdentifier
from stewartid.identification.harmonics import (
    friction_bias_bound,
    harmonic_coefficients,
    motion_gains,
    residual_third_harmonic,
    third_harmonic,
    third_harmonic_blocks,
)
from stewartid.identification.pairs import calibrate_by_pairs
from stewartid.identification.preparation import prepare
from stewartid.identification.registry import register_method
from stewartid.identification.result import IdentificationResult
from stewartid.identification.solvers import regressor_names, solve_least_squares
from stewartid.platform import Platform
from stewartid.signals.differentiation import (
    DEFAULT_ORDER,
    default_window,
    differentiate,
    estimate_frequency,
    trim,
)

#: Amplitude, relative to the largest line, below which a harmonic of a fitted frequency is
#: taken as the servo's distortion; above it, as a second sine of the excitation.
HARMONIC_FRACTION = 0.2


def check_whole_period(name: str, motion: np.ndarray, sample_rate: float) -> None:
    """Refuse a record shorter than one period of its motion, naming both.

    The period is that of a sine fitted to the largest leg excursion (``motion`` (N, 6), m, mean removed).

    Raises
    ------
    IdentificationError
        When no leg's motion crosses its mean twice.
    """
    column = motion[:, int(np.argmax(np.ptp(motion, axis=0)))]
    centred = column - column.mean()
    crossings = int(np.count_nonzero(np.diff(np.signbit(centred))))
    if crossings >= 2:
        return
    from scipy.optimize import minimize_scalar

    length = len(column) / sample_rate
    t = np.arange(len(column)) / sample_rate

    def cost(w: float) -> float:
        basis = np.column_stack([np.ones_like(t), np.cos(w * t), np.sin(w * t)])
        residual = column - basis @ np.linalg.lstsq(basis, column, rcond=None)[0]
        return float(residual @ residual)

    grid = 2 * np.pi / length * np.geomspace(0.01, 1.0, 200)
    k = int(np.argmin([cost(w) for w in grid]))
    found = minimize_scalar(cost, bounds=(grid[max(k - 1, 0)], grid[min(k + 1, len(grid) - 1)]),
                            method="bounded")
    period = 2 * np.pi / float(found.x)
    fitted = found.fun <= 1e-4 * float(centred @ centred) and 0 < k < len(grid) - 1
    needs = (f"one period of its motion, about {period:.2g} s (a sine fits it)" if fitted
             else "one period of its motion")
    raise IdentificationError(
        f"{name}: the record lasts {length:.3g} s, shorter than {needs}: Method A fits the "
        "first harmonic over whole periods of the excitation; record at least one period, "
        "or use Method B or least squares (--method wavelet or ls).")


def check_single_sine(name: str, pose: np.ndarray, sample_rate: float, platform: Platform,
                      frequencies_hz: Sequence[float], given: bool = False) -> None:
    """Refuse an experiment whose motion is not one sine at the fitted (or ``given``) frequencies.

    Every leg-length line above :data:`~stewartid.datasets.excitation.LINE_FRACTION` of the largest must
    sit at ``frequencies_hz`` or at a harmonic below :data:`HARMONIC_FRACTION`.

    Raises
    ------
    IdentificationError
        Naming the experiment and the lines found.
    """
    lines = spectral_lines(leg_space_motion(pose, platform), sample_rate)
    tolerance = lines.resolution_hz

    def order(f: float) -> int:
        """1 at a fitted frequency, n at its n-th harmonic, 0 elsewhere."""
        if any(abs(f - g) <= tolerance for g in frequencies_hz):
            return 1
        return next((round(f / g) for g in frequencies_hz
                     if round(f / g) >= 2 and abs(f - round(f / g) * g) <= tolerance), 0)

    orders = [order(f) for f in lines.frequencies_hz]
    foreign = [n == 0 or (n >= 2 and a >= HARMONIC_FRACTION)
               for n, a in zip(orders, lines.amplitudes, strict=True)]
    if not any(foreign):
        return
    listed = ", ".join(f"{g:.3g}" for g in frequencies_hz)
    needs = f"motion at the given {listed} Hz only" if given else "one sine per experiment"
    raise IdentificationError(
        f"{name}: Method A needs {needs}; the pose of {name} has {len(lines)} spectral lines "
        f"above {100 * LINE_FRACTION:.3g} % of the largest ({lines.describe()}); use Method B "
        "or least squares (--method wavelet or ls).")


@register_method(
    name="fourier", letter="A", color="#1f77b4",
    display_name="Method A (Fourier)",
    description="first-harmonic Fourier coefficients over whole periods of a sine excitation "
                "(the paper's Method A)",
    reference="Tian et al., single-DOF sine excitation, Method A in Zhang, C. Mathematics "
              "8(2), 257 (2020). doi:10.3390/math8020257")
class FourierIdentifier(BaseIdentifier):
    """Method A: first-harmonic Fourier identification of Mt and Bt over whole periods.

    Parameters
    ----------
    frequency_hz : float or sequence of float, optional
        Hz; the dominant sine of each experiment when not given.
    window : float, optional
        Savitzky-Golay window, s; default 0.2 periods of the highest frequency.
    order : int
        Savitzky-Golay polynomial order.
    gravity : bool
        Subtract the model's G(q).
    remainder : bool
        Subtract the model's departure from its linearisation along the motion.
    sampling_check : bool
        Widen standard errors where the log's sampling limits them.
    stiffness : bool
        Identify a stiffness matrix K too (two or more frequencies).
    symmetric : bool
        Impose Mt = Mt^T, Bt = Bt^T.
    periods_per_segment : int
        Whole periods of the lowest frequency per equation block.

    Attributes
    ----------
    M_, B_, stiffness_ : ndarray, shape (6, 6)
        ``stiffness_`` None unless fitted.
    std_errors_ : dict of ndarray (6, 6)
    condition_number_ : float
    frequencies_ : list of list of float
        Hz, per experiment.
    result_ : IdentificationResult
    """

    def __init__(self, frequency_hz: float | Sequence[float] | None = None,
                 window: float | None = None, order: int = DEFAULT_ORDER, gravity: bool = True,
                 stiffness: bool = False, symmetric: bool = False,
                 periods_per_segment: int = 1, remainder: bool = True,
                 sampling_check: bool = True):
        self.frequency_hz = frequency_hz
        self.window = window
        self.order = order
        self.gravity = gravity
        self.remainder = remainder
        self.stiffness = stiffness
        self.symmetric = symmetric
        self.periods_per_segment = periods_per_segment
        self.sampling_check = sampling_check

    _parameter_constraints = {
        "frequency_hz": [positive(), ListOf(positive()), None],
        **DIFFERENTIATION_CONSTRAINTS,
        "periods_per_segment": [Interval(Integral, 1, None)],
        "sampling_check": [BOOLEAN],
    }

    def _validate_params(self) -> None:
        super()._validate_params()
        freqs = self._given_frequencies()
        if self.stiffness and freqs is not None and len(freqs) < 2:
            raise ConfigError(
                "a stiffness matrix cannot be separated from inertia at a single excitation "
                f"frequency ({freqs[0]} Hz); give two or more frequencies in frequency_hz or "
                "switch stiffness off.")

    def _given_frequencies(self) -> list[float] | None:
        if self.frequency_hz is None:
            return None
        if np.ndim(self.frequency_hz) == 0:
            return [float(self.frequency_hz)]
        return [float(f) for f in self.frequency_hz]

    def _fit(self, datasets: list[Dataset], platform: Platform
             ) -> tuple[IdentificationResult, dict]:
        experiments = prepare(datasets, platform, gravity=self.gravity, remainder=self.remainder)
        rows_motion, rows_force, used, rows, third_blocks = [], [], [], [], []
        for exp in experiments:
            # on the leg-length motion every DOF counts in one unit
            motion = leg_space_motion(exp.q, platform)
            check_whole_period(exp.name, motion, exp.sample_rate)
            freqs = self._given_frequencies() or [estimate_frequency(motion, exp.sample_rate)]
            check_single_sine(exp.name, exp.q, exp.sample_rate, platform, freqs,
                              given=self.frequency_hz is not None)
            window = self.window or default_window(max(freqs))
            q0 = exp.q.mean(axis=0)
            q, qd, qdd = differentiate(exp.q - q0, exp.sample_rate, window, self.order)
            signals = np.concatenate([qdd, qd, q, exp.generalized_force], axis=1)
            cut = trim(window, exp.sample_rate, self.order)
            segment = self.periods_per_segment * exp.sample_rate / min(freqs)
            usable = len(exp.t) - 2 * cut
            n_segments = int(np.floor(usable / segment + 1e-9))
            if n_segments < 1:
                raise DataError(
                    f"{exp.name}: {usable / exp.sample_rate:.3g} s usable after the "
                    f"differentiation window, less than {self.periods_per_segment} period(s) of "
                    f"{min(freqs):.4g} Hz; record longer or lower periods_per_segment.")
            gains = motion_gains(freqs, exp.sample_rate, window, self.order)
            blocks, slices, first = [], [], sum(len(r) for r in rows_motion)
            for s in range(n_segments):
                start = cut + int(round(s * segment))
                stop = cut + int(round((s + 1) * segment))
                sl = slice(start, stop)
                t = exp.t[sl]
                coefficients = harmonic_coefficients(signals[sl], t, freqs)
                coefficients[:, :18] /= gains
                rows_motion.append(coefficients[:, :18])
                rows_force.append(coefficients[:, 18:])
                blocks.append([float(t[0]), float(t[-1] + 1.0 / exp.sample_rate)])
                slices.append(sl)
            rows.append(first + 2 * len(freqs) * np.arange(n_segments)[:, None]
                        + np.arange(2)[None, :])
            third_blocks.append(third_harmonic_blocks(
                signals, exp.t, slices, freqs[0], exp.sample_rate, window, self.order)
                if len(freqs) == 1 else None)
            used.append({"name": exp.name, "frequencies_hz": freqs, "window_s": window,
                         "segments": blocks})
        motion = np.concatenate(rows_motion)
        force = np.concatenate(rows_force)
        groups = ["q_ddot", "q_dot"] + (["q"] if self.stiffness else [])
        phi = motion[:, :6 * len(groups)]
        solution = solve_least_squares(phi, force, symmetric=self.symmetric,
                                       regressor_names=regressor_names(*groups))
        theta, noise_std = solution.theta, solution.theta_std
        residual = force - phi @ theta.T
        covariance = residual.T @ residual / max(len(residual) - phi.shape[1], 1)
        third, statistic, threshold = third_harmonic(
            [None if c is None else residual_third_harmonic(c, theta) for c in third_blocks],
            covariance)
        bias = friction_bias_bound(np.linalg.pinv(phi), rows, third)
        std = np.hypot(noise_std, bias)
        calibration = {} if self.symmetric else calibrate_by_pairs(
            theta[:, :6], theta[:, 6:12], std[:, :6], std[:, 6:12])
        stiffness = theta[:, 12:18] if self.stiffness else None
        diagnostics = {"experiments": used, "n_equations": int(solution.n_equations),
                       "friction_bias": {"third_harmonic": np.array(third),
                                         "statistic": statistic, "threshold": threshold,
                                         "bound_M": bias[:, :6], "bound_B": bias[:, 6:12],
                                         "noise_std_M": noise_std[:, :6],
                                         "noise_std_B": noise_std[:, 6:12]},
                       "pair_calibration": calibration}
        if stiffness is not None:
            diagnostics["K"] = stiffness
            diagnostics["std_errors_K"] = std[:, 12:18]
        return IdentificationResult(
            M=theta[:, :6], B=theta[:, 6:12], std_errors_M=std[:, :6], std_errors_B=std[:, 6:12],
            condition_number=solution.condition_number, residual_rms=solution.residual_rms,
            method=self.method, settings=self.get_params(), diagnostics=diagnostics), {
            "stiffness_": stiffness, "frequencies_": [u["frequencies_hz"] for u in used]}


__all__ = ["HARMONIC_FRACTION", "FourierIdentifier", "check_single_sine", "check_whole_period"]
