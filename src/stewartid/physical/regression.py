"""Physical model's regression: regressor and generalized force, kernel-filtered, a few rows per window."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from stewartid.identification.preparation import Experiment
from stewartid.identification.stops import find_stops, project_out, stop_basis
from stewartid.identification.wavelet.noise import white_noise_covariance
from stewartid.model import regressor as reg
from stewartid.model.kinematics import leg_jacobian
from stewartid.model.regressor_rows import smooth_sign
from stewartid.platform import Platform
from stewartid.signals.differentiation import (
    default_window,
    differentiate,
    estimate_frequency,
    kernel_taps,
)
from stewartid.signals.filtered_rows import kernel_filter_rows
from stewartid.signals.sign_rates import coulomb_sign_rates


@dataclass(frozen=True)
class Regression:
    """Filtered regression of one set of experiments.

    Attributes
    ----------
    Y : ndarray, shape (K, 6, N_STANDARD)
    y : ndarray, shape (K, 6)
        J_lq^T f (N, N m).
    experiments : list of dict
        Name, window (s), rows used, rows the legs' stops took (``stop_rows``).
    pose_noise : list of ndarray, each shape (6, 6)
        Pose white-noise covariance per sample (m^2, rad^2).
    poses : ndarray, shape (K, 6)
        Filtered pose per row (m, rad).
    force_noise : list of ndarray, each shape (6, 6)
        Leg force white-noise covariance per sample (N^2).
    """

    Y: np.ndarray
    y: np.ndarray
    experiments: list[dict[str, Any]]
    pose_noise: list[np.ndarray]
    poses: np.ndarray
    force_noise: list[np.ndarray]

    def measured_force_noise(self) -> list[tuple[np.ndarray, np.ndarray]]:
        """Per experiment, leg force covariance per sample and the kernel's autocorrelation at row lags
        (:func:`~stewartid.identification.long_run.filtered_noise_covariance`).
        """
        out = []
        for S, e in zip(self.force_noise, self.experiments, strict=True):
            h = kernel_taps(e["sample_rate"], e["window_s"])[0]
            autocorrelation = np.correlate(h, h, "full")[len(h) - 1:]
            out.append((S, autocorrelation[::e["row_step"]]))
        return out


#: Savitzky-Golay order and window (a fraction of the kernel's) of the rates and accelerations
#: the regressor is evaluated at: flat gain wherever the kernel passes the signal.
SAVGOL_ORDER, SAVGOL_FRACTION = 5, 8

#: Filtered rows kept per kernel window when the row step is automatic (the filtered signals
#: vary on the scale of the window).
ROWS_PER_WINDOW = 20


def row_step(window: float, sample_rate: float) -> int:
    """Row step giving ``ROWS_PER_WINDOW`` rows per ``window`` (s), at least 1."""
    return max(1, int(window * sample_rate) // ROWS_PER_WINDOW)


def filtered_regression(experiments: list[Experiment], platform: Platform,
                        window: float | None = None, order: int = SAVGOL_ORDER,
                        decimate: int | None = 1, gravity: bool = True,
                        coulomb_smoothing: float = 1e-4, leg_stops: bool = False) -> Regression:
    """Regressor Y and generalized force of every experiment, filtered with h; J_lq^T f = Y pi is
    linear in pi, so the filtered equation holds exactly.

    Parameters
    ----------
    experiments : list of Experiment
        Prepared without gravity subtraction.
    platform : Platform
    window : float, optional
        Kernel support (s); default 0.2 periods of the dominant frequency.
    order : int
        Savitzky-Golay order.
    decimate : int, optional
        Row step; None: smallest :func:`row_step` over the experiments.
    gravity : bool
        Include the gravity columns.
    coulomb_smoothing : float
        rad/s.
    leg_stops : bool
        Leave the legs' stops out of their Coulomb sign law and their friction free
        (:mod:`~stewartid.identification.stops`): the rows lose its filtered signatures.
    """
    Ys, ys, used, pose_noise, poses, force_noise = [], [], [], [], [], []
    windows = [window or default_window(estimate_frequency(exp.q, exp.sample_rate))
               for exp in experiments]
    # one step for every experiment: each keeps its share of the rows, as without decimation
    step = decimate or min(row_step(w, exp.sample_rate)
                           for w, exp in zip(windows, experiments, strict=True))
    # one buffer for every experiment's signals, time last for contiguous kernel sums
    width = 2 + reg.N_STANDARD  # force, regressor columns, pose
    buffer = np.empty(6 * width * max(len(exp.q) for exp in experiments))
    for exp, w in zip(experiments, windows, strict=True):
        n = len(exp.q)
        q, q_dot, q_ddot = differentiate(exp.q, exp.sample_rate, w / SAVGOL_FRACTION, order)
        pose_noise.append(white_noise_covariance(exp.q, q))
        forces = np.linalg.solve(np.swapaxes(exp.leg_jacobian, 1, 2),
                                 exp.generalized_force[..., None])[..., 0]
        force_noise.append(white_noise_covariance(forces, differentiate(
            forces, exp.sample_rate, w / SAVGOL_FRACTION, order, (0,))[0]))
        stops = None
        if leg_stops:  # the stops are found on the sign rates, which they return
            stops = find_stops(exp.q, exp.leg_jacobian, exp.sample_rate, w, pose_noise[-1])
            sign_rates, sign_window = stops.q_dot, stops.sign_window
        else:
            sign_rates, sign_window = coulomb_sign_rates(exp.q, exp.sample_rate, w,
                                                         pose_noise[-1])
        motion = [np.ascontiguousarray(x.T) for x in (q, q_dot, q_ddot, sign_rates)]
        signals = buffer[:6 * width * n].reshape(6, width, n)
        signals[:, 0] = exp.generalized_force.T
        signals[:, -1] = exp.q.T
        for lo in range(0, n, REGRESSOR_CHUNK):  # chunks keep the temporaries in cache
            hi = min(n, lo + REGRESSOR_CHUNK)
            reg.regressor_columns(platform, *(x[:, lo:hi] for x in motion), gravity,
                                  coulomb_smoothing, out=signals[:, 1:-1, lo:hi])
        if stops is not None:  # no sign law in a stop
            law = smooth_sign(stops.leg_rates, reg.ACTUATOR_SMOOTHING) * stops.stopped
            signals[:, 1 + reg.PARAMETERS.index("coulomb[actuator]")] -= np.einsum(
                "nl,nlc->cn", law, exp.leg_jacobian)
        filtered = kernel_filter_rows(signals, exp.sample_rate, w, step, time_last=True)
        Y, y = filtered[:, 1:-1].transpose(2, 0, 1), filtered[:, 0].T
        absorbed = 0
        if stops is not None:  # the stops' free friction out of every row
            basis = stop_basis(stops, exp.sample_rate, w, step, exp.name)
            Y, y = project_out(basis, Y, y)
            absorbed = basis.shape[1]
        Ys.append(Y)
        ys.append(y)
        poses.append(filtered[:, -1].T)
        used.append({"name": exp.name, "window_s": w, "samples": filtered.shape[-1],
                     "row_step": step, "sign_window_s": sign_window,
                     "sample_rate": exp.sample_rate, "stop_rows": absorbed})
    return Regression(np.concatenate(Ys), np.concatenate(ys), used, pose_noise,
                      np.concatenate(poses), force_noise)


def leg_force_transforms(platform: Platform, poses: np.ndarray) -> np.ndarray:
    """J_lq^-T (K, 6, 6) at each row's pose: in leg forces a row's noise has equal uncorrelated
    channels, so residual-variance weighting is generalized least squares.
    """
    return np.swapaxes(np.linalg.inv(leg_jacobian(platform, poses)), 1, 2)


#: Samples per call of the regressor in :func:`filtered_regression`.
REGRESSOR_CHUNK = 1000


__all__ = ["REGRESSOR_CHUNK", "ROWS_PER_WINDOW", "SAVGOL_FRACTION", "SAVGOL_ORDER", "Regression",
           "filtered_regression", "leg_force_transforms", "row_step"]
