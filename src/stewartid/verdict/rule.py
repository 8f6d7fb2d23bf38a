"""Which of several identified models to trust on the same data, and why.

:func:`choose_trusted` returns the finding as data (:class:`Verdict`); the report puts it
into words and ``result.json`` holds it (:meth:`Verdict.to_dict`). The rule, step by step, is
in ``docs/verdict.md``; its thresholds are a :class:`~stewartid.verdict.policy.VerdictPolicy`.
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
from stewartid.reference.published import PAPER_ENTRIES, EntryKey, entry_label
from stewartid.validation.heldout import (
    ResidualDelay,
    ValidationResult,
    coulomb_estimate,
    friction_signature,
)
from stewartid.verdict.accuracy import (
    entry_estimate,
    entry_relative_std,
    error_posterior,
    expected_worst_error,
)
from stewartid.verdict.policy import DEFAULT_POLICY, VerdictPolicy, entries_text


def worst_dof(validation: ValidationResult) -> tuple[float, str]:
    """Held-out VAF (%) of the worst DOF and the DOF's name (``"x"`` ... ``"rz"``)."""
    vaf = validation.vaf_percent
    k = int(np.nanargmin(vaf))
    return float(vaf[k]), COORDINATES[k]


def worst_relative_std(result: IdentificationResult,
                       entries: Sequence[EntryKey] = PAPER_ENTRIES) -> tuple[float, str]:
    """The largest relative standard error over ``entries`` and the entry's label
    (``"Bt(5,1)"``)."""
    values = entry_relative_std(result, entries)
    k = int(np.argmax(values))
    return float(values[k]), entry_label(entries[k])


def delay_bias(result: IdentificationResult, delay: ResidualDelay) -> np.ndarray:
    """What a force delay left in the data puts on the Bt diagonal of ``result``, shape (6,)
    (N s/m, N m s/rad): |tau| (2 pi f_i)^2 Mt(i, i) at the frequencies the fit reads it at
    (:attr:`~stewartid.validation.heldout.ResidualDelay.frequencies_hz`; the gravity
    stiffness's share, 3 % on the paper's Bt(4,4) at 0.5 Hz, left out). NaN where not known."""
    frequencies = np.full(6, np.nan)
    frequencies[:len(delay.frequencies_hz)] = delay.frequencies_hz
    return abs(delay.seconds) * (2 * np.pi * frequencies) ** 2 * np.abs(np.diag(result.M))


def uncertain_entries(trusted: IdentificationResult,
                      others: Mapping[str, IdentificationResult],
                      entries: Sequence[EntryKey] = PAPER_ENTRIES,
                      policy: VerdictPolicy = DEFAULT_POLICY,
                      delay: ResidualDelay | None = None) -> list[dict]:
    """The scored entries the trusted result is unsure of, and why.

    Parameters
    ----------
    trusted : IdentificationResult
    others : mapping of str to IdentificationResult
        The other plausible methods' results, by name.
    entries : sequence of (str, int, int)
        The scored entries.
    policy : VerdictPolicy
    delay : ResidualDelay, optional
        A force delay found in the held-out residuals: the Bt diagonal entries it biases by
        more than their standard error (:func:`delay_bias`) are uncertain too.

    Returns
    -------
    list of dict
        ``{"entry": "Bt(5,1)", "relative_std": r, "disagrees_with": [names]}`` for every
        entry whose relative standard error exceeds ``policy.uncertain_relative`` or whose
        estimate another method contradicts beyond ``policy.disagreement`` combined errors;
        ``"delay_bias"`` where the delay biases it: the first-order bias |tau| (2 pi f)^2
        Mt(i, i) over the entry's value.
    """
    bias = None if delay is None else delay_bias(trusted, delay)
    found = []
    for matrix, i, j in entries:
        value, std = entry_estimate(trusted, matrix, i, j)
        relative = std / abs(value) if value != 0 else np.inf
        against = []
        for name, other in others.items():
            v, s = entry_estimate(other, matrix, i, j)
            if abs(v - value) > policy.disagreement * np.hypot(s, std):
                against.append(name)
        # a bias not known (no motion in that DOF) counts: the delay is there
        biased = (bias is not None and matrix == "B" and i == j
                  and not bias[i] <= std)
        if relative > policy.uncertain_relative or against or biased:
            item = {"entry": entry_label((matrix, i, j)),
                    "relative_std": float(relative), "disagrees_with": against}
            if biased:
                item["delay_bias"] = float(bias[i] / abs(value)) if value != 0 else np.inf
            found.append(item)
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
    return result.friction_model == "free" and result.diagnostics.get("soft_sign_rate") is None


def models_friction(result: IdentificationResult) -> bool:
    """The method estimates a Coulomb level for every joint type."""
    return bool(np.all(np.isfinite(coulomb_estimate(result)[0])))


def finds_friction(result: IdentificationResult,
                   significant: float = DEFAULT_POLICY.significant) -> bool:
    """The method estimates a Coulomb level above ``significant`` standard errors."""
    levels, std = coulomb_estimate(result)
    return bool(np.any(np.isfinite(levels) & (levels > significant * np.nan_to_num(std))))


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
        by more than ``policy.damping_excess``) or stays in its residuals; else None.
    damping_excess : float
        Mean relative excess of its Bt diagonal over the trusted method's, where
        ``friction_effect`` is set (NaN elsewhere).
    friction_share : float
        Share of its held-out residual that has the shape of Coulomb friction
        (:func:`~stewartid.validation.heldout.friction_signature`).
    worst_relative_std : float
        Its largest relative standard error over the scored entries (a fraction).
    worst_entry : str
        That entry (``"Bt(5,1)"``).
    misfit : bool
        Its held-out prediction leaves more than ``policy.misfit_factor`` times the least
        unexplained force (and over ``policy.misfit_floor_percent`` %).
    friction_immune : bool
        Its Mt and Bt do not rest on a friction law (:func:`friction_immune`).
    expected_worst : float
        Its expected largest relative error over the scored entries (a fraction), its
        errors conditioned on the others' (:func:`~stewartid.verdict.accuracy.error_posterior`).
    residual_delay : ResidualDelay or None
        The force delay left in its held-out residuals, where measured.
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
    residual_delay: ResidualDelay | None = None

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
        The applicable methods, trusted first, then the plausible ones before the others,
        each group by expected largest error.
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
        ``policy.close_factor`` of its own: on these data any of them may be the more
        accurate.
    entries : tuple of (str, int, int)
        The entries the methods were judged on.
    policy : VerdictPolicy
        The thresholds the verdict was reached with.
    residual_delay : ResidualDelay or None
        A force delay the trusted method's held-out residuals show beyond
        ``policy.significant`` standard errors and ``policy.delay_floor_s``: the fits absorbed
        it, and their standard errors do not cover the bias.
    """

    trusted: str
    ranking: tuple[str, ...]
    standings: dict[str, Standing]
    friction_source: str | None
    not_applicable: tuple[str, ...]
    uncertain: list[dict] = dataclasses.field(default_factory=list)
    reasons: list[str] = dataclasses.field(default_factory=list)
    close: tuple[str, ...] = ()
    entries: tuple[EntryKey, ...] = PAPER_ENTRIES
    policy: VerdictPolicy = DEFAULT_POLICY
    residual_delay: ResidualDelay | None = None

    def to_dict(self) -> dict:
        """The ``verdict`` object of ``result.json``: ``trusted``, ``ranking`` (registry
        names), ``uncertain_entries`` (entry labels), ``reasons``, ``close`` (the close call,
        :attr:`close`), the evidence per method under ``evidence`` (with its
        ``residual_delay`` where measured) and ``residual_delay``, the delay found or None."""
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
                **({} if st.residual_delay is None
                   else {"residual_delay": st.residual_delay.to_dict()})}
                for name, st in self.standings.items()},
            "uncertain_detail": self.uncertain,
            "residual_delay": (None if self.residual_delay is None
                               else self.residual_delay.to_dict())}


def choose_trusted(assessed: Mapping[str, tuple[IdentificationResult, ValidationResult] | None],
                   entries: Sequence[EntryKey] = PAPER_ENTRIES,
                   policy: VerdictPolicy = DEFAULT_POLICY,
                   residual_delays: Mapping[str, ResidualDelay | None] | None = None
                   ) -> Verdict:
    """Which method to trust on these data (``docs/verdict.md`` states the rule).

    Parameters
    ----------
    assessed : mapping
        Method name -> (result, its held-out validation), or None for a method that could
        not be applied. At least one must be applicable.
    entries : sequence of (str, int, int)
        The entries of Mt and Bt the methods are judged on
        (:func:`~stewartid.verdict.policy.scored_entries`).
    policy : VerdictPolicy
        The thresholds.
    residual_delays : mapping, optional
        Method name -> force delay left in its held-out residuals
        (:func:`~stewartid.validation.heldout.residual_delay`); the trusted method's, when
        significant, is a reason and makes the Bt diagonal entries it biases uncertain.

    Returns
    -------
    Verdict
    """
    entries = tuple(entries)
    residual_delays = dict(residual_delays or {})
    ok = {name: pair for name, pair in assessed.items() if pair is not None}
    worst = {name: worst_dof(validation) for name, (_, validation) in ok.items()}
    unexplained = {name: 100.0 - vaf for name, (vaf, _) in worst.items()}
    spread = {name: worst_relative_std(result, entries) for name, (result, _) in ok.items()}
    compared = [name for name, (result, _) in ok.items() if is_definite(result)] or list(ok)
    floor = min(unexplained[name] for name in compared)
    misfit = {name: bool(unexplained[name] > max(policy.misfit_factor * floor,
                                                 policy.misfit_floor_percent))
              for name in ok}
    candidates = [name for name in compared if not misfit[name]] or compared
    checked = {name: error_posterior(result, [ok[o][0] for o in candidates if o != name],
                                     entries)
               for name, (result, _) in ok.items()}
    expected = {name: expected_worst_error(std, mean)
                for name, (mean, std) in checked.items()}
    # an exact tie goes to the better held-out prediction
    trusted = min(candidates, key=lambda name: (expected[name], unexplained[name]))
    friction_source = next((name for name, (result, _) in ok.items()
                            if finds_friction(result, policy.significant)), None)
    reference_B = np.diag(ok[trusted][0].B)
    standings = {}
    for name, (result, validation) in ok.items():
        modelled = models_friction(result)
        excess, effect = float("nan"), None
        if friction_source is not None and not modelled and name != trusted:
            excess = float(np.mean(np.diag(result.B) / reference_B) - 1.0)
            effect = "damping" if excess > policy.damping_excess else "residuals"
        standings[name] = Standing(
            name=name, worst_vaf_percent=worst[name][0], worst_dof=worst[name][1],
            unexplained_ratio=(100 - worst[name][0]) / max(100 - worst[trusted][0], 1e-12),
            compared=name in compared, models_friction=modelled, friction_effect=effect,
            damping_excess=excess, friction_share=friction_signature(validation),
            worst_relative_std=spread[name][0], worst_entry=spread[name][1],
            misfit=misfit[name], friction_immune=friction_immune(result),
            expected_worst=expected[name], residual_delay=residual_delays.get(name))
    others = sorted((name for name in ok if name != trusted),
                    key=lambda name: (name not in compared, misfit[name], expected[name]))
    # a delay in the data is in every method's residuals: it sets no method back, but the
    # bias it puts on Bt is in none of their standard errors
    delay = residual_delays.get(trusted)
    if delay is not None and not delay.significant(policy.significant, policy.delay_floor_s):
        delay = None
    uncertain = uncertain_entries(ok[trusted][0], {name: ok[name][0] for name in compared
                                                   if name != trusted}, entries, policy, delay)
    not_applicable = tuple(name for name, pair in assessed.items() if pair is None)
    close = (trusted, *(name for name in others if name in candidates
                        and expected[name] <= policy.close_factor * expected[trusted]))
    verdict = Verdict(trusted, (trusted, *others), standings, friction_source, not_applicable,
                      uncertain, [], close, entries, policy, delay)
    return dataclasses.replace(verdict, reasons=_reasons(verdict))


def _reasons(verdict: Verdict) -> list[str]:
    """One sentence per finding, for ``result.json`` (registry names, numbers)."""
    trusted, standings, policy = verdict.trusted, verdict.standings, verdict.policy
    close, scored = verdict.close, entries_text(verdict.entries)
    best = standings[trusted]
    reasons = [f"{trusted}: its standard errors, conditioned on the other methods' "
               "estimates, predict a largest error of "
               f"{100 * best.expected_worst:.3g} % over {scored} (largest "
               f"standard error {100 * best.worst_relative_std:.3g} %, {best.worst_entry}), the "
               "least of the plausible methods that predict held-out data; held-out VAF "
               f"{best.worst_vaf_percent:.4g} % in its worst DOF ({best.worst_dof})."]
    if verdict.residual_delay is not None:
        reasons.append(delay_reason(verdict.residual_delay, standings))
    if len(close) > 1:
        reasons.append(f"close call: {', '.join(close)} predict largest errors within "
                       f"{policy.close_factor:g}x of each other ("
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
                           f"force unexplained in {standing.worst_dof}, over "
                           f"{policy.misfit_factor:g}x the least.")
        else:
            reasons.append(f"{name}: predicted largest error "
                           f"{100 * standing.expected_worst:.3g} % (largest standard error "
                           f"{100 * standing.worst_relative_std:.3g} %, {standing.worst_entry}).")
    reasons += [f"{name}: not applicable to these data." for name in verdict.not_applicable]
    if verdict.uncertain:
        reasons.append(uncertain_sentence(verdict.uncertain))
    return reasons


def delay_reason(delay: ResidualDelay, standings: Mapping[str, Standing]) -> str:
    """The reason naming a force delay left in the held-out residuals, and the fix."""
    others = ", ".join(f"{name} {1e3 * st.residual_delay.seconds:.3g}"
                       for name, st in standings.items()
                       if st.residual_delay is not None and st.residual_delay is not delay
                       and np.isfinite(st.residual_delay.seconds))
    return (f"force delay left in the held-out residuals: the measured forces lag the "
            f"prediction by {1e3 * delay.seconds:.3g} ms (standard error "
            f"{1e3 * delay.std_error:.2g} ms" + (f"; ms by method: {others}" if others else "")
            + "); every fit absorbed it into Mt and Bt, beyond their standard errors: align "
            "the forces with --delay auto, or a known --delay SECONDS.")


def uncertain_reason(item: dict) -> str:
    """Why an uncertain entry (:func:`uncertain_entries`) is uncertain, for a parenthesis."""
    if item["disagrees_with"]:
        return f"disagrees with {', '.join(item['disagrees_with'])}"
    if "delay_bias" in item:
        # the first-order figure understates what the fits' weighting of the lines makes
        # of it (docs/verdict.md): the entry is named, not the figure
        return "biased by the force delay"
    return f"{100 * item['relative_std']:.3g} % standard error"


def uncertain_sentence(uncertain: Sequence[dict]) -> str:
    """The reason naming the uncertain entries (:func:`uncertain_entries`) and why."""
    return "uncertain entries: " + ", ".join(
        f"{u['entry']} ({uncertain_reason(u)})" for u in uncertain) + "."


__all__ = ["Standing", "Verdict", "choose_trusted", "delay_bias", "delay_reason",
           "finds_friction", "friction_immune", "is_definite", "models_friction",
           "uncertain_entries", "uncertain_reason", "uncertain_sentence", "worst_dof", "worst_relative_std"]
