"""The regressor: the generalized force linear in the physical parameters, J_lq(q)^T f_meas =
Y(q, q_dot, q_ddot) pi, Y (6, P) per sample, pi the standard parameters (:data:`PARAMETERS`);
:func:`base_parameters` finds their identifiable combinations numerically.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from stewartid.model import regressor_rows as rows
from stewartid.model.dynamics import COULOMB_SMOOTHING
from stewartid.model.joints import JOINT_TYPES
from stewartid.model.kinematics import as_batch
from stewartid.platform import GRAVITY, Platform

#: The moving body's parameters: mass (kg), first moment m c (kg m) and inertia about the
#: reference point (kg m^2; products with the matrix's sign, Ixy = -sum x y dm).
BODY_PARAMETERS = ("m", "mc_x", "mc_y", "mc_z", "I_xx", "I_yy", "I_zz", "I_xy", "I_xz", "I_yz")
#: The legs' parameters: upper part's mass (kg) and first moment about its gimbal point
#: (kg m), lower part's first moment (kg m), transverse inertias about the gimbal points (kg m^2).
LEG_PARAMETERS = ("m_u", "md_u", "md_l", "J_u", "J_l")
#: Joint friction per joint type: viscous (N m s/rad) and Coulomb (N m).
FRICTION_PARAMETERS = (tuple(f"viscous[{t}]" for t in JOINT_TYPES)
                       + tuple(f"coulomb[{t}]" for t in JOINT_TYPES))
#: Friction along the actuators: viscous (N s/m) and Coulomb (N).
ACTUATOR_PARAMETERS = ("viscous[actuator]", "coulomb[actuator]")
#: Mass seen along each leg by an electric actuator's rotor and screw (kg): its column is
#: computed for an electric ``[actuator]`` (or one with a reflected mass) only, zero otherwise,
#: so that a hydraulic platform's base parameters are those without it.
REFLECTED_PARAMETERS = ("reflected_mass",)
#: Force-sensor offsets per leg (N).
OFFSET_PARAMETERS = tuple(f"offset[leg{i}]" for i in range(1, 7))
#: Every standard parameter, in the order of the regressor's columns (and of the preference
#: for keeping a column in :func:`base_parameters`).
PARAMETERS = (BODY_PARAMETERS + FRICTION_PARAMETERS + ACTUATOR_PARAMETERS + REFLECTED_PARAMETERS
              + OFFSET_PARAMETERS + LEG_PARAMETERS)
#: Number of standard parameters.
N_STANDARD = len(PARAMETERS)
#: Columns linear in the joint or actuator rates: what Bt is made of.
VISCOUS_PARAMETERS = FRICTION_PARAMETERS[:3] + ACTUATOR_PARAMETERS[:1]
#: Default regularisation rate of the actuators' Coulomb sign (m/s).
ACTUATOR_SMOOTHING = 1e-4

_INDEX = {name: k for k, name in enumerate(PARAMETERS)}
INERTIA_ENTRIES = rows.INERTIA_ENTRIES


def parameter_index(names: tuple[str, ...] | list[str]) -> np.ndarray:
    """Column indices of the standard parameters ``names`` in :data:`PARAMETERS`."""
    return np.array([_INDEX[name] for name in names], dtype=int)


def standard_parameters(platform: Platform) -> np.ndarray:
    """The standard parameters of a platform description, shape (N_STANDARD,).

    Moving body :attr:`~stewartid.platform.Platform.moving_body`, joint friction ``[friction]``
    (viscous on gimbals only), reflected mass and friction along the legs ``[actuator]`` (zero
    when absent), offsets ``[sensors] force_bias``.
    """
    body, i, f = platform.moving_body, platform.inertia, platform.friction
    pi = np.zeros(N_STANDARD)
    pi[0] = body.mass
    pi[1:4] = body.mass * body.com
    pi[4:10] = [body.inertia[a, b] for a, b in INERTIA_ENTRIES]
    values = {"m_u": i.upper_leg_mass, "md_u": i.upper_leg_mass * i.upper_leg_com,
              "md_l": i.lower_leg_mass * i.lower_leg_com,
              "J_u": i.upper_leg_inertia + i.upper_leg_mass * i.upper_leg_com ** 2,
              "J_l": i.lower_leg_inertia + i.lower_leg_mass * i.lower_leg_com ** 2,
              "viscous[lower_gimbal]": f.gimbal_viscous,
              "viscous[upper_gimbal]": f.gimbal_viscous,
              "reflected_mass": platform.actuator.reflected_mass,
              "viscous[actuator]": platform.actuator.viscous,
              "coulomb[actuator]": platform.actuator.coulomb}
    for t in JOINT_TYPES:
        values[f"coulomb[{t}]"] = f.coulomb
    for name in OFFSET_PARAMETERS:
        values[name] = platform.sensors.force_bias
    for name, value in values.items():
        pi[_INDEX[name]] = value
    return pi


def models_reflected_mass(platform: Platform) -> bool:
    """Whether the regressor has a reflected-mass column for ``platform``: an electric
    ``[actuator]``, or any with a reflected mass."""
    return platform.actuator.kind == "electric" or platform.actuator.reflected_mass > 0


def about_centre_of_mass(body: np.ndarray) -> tuple[float, np.ndarray, np.ndarray]:
    """Mass (kg), centre of mass (3,) (m) and inertia about it (6,) (I_xx, I_yy, I_zz, I_xy, I_xz, I_yz;
    kg m^2) of a body's ten standard parameters: I_c = I_o - (h.h 1 - h h^T) / m, h = m c.
    """
    body = np.asarray(body, dtype=float)
    m, h = float(body[0]), body[1:4]
    shift = (h @ h * np.eye(3) - np.outer(h, h)) / m
    return m, h / m, body[4:10] - shift[tuple(np.array(INERTIA_ENTRIES).T)]


def pseudo_inertia(body: np.ndarray) -> np.ndarray:
    """The pseudo-inertia matrix (..., 4, 4) of bodies' ten standard parameters (..., 10).

    J = [[Sigma, h], [h^T, m]], Sigma = tr(I) / 2 1 - I, h = m c; linear in the parameters, and
    positive semidefinite exactly when the body is physically realisable (Wensing et al., 2017).
    """
    body = np.asarray(body, dtype=float)
    inertia = np.zeros(body.shape[:-1] + (3, 3))
    for k, (a, b) in enumerate(INERTIA_ENTRIES):
        inertia[..., a, b] = inertia[..., b, a] = body[..., 4 + k]
    J = np.zeros(body.shape[:-1] + (4, 4))
    J[..., :3, :3] = np.trace(inertia, axis1=-2, axis2=-1)[..., None, None] / 2 * np.eye(3) - inertia
    J[..., :3, 3] = J[..., 3, :3] = body[..., 1:4]
    J[..., 3, 3] = body[..., 0]
    return J


def regressor(platform: Platform, q: np.ndarray, q_dot: np.ndarray, q_ddot: np.ndarray,
              gravity: bool = True, coulomb_smoothing: float = COULOMB_SMOOTHING,
              actuator_smoothing: float = ACTUATOR_SMOOTHING,
              coulomb_rates: np.ndarray | None = None) -> np.ndarray:
    """Y(q, q_dot, q_ddot), shape (N, 6, N_STANDARD) or (6, N_STANDARD): J_lq^T f_meas = Y pi.

    Column k is the generalized force (N, N m) per unit of ``PARAMETERS[k]``; Y depends on the
    platform's geometry only, and on its actuator's kind for the reflected mass's column
    (:func:`models_reflected_mass`; zero otherwise).

    Parameters
    ----------
    q, q_dot, q_ddot : ndarray, shape (N, 6) or (6,)
        m, rad and rates.
    gravity : bool
        False leaves gravity out.
    coulomb_smoothing, actuator_smoothing : float
        s in the Coulomb sign w / sqrt(w^2 + s^2) of joints (rad/s) and actuators (m/s).
    coulomb_rates : ndarray, shape of q, optional
        Rates the Coulomb signs are taken from, when not ``q_dot``.
    """
    q2, single = as_batch(q)
    rates = (as_batch(q_dot, "q_dot")[0], as_batch(q_ddot, "q_ddot")[0],
             None if coulomb_rates is None else as_batch(coulomb_rates, "coulomb_rates")[0])
    Y = regressor_columns(platform, np.ascontiguousarray(q2.T),
                          *(None if x is None else np.ascontiguousarray(x.T) for x in rates),
                          gravity, coulomb_smoothing, actuator_smoothing)
    Y = np.ascontiguousarray(Y.transpose(2, 0, 1))
    return Y[0] if single else Y


def regressor_columns(platform: Platform, q: np.ndarray, q_dot: np.ndarray,
                      q_ddot: np.ndarray, coulomb_rates: np.ndarray | None = None,
                      gravity: bool = True, coulomb_smoothing: float = COULOMB_SMOOTHING,
                      actuator_smoothing: float = ACTUATOR_SMOOTHING, rigid: bool = True,
                      friction: bool = True, out: np.ndarray | None = None) -> np.ndarray:
    """:func:`regressor` with time last, shape (6, N_STANDARD, N), for many samples.

    Inputs (6, N); ``rigid``, ``friction`` compute the bodies', the friction and offset columns
    (each else zero); ``out`` is written in place and returned.
    """
    return rows.regressor_columns(
        platform.upper_joints, platform.base_joints, np.asarray(q, dtype=float),
        np.asarray(q_dot, dtype=float), np.asarray(q_ddot, dtype=float),
        GRAVITY if gravity else 0.0, _INDEX, coulomb_rates, coulomb_smoothing,
        actuator_smoothing, rigid, friction, out, models_reflected_mass(platform))


class BaseParameters(NamedTuple):
    """The identifiable combinations of the standard parameters (:func:`base_parameters`).

    Attributes
    ----------
    names : tuple of str
        The standard parameter whose column each keeps.
    columns : ndarray of int, shape (B,)
        Y_base = Y[..., columns].
    combination : ndarray, shape (B, N_STANDARD)
        pi_base = combination @ pi, so Y pi = Y_base pi_base.
    combinations : tuple of str
        ``combination`` written out, e.g. ``"m + 6 m_u"``.
    unidentifiable : tuple of str
        Standard parameters whose columns are zero on every state.
    """

    names: tuple[str, ...]
    columns: np.ndarray
    combination: np.ndarray
    combinations: tuple[str, ...]
    unidentifiable: tuple[str, ...]


#: Pose offsets from neutral (m, rad), rates and accelerations of the random states of
#: :func:`base_parameters`: well inside any workspace, every column far above round-off.
SAMPLE_SPAN = np.array([0.1, 0.1, 0.1, 0.06, 0.06, 0.06])
SAMPLE_RATES = np.array([0.3, 0.3, 0.3, 0.4, 0.4, 0.4])
SAMPLE_ACCELERATIONS = np.array([2.0, 2.0, 2.0, 2.0, 2.0, 2.0])


def random_states(platform: Platform, n: int, seed: int = 0
                  ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``n`` random states (q, q_dot, q_ddot), each of shape (n, 6), about the neutral pose."""
    rng = np.random.default_rng(seed)
    q = platform.neutral_pose + rng.uniform(-1.0, 1.0, (n, 6)) * SAMPLE_SPAN
    return (q, rng.uniform(-1.0, 1.0, (n, 6)) * SAMPLE_RATES,
            rng.uniform(-1.0, 1.0, (n, 6)) * SAMPLE_ACCELERATIONS)


def base_parameters(platform: Platform, samples: int = 100, seed: int = 0,
                    tolerance: float = 1e-8) -> BaseParameters:
    """The base parameters of the regressor, found numerically.

    The regressor at ``samples`` random states, columns scaled to unit norm, gets its rank from
    its singular values; a column is kept (in :data:`PARAMETERS` order) when independent of those
    kept before, the others written as combinations. ``tolerance`` is relative to the largest
    singular value.

    Raises
    ------
    ArithmeticError
        If the ordered selection disagrees with the pivoted QR's rank.
    """
    Y = regressor(platform, *random_states(platform, samples, seed)).reshape(-1, N_STANDARD)
    norms = np.linalg.norm(Y, axis=0)
    zero = norms <= tolerance * norms.max()
    scaled = Y / np.where(zero, 1.0, norms)
    # numpy's SVD rather than scipy's pivoted QR: scipy.linalg takes longer to import than this
    # takes to run
    singular = np.linalg.svd(scaled[:, ~zero], compute_uv=False)
    rank = int(np.sum(singular > tolerance * singular[0]))
    kept: list[int] = []
    basis = np.zeros((len(Y), 0))
    for k in np.flatnonzero(~zero):
        residual = scaled[:, k] - basis @ (basis.T @ scaled[:, k])
        residual -= basis @ (basis.T @ residual)  # re-orthogonalised
        if np.linalg.norm(residual) > np.sqrt(tolerance):
            kept.append(int(k))
            basis = np.column_stack([basis, residual / np.linalg.norm(residual)])
    if len(kept) != rank:
        raise ArithmeticError(f"base parameters: {len(kept)} columns kept in order, but the "
                              f"regressor's rank is {rank}; change the tolerance.")
    columns = np.array(kept)
    beta = np.linalg.lstsq(scaled[:, columns], scaled, rcond=None)[0]
    beta[np.abs(beta) < 1e-9] = 0.0
    combination = beta * norms[None, :] / norms[columns, None]
    combination[:, zero] = 0.0
    names = tuple(PARAMETERS[k] for k in columns)
    return BaseParameters(names, columns, combination,
                          tuple(combination_text(row) for row in combination),
                          tuple(PARAMETERS[k] for k in np.flatnonzero(zero)))


def combination_text(row: np.ndarray) -> str:
    """A combination of the standard parameters written out: ``"m + 6 m_u"``."""
    terms = []
    for k in np.flatnonzero(row):
        c = float(row[k])
        magnitude = "" if abs(abs(c) - 1.0) < 1e-9 else f"{abs(c):.6g} "
        sign = "-" if c < 0 else "+"
        terms.append(f"{sign} {magnitude}{PARAMETERS[k]}")
    text = " ".join(terms)
    return text[2:] if text.startswith("+ ") else "-" + text[2:]


__all__ = ["ACTUATOR_PARAMETERS", "ACTUATOR_SMOOTHING", "BODY_PARAMETERS", "BaseParameters",
           "FRICTION_PARAMETERS", "INERTIA_ENTRIES", "LEG_PARAMETERS", "N_STANDARD",
           "OFFSET_PARAMETERS", "PARAMETERS", "REFLECTED_PARAMETERS", "SAMPLE_ACCELERATIONS",
           "SAMPLE_RATES", "SAMPLE_SPAN",
           "VISCOUS_PARAMETERS", "about_centre_of_mass", "base_parameters", "combination_text",
           "models_reflected_mass", "parameter_index", "pseudo_inertia", "random_states",
           "regressor", "regressor_columns", "standard_parameters"]
