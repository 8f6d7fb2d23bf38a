"""The regressor of the platform model: the generalized force linear in its physical parameters.

The measured generalized force is linear in the standard parameters pi (:data:`PARAMETERS`),

    J_lq(q)^T f_meas = Y(q, q_dot, q_ddot) pi,

with Y of shape (6, P) per sample (q coordinates, as :class:`~stewartid.model.dynamics.ModelTerms`).
Every body's Newton-Euler force is linear in its mass, first moment and inertia, and the
generalized force is the sum of each body's velocity Jacobian transposed times it (Kane):

- the moving body (platform and payload): mass m, first moment m c (platform frame, from the
  reference point) and inertia about the reference point (platform frame): 10 parameters;
- the legs (six identical, zero inertia about their own axis): the lower part turns about its
  fixed gimbal point, so it enters through its first moment m_l d_l (gravity) and its
  transverse inertia about the gimbal point J_l = I_l + m_l d_l^2 only; the upper part through
  its mass m_u, first moment m_u d_u about the upper gimbal point and J_u = I_u + m_u d_u^2;
- joint friction per joint type (:data:`~stewartid.model.joints.FRICTION_TYPES`): a viscous
  coefficient and a Coulomb level (the model's viscous friction is on the gimbal axes only, so
  the revolute's viscous coefficient is nominally zero);
- friction along each actuator, viscous and Coulomb (not part of the plant model: nominally
  zero);
- an offset per leg force sensor: f_meas = f + offset (``[sensors] force_bias`` nominally).

Not all of them can be told apart by any motion: the upper parts' mass acts as point masses at
the upper joints, a combination of the moving body's columns, and J_u and J_l have the same
column. :func:`base_parameters` finds the identifiable combinations numerically: the regressor
stacked over random states, QR with column pivoting for the rank, and the columns kept in the
order of :data:`PARAMETERS` (the moving body first), each dependent column folded into the
kept ones it is a combination of.

Coordinates as in :mod:`stewartid.model.kernels`: q = [x, y, z, rx, ry, rz] (m, rad), R = Rz Ry Rx,
z down, gravity g along +z; the body equations in the twist [v, omega] at the reference point,
mapped to q with T = blockdiag(I, E(q)).
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
import scipy.linalg

from stewartid.model.dynamics import COULOMB_SMOOTHING
from stewartid.model.joints import JOINT_TYPES
from stewartid.model.kinematics import as_batch, compute_leg_terms
from stewartid.model.leg_terms import leg_vectors
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
#: Force-sensor offsets per leg (N).
OFFSET_PARAMETERS = tuple(f"offset[leg{i}]" for i in range(1, 7))
#: Every standard parameter, in the order of the regressor's columns (and of the preference
#: for keeping a column in :func:`base_parameters`).
PARAMETERS = (BODY_PARAMETERS + FRICTION_PARAMETERS + ACTUATOR_PARAMETERS + OFFSET_PARAMETERS
              + LEG_PARAMETERS)
#: Number of standard parameters.
N_STANDARD = len(PARAMETERS)
#: Columns linear in the joint or actuator rates: what Bt is made of.
VISCOUS_PARAMETERS = FRICTION_PARAMETERS[:3] + ACTUATOR_PARAMETERS[:1]
#: Default regularisation rate of the actuators' Coulomb sign (m/s).
ACTUATOR_SMOOTHING = 1e-4

_INDEX = {name: k for k, name in enumerate(PARAMETERS)}
# inertia entries (row, column) of I_xx ... I_yz
_INERTIA_ENTRIES = ((0, 0), (1, 1), (2, 2), (0, 1), (0, 2), (1, 2))


def parameter_index(names: tuple[str, ...] | list[str]) -> np.ndarray:
    """Column indices of the standard parameters ``names`` in :data:`PARAMETERS`."""
    return np.array([_INDEX[name] for name in names], dtype=int)


def standard_parameters(platform: Platform) -> np.ndarray:
    """The standard parameters of a platform description, shape (N_STANDARD,).

    The moving body is :attr:`~stewartid.platform.Platform.moving_body`; the joint friction
    ``[friction]`` (viscous on the gimbal types only); actuator friction zero; the offsets
    ``[sensors] force_bias``.
    """
    body, i, f = platform.moving_body, platform.inertia, platform.friction
    pi = np.zeros(N_STANDARD)
    pi[0] = body.mass
    pi[1:4] = body.mass * body.com
    pi[4:10] = [body.inertia[a, b] for a, b in _INERTIA_ENTRIES]
    values = {"m_u": i.upper_leg_mass, "md_u": i.upper_leg_mass * i.upper_leg_com,
              "md_l": i.lower_leg_mass * i.lower_leg_com,
              "J_u": i.upper_leg_inertia + i.upper_leg_mass * i.upper_leg_com ** 2,
              "J_l": i.lower_leg_inertia + i.lower_leg_mass * i.lower_leg_com ** 2,
              "viscous[lower_gimbal]": f.gimbal_viscous,
              "viscous[upper_gimbal]": f.gimbal_viscous}
    for t in JOINT_TYPES:
        values[f"coulomb[{t}]"] = f.coulomb
    for name in OFFSET_PARAMETERS:
        values[name] = platform.sensors.force_bias
    for name, value in values.items():
        pi[_INDEX[name]] = value
    return pi


def pseudo_inertia(body: np.ndarray) -> np.ndarray:
    """The pseudo-inertia matrix of a rigid body from its ten standard parameters.

    J = [[Sigma, h], [h^T, m]] with Sigma = integral r r^T dm = tr(I) / 2 1 - I the second
    moment about the reference point, h = m c the first moment and m the mass. The body is
    physically realisable (a nonnegative mass density exists) exactly when J is positive
    semidefinite (Wensing, Kim, Slotine, IEEE RA-L 3(1), 2017); J is linear in the parameters.

    Parameters
    ----------
    body : ndarray, shape (..., 10)
        m (kg), m c (kg m), I_xx, I_yy, I_zz, I_xy, I_xz, I_yz about the reference point
        (kg m^2), in the order of :data:`BODY_PARAMETERS`.

    Returns
    -------
    ndarray, shape (..., 4, 4)
        kg, kg m, kg m^2.
    """
    body = np.asarray(body, dtype=float)
    inertia = np.zeros(body.shape[:-1] + (3, 3))
    for k, (a, b) in enumerate(_INERTIA_ENTRIES):
        inertia[..., a, b] = inertia[..., b, a] = body[..., 4 + k]
    J = np.zeros(body.shape[:-1] + (4, 4))
    J[..., :3, :3] = np.trace(inertia, axis1=-2, axis2=-1)[..., None, None] / 2 * np.eye(3) - inertia
    J[..., :3, 3] = J[..., 3, :3] = body[..., 1:4]
    J[..., 3, 3] = body[..., 0]
    return J


def _cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    # by components: np.cross's axis handling costs more than the products on small blocks
    a0, a1, a2 = a[..., 0], a[..., 1], a[..., 2]
    b0, b1, b2 = b[..., 0], b[..., 1], b[..., 2]
    return np.stack([a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0], axis=-1)


def _dot(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    return np.einsum("...k,...k->...", a, b)[..., None]


def _euler_maps(q: np.ndarray, q_dot: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """E(q) (N, 3, 3) with omega = E q_dot[3:], and dE/dt q_dot[3:] (N, 3)."""
    cy, sy, cz, sz = np.cos(q[:, 4]), np.sin(q[:, 4]), np.cos(q[:, 5]), np.sin(q[:, 5])
    zero, one = np.zeros_like(cy), np.ones_like(cy)
    E = np.stack([np.stack([cz * cy, -sz, zero], -1), np.stack([sz * cy, cz, zero], -1),
                  np.stack([-sy, zero, one], -1)], -2)
    dx, dy, dz = q_dot[:, 3], q_dot[:, 4], q_dot[:, 5]
    bias = np.stack([(-sz * cy * dz - cz * sy * dy) * dx - cz * dz * dy,
                     (cz * cy * dz - sz * sy * dy) * dx - sz * dz * dy,
                     -cy * dy * dx], -1)
    return E, bias


def regressor(platform: Platform, q: np.ndarray, q_dot: np.ndarray, q_ddot: np.ndarray,
              gravity: bool = True, coulomb_smoothing: float = COULOMB_SMOOTHING,
              actuator_smoothing: float = ACTUATOR_SMOOTHING,
              coulomb_rates: np.ndarray | None = None) -> np.ndarray:
    """Y(q, q_dot, q_ddot): the measured generalized force J_lq^T f_meas = Y pi.

    Parameters
    ----------
    platform : Platform
        Geometry only (the joints); the regressor does not depend on the masses.
    q, q_dot, q_ddot : ndarray, shape (N, 6) or (6,)
        Poses (m, rad), their rates and accelerations.
    gravity : bool
        False: leave out gravity (the columns at g = 0).
    coulomb_smoothing : float
        Regularisation rate (rad/s) of the joints' Coulomb sign, w / sqrt(w^2 + s^2).
    actuator_smoothing : float
        The same for the actuators' (m/s).
    coulomb_rates : ndarray, shape of q, optional
        Pose rates the Coulomb signs are taken from, when not ``q_dot`` (the columns at rest
        with the signs of the motion, for filtering at every sample).

    Returns
    -------
    ndarray, shape (N, 6, N_STANDARD) or (6, N_STANDARD)
        Column k is the generalized force (N, N m) per unit of ``PARAMETERS[k]``.
    """
    q2, single = as_batch(q)
    qd, qdd = as_batch(q_dot, "q_dot")[0], as_batch(q_ddot, "q_ddot")[0]
    g = GRAVITY if gravity else 0.0
    n = len(q2)
    _, R, r, u, lengths = leg_vectors(platform.upper_joints, platform.base_joints, q2)
    R = np.stack(R, -1).reshape(n, 3, 3)
    r, u, lengths = np.stack(r, -1), np.stack(u, -1), lengths[..., None]  # (n, 6, 3), (n, 6, 1)
    E, bias = _euler_maps(q2, qd)
    omega = np.einsum("nij,nj->ni", E, qd[:, 3:])
    alpha = np.einsum("nij,nj->ni", E, qdd[:, 3:]) + bias
    a_g = qdd[:, :3] - g * np.array([0.0, 0.0, 1.0])  # a - g e_z
    Yn = np.zeros((n, 6, N_STANDARD))  # twist coordinates
    # at rest (the gravity, offset and Coulomb columns filtered at every sample) the
    # velocity and acceleration terms vanish: skipped, not computed as zeros
    moving = bool(qd.any() or qdd.any())
    Yn[:, :3, 0] = a_g
    for k in range(3):
        s = R[:, :, k]
        if moving:
            Yn[:, :3, 1 + k] = _cross(alpha, s) + _cross(omega, _cross(omega, s))
        Yn[:, 3:, 1 + k] = _cross(s, a_g)
    w_b = np.einsum("nji,nj->ni", R, omega)
    alpha_b = np.einsum("nji,nj->ni", R, alpha)
    for k, (a, b) in enumerate(_INERTIA_ENTRIES if moving else ()):
        unit = np.zeros((3, 3))
        unit[a, b] = unit[b, a] = 1.0
        moment = alpha_b @ unit + _cross(w_b, w_b @ unit)
        Yn[:, 3:, 4 + k] = np.einsum("nij,nj->ni", R, moment)
    _leg_columns(r, u, lengths, qd, qdd, omega, alpha, g, Yn, moving)
    Y = Yn  # the moment rows to q coordinates, E^T m, in place
    Y[:, 3:] = np.swapaxes(E, 1, 2) @ Y[:, 3:]
    signs = qd if coulomb_rates is None else as_batch(coulomb_rates, "coulomb_rates")[0]
    _friction_columns(platform, q2, qd, signs, coulomb_smoothing, actuator_smoothing, Y, moving)
    return Y[0] if single else Y


def _leg_columns(r, u, lengths, qd, qdd, omega, alpha, g, Yn, moving=True):
    """The legs' columns (twist coordinates) into ``Yn``: every leg term is J_A^T x for a
    3-vector x at the upper joint, i.e. the wrench [x, r x x] at the reference point.
    ``moving`` False: the rates and accelerations are zero (gravity only)."""
    e_z = np.array([0.0, 0.0, 1.0])

    def project(x):  # (I - u u^T) x / l
        return (x - u * _dot(u, x)) / lengths

    if moving:
        v, a = qd[:, None, :3], qdd[:, None, :3]
        w, al = omega[:, None], alpha[:, None]
        v_A = v + _cross(w, r)
        a_A = a + _cross(al, r) + _cross(w, _cross(w, r))
        rate = _dot(u, v_A)
        u_dot = (v_A - rate * u) / lengths
        u_ddot = (a_A - u * _dot(u, a_A) - lengths * _dot(u_dot, u_dot) * u
                  - 2.0 * rate * u_dot) / lengths
        a_g = a_A - g * e_z
        forces = {"m_u": a_g, "md_u": -(u_ddot + project(a_g)), "J_u": project(u_ddot)}
        forces["J_l"] = forces["J_u"]
    else:
        a_g = np.broadcast_to(-g * e_z, u.shape)
        forces = {"m_u": a_g, "md_u": -project(a_g)}
    forces["md_l"] = -g * project(np.broadcast_to(e_z, u.shape))
    for name, x in forces.items():
        k = _INDEX[name]
        Yn[:, :3, k] = x.sum(1)
        Yn[:, 3:, k] = _cross(r, x).sum(1)


# the joint axes of each friction type, as a mask over the rows (legs x axes) of a sample
_TYPE_MASK_LEGS = np.tile([[a in axes for a in range(5)] for axes in JOINT_TYPES.values()],
                          (1, 6)).astype(float)


def _friction_columns(platform, q, qd, qd_signs, coulomb_smoothing, actuator_smoothing, Y,
                      moving=True):
    """Joint friction per type, actuator friction and sensor offsets (q coordinates) into
    ``Y``, the Coulomb signs from the rates ``qd_signs``; ``moving`` False: ``qd`` is zero,
    and so are the viscous columns (left as they are)."""
    n = len(q)
    terms = compute_leg_terms(platform, q, joints=True)
    J, flat = terms.leg_jacobian, terms.joint_jacobians.reshape(n, -1, 6)  # legs x axes rows

    def axis_rates(rates):  # (n, 6) -> (n, legs, axes)
        return (flat @ rates[:, :, None]).reshape(n, 6, -1)

    def by_type(weights):  # sum over legs and the axes of each type of weight x row
        return np.swapaxes((weights.reshape(n, 1, -1) * _TYPE_MASK_LEGS) @ flat, 1, 2)

    rates = axis_rates(qd) if moving or qd_signs is qd else None
    signs = _smooth_sign(rates if qd_signs is qd else axis_rates(qd_signs), coulomb_smoothing)
    friction = parameter_index(FRICTION_PARAMETERS)  # the viscous types, then the Coulomb
    if moving:
        Y[:, :, friction[:len(JOINT_TYPES)]] = by_type(rates)
    Y[:, :, friction[len(JOINT_TYPES):]] = by_type(signs)
    leg_rates = (J @ qd[:, :, None])[..., 0]
    actuator = parameter_index(ACTUATOR_PARAMETERS)
    Y[:, :, actuator[0]] = (leg_rates[:, None] @ J)[:, 0]
    sign_rates = leg_rates if qd_signs is qd else (J @ qd_signs[:, :, None])[..., 0]
    Y[:, :, actuator[1]] = (_smooth_sign(sign_rates, actuator_smoothing)[:, None] @ J)[:, 0]
    Y[:, :, parameter_index(OFFSET_PARAMETERS)] = np.swapaxes(J, 1, 2)


def _smooth_sign(x: np.ndarray, smoothing: float) -> np.ndarray:
    return np.sign(x) if smoothing == 0 else x / np.sqrt(x * x + smoothing * smoothing)


class BaseParameters(NamedTuple):
    """The identifiable combinations of the standard parameters (:func:`base_parameters`).

    Attributes
    ----------
    names : tuple of str
        Each base parameter is named for the standard parameter whose column it keeps.
    columns : ndarray of int, shape (B,)
        Those columns' indices in :data:`PARAMETERS`: Y_base = Y[..., columns].
    combination : ndarray, shape (B, N_STANDARD)
        pi_base = combination @ pi, so that Y pi = Y_base pi_base for every pi.
    combinations : tuple of str
        ``combination`` written out, e.g. ``"m + 6 m_u"``.
    unidentifiable : tuple of str
        Standard parameters no motion can identify (columns zero on every state).
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

    The regressor is stacked over ``samples`` random states (:func:`random_states`), its
    columns scaled to unit norm; QR with column pivoting gives its rank. The columns are then
    kept in the order of :data:`PARAMETERS` when independent of those kept before (the
    moving body's first), and every other column is written as a combination of the kept.

    Parameters
    ----------
    platform : Platform
        Geometry.
    samples : int
        Random states stacked.
    seed : int
        Their seed.
    tolerance : float
        Relative size (of the largest) below which a diagonal entry of R counts as zero.

    Returns
    -------
    BaseParameters

    Raises
    ------
    ArithmeticError
        If the ordered selection disagrees with the pivoted QR's rank (a tolerance between
        the scales of independent and dependent columns does not exist for these states).
    """
    Y = regressor(platform, *random_states(platform, samples, seed)).reshape(-1, N_STANDARD)
    norms = np.linalg.norm(Y, axis=0)
    zero = norms <= tolerance * norms.max()
    scaled = Y / np.where(zero, 1.0, norms)
    rdiag = np.abs(np.diag(scipy.linalg.qr(scaled[:, ~zero], mode="r", pivoting=True)[0]))
    rank = int(np.sum(rdiag > tolerance * rdiag[0]))
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
           "FRICTION_PARAMETERS", "LEG_PARAMETERS", "N_STANDARD", "OFFSET_PARAMETERS",
           "PARAMETERS", "SAMPLE_ACCELERATIONS", "SAMPLE_RATES", "SAMPLE_SPAN",
           "VISCOUS_PARAMETERS", "base_parameters", "combination_text",
           "parameter_index", "pseudo_inertia", "random_states",
           "regressor", "standard_parameters"]
