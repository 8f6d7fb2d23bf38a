"""The regressor's columns in numpy, time last (a leg quantity is (6, N), a vector three
components), each leg term the wrench [x, r x x] at the reference point of a vector x at the upper joint.
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np

from stewartid.model.kernels import euler_rate_entries, leg_frame, leg_vector, rotation_entries

#: The inertia matrix's (row, column) of I_xx, I_yy, I_zz, I_xy, I_xz, I_yz: the order of a
#: body's inertia parameters.
INERTIA_ENTRIES = ((0, 0), (1, 1), (2, 2), (0, 1), (0, 2), (1, 2))


def _cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def _dot(a, b):
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def smooth_sign(x: np.ndarray, smoothing: float) -> np.ndarray:
    """x / sqrt(x^2 + s^2), the regularised sign of the Coulomb terms; sign(x) for s = 0."""
    return np.sign(x) if smoothing == 0 else x / np.sqrt(x * x + smoothing * smoothing)


class _Geometry:
    """The pose terms of N samples: entries of R (9) and E (5), r, u, lengths and inverses (6, N)."""

    def __init__(self, upper: np.ndarray, base: np.ndarray, q: np.ndarray):
        cos, sin = np.cos(q[3:]), np.sin(q[3:])
        self.R = rotation_entries(cos[0], sin[0], cos[1], sin[1], cos[2], sin[2])
        columns = [c[:, None] for c in (*upper.T, *base.T)]  # (6, 1): legs against samples
        *ru, self.lengths = leg_vector(self.R, q[0], q[1], q[2], *columns)
        self.r, self.u = tuple(ru[:3]), tuple(ru[3:])
        self.inverse = 1.0 / self.lengths
        self.trigonometry = (cos[1], sin[1], cos[2], sin[2])  # of ry and rz
        self.E = euler_rate_entries(*self.trigonometry)

    def angular(self, x) -> tuple:
        """E x for Euler-angle rates or accelerations x (three rows)."""
        E00, E10, E20, E01, E11 = self.E
        return (E00 * x[0] + E01 * x[1], E10 * x[0] + E11 * x[1], E20 * x[0] + x[2])

    def motion(self, rates: np.ndarray) -> tuple:
        """Angular velocity, omega x r and the upper joints' velocities of pose rates (6, N)."""
        omega = self.angular(rates[3:])
        turn = _cross(omega, self.r)
        return omega, turn, tuple(rates[k] + turn[k] for k in range(3))


class _Wrenches:
    """Leg vectors x (6, N) whose summed wrench [x, r x x] goes into a column of Y."""

    def __init__(self):
        self.columns: list[int] = []
        self.vectors: list = []

    def add(self, column: int, x) -> None:
        """Add the wrench of ``x`` to column ``column`` (each column once)."""
        self.columns.append(column)
        self.vectors.append(x)

    def into(self, Y: np.ndarray, r) -> None:
        """Add every wrench (twist coordinates) into ``Y`` (6, P, N)."""
        if not self.columns:
            return
        x = np.array(self.vectors).swapaxes(0, 1)  # (3, K, 6, N)
        Y[:3, self.columns] += x.sum(2)
        for i, (a, b) in enumerate(((1, 2), (2, 0), (0, 1))):  # sum over legs of r x x
            Y[3 + i, self.columns] += (np.einsum("ln,kln->kn", r[a], x[b])
                                       - np.einsum("ln,kln->kn", r[b], x[a]))


def _euler_bias(geo: _Geometry, qd: np.ndarray) -> tuple:
    """dE/dt q_dot[3:]: the angular acceleration not due to angle accelerations."""
    cy, sy, cz, sz = geo.trigonometry
    dx, dy, dz = qd[3], qd[4], qd[5]
    return ((-sz * cy * dz - cz * sy * dy) * dx - cz * dz * dy,
            (cz * cy * dz - sz * sy * dy) * dx - sz * dz * dy, -cy * dy * dx)


def _body_columns(geo: _Geometry, omega, alpha, a_g, Y, index, moving) -> None:
    """The moving body's ten columns into ``Y`` (6, P, N).

    Inertia columns in the world frame: R (U alpha_b + w_b x U w_b) for the symmetric unit matrix U of
    entry (a, b), alpha_b = R^T alpha, w_b = R^T omega.
    """
    R = np.stack(geo.R).reshape(3, 3, -1)  # R[i, k]: component i of the column k
    first = index["mc_x"]
    Y[:3, index["m"]] = a_g
    Y[3:, first:first + 3] = _cross(R, a_g)  # s_k x a_g for the columns s_k of R
    if not moving:
        return
    turn = np.stack(_cross(omega, R))  # omega x s_k
    Y[:3, first:first + 3] = np.stack(_cross(alpha, R)) + np.stack(_cross(omega, turn))
    w_b, alpha_b = (R[0] * v[0] + R[1] * v[1] + R[2] * v[2] for v in (omega, alpha))
    a, b = ([e[j] for e in INERTIA_ENTRIES] for j in (0, 1))
    moment = R[:, a] * alpha_b[b] + turn[:, a] * w_b[b]
    moment[:, 3:] += R[:, b[3:]] * alpha_b[a[3:]] + turn[:, b[3:]] * w_b[a[3:]]
    Y[3:, index["I_xx"]:index["I_xx"] + 6] = moment


def _leg_columns(geo: _Geometry, motion, alpha, a, g, wrenches: _Wrenches, index,
                 reflected: bool = False) -> None:
    """The legs' inertial and gravity columns into ``wrenches``; ``motion`` None at rest.

    ``reflected`` adds the column of a reflected mass moving with the leg length, l_ddot u (no
    weight: the leg's housing carries it).
    """
    r, u, inverse = geo.r, geo.u, geo.inverse

    def project(x):  # (I - u u^T) x / l
        along = _dot(u, x)
        return tuple((x[k] - u[k] * along) * inverse for k in range(3))

    down = tuple(-g * x for x in project((0.0, 0.0, 1.0)))  # -g (I - u u^T) e_z / l
    wrenches.add(index["md_l"], down)
    if motion is None:
        wrenches.add(index["md_u"], tuple(-x for x in down))
        zero = np.zeros_like(u[0])
        wrenches.add(index["m_u"], (zero, zero, zero - g))
        return
    omega, turn, v_A = motion
    spin = _cross(alpha, r)
    a_A = tuple(a[k] + spin[k] + c for k, c in enumerate(_cross(omega, turn)))
    rate = _dot(u, v_A)
    u_dot = tuple((v_A[k] - rate * u[k]) * inverse for k in range(3))
    radial, speed = _dot(u, a_A), geo.lengths * _dot(u_dot, u_dot)
    u_ddot = tuple((a_A[k] - u[k] * radial - speed * u[k] - 2.0 * rate * u_dot[k]) * inverse
                   for k in range(3))
    a_g = (a_A[0], a_A[1], a_A[2] - g)
    wrenches.add(index["m_u"], a_g)
    wrenches.add(index["md_u"], tuple(-(x + y) for x, y in zip(u_ddot, project(a_g),
                                                                strict=True)))
    wrenches.add(index["J_u"], project(u_ddot))
    if reflected:
        length_acceleration = radial + speed  # u . a_A + l |u_dot|^2
        wrenches.add(index["reflected_mass"], tuple(length_acceleration * x for x in u))


def _joint_rates(geo: _Geometry, frame, motion) -> tuple:
    """The five joint rates of every leg (5 of (6, N))."""
    omega, _, v_A = motion
    e10, e11, e20, e21, e22 = frame
    lower_1 = -(e20 * v_A[0] + e21 * v_A[1] + e22 * v_A[2]) * geo.inverse
    lower_2 = (e10 * v_A[0] + e11 * v_A[1]) * geo.inverse
    return (lower_1, lower_2, e10 * omega[0] + e11 * omega[1] - lower_1,
            e20 * omega[0] + e21 * omega[1] + e22 * omega[2] - lower_2, _dot(geo.u, omega))


def _friction_type_columns(geo: _Geometry, frame, weights, columns, Y, wrenches) -> None:
    """Joint friction of ``weights`` (5 of (6, N)) into the per-type columns of ``Y`` and ``wrenches``."""
    e10, e11, e20, e21, e22 = frame
    inverse, (w1, w2, w3, w4, w5) = geo.inverse, weights
    lower, upper, revolute = columns
    wrenches.add(lower, ((w2 * e10 - w1 * e20) * inverse, (w2 * e11 - w1 * e21) * inverse,
                         -w1 * e22 * inverse))
    wrenches.add(upper, ((w3 * e20 - w4 * e10) * inverse, (w3 * e21 - w4 * e11) * inverse,
                         w3 * e22 * inverse))
    moment = ((w3 * e10 + w4 * e20).sum(0), (w3 * e11 + w4 * e21).sum(0), (w4 * e22).sum(0))
    for i in range(3):
        Y[3 + i, upper] = moment[i]
        Y[3 + i, revolute] = (w5 * geo.u[i]).sum(0)


def _friction_columns(geo: _Geometry, motion, sign_motion, smoothing, actuator_smoothing,
                      Y, wrenches, index) -> None:
    """Joint and actuator friction and sensor offsets into ``Y`` and ``wrenches``."""
    u, r = geo.u, geo.r
    frame = leg_frame(*u)
    moment_arm = _cross(r, u)  # the offsets' and actuators' moments per unit force
    for leg in range(6):
        Y[:3, index[f"offset[leg{leg + 1}]"]] = [x[leg] for x in u]
        Y[3:, index[f"offset[leg{leg + 1}]"]] = [x[leg] for x in moment_arm]
    by_type = {kind: [index[f"{kind}[{t}]"] for t in ("lower_gimbal", "upper_gimbal",
                                                      "revolute")]
               for kind in ("viscous", "coulomb")}
    signs = [smooth_sign(w, smoothing) for w in _joint_rates(geo, frame, sign_motion)]
    _friction_type_columns(geo, frame, signs, by_type["coulomb"], Y, wrenches)
    actuator = {"coulomb[actuator]": smooth_sign(_dot(u, sign_motion[2]), actuator_smoothing)}
    if motion is not None:
        _friction_type_columns(geo, frame, _joint_rates(geo, frame, motion), by_type["viscous"],
                               Y, wrenches)
        actuator["viscous[actuator]"] = _dot(u, motion[2])
    for name, weight in actuator.items():
        Y[:3, index[name]] = [(weight * x).sum(0) for x in u]
        Y[3:, index[name]] = [(weight * x).sum(0) for x in moment_arm]


def regressor_columns(upper: np.ndarray, base: np.ndarray, q: np.ndarray, qd: np.ndarray,
                      qdd: np.ndarray, g: float, index: Mapping[str, int],
                      sign_rates: np.ndarray | None = None, smoothing: float = 0.0,
                      actuator_smoothing: float = 0.0, rigid: bool = True,
                      friction: bool = True, out: np.ndarray | None = None,
                      reflected: bool = False) -> np.ndarray:
    """The regressor Y of :func:`stewartid.model.regressor.regressor` time last, (6, len(index), N).

    Parameters
    ----------
    upper, base : ndarray, shape (6, 3)
        Upper joints (platform frame, from the reference point) and base joints (m).
    q, qd, qdd : ndarray, shape (6, N)
        m, rad and rates.
    g : float
        Gravity along +z (m/s^2); 0 leaves it out.
    index : mapping of str to int
        Column of each standard parameter; first moments and inertias in consecutive columns.
    sign_rates : ndarray, shape (6, N), optional
        Rates the Coulomb signs are taken from; ``qd`` by default.
    smoothing, actuator_smoothing : float
        Coulomb sign regularisation of joints (rad/s) and actuators (m/s).
    rigid, friction : bool
        Compute the bodies', the friction and offset columns (each else zero).
    out : ndarray, shape (6, len(index), N), optional
        Written in place (any strides) and returned.
    reflected : bool
        Compute the reflected mass's column (else zero).
    """
    geo = _Geometry(upper, base, q)
    if out is None:
        Y = np.zeros((6, len(index), q.shape[1]))
    else:
        Y = out
        Y[...] = 0.0
    wrenches = _Wrenches()
    moving = bool(qd.any() or qdd.any())
    motion = geo.motion(qd) if moving else None
    if rigid:
        alpha = geo.angular(qdd[3:])
        if moving:
            alpha = tuple(x + y for x, y in zip(alpha, _euler_bias(geo, qd), strict=True))
        a_g = (qdd[0], qdd[1], qdd[2] - g)
        _body_columns(geo, motion and motion[0], alpha, a_g, Y, index, moving)
        _leg_columns(geo, motion, alpha, qdd[:3], g, wrenches, index, reflected)
    if friction:
        signs = motion if sign_rates is None else geo.motion(sign_rates)
        _friction_columns(geo, motion, signs or geo.motion(qd), smoothing, actuator_smoothing,
                          Y, wrenches, index)
    wrenches.into(Y, geo.r)
    if rigid:
        Y[:, index["J_l"]] = Y[:, index["J_u"]]
    E00, E10, E20, E01, E11 = geo.E  # the moment rows to q coordinates: E^T m
    Y[3], Y[4] = Y[3] * E00 + Y[4] * E10 + Y[5] * E20, Y[3] * E01 + Y[4] * E11
    return Y


__all__ = ["INERTIA_ENTRIES", "regressor_columns", "smooth_sign"]
