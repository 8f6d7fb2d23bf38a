"""Weak-form equations on constant-direction intervals, and their noise-aware solution.

The default Method B. Inside a constant-direction interval the equation of motion is

    Mt q_ddot + Bt q_dot + c_m = y,        y = J_lq(q)^T f_a - G(q),

with c_m the interval's constant (Coulomb friction of the moving joints, what the gravity
model leaves over). Multiplying by a test function phi that vanishes with its first
derivative at the interval's ends and integrating by parts moves both derivatives onto phi,

    Mt <phi'', q> - Bt <phi', q> + c_m <phi, 1> = <phi, y>,

so no signal is differentiated numerically (the modulating-function, or weak, form; the
paper's wavelet transform is the special case of one dilated and shifted wavelet).

Test functions, per interval of half-length L and centre c, x = (t - c) / L:

- a family of ``size`` zero-mean functions phi_k = d/dt [(1 - x^2)^p x^k], k = 0..size-1,
  orthonormalised on the samples (so that white force noise stays white and equally
  weighted, as in WENDy), which remove c_m exactly: these rows are Coulomb-invariant;
- one mean row, the bump (1 - x^2)^p orthogonalised against the family, which keeps c_m.

The mean rows say what the interval constants hold. With ``shared_friction`` the constant is
modelled as c_m = o_e + sum_types F_type W_m,type + delta_m: an offset per experiment, the
Coulomb level of each joint type (lower gimbal, upper gimbal, revolute) mapped through the
joint Jacobians with the interval's joint directions, and a random deviation delta_m of
variance tau^2 per channel estimated from the data (idle joints, a friction law other than
Coulomb's). Inside one interval the mean viscous force cannot be told from the constant; the
friction structure across intervals and experiments gives that information back, and tau^2
decides how much it is trusted: a plant whose friction does not fit the structure gets a
large tau^2 and the estimate falls back on the invariant rows alone.

The solve is iteratively reweighted least squares over all channels at once (the Coulomb
levels are shared by the channels), with the noise variance of each channel estimated from
the invariant rows' residuals. Standard errors are the larger of the model-based ones and a
cluster-robust sandwich over intervals (model errors such as a friction reversal inside an
interval show in the spread between intervals, not in the noise level).

References
----------
Zhang, C. "A Parameter Identification Method for Stewart Manipulator Based on Wavelet
Transform." Mathematics 8(2), 257 (2020). doi:10.3390/math8020257

Bortz, D. M., Messenger, D. A., Dukic, V. "Direct Estimation of Parameters in ODE Models Using
WENDy: Weak-Form Estimation of Nonlinear Dynamics." Bull. Math. Biol. 85, 110 (2023).
doi:10.1007/s11538-023-01208-6

Shinbrot, M. "On the analysis of linear and nonlinear systems." Trans. ASME 79, 547 (1957).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from functools import lru_cache

import numpy as np
from numpy.polynomial import polynomial

from stewartid.identification.least_squares import JOINT_TYPES
from stewartid.identification.solvers import _check_rank, regressor_names


@lru_cache(maxsize=32)
def _family_coefficients(order: int, size: int) -> tuple[np.ndarray, ...]:
    """Power-series coefficients (degree + 1, size + 1) of g, g', g'', g''' on [-1, 1].

    Column 0 is the bump (1 - x^2)^order; column k + 1 is (1 - x^2)^order x^k, whose
    derivative is the k-th zero-mean test function.
    """
    bump = polynomial.polypow([1.0, 0.0, -1.0], order)
    columns = [bump] + [np.r_[np.zeros(k), bump] for k in range(size)]
    degree = 2 * order + size + 1
    out = []
    for derivative in range(4):
        block = np.zeros((degree, size + 1))
        for j, c in enumerate(columns):
            d = polynomial.polyder(c, derivative) if derivative else c
            block[:len(d), j] = d
        out.append(block)
    return tuple(out)


@dataclass(frozen=True)
class IntervalEquations:
    """Weak-form equations of one constant-direction interval.

    Attributes
    ----------
    regressors : ndarray, shape (K, 12)
        Invariant rows: [<phi_k'', q>, -<phi_k', q>] (m s^-1, rad s^-1 times s^0 ...: the
        units of q_ddot and q_dot times seconds).
    targets : ndarray, shape (K, 6)
        <phi_k, y> (N s, N m s).
    mean_regressors : ndarray, shape (12,)
        The mean row's [<g'', q>, -<g', q>].
    mean_target : ndarray, shape (6,)
        <g, y>.
    weight : float
        <g, 1> (s^(1/2)): the mean row's coefficient of the interval constant.
    coulomb : ndarray, shape (n_types, 6)
        <g, W_type>: generalized Coulomb force per unit level of each joint type, with the
        interval's joint directions.
    experiment : int
        Index of the experiment the interval belongs to.
    """

    regressors: np.ndarray
    targets: np.ndarray
    mean_regressors: np.ndarray
    mean_target: np.ndarray
    weight: float
    coulomb: np.ndarray
    experiment: int


def interval_equations(t: np.ndarray, q: np.ndarray, y: np.ndarray,
                       joint_jacobians: np.ndarray | Callable[[np.ndarray], np.ndarray],
                       joint_rates: np.ndarray,
                       rate_noise: np.ndarray, interval: Sequence[float], order: int, size: int,
                       experiment: int = 0) -> IntervalEquations | None:
    """Weak-form equations of one interval (see the module docstring).

    Parameters
    ----------
    t : ndarray, shape (N,)
        Uniform sample times (s).
    q : ndarray, shape (N, 6)
        Measured pose (m, rad).
    y : ndarray, shape (N, 6)
        Generalized force J^T f - G(q) (N, N m).
    joint_jacobians : ndarray, shape (N, 6, 5, 6), or callable
        Joint-axis rate Jacobians (rad/s per unit q_dot), or a function returning them
        (n, 6, 5, 6) at the sample indices it is given (long records need not hold them).
    joint_rates : ndarray, shape (N, 6, 5)
        Smoothed joint-axis rates (rad/s); only their mean over the interval is used, for the
        joint directions.
    rate_noise : ndarray, shape (6, 5)
        Noise level of those rates (rad/s): a joint whose mean rate is within it counts as
        idle (its direction weighs |mean| / noise).
    interval : (start, stop)
        s.
    order : int
        Exponent p of the bump (1 - x^2)^p, >= 3 so that phi and phi' vanish at the ends.
    size : int
        Number of invariant test functions K.
    experiment : int
        Stored in the result.

    Returns
    -------
    IntervalEquations or None
        None when the interval holds fewer than 4 (K + 1) samples.
    """
    start, stop = float(interval[0]), float(interval[1])
    sel = np.flatnonzero((t > start) & (t < stop))
    if len(sel) < 4 * (size + 1):
        return None
    h = float(t[1] - t[0])
    half, centre = 0.5 * (stop - start), 0.5 * (start + stop)
    x = (t[sel] - centre) / half
    vander = polynomial.polyvander(x, _family_coefficients(order, size)[0].shape[0] - 1)
    # rows: test functions and their time derivatives, times the quadrature step
    g0, g1, g2, g3 = (vander @ c * (h / half ** d)
                      for d, c in enumerate(_family_coefficients(order, size)))
    phi0, phi1, phi2 = g1[:, 1:].T, g2[:, 1:].T, g3[:, 1:].T
    u, s, _ = np.linalg.svd(phi0, full_matrices=False)
    transform = (u / s).T  # orthonormal rows
    phi0, phi1, phi2 = transform @ phi0, transform @ phi1, transform @ phi2
    bump0, bump1, bump2 = g0[:, 0], g1[:, 0], g2[:, 0]
    projection = phi0 @ bump0
    bump0, bump1, bump2 = bump0 - projection @ phi0, bump1 - projection @ phi1, \
        bump2 - projection @ phi2
    norm = np.linalg.norm(bump0)
    bump0, bump1, bump2 = bump0 / norm, bump1 / norm, bump2 / norm
    # constants and straight lines vanish against phi'' and phi', so the offset only costs
    # rounding; removing the mean keeps it from being amplified
    qc = q[sel] - q[sel].mean(axis=0)
    ys = y[sel]
    mean_rate = joint_rates[sel].mean(axis=0)
    direction = mean_rate / np.sqrt(mean_rate ** 2 + rate_noise ** 2)
    jacobians = joint_jacobians(sel) if callable(joint_jacobians) else joint_jacobians[sel]
    pattern = np.einsum("la,nlac->nac", direction, jacobians)                  # (n, 5, 6)
    coulomb = np.array([bump0 @ pattern[:, list(axes)].sum(axis=1)
                        for axes in JOINT_TYPES.values()])
    return IntervalEquations(
        regressors=np.hstack([phi2 @ qc, -(phi1 @ qc)]), targets=phi0 @ ys,
        mean_regressors=np.r_[bump2 @ qc, -(bump1 @ qc)], mean_target=bump0 @ ys,
        weight=float(bump0.sum()), coulomb=coulomb, experiment=int(experiment))


@dataclass(frozen=True)
class WeakFormSolution:
    """Solution of :func:`solve_weak_form`.

    Attributes
    ----------
    theta, theta_std : ndarray, shape (6, 12)
        [Mt Bt] and standard errors.
    coulomb, coulomb_std : ndarray, shape (n_types,)
        Coulomb level per joint type (N m), NaN without shared friction.
    offsets : ndarray, shape (n_experiments, 6)
        Constant per experiment (N, N m), NaN without shared friction.
    noise_std : ndarray, shape (6,)
        Residual standard deviation of the invariant rows per channel.
    constant_scatter : ndarray, shape (6,)
        tau: spread of the interval constants around the friction structure (N, N m).
    condition_number : float
        Of the column-equilibrated invariant regression.
    n_equations : int
        Rows per channel.
    """

    theta: np.ndarray
    theta_std: np.ndarray
    coulomb: np.ndarray
    coulomb_std: np.ndarray
    offsets: np.ndarray
    noise_std: np.ndarray
    constant_scatter: np.ndarray
    condition_number: float
    n_equations: int


def solve_weak_form(equations: Sequence[IntervalEquations], n_experiments: int,
                    shared_friction: bool = True, iterations: int = 5,
                    max_condition: float = 1e8) -> WeakFormSolution:
    """Iteratively reweighted least squares for [Mt Bt] (and the friction structure).

    Parameters
    ----------
    equations : sequence of IntervalEquations
    n_experiments : int
    shared_friction : bool
        Use the mean rows with the friction structure of the module docstring; False: the
        invariant rows alone (every interval constant free).
    iterations : int
        Reweighting passes.
    max_condition : float
        Rank check of the invariant regression (names the DOF never excited).

    Returns
    -------
    WeakFormSolution
    """
    x = np.concatenate([e.regressors for e in equations])
    y = np.concatenate([e.targets for e in equations])
    rows_per = np.array([len(e.regressors) for e in equations])
    cluster = np.repeat(np.arange(len(equations)), rows_per)
    condition = _check_rank(x.T @ x, regressor_names("q_ddot", "q_dot"), max_condition)
    theta = np.linalg.solve(x.T @ x, x.T @ y).T
    dof = max(len(x) - 12, 1)
    # floor: noise-free data must not give infinite weights
    floor = 1e-24 * np.maximum(np.mean(y ** 2, axis=0), 1e-300)

    def channel_noise(coefficients: np.ndarray) -> np.ndarray:
        return np.maximum(np.sum((y - x @ coefficients.T) ** 2, axis=0) / dof, floor)

    noise = channel_noise(theta)
    n_types = equations[0].coulomb.shape[0]
    n_theta = 72
    n_unknowns = n_theta + (6 * n_experiments + n_types if shared_friction else 0)
    if shared_friction:
        xm = np.array([e.mean_regressors for e in equations])
        ym = np.array([e.mean_target for e in equations])
        weight = np.array([e.weight for e in equations])
        wm = np.array([e.coulomb for e in equations])                     # (m, types, 6)
        owner = np.array([e.experiment for e in equations])
        mean_cluster = np.arange(len(equations))
    scatter = np.zeros(6)
    if shared_friction:
        # the scatter of the interval constants around the friction structure, measured with
        # the invariant estimate: a joint fit would bend Bt to hide a structure that does
        # not hold, and so report a scatter too small to notice it
        base = ym - xm @ theta.T
        design = np.zeros((len(ym), 6, 6 * n_experiments + n_types))
        for i in range(6):
            design[np.arange(len(ym)), i, 6 * owner + i] = weight
            design[:, i, 6 * n_experiments:] = wm[:, :, i]
        flat = design.reshape(-1, design.shape[-1]) / np.sqrt(np.tile(noise, len(ym)))[:, None]
        nuisance = np.linalg.lstsq(flat, base.ravel() / np.sqrt(np.tile(noise, len(ym))),
                                   rcond=None)[0]
        mean_residual = base - design @ nuisance
        excess = np.sum(mean_residual ** 2, axis=0) - noise * len(ym)
        scatter = np.sqrt(np.maximum(excess, 0.0) / np.sum(weight ** 2))
    xtx = x.T @ x
    n_clusters = len(equations)
    if shared_friction:
        # the mean rows as an explicit (small) design: channel-major, (6 m, n_unknowns)
        n_mean = len(xm)
        mean_design = np.zeros((6, n_mean, n_unknowns))
        for i in range(6):
            mean_design[i, :, 12 * i:12 * i + 12] = xm
            mean_design[i, np.arange(n_mean), n_theta + 6 * owner + i] = weight
            mean_design[i, :, n_theta + 6 * n_experiments:] = wm[:, :, i]
        mean_design = mean_design.reshape(6 * n_mean, n_unknowns)
        mean_rhs = ym.T.ravel()
        mean_groups = np.tile(mean_cluster, 6)
    for _ in range(max(1, iterations)):
        # normal equations of the weighted rows: the invariant rows of channel i share the
        # design x, so they contribute x^T x / noise_i to their own 12 x 12 block
        normal = np.zeros((n_unknowns, n_unknowns))
        rhs = np.zeros(n_unknowns)
        xty = x.T @ y
        for i in range(6):
            block = slice(12 * i, 12 * i + 12)
            normal[block, block] = xtx / noise[i]
            rhs[block] = xty[:, i] / noise[i]
        if shared_friction:
            row_weight = 1.0 / (np.repeat(noise, n_mean)
                                + np.repeat(scatter ** 2, n_mean) * np.tile(weight ** 2, 6))
            weighted = mean_design * row_weight[:, None]
            normal += mean_design.T @ weighted
            rhs += weighted.T @ mean_rhs
        scale = np.sqrt(np.diag(normal))
        scale = np.where(scale > 0, scale, 1.0)
        z = np.linalg.solve(normal / np.outer(scale, scale), rhs / scale) / scale
        theta = z[:n_theta].reshape(6, 12)
        noise_used = noise
        noise = channel_noise(theta)
        if shared_friction:
            offsets = z[n_theta:n_theta + 6 * n_experiments].reshape(n_experiments, 6)
            levels = z[n_theta + 6 * n_experiments:]
    # covariances of the last solve (weights noise_used), in scaled coordinates
    residual = (y - x @ theta.T) / np.sqrt(noise_used)                 # weighted, (n, 6)
    scores = np.zeros((n_clusters, n_unknowns))
    for i in range(6):
        np.add.at(scores[:, 12 * i:12 * i + 12], cluster,
                  x * (residual[:, i] / np.sqrt(noise_used[i]))[:, None])
    squares = float(np.sum(residual ** 2))
    n_rows = residual.size
    if shared_friction:
        mean_residual = (mean_rhs - mean_design @ z) * np.sqrt(row_weight)
        np.add.at(scores, mean_groups, mean_design * (mean_residual * np.sqrt(row_weight))[:, None])
        squares += float(mean_residual @ mean_residual)
        n_rows += len(mean_residual)
    scores /= scale
    bread = np.linalg.pinv(normal / np.outer(scale, scale))
    model_cov = bread * (squares / max(n_rows - n_unknowns, 1))
    g = n_clusters
    robust_cov = (g / max(g - 1, 1) * (n_rows - 1) / max(n_rows - n_unknowns, 1)
                  * bread @ (scores.T @ scores) @ bread)
    std = np.sqrt(np.maximum(np.diag(model_cov), np.diag(robust_cov))) / scale
    if shared_friction:
        coulomb, coulomb_std = levels, std[n_theta + 6 * n_experiments:]
    else:
        offsets = np.full((n_experiments, 6), np.nan)
        coulomb = coulomb_std = np.full(n_types, np.nan)
    return WeakFormSolution(
        theta=theta, theta_std=std[:n_theta].reshape(6, 12), coulomb=coulomb,
        coulomb_std=coulomb_std, offsets=offsets, noise_std=np.sqrt(noise),
        constant_scatter=scatter, condition_number=condition, n_equations=int(len(x)))


__all__ = ["IntervalEquations", "WeakFormSolution", "interval_equations", "solve_weak_form"]
