"""Method B's friction treatments: the equations and solve of each, and on one sine per
experiment the choice between the free interval constants and the Coulomb law of each joint
type.

On one sine per experiment neither wins everywhere. The free constants give away the motion
inside each interval, and Bt pays for it; the law keeps it, and reads friction it lacks as
damping. Our plant, paper platform, reference noise, 4 seeds: the law's largest error over
the paper's 20 entries 1.9-9.0 % where the free constants give 2.5-7.7 % (median 2.7 against
7.0 %; Bt(3,3) at 9-12 % relative standard error for the free constants). The independent
example without noise, whose friction is not the law's: the free constants 0.016 %, the law
2.7 %. Both fits' errors are honest, so the data decide (:func:`choose_friction_fit`).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np

from stewartid.datasets.dataset import Dataset
from stewartid.errors import IdentificationError
from stewartid.identification.preparation import Experiment
from stewartid.identification.result import IdentificationResult
from stewartid.identification.wavelet.detection import (
    SINGLE_SINE_SHARE,
    Detection,
    check_coverage,
    raise_no_interval,
    sine_share,
)
from stewartid.identification.wavelet.gls import WeakFormSolution
from stewartid.identification.wavelet.rate_selection import solve_weak_form_over_rates
from stewartid.identification.wavelet.weak_form import experiment_equations
from stewartid.identification.wavelet.windows import solve_windows_over_rates, window_equations
from stewartid.verdict.accuracy import predicted_worst_error

#: Window length (s) of ``friction="coulomb"``.
WINDOW_LENGTH = 2.0


def friction_models(setting: str, datasets: Sequence[Dataset]) -> tuple[str, ...]:
    """The friction models to fit: ``setting``; for "auto" both "free" and "coulomb" when
    every experiment is one sine (:func:`.detection.sine_share`), else "coulomb"."""
    if setting != "auto":
        return (setting,)
    single = all(sine_share(d.lengths, 1.0 / float(d.t[1] - d.t[0])) >= SINGLE_SINE_SHARE
                 for d in datasets)
    return ("free", "coulomb") if single else ("coulomb",)


def model_equations(model: str, experiment: Experiment, found: Detection, order: int,
                    functions: int, k: int) -> list:
    """The weak-form equations of experiment ``k`` under friction model ``model``: windows
    across reversals with each joint type's Coulomb rows for "coulomb"
    (:func:`.windows.window_equations`), else the constant-direction intervals
    (:func:`.weak_form.experiment_equations`)."""
    if model == "coulomb":
        return window_equations(experiment, found, order, functions, k, False, WINDOW_LENGTH)
    return experiment_equations(experiment, found, order, functions, k, model)


def solve_model(model: str, equations: list, infos: list[dict], motion: list[np.ndarray],
                noise: dict) -> tuple[WeakFormSolution, float]:
    """Solve one friction model's equations over the soft-sign rates
    (:func:`.windows.solve_windows_over_rates`, :func:`.rate_selection.solve_weak_form_over_rates`);
    the intervals' coverage of every DOF checked first. Returns the solution and its rate."""
    if not equations:
        raise_no_interval(infos)
    if model == "coulomb":
        return solve_windows_over_rates(equations, **noise)
    check_coverage([i["name"] for i in infos], np.array(motion),
                   [sum(e.experiment == k for e in equations) for k in range(len(infos))])
    return solve_weak_form_over_rates(equations, len(infos), model != "free", **noise)


def solve_models(models: Sequence[str], equations: Mapping[str, list], infos: list[dict],
                 motion: list[np.ndarray], noise: dict
                 ) -> tuple[dict[str, tuple[WeakFormSolution, float]], dict[str, str]]:
    """:func:`solve_model` of every friction model. One the data refuse (no interval, a DOF
    no interval covers, a singular system) is left out and its reason returned, for another
    may still fit; when every model is refused, the first refusal is raised.

    Returns
    -------
    solved : dict
        Model -> (solution, soft-sign rate).
    refused : dict
        Model -> the first line of its refusal.
    """
    solved, refused, first = {}, {}, None
    for model in models:
        try:
            solved[model] = solve_model(model, equations[model], infos, motion, noise)
        except (IdentificationError, np.linalg.LinAlgError) as error:  # singular: unexcited
            first = first or error
            refused[model] = str(error).splitlines()[0]
    if not solved:
        raise first
    return solved, refused


def choose_friction_fit(results: Mapping[str, IdentificationResult],
                        solutions: Mapping[str, WeakFormSolution]) -> tuple[str, dict]:
    """Which fit to keep, and the diagnostics that say why.

    One fit is kept as it is. Of "free" and "coulomb", the law's is kept unless its
    standard errors predict the larger worst error
    (:func:`~stewartid.verdict.accuracy.predicted_worst_error`) or
    :func:`friction_law_test` rejects the law.

    Parameters
    ----------
    results : mapping
        Friction model -> its result.
    solutions : mapping
        Friction model -> its solve, before the symmetric pairs are combined (its
        residual-based standard errors).

    Returns
    -------
    chosen : str
    diagnostics : dict
        ``{"friction_candidates": {model: {"predicted_worst_relative_error": e}},
        "friction_law_test": friction_law_test(...)}``; empty for one fit.
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


#: Family-wise level of :func:`friction_law_test` over the 12 diagonal entries of Mt and Bt.
FRICTION_LAW_LEVEL = 0.01


def friction_law_test(free: np.ndarray, free_std: np.ndarray, law: np.ndarray,
                      law_std: np.ndarray) -> dict:
    """Does the fit with a friction law depart from the fit immune to it?

    A specification test in Hausman's spirit on the diagonals of Mt and Bt. The free
    interval constants estimate them whatever the friction law (each DOF's own excitation;
    their couplings carry the idle joints' friction, :mod:`stewartid.identification.pairs`);
    the Coulomb law's rows estimate them more precisely if the law holds, and where it does
    not, read the friction it lacks as damping. Each diagonal entry's difference is scored in
    the residual-based standard errors of the two fits (before any allowance for model
    error, which is what is tested), combined as sqrt(s_free^2 + s_law^2): larger than the
    difference's when the two are positively correlated, so the test errs towards keeping
    the law. The largest of the 12 scores is compared with the two-sided normal point at
    :data:`FRICTION_LAW_LEVEL` shared over them.

    Parameters
    ----------
    free, law : ndarray, shape (6, 12)
        [Mt Bt] of the ``friction="free"`` and ``friction="coulomb"`` solves of the same
        data, before the symmetric pairs are combined.
    free_std, law_std : ndarray, shape (6, 12)
        Their residual-based standard errors.

    Returns
    -------
    dict
        ``{"largest_disagreement": z, "entry": "Bt(6,6)", "threshold": t, "rejected": bool}``.
    """
    from scipy.special import ndtri

    def diagonals(x: np.ndarray) -> np.ndarray:   # Mt's, then Bt's
        return np.r_[np.diag(x[:, :6]), np.diag(x[:, 6:12])]

    spread = np.hypot(diagonals(free_std), diagonals(law_std))
    scores = np.abs(diagonals(free) - diagonals(law)) / np.maximum(spread, 1e-300)
    labels = [f"{name}t({k + 1},{k + 1})" for name in ("M", "B") for k in range(6)]
    threshold = float(ndtri(1.0 - FRICTION_LAW_LEVEL / (2 * scores.size)))
    if not np.any(np.isfinite(scores)):   # no error to judge by: nothing contradicts the law
        return {"largest_disagreement": float("nan"), "entry": None, "threshold": threshold,
                "rejected": False}
    worst = int(np.nanargmax(scores))
    return {"largest_disagreement": float(scores[worst]), "entry": labels[worst],
            "threshold": threshold, "rejected": bool(scores[worst] > threshold)}


__all__ = ["FRICTION_LAW_LEVEL", "WINDOW_LENGTH", "choose_friction_fit", "friction_law_test",
           "friction_models", "model_equations", "solve_model", "solve_models"]
