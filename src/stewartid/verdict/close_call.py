"""The verdict's answer to a close call: trust the consensus of the close methods.

Where several plausible methods predict largest errors within the policy's ``close_factor``
of each other, the noise decides which of them is the more accurate; their consensus
(:func:`~stewartid.verdict.consensus.combine_results`) is trusted instead.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence

import numpy as np

from stewartid.identification.result import IdentificationResult
from stewartid.reference.published import PAPER_ENTRIES, EntryKey
from stewartid.validation.heldout import ResidualDelay, ValidationResult, friction_signature
from stewartid.verdict.accuracy import entry_relative_std, expected_worst_error
from stewartid.verdict.policy import entries_text
from stewartid.verdict.rule import (
    Standing,
    Verdict,
    models_friction,
    uncertain_entries,
    uncertain_sentence,
    worst_dof,
    worst_relative_std,
)

#: Registry name of the consensus.
CONSENSUS = "consensus"


def consensus_members(verdict: Verdict) -> tuple[str, ...]:
    """The methods whose consensus the verdict trusts: its close call
    (:attr:`~stewartid.verdict.rule.Verdict.close`, the trusted method first) when it
    holds two or more, else none."""
    return verdict.close if len(verdict.close) > 1 else ()


def combined_entries(result: IdentificationResult, entries: Sequence[EntryKey]) -> int:
    """How many of ``entries`` the consensus ``result`` averaged over two or more members
    (the others are its reference member's)."""
    found = result.diagnostics.get("consensus", {})
    used = {"M": np.asarray(found.get("used_M")), "B": np.asarray(found.get("used_B"))}
    if used["M"].ndim != 3 or used["B"].ndim != 3:
        return 0
    return sum(int(used[matrix][:, i, j].sum() > 1) for matrix, i, j in entries)


def combined_text(result: IdentificationResult, reference: str,
                  entries: Sequence[EntryKey]) -> str:
    """Which of ``entries`` the consensus ``result`` averaged, for a sentence (``reference``:
    how to name its reference member)."""
    count = combined_entries(result, entries)
    if count == len(entries):
        return (f"all {count} of the paper's entries" if tuple(entries) == PAPER_ENTRIES
                else f"all {count} scored entries")
    return f"{count} of {entries_text(entries)}; {reference}'s elsewhere"


def trust_consensus(verdict: Verdict, result: IdentificationResult,
                    validation: ValidationResult,
                    compared: dict[str, IdentificationResult],
                    residual_delay: ResidualDelay | None = None) -> Verdict:
    """``verdict`` with the consensus of its close call trusted and ranked first.

    Parameters
    ----------
    verdict : Verdict
        With a close call (:func:`consensus_members` not empty).
    result : IdentificationResult
        The consensus of the close methods, the trusted one first.
    validation : ValidationResult
        Its held-out (or validation records') scores.
    compared : dict of str to IdentificationResult
        The plausible methods' results, by name: the entries the consensus is unsure of are
        those its relative error leaves uncertain or one of them contradicts.
    residual_delay : ResidualDelay, optional
        The force delay left in its held-out residuals.

    Returns
    -------
    Verdict
        Trusted :data:`CONSENSUS`; the earlier trusted method's reasons follow the
        consensus's; every standing's unexplained force relative to the consensus's.
    """
    members = consensus_members(verdict)
    entries = verdict.entries
    vaf, dof = worst_dof(validation)
    worst, entry = worst_relative_std(result, entries)
    unexplained = max(100 - vaf, 1e-12)
    standings = {CONSENSUS: Standing(
        name=CONSENSUS, worst_vaf_percent=vaf, worst_dof=dof, unexplained_ratio=1.0,
        compared=True, models_friction=models_friction(result), friction_effect=None,
        damping_excess=float("nan"), friction_share=friction_signature(validation),
        worst_relative_std=worst, worst_entry=entry,
        expected_worst=expected_worst_error(entry_relative_std(result, entries)),
        residual_delay=residual_delay)}
    standings.update({name: dataclasses.replace(
        standing, unexplained_ratio=standing.unexplained_percent / unexplained)
        for name, standing in verdict.standings.items()})
    agreement = result.diagnostics.get("consensus", {}).get("agreement", float("nan"))
    reason = (f"{CONSENSUS}: {', '.join(members)} are a close call, so their estimates (each "
              "one's symmetric pairs pooled) are averaged, weighted by their inverse "
              "variances, where they agree within "
              f"{agreement:g} standard error of their difference "
              f"({combined_text(result, members[0], entries)}); its standard errors take "
              "the members' errors as fully correlated, and predict a largest error of "
              f"{100 * standings[CONSENSUS].expected_worst:.3g} %; held-out VAF {vaf:.4g} % in "
              f"its worst DOF ({dof}).")
    uncertain = uncertain_entries(result, compared, entries, verdict.policy,
                                  verdict.residual_delay)
    reasons = [reason, *(r for r in verdict.reasons if not r.startswith("uncertain entries:"))]
    if uncertain:
        reasons.append(uncertain_sentence(uncertain))
    return dataclasses.replace(verdict, trusted=CONSENSUS, ranking=(CONSENSUS, *verdict.ranking),
                               standings=standings, uncertain=uncertain, reasons=reasons)


__all__ = ["CONSENSUS", "combined_entries", "combined_text", "consensus_members",
           "trust_consensus"]
