"""Pose-only model terms in numpy (leg lengths, J_lq, G(q), joint-axis Jacobians): the kernels'
own per-sample geometry applied to arrays, bit for bit, without numba's start-up.
"""

from __future__ import annotations

from typing import Any, NamedTuple

import numpy as np

from stewartid.model import parameters as layout
from stewartid.model.joints import N_JOINTS
from stewartid.model.kernels import (
    body_gravity,
    centre_of_mass_rates,
    euler_columns,
    euler_rate_entries,
    joint_rate_column,
    leg_angular_rate,
    leg_frame,
    leg_gravity,
    leg_rate,
    leg_vector,
    rotation_entries,
    twist_column,
)


class LegTerms(NamedTuple):
    """Result of :func:`leg_terms` for N poses.

    Attributes
    ----------
    gravity : ndarray, shape (N, 6)
        G(q) (N, N m) in M q_ddot + h + G + F = J_lq^T f.
    leg_jacobian : ndarray, shape (N, 6, 6)
        J_lq: leg-length rates (m/s) = J_lq q_dot.
    lengths : ndarray, shape (N, 6)
        Leg lengths (m).
    joint_jacobians : ndarray, shape (N, 6, 5, 6), or (0, 6, 5, 6) unless requested
        Joint rates (rad/s) = J[:, leg, axis] @ q_dot.
    """

    gravity: np.ndarray
    leg_jacobian: np.ndarray
    lengths: np.ndarray
    joint_jacobians: np.ndarray


#: Samples per block: each block's arrays stay in the processor's cache while the outputs,
#: interleaved per sample, are written.
BLOCK = 2048


class _StructuralZero:
    """An exact zero on arrays (x + ZERO is x, x * ZERO is ZERO), sparing whole-array operations."""

    __array_ufunc__ = None  # arrays defer their operators to this class's reflected ones

    def __mul__(self, other: Any) -> _StructuralZero:
        return self

    __rmul__ = __mul__
    __truediv__ = __mul__

    def __neg__(self) -> _StructuralZero:
        return self

    def __add__(self, other: Any) -> Any:
        return other

    __radd__ = __add__
    __rsub__ = __add__

    def __sub__(self, other: Any) -> Any:
        return -other


class _StructuralOne:
    """An exact one in the kernels' arithmetic on arrays: x * ONE is x itself."""

    __array_ufunc__ = None

    def __mul__(self, other: Any) -> Any:
        return other

    __rmul__ = __mul__

    def __sub__(self, other: Any) -> Any:
        return 1.0 - other

    def __rsub__(self, other: Any) -> Any:
        return other - 1.0

    def __add__(self, other: Any) -> Any:
        return other + 1.0

    __radd__ = __add__


#: The structural zero and one of J_A passed to the kernels' geometry functions.
ZERO = _StructuralZero()
ONE = _StructuralOne()


def leg_terms(params: np.ndarray, upper: np.ndarray, base: np.ndarray, q: np.ndarray,
              joints: bool = False, pose_terms: bool = True) -> LegTerms:
    """Leg lengths, J_lq, G(q) and optionally the joint-axis Jacobians at poses ``q`` (N, 6) (m, rad).

    Parameters
    ----------
    params : ndarray, shape (N_PARAMETERS,)
        ``Platform.parameters()``.
    upper, base : ndarray, shape (6, 3)
        Upper joints (platform frame, from the reference point) and base joints (fixed frame), m.
    joints : bool
        Also compute the joint-axis Jacobians.
    pose_terms : bool
        False leaves ``gravity`` and ``leg_jacobian`` empty, shape (0, ...).
    """
    q = np.asarray(q, dtype=float)
    n = len(q)
    m = n if pose_terms else 0
    out = LegTerms(np.empty((m, 6)), np.empty((m, 6, 6)), np.empty((n, 6)),
                   np.empty((n if joints else 0, 6, 5, 6)))
    for start in range(0, n, BLOCK):
        block = slice(start, start + BLOCK)
        _leg_terms_block(params, upper, base, q[block],
                         *(part[block] if pose_terms else None for part in out[:2]),
                         out.lengths[block], out.joint_jacobians[block] if joints else None)
    return out


def leg_vectors(upper: np.ndarray, base: np.ndarray, q: np.ndarray
                ) -> tuple[tuple[np.ndarray, ...], tuple[np.ndarray, ...], list[np.ndarray],
                           list[np.ndarray], np.ndarray]:
    """Leg vectors at poses ``q`` (N, 6) by :func:`~stewartid.model.kernels.leg_vector`.

    Returns
    -------
    E, R : tuples of 5 and 9 ndarrays, shape (N, 1)
        Entries of the Euler-rate map and the rotation matrix.
    r, u : lists of 3 ndarrays, shape (N, 6)
        Components of R upper_i (m) and of the unit leg vectors.
    lengths : ndarray, shape (N, 6)
        Leg lengths (m).
    """
    trig = [f(q[:, k:k + 1]) for k in (3, 4, 5) for f in (np.cos, np.sin)]  # (N, 1) each
    R = rotation_entries(*trig)
    r0, r1, r2, u0, u1, u2, lengths = leg_vector(R, q[:, 0:1], q[:, 1:2], q[:, 2:3], *upper.T,
                                                 *base.T)
    return euler_rate_entries(*trig[2:]), R, [r0, r1, r2], [u0, u1, u2], lengths


def _leg_terms_block(params, upper, base, q, G, J_leg, lengths, J_joint):
    """:func:`leg_terms` for one block of samples into the outputs; leg quantities are (n, 6)."""
    E, R, (r0, r1, r2), u, length = leg_vectors(upper, base, q)
    lengths[:] = length
    columns = [twist_column(c, r0, r1, r2, ZERO, ONE) for c in range(6)]
    if G is not None:
        rates = [leg_rate(*u, *b) for b in columns]
        _gravity(params, tuple(e[:, 0] for e in R), u[2], columns, rates, length,
                 tuple(e[:, 0] for e in E), G)
        for c, column in enumerate([*rates[:3], *euler_columns(*rates[3:], E)]):
            J_leg[:, :, c] = column
    if J_joint is not None:
        _joint_jacobians(u, columns, length, E, J_joint)


def _gravity(params, R, u2, columns, rates, length, E, G):
    """G into ``G`` (n, 6), summed leg by leg in the kernel's order."""
    m_u, m_l = params[layout.M_UPPER], params[layout.M_LOWER]
    d_u, d_l = params[layout.D_UPPER], params[layout.D_LOWER]
    g = params[layout.GRAVITY]
    Gn = [0.0, 0.0, *body_gravity(R, g, params[layout.MASS], params[layout.COM_X],
                                  params[layout.COM_Y], params[layout.COM_Z]), 0.0]
    for c, b in enumerate(columns):
        _, lower_z, upper_z = centre_of_mass_rates(b[2], u2, rates[c], length, d_u, d_l)
        term = leg_gravity(g, m_u, m_l, lower_z, upper_z)
        for i in range(6):
            Gn[c] = Gn[c] - term[:, i]
    G[:, :3] = np.stack(Gn[:3], -1)
    G[:, 3:] = np.stack(euler_columns(*Gn[3:], E), -1)


def _joint_jacobians(u, columns, length, E, out):
    """Joint-axis Jacobians into ``out`` (n, 6, 5, 6)."""
    frame = leg_frame(*u)
    by_column = [joint_rate_column(c, frame, *u, *leg_angular_rate(*u, *b, length))
                 for c, b in enumerate(columns)]
    # gathered contiguously, then interleaved per sample in one copy (faster than writing each
    # (axis, column) entry across the samples)
    gathered = np.empty((N_JOINTS, 6, *length.shape))
    for j in range(N_JOINTS):
        row = [rates[j] for rates in by_column]
        row[3:] = euler_columns(*row[3:], E)
        for c in range(6):
            gathered[j, c] = 0.0 if row[c] is ZERO else row[c]
    out[:] = gathered.transpose(2, 3, 0, 1)
