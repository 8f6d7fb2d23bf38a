"""Physical model: weighted least squares of J_lq^T f = Y(q, q_dot, q_ddot) pi on the regressor's
base parameters (or a payload on the known platform), both sides kernel-filtered; the paper's
Mt, Bt at neutral follow from the parameters.
"""

from __future__ import annotations

import dataclasses
import functools
import math
from dataclasses import dataclass, field
from numbers import Integral
from typing import Any

import numpy as np

from stewartid.datasets.dataset import Dataset
from stewartid.errors import IdentificationError
from stewartid.fields import BOOLEAN, Interval, nonnegative, positive
from stewartid.identification.base import DIFFERENTIATION_CONSTRAINTS, BaseIdentifier
from stewartid.identification.consistency import require_cvxpy
from stewartid.identification.preparation import prepare
from stewartid.identification.registry import register_method
from stewartid.identification.result import IdentificationResult
from stewartid.identification.sampling import thinned_fits
from stewartid.model import matrix_regressors
from stewartid.model import regressor as reg
from stewartid.physical.noise import regressor_noise
from stewartid.physical.parameter_fit import (
    Body,
    ConsistentParameters,
    Solution,
    nearest_consistent,
    solve_parameters,
)
from stewartid.physical.regression import (
    SAVGOL_FRACTION,
    SAVGOL_ORDER,
    Regression,
    filtered_regression,
    leg_force_transforms,
)
from stewartid.platform import Platform

#: Names of the payload's parameters in payload mode (the moving body's columns).
PAYLOAD_PARAMETERS = tuple(f"payload.{name}" for name in reg.BODY_PARAMETERS)
#: The nuisance parameters of payload mode; an electric leg's reflected mass
#: (:data:`~stewartid.model.regressor.REFLECTED_PARAMETERS`) joins them.
NUISANCE_PARAMETERS = (reg.FRICTION_PARAMETERS + reg.ACTUATOR_PARAMETERS
                       + reg.OFFSET_PARAMETERS)
#: Standard parameters positive by nature, whose standard error is judged against their size.
POSITIVE_PARAMETERS = ("m", "I_xx", "I_yy", "I_zz", "m_u", "md_u", "md_l", "J_u", "J_l",
                       "viscous[lower_gimbal]", "viscous[upper_gimbal]", "reflected_mass")
#: Parameters that cannot be negative: friction coefficients and the reflected mass.
NONNEGATIVE_PARAMETERS = (reg.FRICTION_PARAMETERS + reg.ACTUATOR_PARAMETERS
                          + reg.REFLECTED_PARAMETERS)


@dataclass(frozen=True)
class PhysicalResult(IdentificationResult):
    """:class:`~stewartid.identification.result.IdentificationResult` of the physical model.

    Attributes
    ----------
    model : str
        ``"physical"``.
    parameters : dict of str to float
        Identified or fixed value per parameter.
    parameter_std_errors : dict of str to float
        NaN (JSON ``null``) when fixed at the file's value.
    base_parameters : dict of str to str
        Standard-parameter combination each stands for.
    """

    model: str = "physical"
    parameters: dict[str, float] = field(default_factory=dict)
    parameter_std_errors: dict[str, float] = field(default_factory=dict)
    base_parameters: dict[str, str] = field(default_factory=dict)

    def to_dict(self) -> dict[str, Any]:
        """:meth:`IdentificationResult.to_dict` plus the parameter fields."""
        from stewartid.files import to_jsonable

        return {**super().to_dict(), **to_jsonable({
            "model": self.model, "parameters": self.parameters,
            "parameter_std_errors": self.parameter_std_errors,
            "base_parameters": self.base_parameters})}


def known_platform(platform: Platform) -> Platform:
    """What payload mode takes as known: the description without its payload."""
    return platform.replace(payload=None)


@register_method(
    name="physical", color="#8c564b", compared=False,
    display_name="Physical model",
    description="weighted least squares on the base parameters of the rigid-body model "
                "(masses, first moments, inertias, friction per joint type, sensor offsets); "
                "Mt, Bt from them",
    reference="Khalil, W., Dombre, E. Modeling, Identification and Control of Robots, "
              "ch. 12 (2002); Gautier, M. Numerical calculation of the base inertial "
              "parameters of robots, J. Robotic Systems 8(4) (1991)")
class PhysicalIdentifier(BaseIdentifier):
    """Physical parameters of the rigid-body model by weighted least squares, and Mt, Bt at
    neutral from them.

    Parameters
    ----------
    payload : bool
        Identify the payload alone on the known platform; friction and offsets as nuisance.
    window : float, optional
        Kernel support (s); default 0.2 periods of the dominant frequency.
    order : int
        Savitzky-Golay order.
    gravity : bool
        Model gravity.
    coulomb_smoothing : float
        Rate (rad/s) below which a Coulomb sign is attenuated.
    decimate : int, optional
        Row step; None: ``ROWS_PER_WINDOW`` rows per window.
    max_condition : float
        Condition number above which a parameter is fixed.
    max_relative_error : float
        Relative standard error above which a positive parameter is fixed.
    consistent : bool
        Project onto the nearest physically consistent parameters
        (:func:`~stewartid.physical.parameter_fit.nearest_consistent`; ``convex`` extra).
    noise_correction : bool
        Remove the pose-noise bias (:func:`~stewartid.physical.noise.regressor_noise`).
    leg_stops : bool
        For an electric ``[actuator]``, leave the legs' stops out of their Coulomb sign law and
        fit their friction freely (:mod:`~stewartid.identification.stops`).
    sampling_check : bool
        Refit at 1/2, 1/3, 1/4 of the rate and add each parameter's change to its variance.

    Attributes
    ----------
    M_, B_ : ndarray, shape (6, 6)
    std_errors_ : dict of ndarray (6, 6)
    parameters_, parameter_std_errors_ : dict of str to float
    covariance_ : ndarray, shape (p, p)
        In the order of ``parameters_``.
    fixed_ : dict of str to str
        Fixed parameters and why.
    condition_number_ : float
    result_ : PhysicalResult
    """

    def __init__(self, payload: bool = False, window: float | None = None,
                 order: int = SAVGOL_ORDER, gravity: bool = True,
                 coulomb_smoothing: float = 1e-4, decimate: int | None = None,
                 max_condition: float = 1e5, max_relative_error: float = 0.3,
                 consistent: bool = False, noise_correction: bool = True,
                 leg_stops: bool = True, sampling_check: bool = True):
        self.payload = payload
        self.window = window
        self.order = order
        self.gravity = gravity
        self.coulomb_smoothing = coulomb_smoothing
        self.decimate = decimate
        self.max_condition = max_condition
        self.max_relative_error = max_relative_error
        self.consistent = consistent
        self.noise_correction = noise_correction
        self.leg_stops = leg_stops
        self.sampling_check = sampling_check

    _parameter_constraints = {
        **DIFFERENTIATION_CONSTRAINTS,
        "payload": [BOOLEAN],
        "gravity": [BOOLEAN],
        "coulomb_smoothing": [nonnegative()],
        "decimate": [Interval(Integral, 1, None), None],
        "max_condition": [positive()],
        "max_relative_error": [positive()],
        "consistent": [BOOLEAN],
        "noise_correction": [BOOLEAN],
        "leg_stops": [BOOLEAN],
        "sampling_check": [BOOLEAN],
    }

    def _fit(self, datasets: list[Dataset], platform: Platform
             ) -> tuple[IdentificationResult, dict]:
        if self.consistent:
            require_cvxpy()  # before the fit, not after it
        experiments = prepare(datasets, platform, gravity=False)
        data = filtered_regression(experiments, platform, self.window, self.order,
                                   self.decimate, self.gravity, self.coulomb_smoothing,
                                   self.leg_stops and platform.actuator.kind == "electric")
        model = parameter_model(platform, self.payload)
        names, _, selection, nominal, offset = model
        columns = np.argmax(selection, axis=1)  # selection: rows of the identity
        # rows in leg forces, whose noise is alike and uncorrelated across the channels
        transforms = leg_force_transforms(platform, data.poses)
        X = np.einsum("kij,kjp->kip", transforms, data.Y[:, :, columns], optimize=True)
        y = np.einsum("kij,kj->ki", transforms, data.y - data.Y @ offset)
        noise = target_noise = None
        if self.noise_correction:  # y holds -Y offset, whose noise is that of X's rows
            ends = np.cumsum([0] + [e["samples"] for e in data.experiments])
            per_experiment = [transforms[a:b] for a, b in zip(ends[:-1], ends[1:], strict=True)]
            full = regressor_noise(experiments, [e["window_s"] for e in data.experiments],
                                   data.experiments[0]["row_step"], platform,
                                   SAVGOL_FRACTION, self.order, data.pose_noise,
                                   per_experiment, by_experiment=True)
            # the noise the projected rows keep
            full = full * np.array([1 - e["stop_rows"] / e["samples"]
                                    for e in data.experiments])[:, None, None, None]
            noise = full[:, :, columns][:, :, :, columns]
            target_noise = -full[:, :, columns] @ offset
        # the size of a positive parameter: the whole body's (of a payload's, too)
        positive = np.isin(reg.PARAMETERS, POSITIVE_PARAMETERS)
        scales = selection @ np.where(positive, np.abs(reg.standard_parameters(platform)), 0.0)
        solution = solve_parameters(X, y, list(names), nominal, scales, self.max_condition,
                                    self.max_relative_error, noise, target_noise,
                                    correlation_segments(data, experiments),
                                    data.measured_force_noise())
        projection = None
        if self.consistent:
            nonnegative = np.isin(names, NONNEGATIVE_PARAMETERS)
            projection = nearest_consistent(solution.values, solution.covariance,
                                            _bodies(platform, model, self.payload), nonnegative)
        result = _result(self, platform, model, solution, data, projection)
        learned = {"parameters_": result.parameters,
                   "parameter_std_errors_": result.parameter_std_errors,
                   "covariance_": solution.covariance, "fixed_": solution.fixed}
        return result, learned

    def _check_sampling(self, datasets: list[Dataset], platform: Platform,
                        result: IdentificationResult, learned: dict
                        ) -> tuple[IdentificationResult, dict]:
        """Each free parameter's largest change over the thinned fits joins its variance."""
        quick = type(self)(**{**self.get_params(), "consistent": False,
                              "sampling_check": False})
        summary, fits = thinned_fits(lambda part: quick._fit(part, platform)[0], datasets,
                                     result)
        if fits:
            values = result.diagnostics.get("consistent", {}).get("unconstrained",
                                                                  result.parameters)
            spread = np.array([max([abs(values[name] - f.parameters[name]) for f in fits
                                    if np.isfinite(f.parameter_std_errors[name])], default=0.0)
                               if name not in learned["fixed_"] else 0.0
                               for name in result.parameters])
            covariance = learned["covariance_"] + np.diag(spread ** 2)
            std = np.sqrt(np.diag(covariance))
            std[[list(result.parameters).index(name) for name in learned["fixed_"]]] = np.nan
            std_M, std_B = matrix_std_errors(
                platform, parameter_model(platform, self.payload)[2], covariance)
            result = dataclasses.replace(
                result, std_errors_M=std_M, std_errors_B=std_B,
                parameter_std_errors=dict(zip(result.parameters, std.tolist(), strict=True)))
            learned = {**learned, "covariance_": covariance,
                       "parameter_std_errors_": result.parameter_std_errors}
            summary["parameter_spread"] = dict(zip(result.parameters, spread.tolist(), strict=True))
        diagnostics = {**result.diagnostics, "sampling": summary}
        return dataclasses.replace(result, diagnostics=diagnostics), learned


def correlation_segments(data, experiments: list) -> list[tuple[int, int]]:
    """Per experiment, filtered rows and the lag (rows) beyond which their noise is uncorrelated."""
    return [(e["samples"], math.ceil((1 + 1 / SAVGOL_FRACTION) * e["window_s"]
                                     * exp.sample_rate / e["row_step"]) + 1)
            for e, exp in zip(data.experiments, experiments, strict=True)]


@functools.lru_cache(maxsize=4)
def _base_parameters(platform: Platform) -> reg.BaseParameters:
    return reg.base_parameters(platform)


def parameter_model(platform: Platform, payload: bool = False) -> tuple:
    """Parameters an identification regresses on.

    ``platform`` excludes the payload in payload mode; ``payload`` selects the payload's ten and
    nuisance parameters, else every base parameter.

    Returns
    -------
    names : tuple of str
    combinations : dict of str to str
        What each stands for.
    selection : ndarray, shape (p, N_STANDARD)
        Identity rows: the regressor columns used.
    nominal : ndarray, shape (p,)
    offset : ndarray, shape (N_STANDARD,)
        Known standard parameters, subtracted from the force.
    """
    return _payload_model(platform) if payload else _full_model(platform)


def _full_model(platform: Platform):
    base = _base_parameters(platform)
    pi = reg.standard_parameters(platform)
    return (base.names, dict(zip(base.names, base.combinations, strict=True)),
            np.eye(reg.N_STANDARD)[base.columns], base.combination @ pi,
            np.zeros(reg.N_STANDARD))


def _payload_model(platform: Platform):
    """Payload mode's :func:`parameter_model`; known platform and legs as the offset."""
    known = reg.standard_parameters(known_platform(platform))
    loaded = reg.standard_parameters(platform)
    body = reg.parameter_index(reg.BODY_PARAMETERS)
    nuisances = NUISANCE_PARAMETERS + (reg.REFLECTED_PARAMETERS
                                       if reg.models_reflected_mass(platform) else ())
    nuisance = reg.parameter_index(nuisances)
    columns = np.concatenate([body, nuisance])
    selection = np.eye(reg.N_STANDARD)[columns]
    offset = known.copy()
    offset[columns] = 0.0
    offset[body] = known[body]  # the platform's own body is known
    nominal = np.concatenate([loaded[body] - known[body], known[nuisance]])
    names = PAYLOAD_PARAMETERS + nuisances
    what = {name: f"{standard} of the moving body minus the platform file's own"
            for name, standard in zip(PAYLOAD_PARAMETERS, reg.BODY_PARAMETERS, strict=True)}
    return (names, {**what, **{name: name for name in nuisances}}, selection,
            nominal, offset)


def _bodies(platform: Platform, model, payload: bool) -> list[Body]:
    """Rigid body of the consistent fit (payload or moving body), legs' upper parts at file values."""
    names, _, selection, nominal, _ = model
    body = reg.parameter_index(reg.BODY_PARAMETERS)
    if not np.all(selection[:, body].any(axis=0)):
        raise IdentificationError("the consistent fit needs the moving body's ten parameters "
                                  "among the base parameters; they are not for this platform.")
    rows = np.argmax(selection[:, body], axis=0)
    mapping = np.zeros((len(body), len(names)))
    mapping[np.arange(len(body)), rows] = 1.0
    scale = platform.moving_body.mass
    if payload:
        return [Body("payload", mapping, np.zeros(len(body)), scale)]
    return [Body("moving body", mapping, reg.standard_parameters(platform)[body] - nominal[rows],
                 scale)]


def _result(estimator: PhysicalIdentifier, platform: Platform, model, solution: Solution,
            data: Regression, projection: ConsistentParameters | None = None) -> PhysicalResult:
    """Mt, Bt at neutral with delta-method standard errors, and the (consistent when projected) parameters."""
    names, combinations, selection, _, offset = model
    values = solution.values if projection is None else projection.values
    matrices = [A @ (selection.T @ values + offset)
                for A in (matrix_regressors.inertia_regressor(platform),
                          matrix_regressors.viscous_regressor(platform))]
    errors = matrix_std_errors(platform, selection, solution.covariance)
    std = np.sqrt(np.diag(solution.covariance))
    std[[names.index(name) for name in solution.fixed]] = np.nan
    # of the generalized force (the fit's channels are the leg forces)
    residual = data.y - data.Y @ (selection.T @ solution.values + offset)
    diagnostics = {"experiments": data.experiments, "fixed": solution.fixed,
                   "mode": "payload" if estimator.payload else "full",
                   "singular_values": solution.singular_values,
                   "n_equations": solution.n_equations}
    if projection is not None:
        free = [k for k, name in enumerate(names) if name not in solution.fixed]
        diagnostics["consistent"] = {
            "solver": projection.solver, "status": projection.status,
            "objective": projection.objective,
            "max_change_std_errors": float(np.max(np.abs(projection.change), initial=0.0)),
            "change_std_errors": {names[k]: float(projection.change[k]) for k in free},
            "unconstrained": dict(zip(names, solution.values.tolist(), strict=True)),
            "min_eigenvalue_pseudo_inertia": projection.min_eigenvalues}
    if estimator.payload:
        diagnostics["payload"] = payload_section(dict(zip(names, values, strict=True)))
    return PhysicalResult(
        M=matrices[0], B=matrices[1], std_errors_M=errors[0], std_errors_B=errors[1],
        condition_number=solution.condition_number,
        residual_rms=np.sqrt(np.mean(residual ** 2, axis=0)), method=estimator.method,
        settings=estimator.get_params(), diagnostics=diagnostics,
        parameters=dict(zip(names, values.tolist(), strict=True)),
        parameter_std_errors=dict(zip(names, std.tolist(), strict=True)),
        base_parameters=dict(combinations))


def matrix_std_errors(platform: Platform, selection: np.ndarray, covariance: np.ndarray,
                      pose: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Delta-method standard errors (6, 6) of Mt and Bt at absolute ``pose`` (neutral by default),
    from the parameters' ``covariance`` (p, p) placed by ``selection`` (p, N_STANDARD).
    """
    out = []
    for A in (matrix_regressors.inertia_regressor(platform, pose),
              matrix_regressors.viscous_regressor(platform, pose)):
        rows = A @ selection.T  # (6, 6, p): the matrix's entries in the parameters
        out.append(np.sqrt(np.clip(np.einsum("ijp,pq,ijq->ij", rows, covariance, rows),
                                   0.0, None)))
    return out[0], out[1]


def payload_section(parameters: dict[str, float]) -> dict[str, Any]:
    """``[payload]`` keys (mass, com, inertia about the com) from the payload's identified
    parameters; mass <= 0 puts the com at the reference point.
    """
    body = np.array([parameters[f"payload.{n}"] for n in reg.BODY_PARAMETERS])
    if not body[0] > 0:
        return {"mass": float(body[0]), "com": [0.0] * 3, "inertia": body[4:].tolist()}
    m, c, inertia = reg.about_centre_of_mass(body)
    return {"mass": m, "com": c.tolist(), "inertia": inertia.tolist()}


__all__ = ["NONNEGATIVE_PARAMETERS", "NUISANCE_PARAMETERS", "PAYLOAD_PARAMETERS",
           "POSITIVE_PARAMETERS",
           "PhysicalIdentifier", "PhysicalResult", "correlation_segments", "known_platform",
           "matrix_std_errors", "parameter_model", "payload_section"]
