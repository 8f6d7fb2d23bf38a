"""Method B's friction treatments (free interval constants, Coulomb law per joint type).

The equations and solve of each, and the choice between them on one sine per experiment.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable, Mapping, Sequence
from functools import partial
from typing import Any

import numpy as np

from stewartid.datasets.dataset import Dataset
from stewartid.errors import IdentificationError
from stewartid.identification.preparation import Experiment
from stewartid.identification.quantiles import chi2_upper_quantile, normal_upper_quantile
from stewartid.identification.result import IdentificationResult
from stewartid.identification.stops import check_motion
from stewartid.identification.wavelet.detection import (
    SINGLE_SINE_SHARE,
    Detection,
    check_coverage,
    raise_no_interval,
    sign_rate_fields,
    sine_share,
)
from stewartid.identification.wavelet.gls import WeakFormSolution
from stewartid.identification.wavelet.rate_selection import (
    HALF_WINDOW_RATE,
    Run,
    plain_fit,
    solve_weak_form_over_rates,
)
from stewartid.identification.wavelet.weak_form import (
    SOFT_SIGN_RATES,
    PatternsBySamples,
    experiment_equations,
)
from stewartid.identification.wavelet.windows import (
    solve_windows_over_rates,
    stop_window_length,
    window_equations,
    window_stops,
)
from stewartid.parallel import WorkerPool
from stewartid.signals.differentiation import estimate_frequency
from stewartid.signals.sign_rates import lengthened_by_noise, shorter_sign_window
from stewartid.verdict.accuracy import predicted_worst_error

#: Window length (s) of ``friction="coulomb"``.
WINDOW_LENGTH = 2.0


def friction_models(setting: str) -> tuple[str, ...]:
    """The friction models an experiment's equations are built for: "auto" gives "free" and
    "coulomb", and :func:`chosen_models` keeps both only on one sine per experiment."""
    return ("free", "coulomb") if setting == "auto" else (setting,)


def one_sine(dataset: Dataset) -> bool:
    """Whether one sine at the pose's dominant frequency (computed once per record, every
    method asks for it) explains :data:`SINGLE_SINE_SHARE` of the record's leg motion."""
    return sine_share(dataset.lengths, 1.0 / float(dataset.t[1] - dataset.t[0]),
                      estimate_frequency(dataset.pose, dataset.sample_rate)) >= SINGLE_SINE_SHARE


def chosen_models(setting: str, single: Sequence[bool]) -> tuple[str, ...]:
    """The friction models to fit, ``single``: :func:`one_sine` of each experiment under "auto"."""
    if setting != "auto":
        return (setting,)
    return ("free", "coulomb") if all(single) else ("coulomb",)


def patterns_with_half_window(experiment: Experiment, found: Detection, legs: bool,
                              check: bool = True) -> PatternsBySamples:
    """The Coulomb patterns (N, R, types, 6) of
    :func:`~stewartid.identification.wavelet.weak_form.coulomb_patterns` and, with ``check`` where
    the pose noise lengthened the signs' window, after them that of the signs from half of it at
    the rate :data:`~stewartid.identification.wavelet.rate_selection.HALF_WINDOW_RATE`
    (N, R + 1, types, 6): the refit that measures the long window's bias
    (:mod:`~stewartid.identification.sign_window`). ``legs``: the patterns carry the legs' type.
    Both come from one pass over the joints' Jacobians, for the samples asked
    (:class:`~stewartid.identification.wavelet.weak_form.PatternsBySamples`).
    """
    half = None
    if check:
        window, covariance = found.info["differentiation_window"], found.info["noise_covariance"]
        if lengthened_by_noise(window, found.sign_window):
            half = found._replace(**sign_rate_fields(
                experiment, window, covariance, found.mean_jacobian,
                shorter_sign_window(window, found.sign_window)))
    also = (() if half is None else
            ((half, SOFT_SIGN_RATES[HALF_WINDOW_RATE:HALF_WINDOW_RATE + 1]),))
    return PatternsBySamples(found, experiment.joint_jacobians, False,
                             leg_jacobian=experiment.leg_jacobian if legs else None, also=also)


def model_equations(model: str, experiment: Experiment, found: Detection, order: int,
                    functions: int, k: int,
                    patterns: np.ndarray | PatternsBySamples | None = None,
                    legs: bool = False) -> list:
    """The weak-form equations of one experiment under friction model ``model`` (windows or intervals).

    ``patterns``: :func:`~stewartid.identification.wavelet.weak_form.coulomb_patterns` of the
    experiment (or its rows on demand), shared by the models that use them; ``legs``: the
    windows leave the friction in
    the legs' stops free (:func:`~stewartid.identification.wavelet.windows.window_stops`), and
    the detection's info records the legs' share of samples at a stop and the window (s).
    """
    if model == "coulomb":
        stops, length = None, WINDOW_LENGTH
        if legs:
            stops = window_stops(found, experiment.sample_rate)
            share = sum(stop.stop - stop.start for stop in stops) / (6 * len(experiment.t))
            check_motion(share, experiment.name, "record a faster or larger motion")
            length = stop_window_length(stops, float(experiment.t[-1] - experiment.t[0]),
                                        functions, WINDOW_LENGTH)
            found.info.update(stopped_share=share, stop_window_s=length)
        return window_equations(experiment, found, order, functions, k, False, length,
                                patterns, stops)
    return experiment_equations(experiment, found, order, functions, k, model, patterns)


def solve_model(model: str, equations: list, infos: list[dict], motion: list[np.ndarray],
                noise: dict, run: Run | None = None, start: tuple | None = None
                ) -> tuple[WeakFormSolution, float]:
    """Solve one friction model's equations over the soft-sign rates; returns the solution and
    its rate. ``run``: the fits at the rates side by side
    (:func:`~stewartid.identification.wavelet.rate_selection.solved_over_rates`); ``start``: the
    free constants' :func:`~stewartid.identification.wavelet.rate_selection.plain_fit`, where
    computed already."""
    if not equations:
        raise_no_interval(infos)
    if model == "coulomb":
        return solve_windows_over_rates(equations, run=run, **noise)
    check_coverage([i["name"] for i in infos], np.array(motion),
                   [sum(e.experiment == k for e in equations) for k in range(len(infos))])
    return solve_weak_form_over_rates(equations, len(infos), model != "free", run, start,
                                      **noise)


def solve_models(models: Sequence[str], equations: Mapping[str, list], infos: list[dict],
                 motion: list[np.ndarray], noise: dict, pool: WorkerPool | None = None
                 ) -> tuple[dict[str, tuple[WeakFormSolution, float]], dict[str, str]]:
    """:func:`solve_model` of every model: (solved, refused) dicts; raises the first refusal if
    all fail. ``pool``: the fits side by side (two models: :func:`_side_by_side`), else one
    after the other.
    """
    calls = [partial(solve_model, model, equations[model], infos, motion, noise)
             for model in models]
    if pool is None:
        outcomes = [_attempted(call) for call in calls]
    elif len(models) > 1 and models[0] == "free":  # the free constants and the law
        outcomes = _side_by_side(calls, pool, equations["free"], len(infos), noise)
    else:
        outcomes = [_attempted(partial(call, run=pool.call_all)) for call in calls]
    solved, refused, first = {}, {}, None
    for model, (solution, error) in zip(models, outcomes, strict=True):
        if error is None:
            solved[model] = solution
        else:
            first = first or error
            refused[model] = str(error).splitlines()[0]
    if not solved:
        raise first
    return solved, refused


def _side_by_side(calls: Sequence[Callable[..., Any]], pool: WorkerPool, free: list,
                  n_experiments: int, noise: dict) -> list[tuple[Any, Exception | None]]:
    """The outcomes (:func:`_attempted`) of the free constants' solve ``calls[0]`` (equations
    ``free``) and the other models' ``calls[1:]`` on ``pool``: the others' whole solves and the
    free constants' first fit start side by side, then that fit's soft-sign rates follow on the
    workers as they come free (the free constants cost about three times the law's windows)."""
    pending = pool.submit_all([partial(_attempted, call) for call in calls[1:]])
    start = None
    if free:  # else the solve refuses at once
        # any failure of it is met again by the solve, in its turn
        (start, _), = pool.gather(pool.submit_all([partial(
            _attempted, partial(plain_fit, free, n_experiments, **noise), Exception)]))
    return [_attempted(partial(calls[0], run=pool.call_all, start=start)),
            *pool.gather(pending)]


def _attempted(call: Callable[[], Any],
               errors: type[Exception] | tuple[type[Exception], ...] = (
                   IdentificationError, np.linalg.LinAlgError)
               ) -> tuple[Any, Exception | None]:
    """``call()``'s result, or the ``errors`` it raised (by default a refusal; singular:
    unexcited)."""
    try:
        return call(), None
    except errors as error:
        return None, error


def choose_friction_fit(results: Mapping[str, IdentificationResult],
                        solutions: Mapping[str, WeakFormSolution]) -> tuple[str, dict]:
    """Which fit to keep, and the diagnostics that say why.

    Of "free" and "coulomb", the smaller predicted worst error, unless :func:`friction_law_test`
    rejects the law. ``results`` and ``solutions`` (before pairs are combined) map model names.
    """
    if len(results) == 1:
        return next(iter(results)), {}
    predicted = {model: predicted_worst_error(result) for model, result in results.items()}
    free, coulomb = solutions["free"], solutions["coulomb"]
    law = friction_law_test(free.theta[:, :12], free.theta_std[:, :12], coulomb.theta[:, :12],
                            coulomb.theta_std[:, :12])
    chosen = "free" if law["rejected"] else min(results, key=lambda model: predicted[model])
    return chosen, {"friction_candidates": {
        model: {"predicted_worst_relative_error": float(value)}
        for model, value in predicted.items()}, "friction_law_test": law}


def law_floor(law: IdentificationResult, free: IdentificationResult) -> IdentificationResult:
    """The Coulomb-law fit, its standard errors widened by its bias as the fit with free
    interval constants (which no friction law biases) measures it.

    Under pose noise the soft-sign Coulomb regressors of slowly reversing joints are errors in
    variables: the law fit's couplings can be biased by several of its standard errors while
    the free fit stays unbiased. With the law fit the efficient one, their difference d has
    variance s_free^2 - s_law^2 without bias (Hausman 1978), so b^2 = max(d^2 - s_free^2 +
    s_law^2, 0) estimates the squared bias and the error becomes sqrt(s_law^2 + b^2). Both
    (6, 6) results after their pairs combine.
    """
    def widened(value, std, other, other_std):
        bias = np.maximum((value - other) ** 2 - np.abs(other_std ** 2 - std ** 2), 0.0)
        return np.sqrt(std ** 2 + bias)

    return dataclasses.replace(
        law, std_errors_M=widened(law.M, law.std_errors_M, free.M, free.std_errors_M),
        std_errors_B=widened(law.B, law.std_errors_B, free.B, free.std_errors_B))


def constants_floor(free: WeakFormSolution, law: WeakFormSolution, law_rate: float
                    ) -> WeakFormSolution:
    """The free constants' fit, its standard errors widened by the bias of the Coulomb torques
    its invariant rows leave out, at the levels the law fit measures.

    Where the levels' likelihood-ratio test drops them (noisy signs attenuate them), the free
    constants' fit is the plain one: a constant per interval, which does not absorb the
    generalized force of a constant joint torque changing with the pose along large motions.
    Its bias is b = S c (``level_sensitivity`` S at the law's soft-sign rate, c the law's
    levels); each error becomes sqrt(s^2 + b^2). The law's levels are trusted only where b
    accounts for the two fits' disagreement d over the u = 72 entries of [Mt Bt], s_d^2 =
    s_free^2 + s_law^2: sum ((d - b) / s_d)^2 lies within the chi-square point of u degrees of
    freedom at :data:`FRICTION_LAW_LEVEL`, below sum (d / s_d)^2 by more than that of one (a
    law that does not hold gives levels that predict a bias the data do not show). Other fits
    are returned as they are.
    """
    sensitivity = free.level_sensitivity
    if (sensitivity is None or sensitivity.shape[-1] != len(law.coulomb)
            or law_rate not in SOFT_SIGN_RATES[:len(sensitivity)]
            or not np.all(np.isfinite(law.coulomb))):
        return free
    bias = sensitivity[SOFT_SIGN_RATES.index(law_rate)] @ law.coulomb
    spread = np.maximum(np.hypot(free.theta_std, law.theta_std), 1e-300)
    apart = (free.theta - law.theta) / spread
    left = np.sum((apart - bias / spread) ** 2)
    if not (np.sum(apart ** 2) - left > chi2_upper_quantile(1, FRICTION_LAW_LEVEL)
            and left <= chi2_upper_quantile(apart.size, FRICTION_LAW_LEVEL)):
        return free
    return dataclasses.replace(free, theta_std=np.hypot(free.theta_std, bias))


#: Family-wise level of :func:`friction_law_test` over the 12 diagonal entries of Mt and Bt.
FRICTION_LAW_LEVEL = 0.01


def friction_law_test(free: np.ndarray, free_std: np.ndarray, law: np.ndarray,
                      law_std: np.ndarray) -> dict:
    """Does the fit with a friction law depart from the fit immune to it?

    Hausman-style test on the diagonals of ``free`` and ``law`` [Mt Bt] (6, 12): the largest of the
    12 differences in sqrt(s_free^2 + s_law^2) against the Bonferroni point at :data:`FRICTION_LAW_LEVEL`.
    Returns ``{"largest_disagreement", "entry", "threshold", "rejected"}``.
    """
    def diagonals(x: np.ndarray) -> np.ndarray:   # Mt's, then Bt's
        return np.r_[np.diag(x[:, :6]), np.diag(x[:, 6:12])]

    spread = np.hypot(diagonals(free_std), diagonals(law_std))
    scores = np.abs(diagonals(free) - diagonals(law)) / np.maximum(spread, 1e-300)
    labels = [f"{name}t({k + 1},{k + 1})" for name in ("M", "B") for k in range(6)]
    threshold = normal_upper_quantile(FRICTION_LAW_LEVEL / (2 * scores.size))
    if not np.any(np.isfinite(scores)):   # no error to judge by: nothing contradicts the law
        return {"largest_disagreement": float("nan"), "entry": None, "threshold": threshold,
                "rejected": False}
    worst = int(np.nanargmax(scores))
    return {"largest_disagreement": float(scores[worst]), "entry": labels[worst],
            "threshold": threshold, "rejected": bool(scores[worst] > threshold)}


__all__ = ["FRICTION_LAW_LEVEL", "WINDOW_LENGTH", "choose_friction_fit", "constants_floor",
           "friction_law_test", "friction_models", "law_floor", "model_equations",
           "patterns_with_half_window", "solve_model", "solve_models"]
