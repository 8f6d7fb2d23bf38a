"""Physical consistency of identified Mt and Bt, and the nearest consistent pair.

M symmetric positive definite, B positive semidefinite, nearest in the estimate's standard errors
(needs cvxpy; Traversaro et al., IROS 2016).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from stewartid.errors import ConfigError, IdentificationError

#: Floor of the smallest eigenvalue of Mt, relative to the mean of |diag(M^)|.
STRICT_FRACTION = 1e-6


def asymmetry(matrix: np.ndarray) -> float:
    """Relative Frobenius norm of the antisymmetric part, ||(A - A^T) / 2|| / ||A|| (NaN for zero A)."""
    matrix = np.asarray(matrix, dtype=float)
    norm = np.linalg.norm(matrix)
    return float(np.linalg.norm(matrix - matrix.T) / 2 / norm) if norm > 0 else float("nan")


def min_eigenvalue(matrix: np.ndarray) -> float:
    """Smallest eigenvalue of the symmetric part (A + A^T) / 2; NaN if an entry is not finite."""
    matrix = np.asarray(matrix, dtype=float)
    if not np.all(np.isfinite(matrix)):
        return float("nan")
    return float(np.linalg.eigvalsh((matrix + matrix.T) / 2)[0])


def consistency_metrics(M: np.ndarray, B: np.ndarray) -> dict[str, float]:
    """The ``consistency`` object of ``result.json``: min eigenvalues and asymmetry of M and B."""
    return {"M_min_eigenvalue": min_eigenvalue(M), "B_min_eigenvalue": min_eigenvalue(B),
            "M_asymmetry": asymmetry(M), "B_asymmetry": asymmetry(B)}


def is_consistent(M: np.ndarray, B: np.ndarray, tolerance: float = 1e-9) -> bool:
    """True if M is symmetric positive definite and B positive semidefinite (tolerance relative)."""
    metrics = consistency_metrics(M, B)
    scale_M, scale_B = np.abs(M).max(), max(np.abs(B).max(), 1e-300)
    return bool(metrics["M_asymmetry"] <= tolerance and metrics["B_asymmetry"] <= tolerance
                and metrics["M_min_eigenvalue"] > 0
                and metrics["B_min_eigenvalue"] >= -tolerance * scale_B
                and scale_M > 0)


@dataclass(frozen=True)
class ConsistentEstimate:
    """The nearest physically consistent pair to an estimate.

    Attributes
    ----------
    M, B : ndarray, shape (6, 6)
    change_M, change_B : ndarray, shape (6, 6)
        |consistent - unconstrained| in standard errors.
    solver : str
    objective : float
        Sum of squared changes in standard errors.
    """

    M: np.ndarray
    B: np.ndarray
    change_M: np.ndarray
    change_B: np.ndarray
    solver: str
    objective: float

    @property
    def max_change(self) -> float:
        """Largest change of any entry, in standard errors."""
        return float(max(self.change_M.max(), self.change_B.max()))

    def to_dict(self) -> dict[str, Any]:
        """Summary for ``result.json`` (diagnostics)."""
        return {"solver": self.solver, "objective": self.objective,
                "max_change_std_errors": self.max_change,
                "change_M_std_errors": self.change_M, "change_B_std_errors": self.change_B}


def _weights(std: np.ndarray, estimate: np.ndarray) -> np.ndarray:
    """1 / standard error; unusable errors take the median so no entry is free."""
    std = np.asarray(std, dtype=float)
    usable = np.isfinite(std) & (std > 0)
    scale = float(np.abs(estimate).max()) or 1.0
    fallback = float(np.median(std[usable])) if usable.any() else 1e-6 * scale
    return 1.0 / np.where(usable, np.maximum(std, 1e-9 * scale), fallback)


def require_cvxpy() -> Any:
    """The cvxpy module.

    Raises
    ------
    ConfigError
        If it is not installed.
    """
    try:
        import cvxpy
    except ImportError:
        raise ConfigError('the consistent fit needs cvxpy; install the extra with pip install '
                          '"stewartid[convex]".') from None
    return cvxpy


def default_solver() -> str:
    """Clarabel when installed (the ``convex`` extra's), else SCS."""
    cp = require_cvxpy()
    return "CLARABEL" if "CLARABEL" in cp.installed_solvers() else "SCS"


def solve_convex(problem: Any, solver: str | None, hint: str) -> tuple[str, str]:
    """Solve a consistent-fit cvxpy problem; returns (solver, status), "optimal_inaccurate" counts.

    Raises
    ------
    IdentificationError
        The solver fails or finds no solution (message ends with ``hint``).
    """
    import warnings

    cp = require_cvxpy()
    solver = solver or default_solver()
    try:
        with warnings.catch_warnings():  # "inaccurate" is reported in the status instead
            warnings.filterwarnings("ignore", "Solution may be inaccurate", UserWarning)
            problem.solve(solver=solver)
    except cp.error.SolverError as exc:
        raise IdentificationError(f"the consistent fit failed in solver {solver}: {exc}; "
                                  "try another solver.") from None
    if problem.status not in ("optimal", "optimal_inaccurate") or problem.value is None:
        raise IdentificationError(f"the consistent fit found no solution (solver {solver}, "
                                  f"status {problem.status}); {hint}.")
    return solver, str(problem.status)


def project_consistent(M: np.ndarray, B: np.ndarray, std_M: np.ndarray, std_B: np.ndarray,
                       solver: str | None = None) -> ConsistentEstimate:
    """The consistent (M, B) nearest to an estimate, weighted by its standard errors.

    minimise sum ((M - M^) / s_M)^2 + sum ((B - B^) / s_B)^2 s.t. M - delta I, B positive semidefinite.

    Raises
    ------
    ConfigError
        If cvxpy is not installed.
    IdentificationError
        If the solver fails.
    """
    cp = require_cvxpy()
    M_hat, B_hat = np.asarray(M, dtype=float), np.asarray(B, dtype=float)
    W_M, W_B = _weights(std_M, M_hat), _weights(std_B, B_hat)
    floor = STRICT_FRACTION * float(np.mean(np.abs(np.diag(M_hat))))
    M_var = cp.Variable((6, 6), symmetric=True)
    B_var = cp.Variable((6, 6), symmetric=True)
    # in standard errors the problem is unit-free, which keeps the solver's tolerances meaningful
    objective = cp.Minimize(cp.sum_squares(cp.multiply(W_M, M_var - M_hat))
                            + cp.sum_squares(cp.multiply(W_B, B_var - B_hat)))
    constraints = [M_var - floor * np.eye(6) >> 0, B_var >> 0]
    problem = cp.Problem(objective, constraints)
    solver, _ = solve_convex(problem, solver, "check the standard errors")
    # exact symmetry and definiteness after the solver's tolerances
    M_new, B_new = _symmetric(M_var.value), _clip_psd(_symmetric(B_var.value), 0.0)
    M_new = _clip_psd(M_new, floor)
    return ConsistentEstimate(M=M_new, B=B_new, change_M=np.abs(M_new - M_hat) * W_M,
                              change_B=np.abs(B_new - B_hat) * W_B, solver=solver,
                              objective=float(problem.value))


def _symmetric(matrix: np.ndarray) -> np.ndarray:
    return (matrix + matrix.T) / 2


def _clip_psd(matrix: np.ndarray, floor: float) -> np.ndarray:
    """Raise eigenvalues below ``floor`` to it."""
    values, vectors = np.linalg.eigh(matrix)
    if values[0] >= floor:
        return matrix
    return _symmetric((vectors * np.maximum(values, floor)) @ vectors.T)


__all__ = ["STRICT_FRACTION", "ConsistentEstimate", "asymmetry", "consistency_metrics",
           "default_solver", "is_consistent", "min_eigenvalue", "project_consistent",
           "require_cvxpy", "solve_convex"]
