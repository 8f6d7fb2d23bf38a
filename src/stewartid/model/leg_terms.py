"""Pose-only terms of the platform model, batched over samples in numpy.

The leg lengths, the leg Jacobian J_lq, the gravity forces G(q) and the joint-axis Jacobians
at every sample: what the command tables, forward kinematics and the identifiers need, without
the mass matrix and velocity products of :func:`stewartid.model.kernels.model_terms` (the
simulator's compiled kernel, which evaluates the same leg geometry at one state).

Numpy, not numba: in a fresh process, starting numba and loading its cached kernels costs
0.5-1 s, more than these terms take for the 6 x 20 s at 1 kHz of an identification. Each
leg's twist Jacobian J_A = [I, -[r]x] is written out by column so that its structural zeros
are never multiplied; the other products and sums are in the kernel's order, and the results
equal the kernel's to the last bit (``tests/test_dynamics.py``).

Coordinates and joint axes as in :mod:`stewartid.model.kernels`: q = [x, y, z, rx, ry, rz] (m, rad),
R = Rz Ry Rx, twist nu = [v, omega] mapped to q rates by E(q); leg frame e1 = unit(z x u),
e2 = u x e1; joint axes [lower 1, lower 2, upper 1, upper 2, revolute].
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

#: Indices into Platform.parameters() (the kernels' packed vector) used here.
_MASS, _M_UPPER, _M_LOWER, _D_UPPER, _D_LOWER, _GRAVITY = 0, 4, 5, 6, 7, 12


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
#: interleaved per sample, are written (writing whole columns of them costs 3x the arithmetic).
BLOCK = 2048


def _dot(*pairs):
    """Sum of the products a * b of ``pairs`` in order, None standing for an exact zero factor
    (skipped, as adding a zero product leaves the kernel's sum unchanged); None if all are."""
    total = None
    for a, b in pairs:
        if a is None or b is None:
            continue
        product = a * b
        total = product if total is None else total + product
    return total


def _euler_columns(x0, x1, x2, E):
    """Twist rows' angular part [x0, x1, x2] times E = (E00, E10, E20, E01, E11): the same rows
    in Euler-angle rates (E21 = E02 = E12 = 0, E22 = 1)."""
    E00, E10, E20, E01, E11 = E
    return _dot((x0, E00), (x1, E10), (x2, E20)), _dot((x0, E01), (x1, E11)), x2


def leg_terms(params: np.ndarray, upper: np.ndarray, base: np.ndarray, q: np.ndarray,
              joints: bool = False, pose_terms: bool = True) -> LegTerms:
    """Leg lengths, J_lq, G(q) and optionally the joint-axis Jacobians at poses ``q``.

    Parameters
    ----------
    params : ndarray, shape (13,)
        Packed mass and friction parameters (``Platform.parameters()``).
    upper : ndarray, shape (6, 3)
        Upper joints in the platform frame, relative to the reference point (m).
    base : ndarray, shape (6, 3)
        Base joints in the fixed frame (m).
    q : ndarray, shape (N, 6)
        Poses (m, rad).
    joints : bool
        Also compute the joint-axis Jacobians.
    pose_terms : bool
        False: the joint-axis Jacobians and lengths only (``gravity`` and ``leg_jacobian``
        left empty, shape (0, ...)), for the callers that need no more.

    Returns
    -------
    LegTerms
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


def _leg_terms_block(params, upper, base, q, G, J_leg, lengths, J_joint):
    """:func:`leg_terms` for one block of samples, into the outputs (G and J_leg, J_joint
    if not None)."""
    sx, cx = np.sin(q[:, 3:4]), np.cos(q[:, 3:4])  # (n, 1): broadcast over the legs
    sy, cy = np.sin(q[:, 4:5]), np.cos(q[:, 4:5])
    sz, cz = np.sin(q[:, 5:6]), np.cos(q[:, 5:6])
    R = ((cz * cy, cz * sy * sx - sz * cx, cz * sy * cx + sz * sx),
         (sz * cy, sz * sy * sx + cz * cx, sz * sy * cx - cz * sx),
         (-sy, cy * sx, cy * cx))
    E = (cz * cy, sz * cy, -sy, -sz, cz)
    # r = R upper_i and the unit leg vector u, each component of shape (n, 6)
    r = [R[k][0] * upper[:, 0] + R[k][1] * upper[:, 1] + R[k][2] * upper[:, 2]
         for k in range(3)]
    s = [q[:, k:k + 1] + r[k] - base[:, k] for k in range(3)]
    length = np.sqrt(s[0] * s[0] + s[1] * s[1] + s[2] * s[2])
    lengths[:] = length
    u = [s[k] / length for k in range(3)]
    r0, r1, r2 = r

    # columns of J_A = [I, -[r]x] (None: structural zero) and u . J_A[:, c]
    JA = [(1.0, None, None), (None, 1.0, None), (None, None, 1.0),
          (None, -r2, r1), (r2, None, -r0), (-r1, r0, None)]
    if G is None:  # joint Jacobians only
        _joint_jacobians(u, JA, length, E, J_joint)
        return
    uJ = [_dot(*zip(u, column, strict=True)) for column in JA]

    m_u, m_l = params[_M_UPPER], params[_M_LOWER]
    d_u, d_l = params[_D_UPPER], params[_D_LOWER]
    g = params[_GRAVITY]
    Gn = [0.0, 0.0, -params[_MASS] * g, 0.0, 0.0, 0.0]
    for c in range(6):
        # vertical velocity of the two centres of mass (gravity is along z), summed leg by
        # leg in the kernel's order
        JA2 = 0.0 if JA[c][2] is None else JA[c][2]
        Judot2 = (JA2 - u[2] * uJ[c]) / length
        vertical = JA2 - d_u * Judot2
        term = g * (m_l * (d_l * Judot2) + m_u * vertical)
        for i in range(6):
            Gn[c] = Gn[c] - term[:, i]
    E = tuple(e[:, 0] for e in E)
    G[:, :3] = np.stack(Gn[:3], -1)
    G[:, 3:] = np.stack(_euler_columns(*Gn[3:], E), -1)
    E = tuple(e[:, None] for e in E)
    for c, column in enumerate([*uJ[:3], *_euler_columns(*uJ[3:], E)]):
        J_leg[:, :, c] = column
    if J_joint is not None:
        _joint_jacobians(u, JA, length, E, J_joint)


def _joint_jacobians(u, JA, length, E, out):
    """Joint-axis Jacobians (into ``out``, (n, 6, 5, 6)) from the unit leg vectors ``u``
    (components (n, 6)), the columns of J_A, the leg lengths (n, 6) and the entries of E."""
    u0, u1, u2 = u
    nx, ny = -u1, u0
    nn = np.sqrt(nx * nx + ny * ny)
    e1 = (nx / nn, ny / nn)
    e2 = (-u2 * e1[1], u2 * e1[0], u0 * e1[1] - u1 * e1[0])
    rows = [[None] * 6 for _ in range(5)]
    for c, b in enumerate(JA):
        # angular velocity of the leg, u x J_A[:, c] / l, and of the platform relative to it
        cross = [_dot((u[1], b[2]), (u[2], None if b[1] is None else -b[1])),
                 _dot((u[2], b[0]), (u[0], None if b[2] is None else -b[2])),
                 _dot((u[0], b[1]), (u[1], None if b[0] is None else -b[0]))]
        Jw = [None if w is None else w / length for w in cross]
        rows[0][c] = _dot((e1[0], Jw[0]), (e1[1], Jw[1]))
        rows[1][c] = _dot(*zip(e2, Jw, strict=True))
        if c < 3:  # relative rate -Jw: the rows negated, exactly as the kernel's sums
            along_leg = _dot(*zip(u, Jw, strict=True))
            rows[2][c], rows[3][c], rows[4][c] = (
                None if x is None else -x for x in (rows[0][c], rows[1][c], along_leg))
            continue
        w_rel = [None if w is None else -w for w in Jw]
        w_rel[c - 3] = 1.0 if w_rel[c - 3] is None else w_rel[c - 3] + 1.0
        rows[2][c] = _dot((e1[0], w_rel[0]), (e1[1], w_rel[1]))
        rows[3][c] = _dot(*zip(e2, w_rel, strict=True))
        rows[4][c] = _dot(*zip(u, w_rel, strict=True))
    # gathered contiguously, then interleaved per sample in one copy (5x faster than
    # writing each (axis, column) entry across the samples)
    gathered = np.empty((5, 6, *length.shape))
    for j, row in enumerate(rows):
        row[3:] = _euler_columns(*row[3:], E)
        for c in range(6):
            gathered[j, c] = 0.0 if row[c] is None else row[c]
    out[:] = gathered.transpose(2, 3, 0, 1)
