"""Brent's bounded scalar minimisation, step for step as scipy's ``minimize_scalar(method="bounded")``."""

from __future__ import annotations

import math
from collections.abc import Callable


def minimize_bounded(cost: Callable[[float], float], lower: float, upper: float,
                     tolerance: float, max_evaluations: int = 500) -> float:
    """Minimiser of ``cost`` on [lower, upper] to absolute ``tolerance`` by Brent's bounded method.

    Golden-section steps safeguarded by parabolic interpolation (Forsythe, Malcolm & Moler 1977,
    ``fmin``), at most ``max_evaluations`` of ``cost``.
    """
    sqrt_eps = math.sqrt(2.2e-16)
    golden = 0.5 * (3.0 - math.sqrt(5.0))
    a, b = lower, upper
    v = w = x = a + golden * (b - a)  # v, w: the previous two best points; x: the best
    fv = fw = fx = cost(x)
    d = e = 0.0  # the last step and the one before it
    evaluations = 1
    middle = 0.5 * (a + b)
    tol1 = sqrt_eps * abs(x) + tolerance / 3.0
    while abs(x - middle) > 2.0 * tol1 - 0.5 * (b - a):
        parabolic = False
        if abs(e) > tol1:
            r = (x - w) * (fx - fv)
            q = (x - v) * (fx - fw)
            p = (x - v) * q - (x - w) * r
            q = 2.0 * (q - r)
            if q > 0.0:
                p = -p
            q = abs(q)
            r, e = e, d
            if abs(p) < abs(0.5 * q * r) and q * (a - x) < p < q * (b - x):
                parabolic = True
                d = p / q
                u = x + d
                if u - a < 2.0 * tol1 or b - u < 2.0 * tol1:
                    d = tol1 * (1.0 if middle >= x else -1.0)
        if not parabolic:
            e = (a - x) if x >= middle else (b - x)
            d = golden * e
        u = x + (1.0 if d >= 0 else -1.0) * max(abs(d), tol1)
        fu = cost(u)
        evaluations += 1
        if fu <= fx:
            if u >= x:
                a = x
            else:
                b = x
            v, fv, w, fw, x, fx = w, fw, x, fx, u, fu
        else:
            if u < x:
                a = u
            else:
                b = u
            if fu <= fw or w == x:
                v, fv, w, fw = w, fw, u, fu
            elif fu <= fv or v == x or v == w:
                v, fv = u, fu
        middle = 0.5 * (a + b)
        tol1 = sqrt_eps * abs(x) + tolerance / 3.0
        if evaluations >= max_evaluations:
            break
    return float(x)



__all__ = ["minimize_bounded"]
