"""Which of several identified models to trust on the same data, and why.

:func:`choose_trusted` weighs what each method's result and held-out validation
(:mod:`stewartid.validation.heldout`) show and returns the finding as data
(:class:`Verdict`); the identification report puts it into words and ``result.json`` holds
it (:meth:`Verdict.to_dict`).

Rule, in order:

1. **Applicable**: methods that refused the data (their assumptions fail: several sines for
   Method A, no constant-direction interval for Method B) are out.
2. **Physically plausible**: symmetric parts of Mt positive definite and of Bt positive
   semidefinite (all methods, if none is).
3. **Held-out prediction**: a method whose worst DOF leaves more than :data:`MISFIT_FACTOR`
   times the least unexplained force, and more than :data:`MISFIT_FLOOR` %, misses something
   the others model; it is ranked after the others. Held-out segments of the same excitation
   cannot show a wrong parameter that a friction term compensates, so this is a gate, not the
   ranking.
4. **Honest uncertainty**: among the rest, the method with the smallest expected largest
   relative error over the paper's 20 entries wins
   (:func:`~stewartid.verdict.accuracy.expected_worst_error`, so one conservative
   entry does not outweigh nineteen). Every method's standard errors carry its model error
   where the data show it (:func:`~stewartid.identification.pairs.pair_calibration`; for
   Method A the friction its third harmonic reveals), and each entry's error is conditioned
   on the other plausible methods' estimates of it, their errors correlated as their fits of
   the same folds show (:func:`~stewartid.verdict.accuracy.error_posterior`): the
   less precise of two that disagree takes the larger share of the difference, and a
   difference from estimates over :data:`~stewartid.verdict.accuracy.PRECISION_FACTOR`
   times more precise measures the error. So a standard error widened for a model error a
   precise fit shows absent is not held against a method, and a method several of its
   standard errors from a more precise one is not trusted on them (Method B 9.4 % off on
   Bt(6,6), predicted 4.3 % on its standard errors where least squares, 2.6 % off,
   predicted 5.5 %; conditioned, 10.5 % and 3.7 %).
5. **Ties** (within :data:`TIE_FACTOR`): the better held-out prediction. A method immune to
   the friction law (Method B with free interval constants) is not preferred for it: with
   every method's standard errors carrying its model error, the predicted accuracy already
   says what the friction law costs, and on logs with a known truth the preference chose a
   method up to twice as far off as the best (:doc:`/benchmarks`, "Which method to trust").
6. **Close calls**: where other plausible methods predict largest errors within
   :data:`CLOSE_FACTOR` of the trusted one's, the noise decides which is the more accurate;
   the report then trusts their consensus (:mod:`stewartid.verdict.close_call`).

Entries are *uncertain* when the trusted method's relative standard error exceeds
:data:`UNCERTAIN_RELATIVE`, or when another plausible method's estimate differs from the
trusted one's by more than :data:`DISAGREEMENT` combined standard errors.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Literal

import numpy as np

from stewartid.identification.consistency import consistency_metrics
from stewartid.identification.result import IdentificationResult
from stewartid.platform import COORDINATES
from stewartid.reference.published import PAPER_ENTRIES, entry_label
from stewartid.validation.heldout import (
    ValidationResult,
    coulomb_estimate,
    friction_signature,
)
from stewartid.verdict.accuracy import (
    PRECISION_FACTOR,
    entry_estimate,
    entry_relative_std,
    error_posterior,
    expected_worst_error,
    fold_correlation,
)

#: Methods whose expected largest error is within this factor of the least are tied (the held-out
#: prediction decides). Any tie wider than equality chose worse on logs with a known truth
#: (35 logs: 30 within 1.5x of the best at 1, 29 at 1.02, 28 at 1.1, 27 at 1.2-1.5, 26 at 2
#: with the friction-immune method first): a method whose errors predict a larger worst
#: error was, more often than not, further off.
TIE_FACTOR = 1.0
#: Methods whose expected largest error is within this factor of the trusted one's are a
#: close call: which is the more accurate is decided by the noise realisation, and the verdict
#: says so. Measured over 220 pairs of methods on 100 noisy logs with a known truth (our plant
#: and MuJoCo, two platforms): the one predicting the smaller largest error realised it in 60 %
#: of the pairs within 1.1x, 72 % within 1.1-1.25x, 89 % within 1.25-1.5x (and was then within
#: 1.5x of the other in all 27), 97 % beyond.
CLOSE_FACTOR = 1.25
#: A method leaving more than this factor times the least held-out unexplained force ...
MISFIT_FACTOR = 4.0
#: ... and more than this share (%) of the force in its worst DOF misses part of the physics.
MISFIT_FLOOR = 1.0
#: An entry's relative standard error above which the verdict names it uncertain.
UNCERTAIN_RELATIVE = 0.10
#: Two methods' estimates of an entry disagree beyond this many combined standard errors.
DISAGREEMENT = 3.0
#: A Coulomb level counts as present above this many standard errors.
SIGNIFICANT = 3.0
#: Mean relative excess of the Bt diagonal over the trusted method's above which a method
#: without friction is said to read the friction as viscous damping.
DAMPING_EXCESS = 0.05


def worst_dof(validation: ValidationResult) -> tuple[float, str]:
    """Held-out VAF (%) of the worst DOF and the DOF's name (``"x"`` ... ``"rz"``)."""
    vaf = validation.vaf_percent
    k = int(np.nanargmin(vaf))
    return float(vaf[k]), COORDINATES[k]


def worst_relative_std(result: IdentificationResult) -> tuple[float, str]:
    """The largest relative standard error over the paper's 20 entries and the entry's label
    (``"Bt(5,1)"``)."""
    values = entry_relative_std(result)
    k = int(np.argmax(values))
    return float(values[k]), entry_label(PAPER_ENTRIES[k])


def named_entries(entries: Sequence[str]) -> str:
    """Entry labels for a sentence: listed up to six, counted beyond."""
    return ", ".join(entries) if len(entries) <= 6 else f"{len(entries)} of the paper's 20 entries"


def uncertain_entries(trusted: IdentificationResult,
                      others: Mapping[str, IdentificationResult]) -> list[dict]:
    """The paper's entries the trusted result is unsure of, and why.

    Parameters
    ----------
    trusted : IdentificationResult
    others : mapping of str to IdentificationResult
        The other plausible methods' results, by name.

    Returns
    -------
    list of dict
        ``{"entry": "Bt(5,1)", "relative_std": r, "disagrees_with": [names]}`` for every
        entry whose relative standard error exceeds :data:`UNCERTAIN_RELATIVE` or whose
        estimate another method contradicts beyond :data:`DISAGREEMENT` combined errors.
    """
    found = []
    for k, (matrix, i, j) in enumerate(PAPER_ENTRIES):
        value, std = entry_estimate(trusted, matrix, i, j)
        relative = std / abs(value) if value != 0 else np.inf
        against = []
        for name, other in others.items():
            v, s = entry_estimate(other, matrix, i, j)
            if abs(v - value) > DISAGREEMENT * np.hypot(s, std):
                against.append(name)
        if relative > UNCERTAIN_RELATIVE or against:
            found.append({"entry": entry_label(PAPER_ENTRIES[k]),
                          "relative_std": float(relative), "disagrees_with": against})
    return found


def is_definite(result: IdentificationResult) -> bool:
    """Symmetric part of Mt positive definite and of Bt positive semidefinite (what the
    energy of the model needs; a small asymmetry is reported, not disqualifying)."""
    metrics = consistency_metrics(result.M, result.B)
    scale = float(np.abs(result.B).max())
    return bool(metrics["M_min_eigenvalue"] > 0
                and metrics["B_min_eigenvalue"] >= -1e-9 * scale)


def friction_immune(result: IdentificationResult) -> bool:
    """The method's Mt and Bt do not depend on a friction law: Method B with a free constant
    per constant-direction interval (``friction_model`` "free") and no Coulomb levels on its
    invariant rows (``soft_sign_rate`` None: on large motions it fits the Coulomb force's
    change inside the intervals, and then rests on that structure)."""
    diagnostics = result.diagnostics
    return (diagnostics.get("friction_model") == "free"
            and diagnostics.get("soft_sign_rate") is None)


def models_friction(result: IdentificationResult) -> bool:
    """The method estimates a Coulomb level for every joint type."""
    return bool(np.all(np.isfinite(coulomb_estimate(result)[0])))


def finds_friction(result: IdentificationResult) -> bool:
    """The method estimates a Coulomb level above :data:`SIGNIFICANT` standard errors."""
    levels, std = coulomb_estimate(result)
    return bool(np.any(np.isfinite(levels) & (levels > SIGNIFICANT * np.nan_to_num(std))))


@dataclass(frozen=True)
class Standing:
    """What the verdict found about one applicable method.

    Attributes
    ----------
    name : str
        Registered method name.
    worst_vaf_percent : float
        Held-out VAF (%) in the method's worst DOF.
    worst_dof : str
        That DOF (``"x"`` ... ``"rz"``).
    unexplained_ratio : float
        Its unexplained force in the worst DOF over the trusted method's (1 for the trusted).
    compared : bool
        Among the methods the trust was chosen from (plausible matrices, or all methods when
        none has them).
    models_friction : bool
        The method estimates Coulomb levels.
    friction_effect : {"damping", "residuals"} or None
        When a method finds Coulomb friction and this one (not the trusted) does not model
        it: its friction is read as viscous damping (Bt diagonal above the trusted method's
        by more than :data:`DAMPING_EXCESS`) or stays in its residuals; else None.
    damping_excess : float
        Mean relative excess of its Bt diagonal over the trusted method's, where
        ``friction_effect`` is set (NaN elsewhere).
    friction_share : float
        Share of its held-out residual that has the shape of Coulomb friction
        (:func:`~stewartid.validation.heldout.friction_signature`).
    worst_relative_std : float
        Its largest relative standard error over the paper's 20 entries (a fraction).
    worst_entry : str
        That entry (``"Bt(5,1)"``).
    misfit : bool
        Its held-out prediction leaves more than :data:`MISFIT_FACTOR` times the least
        unexplained force (and over :data:`MISFIT_FLOOR` %).
    friction_immune : bool
        Its Mt and Bt do not rest on a friction law (:func:`friction_immune`).
    expected_worst : float
        Its expected largest relative error over the paper's 20 entries (a fraction), its
        errors conditioned on the others' (:func:`~stewartid.verdict.accuracy.error_posterior`).
    measured_entries : tuple of str
        Entries whose error the other plausible methods' estimates measure (over
        :data:`~stewartid.verdict.accuracy.PRECISION_FACTOR` times more precise).
    error_correlation : dict of str to float
        Correlation of its errors with each other applicable method's, from their fits of the
        same folds (:func:`~stewartid.verdict.accuracy.fold_correlation`; 0 without).
    """

    name: str
    worst_vaf_percent: float
    worst_dof: str
    unexplained_ratio: float
    compared: bool
    models_friction: bool
    friction_effect: Literal["damping", "residuals"] | None
    damping_excess: float
    friction_share: float
    worst_relative_std: float = float("nan")
    worst_entry: str = ""
    misfit: bool = False
    friction_immune: bool = False
    expected_worst: float = float("nan")
    measured_entries: tuple[str, ...] = ()
    error_correlation: dict[str, float] = dataclasses.field(default_factory=dict)

    @property
    def unexplained_percent(self) -> float:
        """Held-out force left unexplained in the worst DOF (%)."""
        return 100 - self.worst_vaf_percent


@dataclass(frozen=True)
class Verdict:
    """Which method to trust, the ranking and the reasons.

    Attributes
    ----------
    trusted : str
        The method to trust.
    ranking : tuple of str
        The applicable methods, trusted first, then the compared ones before the others,
        each group by unexplained force.
    tied : tuple of str
        The compared methods within :data:`TIE_FACTOR` of the least worst relative standard
        error (the held-out prediction decided between them).
    standings : dict of str to Standing
        Per applicable method, in the order given.
    friction_source : str or None
        The first method that finds Coulomb friction, if any.
    not_applicable : tuple of str
        Methods that could not be applied to the data.
    uncertain : list of dict
        The entries the trusted method is unsure of (:func:`uncertain_entries`).
    reasons : list of str
        Why the trusted method was chosen and the others not, one sentence each.
    close : tuple of str
        The trusted method and the plausible ones whose expected largest error is within
        :data:`CLOSE_FACTOR` of its own: on these data any of them may be the more accurate.
    """

    trusted: str
    ranking: tuple[str, ...]
    tied: tuple[str, ...]
    standings: dict[str, Standing]
    friction_source: str | None
    not_applicable: tuple[str, ...]
    uncertain: list[dict] = dataclasses.field(default_factory=list)
    reasons: list[str] = dataclasses.field(default_factory=list)
    close: tuple[str, ...] = ()

    def to_dict(self) -> dict:
        """The ``verdict`` object of ``result.json``: ``trusted``, ``ranking`` (registry
        names), ``uncertain_entries`` (entry labels), ``reasons``, ``close`` (the close call,
        :attr:`close`), and the evidence per method under ``evidence``."""
        return {
            "trusted": self.trusted, "ranking": list(self.ranking),
            "uncertain_entries": [u["entry"] for u in self.uncertain],
            "reasons": list(self.reasons),
            "not_applicable": list(self.not_applicable),
            "close": list(self.close),
            "evidence": {name: {
                "expected_worst_relative_error": st.expected_worst,
                "worst_relative_std": st.worst_relative_std, "worst_entry": st.worst_entry,
                "heldout_worst_vaf_percent": st.worst_vaf_percent,
                "heldout_worst_dof": st.worst_dof, "plausible": st.compared,
                "misfit": st.misfit, "models_friction": st.models_friction,
                "friction_immune": st.friction_immune,
                "measured_entries": list(st.measured_entries),
                "error_correlation": dict(st.error_correlation)}
                for name, st in self.standings.items()},
            "uncertain_detail": self.uncertain}


def choose_trusted(assessed: Mapping[str, tuple[IdentificationResult, ValidationResult] | None],
                   folds: Mapping[str, Sequence[IdentificationResult] | None] | None = None
                   ) -> Verdict:
    """Which method to trust on these data (see the module docstring for the rule).

    Parameters
    ----------
    assessed : mapping
        Method name -> (result, its held-out validation), or None for a method that could
        not be applied. At least one must be applicable.
    folds : mapping, optional
        Method name -> its fits of the validation's (shared) folds, whence the correlation
        of the methods' errors (:func:`~stewartid.verdict.accuracy.fold_correlation`).

    Returns
    -------
    Verdict
    """
    ok = {name: pair for name, pair in assessed.items() if pair is not None}
    worst = {name: worst_dof(validation) for name, (_, validation) in ok.items()}
    unexplained = {name: 100.0 - vaf for name, (vaf, _) in worst.items()}
    spread = {name: worst_relative_std(result) for name, (result, _) in ok.items()}
    compared = [name for name, (result, _) in ok.items() if is_definite(result)] or list(ok)
    floor = min(unexplained[name] for name in compared)
    misfit = {name: bool(unexplained[name] > max(MISFIT_FACTOR * floor, MISFIT_FLOOR))
              for name in ok}
    candidates = [name for name in compared if not misfit[name]] or compared
    names = list(ok)
    links = fold_correlation([ok[name][0] for name in names],
                             [(folds or {}).get(name) for name in names])
    checked = {}
    for name, (result, _) in ok.items():
        rows = [names.index(name)] + [names.index(o) for o in candidates if o != name]
        checked[name] = error_posterior(result, [ok[o][0] for o in candidates if o != name],
                                        links[np.ix_(rows, rows)])
    expected = {name: expected_worst_error(std, mean)
                for name, (mean, std, _) in checked.items()}
    least = min(expected[name] for name in candidates)
    tied = [name for name in candidates if expected[name] <= TIE_FACTOR * least]
    trusted = min(tied, key=lambda name: unexplained[name])
    friction_source = next((name for name, (result, _) in ok.items()
                            if finds_friction(result)), None)
    reference_B = np.diag(ok[trusted][0].B)
    standings = {}
    for name, (result, validation) in ok.items():
        modelled = models_friction(result)
        excess, effect = float("nan"), None
        if friction_source is not None and not modelled and name != trusted:
            excess = float(np.mean(np.diag(result.B) / reference_B) - 1.0)
            effect = "damping" if excess > DAMPING_EXCESS else "residuals"
        standings[name] = Standing(
            name, worst[name][0], worst[name][1],
            (100 - worst[name][0]) / max(100 - worst[trusted][0], 1e-12), name in compared,
            modelled, effect, excess, friction_signature(validation),
            spread[name][0], spread[name][1], misfit[name], friction_immune(result),
            expected[name], tuple(entry_label(PAPER_ENTRIES[k]) for k in checked[name][2]),
            {other: float(links[names.index(name), k]) for k, other in enumerate(names)
             if other != name})
    others = sorted((name for name in ok if name != trusted),
                    key=lambda name: (name not in compared, misfit[name], expected[name]))
    uncertain = uncertain_entries(ok[trusted][0], {name: ok[name][0] for name in compared
                                                   if name != trusted})
    not_applicable = tuple(name for name, pair in assessed.items() if pair is None)
    close = (trusted, *(name for name in others if name in candidates
                        and expected[name] <= CLOSE_FACTOR * expected[trusted]))
    return Verdict(trusted, (trusted, *others), tuple(tied), standings, friction_source,
                   not_applicable, uncertain,
                   _reasons(trusted, standings, tied, not_applicable, uncertain, close),
                   close)


def _reasons(trusted: str, standings: Mapping[str, Standing], tied: list[str],
             not_applicable: tuple[str, ...], uncertain: list[dict],
             close: tuple[str, ...] = ()) -> list[str]:
    """One sentence per finding, for ``result.json`` (registry names, numbers)."""
    best = standings[trusted]
    reasons = [f"{trusted}: its standard errors, conditioned on the other methods' "
               "estimates, predict a largest error of "
               f"{100 * best.expected_worst:.3g} % over the paper's 20 entries (largest "
               f"standard error {100 * best.worst_relative_std:.3g} %, {best.worst_entry}), the "
               "least of the plausible methods that predict held-out data; held-out VAF "
               f"{best.worst_vaf_percent:.4g} % in its worst DOF ({best.worst_dof})."]
    for name, standing in standings.items():
        if standing.measured_entries:
            reasons.append(f"{name}: the other methods' estimates, over {PRECISION_FACTOR:g}x "
                           f"more precise, measure its errors of "
                           f"{named_entries(standing.measured_entries)}; there its predicted "
                           "largest error takes their difference, not its standard errors.")
    if len(tied) > 1:
        reasons.append(f"{', '.join(tied)} predict the same largest error (within "
                       f"{TIE_FACTOR:g}x); the held-out prediction decided.")
    if len(close) > 1:
        reasons.append(f"close call: {', '.join(close)} predict largest errors within "
                       f"{CLOSE_FACTOR:g}x of each other ("
                       + ", ".join(f"{100 * standings[name].expected_worst:.3g} %"
                                   for name in close)
                       + "); on such data the noise decides which is the more accurate; "
                       "compare their entries.")
    for name, standing in standings.items():
        if name == trusted:
            continue
        if not standing.compared:
            reasons.append(f"{name}: Mt or Bt has a negative eigenvalue, which no physical "
                           "platform has.")
        elif standing.misfit:
            reasons.append(f"{name}: leaves {standing.unexplained_percent:.3g} % of the held-out "
                           f"force unexplained in {standing.worst_dof}, over {MISFIT_FACTOR:g}x "
                           "the least.")
        else:
            reasons.append(f"{name}: predicted largest error "
                           f"{100 * standing.expected_worst:.3g} % (largest standard error "
                           f"{100 * standing.worst_relative_std:.3g} %, {standing.worst_entry}).")
    reasons += [f"{name}: not applicable to these data." for name in not_applicable]
    if uncertain:
        reasons.append(uncertain_sentence(uncertain))
    return reasons


def uncertain_sentence(uncertain: Sequence[dict]) -> str:
    """The reason naming the uncertain entries (:func:`uncertain_entries`) and why."""
    return "uncertain entries: " + ", ".join(
        u["entry"] + (f" (disagrees with {', '.join(u['disagrees_with'])})"
                      if u["disagrees_with"] else
                      f" ({100 * u['relative_std']:.3g} % standard error)")
        for u in uncertain) + "."


__all__ = ["CLOSE_FACTOR", "DAMPING_EXCESS", "DISAGREEMENT", "MISFIT_FACTOR", "MISFIT_FLOOR", "SIGNIFICANT",
           "TIE_FACTOR", "UNCERTAIN_RELATIVE", "Standing", "Verdict", "choose_trusted",
           "finds_friction", "friction_immune", "is_definite", "models_friction", "named_entries",
           "uncertain_entries", "uncertain_sentence", "worst_dof", "worst_relative_std"]
