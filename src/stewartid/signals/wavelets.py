"""Mother wavelets and the continuous wavelet transform W_psi f (a, b) = (1/a) integral f(t)
psi((t - b)/a) dt at chosen (a, b) points (Zhang 2020); by parts, W_psi f' = -(1/a) W_psi' f,
W_psi f'' = (1/a^2) W_psi'' f, W_psi F = -a W_psi1 f (F' = f, psi1' = psi).
"""

from __future__ import annotations

import functools
import math
from abc import ABC, abstractmethod
from typing import TYPE_CHECKING

import numpy as np
from numpy.polynomial import Polynomial

from stewartid.errors import ConfigError

if TYPE_CHECKING:  # scipy.sparse is imported where a matrix is built
    from scipy.sparse import csr_matrix

#: Derivative orders a wavelet can be evaluated at: -2 and -1 are its second and first
#: integrals (psi2, psi1), 0 the wavelet, 1 and 2 its derivatives.
DERIVATIVE_ORDERS = (-2, -1, 0, 1, 2)


@functools.cache
def _gauss_legendre(n: int) -> tuple[np.ndarray, np.ndarray]:
    """Gauss-Legendre nodes and weights on [-1, 1], computed once per process."""
    return np.polynomial.legendre.leggauss(n)


class MotherWavelet(ABC):
    """A real mother wavelet psi with two analytic integrals and two analytic derivatives.

    Attributes
    ----------
    name : str
        Used in settings and result files.
    half_width : float
        Support [-half_width, half_width] in scales (truncated beyond it unless compact).
    compact : bool
        Exactly zero outside its support.
    """

    name: str = ""
    half_width: float = 1.0
    compact: bool = True

    def __call__(self, x: np.ndarray, derivative: int = 0) -> np.ndarray:
        """psi^(derivative) at ``x`` = (t - b) / a, zero outside [-half_width, half_width].

        ``derivative`` in :data:`DERIVATIVE_ORDERS`: -2, -1 (integrals psi2, psi1), 0, 1, 2.
        """
        if derivative not in DERIVATIVE_ORDERS:
            raise ConfigError(
                f"wavelet derivative order must be one of {DERIVATIVE_ORDERS}; got {derivative}."
            )
        x = np.asarray(x, dtype=float)
        out = self._evaluate(x, derivative)
        return np.where(np.abs(x) <= self.half_width, out, 0.0)

    @abstractmethod
    def _evaluate(self, x: np.ndarray, derivative: int) -> np.ndarray:
        """Untruncated analytic expression."""

    def to_dict(self) -> dict:
        """Settings that rebuild this wavelet with :func:`make_wavelet`."""
        return {"name": self.name}

    def moments(self, derivative: int, degree: int) -> np.ndarray:
        """Moments m_j = integral psi^(derivative)(x) x^j dx, j = 0..degree, of the untruncated wavelet."""
        key = (derivative, degree)
        cache = self.__dict__.setdefault("_moment_cache", {})
        if key not in cache:
            span = self.half_width if self.compact else max(12.0, self.half_width)
            nodes, weights = _gauss_legendre(256)
            x = span * nodes
            values = self._evaluate(x, derivative) * weights * span
            cache[key] = np.array([np.sum(values * x ** j) for j in range(degree + 1)])
        return cache[key]

    def __repr__(self) -> str:
        args = ", ".join(f"{k}={v!r}" for k, v in self.to_dict().items() if k != "name")
        return f"{type(self).__name__}({args})"


class MexicanHat(MotherWavelet):
    """Mexican hat psi(t) = (1 - t^2) exp(-t^2 / 2), the paper's example wavelet.

    psi1 = t exp(-t^2 / 2), psi2 = -exp(-t^2 / 2); unnormalised (PyWavelets' ``'mexh'`` times
    sqrt(3) pi^(1/4) / 2). ``truncation``: half-width of the support, in scales.
    """

    name = "mexican_hat"
    compact = False

    def __init__(self, truncation: float = 5.0):
        if not (isinstance(truncation, (int, float)) and 2.0 <= truncation <= 20.0):
            raise ConfigError(
                f"The 'truncation' parameter of MexicanHat must be a number in [2, 20] "
                f"(scales); got {truncation!r}."
            )
        self.truncation = float(truncation)
        self.half_width = self.truncation

    def _evaluate(self, x: np.ndarray, derivative: int) -> np.ndarray:
        x2 = x * x
        e = np.exp(-0.5 * x2)
        if derivative == -2:
            return -e
        if derivative == -1:
            return x * e
        if derivative == 0:
            return (1.0 - x2) * e
        if derivative == 1:
            return (x2 - 3.0) * x * e
        return (-x2 * x2 + 6.0 * x2 - 3.0) * e

    def to_dict(self) -> dict:
        return {"name": self.name, "truncation": self.truncation}


class PolynomialWavelet(MotherWavelet):
    """Compactly supported psi = g'' with g(x) = (1 - x^2)^p on [-1, 1], unit L2 norm.

    The modulating-function wavelet: moments 0 and 1 vanish exactly. ``odd=True``: psi = g''',
    moments 0 to 2 vanishing (its psi'' needs p >= 8 or the moment correction). ``order`` p in [5, 20].
    """

    name = "polynomial"
    compact = True
    half_width = 1.0

    def __init__(self, order: int = 8, odd: bool = False):
        if not (isinstance(order, (int, np.integer)) and 5 <= order <= 20):
            raise ConfigError(
                f"The 'order' parameter of PolynomialWavelet must be an integer in [5, 20] "
                f"(exponent p of (1 - x^2)^p); got {order!r}."
            )
        self.order = int(order)
        self.odd = bool(odd)
        lowest = 1 if self.odd else 0  # psi2 = g^(lowest), psi = g^(lowest + 2)
        g = Polynomial([1.0, 0.0, -1.0]) ** self.order
        psi = g.deriv(lowest + 2)
        norm = math.sqrt((psi * psi).integ()(1.0) - (psi * psi).integ()(-1.0))
        g = g / norm
        self._polynomials = {k: g.deriv(k + 2 + lowest) for k in DERIVATIVE_ORDERS}

    def _evaluate(self, x: np.ndarray, derivative: int) -> np.ndarray:
        return self._polynomials[derivative](x)

    def to_dict(self) -> dict:
        return {"name": self.name, "order": self.order, "odd": self.odd}


_WAVELETS = {"mexican_hat": MexicanHat, "polynomial": PolynomialWavelet}


def make_wavelet(wavelet: str | MotherWavelet | dict = "polynomial", **options) -> MotherWavelet:
    """A mother wavelet from its name (``"polynomial"``, ``"mexican_hat"``), an instance (returned as
    is) or ``to_dict()`` settings; ``**options`` go to its constructor.
    """
    if isinstance(wavelet, MotherWavelet):
        return wavelet
    if isinstance(wavelet, dict):
        options = {**{k: v for k, v in wavelet.items() if k != "name"}, **options}
        wavelet = wavelet.get("name", "")
    if wavelet not in _WAVELETS:
        raise ConfigError(
            f"unknown wavelet {wavelet!r}; expected one of {sorted(_WAVELETS)}."
        )
    return _WAVELETS[wavelet](**options)


def _quadrature_weights(t: np.ndarray) -> np.ndarray:
    w = np.empty_like(t)
    dt = np.diff(t)
    w[0], w[-1] = dt[0] / 2, dt[-1] / 2
    w[1:-1] = (dt[:-1] + dt[1:]) / 2
    return w


def transform_matrix(t: np.ndarray, scales: np.ndarray, shifts: np.ndarray,
                     wavelet: MotherWavelet, derivative: int = 0,
                     exact_degree: int | None = None) -> csr_matrix:
    """Sparse (K, N) matrix W with (W @ f)[k] = W_psi f (scales[k], shifts[k]) for samples f of ``t``.

    Row k is (1 / a_k) psi^(derivative)((t - b_k) / a_k) times trapezoid weights. With
    ``exact_degree`` m each row gets the least-norm change that integrates 1, ..., x^m exactly
    (:meth:`MotherWavelet.moments`), so offsets and trends vanish; rows under m + 2 samples stay.
    Times, scales and shifts in s.
    """
    t = np.asarray(t, dtype=float)
    a = np.atleast_1d(np.asarray(scales, dtype=float))
    b = np.atleast_1d(np.asarray(shifts, dtype=float))
    if a.shape != b.shape or a.ndim != 1:
        raise ConfigError(f"scales and shifts must be 1-D of equal length; got {a.shape} "
                          f"and {b.shape}.")
    if np.any(a <= 0) or not np.all(np.isfinite(a)) or not np.all(np.isfinite(b)):
        raise ConfigError("wavelet scales must be finite and positive and shifts finite.")
    weights = _quadrature_weights(t)
    start = np.searchsorted(t, b - wavelet.half_width * a, side="left")
    stop = np.searchsorted(t, b + wavelet.half_width * a, side="right")
    counts = stop - start
    indptr = np.concatenate([[0], np.cumsum(counts)])
    # column indices and the row each nonzero belongs to, built without a Python loop
    rows = np.repeat(np.arange(len(a)), counts)
    cols = np.arange(indptr[-1]) - np.repeat(indptr[:-1], counts) + np.repeat(start, counts)
    x = (t[cols] - b[rows]) / a[rows]
    values = wavelet(x, derivative) * weights[cols] / a[rows]
    if exact_degree is not None and exact_degree >= 0 and len(values):
        values = _correct_moments(values, x, rows, counts, indptr,
                                  wavelet.moments(derivative, int(exact_degree)))
    from scipy.sparse import csr_matrix  # slow to import: only for the methods that build one

    return csr_matrix((values, cols, indptr), shape=(len(a), len(t)))


def _correct_moments(values: np.ndarray, x: np.ndarray, rows: np.ndarray, counts: np.ndarray,
                     indptr: np.ndarray, target: np.ndarray) -> np.ndarray:
    """Least-norm change v + V c of each row so that sum_n v_n x_n^j = target_j."""
    m = len(target)
    # x^0 .. x^(2m-2) by repeated products: float powers through pow() are slow
    rows_of_powers = np.empty((2 * m - 1, len(x)))
    rows_of_powers[0] = 1.0
    for j in range(1, 2 * m - 1):
        np.multiply(rows_of_powers[j - 1], x, out=rows_of_powers[j])
    powers = rows_of_powers.T
    nonempty = counts > 0
    starts = indptr[:-1][nonempty]
    gram_sums = np.zeros((len(counts), 2 * m - 1))
    gram_sums[nonempty] = np.add.reduceat(powers, starts, axis=0)
    moment_sums = np.zeros((len(counts), m))
    moment_sums[nonempty] = np.add.reduceat(values[:, None] * powers[:, :m], starts, axis=0)
    index = np.arange(m)
    gram = gram_sums[:, index[:, None] + index[None, :]]   # (K, m, m) Hankel blocks
    ok = counts >= m + 2
    coefficients = np.zeros((len(counts), m))
    if np.any(ok):
        coefficients[ok] = np.linalg.solve(gram[ok], (target - moment_sums[ok])[..., None]
                                           )[..., 0]
    return values + np.sum(coefficients[rows] * powers[:, :m], axis=1)


def wavelet_transform(signal: np.ndarray, t: np.ndarray, scales: np.ndarray,
                      shifts: np.ndarray, wavelet: str | MotherWavelet = "mexican_hat",
                      derivative: int = 0, exact_degree: int | None = None) -> np.ndarray:
    """Continuous wavelet transform of signals (N,) or (N, C) at points (a_k, b_k): (K,) or (K, C).

    ``derivative`` uses psi's integral (-1, -2) or derivative (1, 2); ``exact_degree`` as in
    :func:`transform_matrix`.
    """
    matrix = transform_matrix(t, scales, shifts, make_wavelet(wavelet), derivative,
                              exact_degree)
    return matrix @ np.asarray(signal, dtype=float)
