"""Least-squares solvers shared by the identifiers.

Feasible generalized least squares with rank checks; errors-in-variables with cluster-robust errors.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from stewartid.errors import IdentificationError
from stewartid.identification.long_run import score_sandwich, with_larger_variances
from stewartid.platform import COORDINATES


@dataclass(frozen=True)
class LeastSquaresSolution:
    """Solution of :func:`solve_least_squares`.

    Attributes
    ----------
    theta, theta_std : ndarray, shape (6, p)
        y_i = sum_j theta[i, j] phi_j (+ shared terms), and standard errors.
    shared, shared_std : ndarray, shape (s,)
        One coefficient per shared term for all channels.
    condition_number : float
        Of the column-equilibrated, channel-weighted regression (2-norm).
    residual_rms : ndarray, shape (6,)
        Units of y.
    n_equations : int
        Rows per channel.
    effective_equations : ndarray, shape (6,)
        Rows per channel over the residual's autocorrelation time.
    """

    theta: np.ndarray
    theta_std: np.ndarray
    shared: np.ndarray
    shared_std: np.ndarray
    condition_number: float
    residual_rms: np.ndarray
    n_equations: int
    effective_equations: np.ndarray


def _regressor_dof(name: str) -> str | None:
    for c in COORDINATES[::-1]:  # 'rx' before 'x'
        if name.endswith(f"[{c}]"):
            return c
    return None


def check_rank(normal: np.ndarray, names: Sequence[str], max_condition: float) -> float:
    """Condition number of the equilibrated regression from ``normal`` (p, p); raise on rank loss.

    Raises
    ------
    IdentificationError
        A zero regressor or a condition number over ``max_condition``, naming the DOF never excited.
    """
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
    """T with vec(theta) = T z (row-major vec of the (6, p) theta)."""
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
                        autocorrelated: bool = False,
                        regressor_noise: np.ndarray | None = None,
                        segments: Sequence[tuple[int, int]] | None = None,
                        absorbed: int = 0, standard_errors: bool = True
                        ) -> LeastSquaresSolution:
    """Least squares for y(k) = theta phi(k) + sum_s c_s S_s(k), with standard errors.

    Channels share ``phi`` and are weighted by their residual variance from a first pass.

    Parameters
    ----------
    phi : ndarray, shape (K, p)
        With ``symmetric``, the first 12 columns are [q_ddot, q_dot].
    y : ndarray, shape (K, 6)
    shared : ndarray, shape (K, s, 6), optional
    symmetric : bool
        Impose Mt = Mt^T, Bt = Bt^T.
    regressor_names, shared_names : sequence of str, optional
        For error messages.
    max_condition : float
    autocorrelated : bool
        Inflate variances by the integrated autocorrelation time.
    regressor_noise : ndarray, shape (p, p), optional
        Summed regressor-noise covariance, subtracted from phi^T phi.
    segments : sequence of (int, int), optional
        Rows and correlation length per record; variances become at least the score sandwich's.
    absorbed : int
        Rows' worth of freedom taken by regressors already projected out of ``phi``, ``y`` and
        ``shared`` (their coefficients free per channel).
    standard_errors : bool
        False: the estimates and residuals only, ``theta_std`` and ``shared_std`` NaN (a fit
        that only moves another's errors).

    Raises
    ------
    IdentificationError
        Too few equations, or rank deficiency (names the DOF never excited).
    """
    phi, y = np.asarray(phi, dtype=float), np.asarray(y, dtype=float)
    K, p = phi.shape
    S = np.zeros((K, 0, 6)) if shared is None else np.asarray(shared, dtype=float)
    s = S.shape[1]
    if y.shape != (K, 6) or S.shape != (K, s, 6):
        raise IdentificationError(f"inconsistent regression shapes: phi {phi.shape}, y "
                                  f"{y.shape}, shared {S.shape}.")
    if symmetric and p < 12:
        raise IdentificationError("the symmetry constraint needs the regressors [q_ddot, "
                                  f"q_dot, ...] (at least 12 columns); got {p}.")
    names = list(regressor_names or [f"phi[{j}]" for j in range(p)])
    snames = list(shared_names or [f"shared[{j}]" for j in range(s)])
    T = _symmetric_map(p, symmetric)
    n_unknowns = T.shape[1] + s
    if 6 * (K - absorbed) <= n_unknowns:
        raise IdentificationError(f"only {K} equations per channel for {n_unknowns} unknowns; "
                                  "use longer records or more (a, b) points / experiments.")

    gram = phi.T @ phi                                    # (p, p)
    if regressor_noise is not None:
        gram = gram - np.asarray(regressor_noise, dtype=float)
    # matrix products over the K rows (BLAS), not einsum loops
    flat = S.reshape(K, s * 6)
    cross = (phi.T @ flat).reshape(p, s, 6).transpose(2, 0, 1)             # (6, p, s)
    products = (flat.T @ flat).reshape(s, 6, s, 6)
    shared_gram = np.stack([products[:, i, :, i] for i in range(6)])       # (6, s, s)
    rhs_theta = phi.T @ y                                                  # (p, 6)
    rhs_shared = np.stack([S[:, :, i].T @ y[:, i] for i in range(6)])      # (6, s)

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
        condition = check_rank(N, z_names, max_condition)
        scale = np.sqrt(np.diag(N))
        Ns = N / np.outer(scale, scale)
        z = np.linalg.solve(Ns, b / scale) / scale
        full = Tf @ z
        theta = full[:6 * p].reshape(6, p)
        c = full[6 * p:]
        residual = y - phi @ theta.T - c @ S
        return theta, c, residual, N, Tf, condition, scale

    scale_y = np.sqrt(np.mean(y ** 2, axis=0))
    scale_y = np.where(scale_y > 0, scale_y, 1.0)
    theta, c, residual, *_ = solve(1.0 / scale_y ** 2)
    dof = max(K - absorbed - n_unknowns / 6.0, 1.0)
    sigma = np.sqrt(np.sum(residual ** 2, axis=0) / dof)
    # floor: exact (noise-free) data must not produce infinite weights
    sigma = np.maximum(sigma, 1e-12 * scale_y)
    theta, c, residual, N, Tf, condition, scale = solve(1.0 / sigma ** 2)
    tau = (np.array([integrated_autocorrelation(r) for r in residual.T]) if autocorrelated
           else np.ones(residual.shape[1]))
    residual_rms = np.sqrt(np.mean(residual ** 2, axis=0))
    if not standard_errors:
        return LeastSquaresSolution(
            theta=theta, theta_std=np.full_like(theta, np.nan), shared=c,
            shared_std=np.full_like(c, np.nan), condition_number=condition,
            residual_rms=residual_rms, n_equations=K, effective_equations=K / tau)
    Ns_inv = np.linalg.inv(N / np.outer(scale, scale)) / np.outer(scale, scale)
    sigma2 = np.sum(residual ** 2, axis=0) / dof * tau
    cov_full = float(np.mean(sigma2 / sigma ** 2)) * (Tf @ Ns_inv @ Tf.T)
    if segments is not None:  # the residual lacks the projected-out share of the noise
        cov_full = with_larger_variances(K / (K - absorbed) * Tf @ score_sandwich(
            Ns_inv, _row_scores(phi, S, residual / sigma ** 2), segments, Tf) @ Tf.T, cov_full)
    std = np.sqrt(np.clip(np.diag(cov_full), 0.0, None))
    return LeastSquaresSolution(
        theta=theta, theta_std=std[:6 * p].reshape(6, p), shared=c, shared_std=std[6 * p:],
        condition_number=condition, residual_rms=residual_rms,
        n_equations=K, effective_equations=K / tau)


def _row_scores(phi: np.ndarray, S: np.ndarray, weighted: np.ndarray) -> np.ndarray:
    """Per row, the gradient of its weighted squared residual (K, 6 p + s); ``weighted`` = r / sigma^2."""
    K, p = phi.shape
    scores = np.empty((K, 6 * p + S.shape[1]))
    np.multiply(phi[:, None, :], weighted[:, :, None], out=scores[:, :6 * p].reshape(K, 6, p))
    np.matmul(S, weighted[:, :, None], out=scores[:, 6 * p:, None])
    return scores


def integrated_autocorrelation(x: np.ndarray, max_lag: int | None = None) -> float:
    """tau = 1 + 2 sum_{k>=1} rho_k (samples), summed up to the first non-positive rho_k."""
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
    """Names like ``q_ddot[x]``, ``q_dot[rz]`` for regressor groups given by prefix."""
    return [f"{g}[{c}]" for g in groups for c in COORDINATES]


def bias_compensated_least_squares(phi: np.ndarray, target: np.ndarray, cluster: np.ndarray,
                                   noise_xx: np.ndarray, noise_xy: np.ndarray
                                   ) -> tuple[np.ndarray, np.ndarray]:
    """Errors-in-variables least squares with cluster-robust standard errors.

    theta_i = (X^T X - sum_k C_k)^-1 (X^T y_i - sum_k D_k[:, i]) (Stoica and Soderstrom 1982), with
    ``noise_xx`` C_k (K, p, p) and ``noise_xy`` D_k (K, p, C); sandwich over ``cluster`` with G / (G - 1).
    Returns theta, std (C, p).
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


__all__ = [
    "LeastSquaresSolution",
    "bias_compensated_least_squares",
    "check_rank",
    "integrated_autocorrelation",
    "regressor_names",
    "solve_least_squares",
]
