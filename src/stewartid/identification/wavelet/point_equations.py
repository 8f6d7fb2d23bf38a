"""Method B's equations at chosen (scale, shift) points: the paper's wavelet transform.

[Mt Bt] [W_psi q_ddot ; W_psi q_dot](a, b) = W_psi y (a, b).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from stewartid.identification.preparation import Experiment
from stewartid.identification.wavelet.detection import Detection
from stewartid.identification.wavelet.intervals import wavelet_points
from stewartid.signals.wavelets import MotherWavelet, transform_matrix

#: Polynomial degree up to which every transform row integrates exactly (moment-corrected
#: quadrature, see :func:`~stewartid.signals.wavelets.transform_matrix`).
EXACT_DEGREE = 5


def point_equations(experiment: Experiment, found: Detection,
                    wavelets: Sequence[MotherWavelet], scale_fractions: tuple[float, ...],
                    shifts_per_scale: int, variant: str):
    """Wavelet equations of one experiment, every wavelet at every (a, b) point of its intervals.

    Returns regressors (K, 12), targets (K, 6), owner interval (K,), products (K, 3, 3) (the rows'
    inner products on q and y: transformed white pose noise covariances, position variant only) and
    the detection's info with the ``scales`` and ``shifts`` used.
    """
    t, q = experiment.t, experiment.q
    intervals, info, q_dot, q_ddot = found.intervals, found.info, found.q_dot, found.q_ddot
    scales, shifts, owner = wavelet_points(intervals, wavelets[0], scale_fractions,
                                           shifts_per_scale)
    info["scales"], info["shifts"] = scales, shifts
    if len(scales) == 0:
        return np.zeros((0, 12)), np.zeros((0, 6)), owner, np.zeros((0, 3, 3)), info
    a = scales[:, None]
    qc = q - q.mean(axis=0)
    rows, targets, products = [], [], []
    for psi in wavelets:
        def matrix(derivative, psi=psi):
            return transform_matrix(t, scales, shifts, psi, derivative,
                                    exact_degree=EXACT_DEGREE)

        w0 = matrix(0)
        targets.append(w0 @ experiment.generalized_force)
        if variant == "position":
            # removing the mean keeps the Mexican hat's truncation error proportional to
            # the motion, not the offset
            from scipy import sparse  # only this path builds sparse matrices

            w2 = sparse.diags(1.0 / scales ** 2) @ matrix(2)
            w1 = sparse.diags(-1.0 / scales) @ matrix(1)
            w_acc, w_vel = w2 @ qc, w1 @ qc
            operators = (w2, w1, w0)
            products.append(np.stack([
                np.stack([np.asarray(u.multiply(v).sum(axis=1)).ravel()
                          for v in operators], axis=-1) for u in operators], axis=-2))
        else:
            w_acc = w0 @ q_ddot
            w_vel = (-a * (matrix(-1) @ q_ddot) if variant == "paper"
                     else w0 @ q_dot)
            products.append(np.zeros((len(scales), 3, 3)))
        rows.append(np.hstack([w_acc, w_vel]))
    owner = np.tile(owner, len(wavelets))
    return (np.vstack(rows), np.vstack(targets), owner, np.concatenate(products),
            info)


__all__ = ["EXACT_DEGREE", "point_equations"]
