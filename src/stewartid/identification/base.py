"""Shared pieces of every identifier: measured experiments, the least-squares solver, the
base estimator.

The identified model is the paper's linearised equation of motion (Zhang 2020, Eq. 5),

    Mt q_ddot + Bt q_dot + G(q) + Fc(q_dot) = J_lq(q)^T f_a,

with J_lq evaluated at every *measured* pose and, by default, the pose-dependent gravity term
G(q) of the platform description subtracted from the measured generalized force, so that
the identifiers see y = J_lq^T f_a - G(q) = Mt q_ddot + Bt q_dot + Fc + (small offsets).

References
----------
Zhang, C. "A Parameter Identification Method for Stewart Manipulator Based on Wavelet
Transform." Mathematics 8(2), 257 (2020). doi:10.3390/math8020257
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from stewartid.dataset import Dataset, read_datasets
from stewartid.dynamics import ModelTerms
from stewartid.errors import ConfigError, IdentificationError
from stewartid.identification.results import IdentificationResult
from stewartid.platform import Platform, load_platform

#: Names of the generalized coordinates, paper order.
COORDINATES = ("x", "y", "z", "rx", "ry", "rz")


@dataclass(frozen=True)
class Experiment:
    """One experiment prepared for identification.

    Attributes
    ----------
    name : str
    t : ndarray, shape (N,)
        Time (s), uniform.
    q : ndarray, shape (N, 6)
        Measured pose (m, rad).
    generalized_force : ndarray, shape (N, 6)
        y = J_lq(q)^T f_a - G(q) (N, N m); without the gravity term when gravity subtraction
        is off.
    leg_jacobian : ndarray, shape (N, 6, 6)
        J_lq at every measured pose.
    joint_jacobians : ndarray, shape (N, 6, 5, 6)
        Joint-axis rate Jacobians at every measured pose (rad/s per unit q_dot), axes
        lower 1, lower 2, upper 1, upper 2, revolute.
    gravity : ndarray, shape (N, 6)
        G(q) of the platform description (N, N m), whether or not it was subtracted.
    sample_rate : float
        Hz.
    """

    name: str
    t: np.ndarray
    q: np.ndarray
    generalized_force: np.ndarray
    leg_jacobian: np.ndarray
    joint_jacobians: np.ndarray
    gravity: np.ndarray
    sample_rate: float

    @property
    def period(self) -> float:
        """Sample period (s)."""
        return 1.0 / self.sample_rate

    def __len__(self) -> int:
        return len(self.t)


def resolve_platform(platform: Platform | str | Path) -> Platform:
    """A Platform from a Platform, ``"paper"`` or a TOML path."""
    if isinstance(platform, Platform):
        return platform
    if isinstance(platform, str | Path):
        return load_platform(platform)
    raise ConfigError(f"platform must be a Platform, 'paper' or a TOML path; got "
                      f"{type(platform).__name__}.")


def resolve_datasets(datasets: Any, platform: Platform) -> list[Dataset]:
    """Datasets from a Dataset, a path, or a sequence of either."""
    if isinstance(datasets, Dataset | str | Path):
        datasets = [datasets]
    datasets = list(datasets)
    if not datasets:
        raise IdentificationError("no experiments given; pass one or more data sets.")
    out: list[Dataset] = []
    for d in datasets:
        if isinstance(d, Dataset):
            out.append(d)
        elif isinstance(d, str | Path):
            out.extend(read_datasets([d], platform))
        else:
            raise IdentificationError(f"expected Dataset objects or file paths; got "
                                      f"{type(d).__name__}.")
    return out


def prepare(datasets: Sequence[Dataset], platform: Platform, gravity: bool = True
            ) -> list[Experiment]:
    """Jacobians, gravity and generalized forces at every measured pose.

    Parameters
    ----------
    datasets : sequence of Dataset
    platform : Platform
        Platform description (geometry for J_lq; leg masses for G(q)).
    gravity : bool
        Subtract the model's pose-dependent gravity term G(q) from J_lq^T f_a. Without it the
        legs' gravity stiffness biases Mt by about -K_G / omega^2 (about -3 % on Mt(4,4) of
        the paper's platform at 0.5 Hz).

    Returns
    -------
    list of Experiment
    """
    out = []
    for d in datasets:
        terms = ModelTerms(platform, d.pose)
        y = np.einsum("nji,nj->ni", terms.leg_jacobian, d.forces)
        if gravity:
            y = y - terms.gravity
        out.append(Experiment(name=d.name, t=d.t, q=d.pose, generalized_force=y,
                              leg_jacobian=terms.leg_jacobian,
                              joint_jacobians=terms.joint_jacobians, gravity=terms.gravity,
                              sample_rate=d.sample_rate))
    return out


# ----------------------------------------------------------------------------- least squares

@dataclass(frozen=True)
class LeastSquaresSolution:
    """Solution of :func:`solve_least_squares`.

    Attributes
    ----------
    theta : ndarray, shape (6, p)
        Coefficients: y_i = sum_j theta[i, j] phi_j (+ shared terms). The first six columns
        are Mt, the next six Bt when the regressors are ordered [q_ddot, q_dot, ...].
    theta_std : ndarray, shape (6, p)
        Standard errors of ``theta``.
    shared : ndarray, shape (s,)
        Coefficients of the shared terms (one scalar for all six channels each).
    shared_std : ndarray, shape (s,)
    condition_number : float
        Of the column-equilibrated, channel-weighted regression matrix (2-norm).
    residual_rms : ndarray, shape (6,)
        Per channel (units of y).
    n_equations : int
        Rows per channel.
    """

    theta: np.ndarray
    theta_std: np.ndarray
    shared: np.ndarray
    shared_std: np.ndarray
    condition_number: float
    residual_rms: np.ndarray
    n_equations: int


def _regressor_dof(name: str) -> str | None:
    for c in COORDINATES[::-1]:  # 'rx' before 'x'
        if name.endswith(f"[{c}]"):
            return c
    return None


def _check_rank(normal: np.ndarray, names: Sequence[str], max_condition: float) -> float:
    """Condition number of the equilibrated regression (square root of the normal matrix's);
    raise IdentificationError on rank loss."""
    diag = np.diag(normal).copy()
    scale = np.sqrt(np.abs(diag))
    top = float(np.max(scale)) if len(scale) else 0.0
    dead = np.flatnonzero(scale <= 1e-12 * max(top, 1e-300))
    if len(dead):
        _raise_unexcited([names[i] for i in dead])
    S = normal / np.outer(scale, scale)
    eigenvalues, vectors = np.linalg.eigh(S)
    eigenvalues = np.clip(eigenvalues, 0.0, None)
    condition = float(np.sqrt(eigenvalues[-1] / eigenvalues[0])) if eigenvalues[0] > 0 \
        else np.inf
    if condition > max_condition:
        weight = np.abs(vectors[:, 0])
        involved = [names[i] for i in np.argsort(weight)[::-1] if weight[i] > 0.2]
        _raise_unexcited(involved, condition)
    return condition


def _raise_unexcited(regressors: Sequence[str], condition: float | None = None) -> None:
    regressors = list(dict.fromkeys(regressors))
    dofs = sorted({d for d in map(_regressor_dof, regressors) if d},
                  key=COORDINATES.index)
    what = (f"the regression is rank deficient (condition number {condition:.3g})"
            if condition is not None else "some regressors are identically zero")
    if dofs:
        raise IdentificationError(
            f"{what}: DOF {', '.join(dofs)} was never excited (regressors "
            f"{', '.join(regressors[:6])}); add an experiment that moves "
            f"{'it' if len(dofs) == 1 else 'them'}.")
    raise IdentificationError(
        f"{what}: the regressors {', '.join(regressors[:6])} cannot be separated from the "
        "others; excite more DOF or drop those terms.")


def _symmetric_map(p: int, symmetric: bool) -> np.ndarray:
    """Matrix T with vec(theta) = T z (row-major vec of the (6, p) theta)."""
    if not symmetric:
        return np.eye(6 * p)
    columns = []
    for block in (0, 6):
        for i in range(6):
            for j in range(i, 6):
                col = np.zeros(6 * p)
                col[i * p + block + j] = 1.0
                col[j * p + block + i] = 1.0
                columns.append(col)
    for i in range(6):
        for j in range(12, p):
            col = np.zeros(6 * p)
            col[i * p + j] = 1.0
            columns.append(col)
    return np.array(columns).T


def solve_least_squares(phi: np.ndarray, y: np.ndarray, shared: np.ndarray | None = None,
                        symmetric: bool = False, regressor_names: Sequence[str] | None = None,
                        shared_names: Sequence[str] | None = None,
                        max_condition: float = 1e8,
                        autocorrelated: bool = False) -> LeastSquaresSolution:
    """Least squares for y(k) = theta phi(k) + sum_s c_s S_s(k), with standard errors.

    Every channel i of ``y`` shares the regressor rows ``phi``; the shared terms S_s are
    6-vectors per row multiplied by one scalar c_s common to all channels (a Coulomb level
    mapped through Jacobians, for instance). Channels have different units (N and N m) and
    noise levels, so the solve is weighted by each channel's residual variance from a first,
    equally weighted pass (feasible generalized least squares); with ``symmetric`` the
    weighting is what couples the channels, without it the coefficients of theta equal the
    per-channel ordinary least squares.

    The normal equations are assembled from p x p Gram blocks, so memory does not grow with
    the number of rows beyond the inputs; columns are equilibrated before solving.

    Parameters
    ----------
    phi : ndarray, shape (K, p)
        Regressor rows; with ``symmetric`` the first 12 columns must be [q_ddot, q_dot]
        (coefficients Mt, Bt).
    y : ndarray, shape (K, 6)
        Targets (generalized forces or their transforms).
    shared : ndarray, shape (K, s, 6), optional
        Shared-coefficient terms.
    symmetric : bool
        Impose Mt = Mt^T and Bt = Bt^T.
    regressor_names, shared_names : sequence of str, optional
        Used in error messages, e.g. ``"q_ddot[rx]"``.
    max_condition : float
        Largest acceptable condition number of the equilibrated regression; above it the
        problem counts as rank deficient and an IdentificationError names the regressors.
    autocorrelated : bool
        The rows are consecutive samples of a time series whose residuals are correlated
        (filtered signals): inflate each channel's variance by its integrated
        autocorrelation time tau = 1 + 2 sum_k rho_k (summed while rho_k > 0), i.e. count
        K / tau independent equations. Without it the standard errors assume white residuals.

    Returns
    -------
    LeastSquaresSolution

    Raises
    ------
    IdentificationError
        Too few equations, or rank deficiency (names the DOF that was never excited).
    """
    phi = np.asarray(phi, dtype=float)
    y = np.asarray(y, dtype=float)
    K, p = phi.shape
    S = np.zeros((K, 0, 6)) if shared is None else np.asarray(shared, dtype=float)
    s = S.shape[1]
    if y.shape != (K, 6) or S.shape != (K, s, 6):
        raise IdentificationError(f"inconsistent regression shapes: phi {phi.shape}, y "
                                  f"{y.shape}, shared {S.shape}.")
    if symmetric and p < 12:
        raise IdentificationError("the symmetry constraint needs the regressors [q_ddot, "
                                  f"q_dot, ...] (at least 12 columns); got {p}.")
    names = list(regressor_names) if regressor_names is not None else \
        [f"phi[{j}]" for j in range(p)]
    snames = list(shared_names) if shared_names is not None else [f"shared[{j}]" for j in
                                                                  range(s)]
    T = _symmetric_map(p, symmetric)
    n_unknowns = T.shape[1] + s
    if 6 * K <= n_unknowns:
        raise IdentificationError(f"only {K} equations per channel for {n_unknowns} unknowns; "
                                  "use longer records or more (a, b) points / experiments.")

    gram = phi.T @ phi                                    # (p, p)
    cross = np.einsum("kj,ksi->ijs", phi, S)              # (6, p, s)
    shared_gram = np.einsum("ksi,kti->ist", S, S)         # (6, s, s)
    rhs_theta = phi.T @ y                                 # (p, 6)
    rhs_shared = np.einsum("ksi,ki->is", S, y)            # (6, s)

    def assemble(weights: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        n_full = 6 * p
        N = np.zeros((n_full + s, n_full + s))
        b = np.zeros(n_full + s)
        for i in range(6):
            w = weights[i]
            sl = slice(i * p, (i + 1) * p)
            N[sl, sl] = w * gram
            N[sl, n_full:] = w * cross[i]
            N[n_full:, sl] = w * cross[i].T
            N[n_full:, n_full:] += w * shared_gram[i]
            b[sl] = w * rhs_theta[:, i]
            b[n_full:] += w * rhs_shared[i]
        Tf = np.zeros((n_full + s, T.shape[1] + s))
        Tf[:n_full, :T.shape[1]] = T
        Tf[n_full:, T.shape[1]:] = np.eye(s)
        return Tf.T @ N @ Tf, Tf.T @ b, Tf

    z_names = _unknown_names(names, snames, T, p)

    def solve(weights):
        N, b, Tf = assemble(weights)
        condition = _check_rank(N, z_names, max_condition)
        scale = np.sqrt(np.diag(N))
        Ns = N / np.outer(scale, scale)
        z = np.linalg.solve(Ns, b / scale) / scale
        full = Tf @ z
        theta = full[:6 * p].reshape(6, p)
        c = full[6 * p:]
        residual = y - phi @ theta.T - np.einsum("ksi,s->ki", S, c)
        return theta, c, residual, N, Tf, condition, scale

    scale_y = np.sqrt(np.mean(y ** 2, axis=0))
    scale_y = np.where(scale_y > 0, scale_y, 1.0)
    theta, c, residual, *_ = solve(1.0 / scale_y ** 2)
    dof = max(K - n_unknowns / 6.0, 1.0)
    sigma = np.sqrt(np.sum(residual ** 2, axis=0) / dof)
    # floor: exact (noise-free) data must not produce infinite weights
    sigma = np.maximum(sigma, 1e-12 * scale_y)
    theta, c, residual, N, Tf, condition, scale = solve(1.0 / sigma ** 2)
    sigma2 = np.sum(residual ** 2, axis=0) / dof
    if autocorrelated:
        sigma2 = sigma2 * np.array([integrated_autocorrelation(r) for r in residual.T])
    weighted_variance = float(np.mean(sigma2 / sigma ** 2))
    Ns_inv = np.linalg.inv(N / np.outer(scale, scale)) / np.outer(scale, scale)
    cov_full = weighted_variance * (Tf @ Ns_inv @ Tf.T)
    std = np.sqrt(np.clip(np.diag(cov_full), 0.0, None))
    return LeastSquaresSolution(
        theta=theta, theta_std=std[:6 * p].reshape(6, p), shared=c, shared_std=std[6 * p:],
        condition_number=condition, residual_rms=np.sqrt(np.mean(residual ** 2, axis=0)),
        n_equations=K)


def integrated_autocorrelation(x: np.ndarray, max_lag: int | None = None) -> float:
    """Integrated autocorrelation time tau = 1 + 2 sum_{k>=1} rho_k of a series (samples).

    The sum stops at the first non-positive autocorrelation (initial positive sequence), so
    white noise gives tau close to 1 and a signal smoothed over w samples about w.
    """
    x = np.asarray(x, dtype=float) - np.mean(x)
    n = len(x)
    if n < 4 or not np.any(x):
        return 1.0
    nfft = 1 << int(np.ceil(np.log2(2 * n)))
    spectrum = np.fft.rfft(x, nfft)
    acf = np.fft.irfft(np.abs(spectrum) ** 2, nfft)[: (max_lag or n // 4) + 1]
    rho = acf[1:] / acf[0]
    stop = np.flatnonzero(rho <= 0)
    rho = rho[: stop[0]] if len(stop) else rho
    return float(max(1.0, 1.0 + 2.0 * np.sum(rho)))


def _unknown_names(names: list[str], snames: list[str], T: np.ndarray, p: int) -> list[str]:
    out = []
    for col in T.T:
        k = int(np.flatnonzero(col)[0])
        out.append(names[k % p])
    return out + snames


def regressor_names(*groups: str) -> list[str]:
    """Names like ``q_ddot[x] ... q_dot[rz]`` for regressor groups given by prefix."""
    return [f"{g}[{c}]" for g in groups for c in COORDINATES]


# ----------------------------------------------------------------------------- estimator

class BaseIdentifier:
    """Base class of the identifiers (scikit-learn estimator contract).

    ``__init__`` of a subclass stores its settings only; :meth:`fit` validates data and
    settings and returns ``self``; everything learned ends in ``_``:

    ``M_``, ``B_`` : ndarray (6, 6)
        Identified inertial and viscous matrices (paper frame).
    ``std_errors_`` : dict with ``"M"`` and ``"B"`` : ndarray (6, 6)
        Standard errors from the residuals.
    ``condition_number_`` : float
    ``result_`` : IdentificationResult
    """

    #: Method name stored in the result.
    method = "base"

    def get_params(self) -> dict[str, Any]:
        """Settings given to ``__init__``."""
        import inspect

        names = [n for n in inspect.signature(type(self).__init__).parameters if n != "self"]
        return {n: getattr(self, n) for n in names}

    def set_params(self, **params: Any) -> BaseIdentifier:
        """Change settings; returns self."""
        valid = self.get_params()
        for key, value in params.items():
            if key not in valid:
                raise ConfigError(f"{type(self).__name__} has no setting {key!r}; valid "
                                  f"settings are {', '.join(valid)}.")
            setattr(self, key, value)
        return self

    def __repr__(self) -> str:
        args = ", ".join(f"{k}={v!r}" for k, v in self.get_params().items())
        return f"{type(self).__name__}({args})"

    def _validate_params(self) -> None:
        """Check the settings; subclasses raise ConfigError with the sklearn-style message."""

    def fit(self, datasets: Any, platform: Platform | str | Path = "paper") -> BaseIdentifier:
        """Identify Mt and Bt from experiments.

        Parameters
        ----------
        datasets : Dataset, path, or sequence of them
            The experiments (several files = several experiments).
        platform : Platform, 'paper' or TOML path
            Platform description: geometry for the Jacobians, leg masses for G(q).

        Returns
        -------
        self
        """
        self._validate_params()
        platform = resolve_platform(platform)
        data = resolve_datasets(datasets, platform)
        result = self._fit(data, platform)
        self.result_ = result
        self.M_ = result.M
        self.B_ = result.B
        self.std_errors_ = {"M": result.std_errors_M, "B": result.std_errors_B}
        self.condition_number_ = result.condition_number
        return self

    def _fit(self, datasets: list[Dataset], platform: Platform) -> IdentificationResult:
        raise NotImplementedError


def check_parameter(owner: str, name: str, value: Any, ok: bool, expected: str) -> None:
    """Raise ConfigError in the form "The 'name' parameter of Owner must be ... Got ... instead."."""
    if not ok:
        raise ConfigError(f"The {name!r} parameter of {owner} must be {expected}. "
                          f"Got {value!r} instead.")


__all__ = [
    "COORDINATES",
    "BaseIdentifier",
    "Experiment",
    "IdentificationResult",
    "LeastSquaresSolution",
    "check_parameter",
    "integrated_autocorrelation",
    "prepare",
    "regressor_names",
    "resolve_datasets",
    "resolve_platform",
    "solve_least_squares",
]
