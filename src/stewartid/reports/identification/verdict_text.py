"""The verdict in words: what to know about one method's result, and among several which to trust
and what set the others back."""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np

from stewartid.comparison import MethodFit
from stewartid.identification.consistency import consistency_metrics, is_consistent
from stewartid.reports.identification.friction_text import (
    friction_law_lines,
    friction_shape_lines,
    friction_text,
    third_harmonic_lines,
)
from stewartid.validation.heldout import ResidualDelay, friction_signature
from stewartid.verdict.accuracy import relative_std
from stewartid.verdict.close_call import CONSENSUS, combined_text
from stewartid.verdict.policy import entries_text
from stewartid.verdict.rule import Verdict, uncertain_reason, worst_dof

#: Held-out VAF (%) in the worst DOF above which a model "predicts closely", "adequately".
CLOSE_VAF, ADEQUATE_VAF = 99.0, 95.0


def changed_text(projection: Any) -> str:
    """The consistent fit's largest change, in standard errors, for a sentence."""
    change = projection.max_change
    return "less than 0.001" if change < 1e-3 else f"{change:.3g}"


def quality_text(vaf: float) -> str:
    """How well a model predicts held-out force, in words, from its worst DOF's VAF (%)."""
    if vaf >= CLOSE_VAF:
        return "predicts the held-out force closely"
    if vaf >= ADEQUATE_VAF:
        return "predicts the held-out force adequately"
    return ("predicts the held-out force poorly: the model misses part of the dynamics "
            "(see the residual spectrum and the friction section)")


def delay_text(delay: ResidualDelay) -> str:
    """A Markdown sentence on a force delay left in the held-out residuals, and the fix."""
    return (f"**The forces lag the motion by {1e3 * delay.seconds:.3g} ms** (standard error "
            f"{1e3 * delay.std_error:.2g} ms) in the held-out residuals: a delay the fit did "
            "not remove, absorbed into Mt and Bt (mostly the Bt diagonal, by about "
            "τ (2πf)² Mt(i,i)) beyond their standard errors. Align the forces: "
            "`--delay auto`, or a known `--delay SECONDS`.")


def method_lines(run: MethodFit, delay: ResidualDelay | None = None) -> list[str]:
    """What to know about one method's result, one Markdown sentence group each; ``delay``: a
    force delay found in its held-out residuals (:attr:`Verdict.residual_delay`)."""
    result = run.result
    vaf, dof = worst_dof(run.validation)
    lines = [f"**{run.display_name}** {quality_text(vaf)}: VAF ≥ {vaf:.2f} % in every DOF "
             f"(worst {dof}) over {run.validation.folds} folds."]
    metrics = consistency_metrics(result.M, result.B)
    if is_consistent(result.M, result.B):
        lines.append(f"Its Mt is symmetric positive definite (smallest eigenvalue "
                     f"{metrics['M_min_eigenvalue']:,.4g}) and its Bt symmetric positive "
                     f"semidefinite (smallest eigenvalue {metrics['B_min_eigenvalue']:,.4g}).")
    else:
        lines.append(f"Its matrices are not physically consistent (Mt smallest eigenvalue "
                     f"{metrics['M_min_eigenvalue']:,.4g}, asymmetry "
                     f"{metrics['M_asymmetry']:.2g}; Bt {metrics['B_min_eigenvalue']:,.4g}, "
                     f"{metrics['B_asymmetry']:.2g}); `--consistent` gives the nearest "
                     "consistent pair.")
    if run.projection is not None:
        lines.append(f"The consistent fit (`--consistent`) moves no entry by more than "
                     f"{changed_text(run.projection)} standard errors; held-out VAF in the worst DOF "
                     f"{np.min(run.validation_unconstrained.vaf_percent):.3f} % → "
                     f"{np.min(run.validation.vaf_percent):.3f} %.")
    if delay is not None:
        lines.append(delay_text(delay))
    lines.append(f"Median relative standard error of the diagonal entries: "
                 f"{100 * relative_std(result):.2g} %.")
    lines += sampling_lines([run])
    if np.all(np.isfinite(run.coulomb[0])):
        lines.append(f"Coulomb friction: {friction_text(run)}.")
    else:
        share = friction_signature(run.validation)
        lines.append(f"It does not estimate friction; {100 * share:.0f} % of its held-out "
                     "residual has the shape of Coulomb joint friction (`--method all` "
                     "compares it with a method that estimates friction).")
    lines += friction_law_lines(result) + friction_shape_lines(result) + third_harmonic_lines(result)
    return lines


def verdict_lines(verdict: Verdict, runs: Sequence[MethodFit]) -> list[str]:
    """The verdict as Markdown sentences: one method's notes, or which to trust and why not the others."""
    ok = [run for run in runs if run.result is not None]
    if len(ok) == 1:
        return method_lines(ok[0], verdict.residual_delay)
    best = next(run for run in ok if run.name == verdict.trusted)
    trusted = verdict.standings[best.name]
    names = {run.name: run.display_name for run in ok}
    lines = [consensus_text(verdict, best, names)] if best.name == CONSENSUS else [
             f"**Trust {best.display_name} on these data.** Of the physically plausible "
             "methods that predict held-out data, its standard errors, each entry's checked "
             "against the other methods' estimates, predict the smallest "
             f"largest error over {entries_text(verdict.entries)}: "
             f"{100 * trusted.expected_worst:.3g} % "
             f"(largest standard error {100 * trusted.worst_relative_std:.3g} %, "
             f"{trusted.worst_entry}); they include the model error its symmetric pairs "
             "reveal. On held-out segments it leaves "
             f"{trusted.unexplained_percent:.3g} % of the force unexplained in its worst DOF "
             f"({trusted.worst_dof})."]
    if len(verdict.close) > 1 and best.name != CONSENSUS:
        lines.append(f"This is a close call: {' and '.join(names[n] for n in verdict.close)} "
                     "predict largest errors "
                     f"within {verdict.policy.close_factor:g}× of each other, and on such "
                     "data the noise "
                     "decides which is the more accurate (on logs with a known truth the one "
                     "predicting less was the more accurate in six or seven of ten such "
                     "cases). Where their entries differ, both are in the tables below.")
    if verdict.residual_delay is not None:
        lines.append(delay_text(verdict.residual_delay))
    if verdict.uncertain:
        lines.append("Entries to treat with care: " + ", ".join(
            u["entry"] + (f" (other methods disagree: {', '.join(u['disagrees_with'])})"
                          if u["disagrees_with"] else f" ({uncertain_reason(u)})")
            for u in verdict.uncertain) + ".")
    lines += sampling_lines(ok)
    if verdict.friction_source is not None:
        source = next(run for run in ok if run.name == verdict.friction_source)
        lines.append(f"Coulomb friction is present: {source.display_name} finds "
                     f"{friction_text(source)}.")
    for run in ok:
        if run is best:
            continue
        standing = verdict.standings[run.name]
        text = (f"{run.display_name}: predicted largest error "
                f"{100 * standing.expected_worst:.3g} % (largest standard error "
                f"{100 * standing.worst_relative_std:.3g} %, {standing.worst_entry}); it leaves "
                f"{standing.unexplained_percent:.3g} % unexplained in its worst held-out DOF "
                f"({standing.worst_dof}), {standing.unexplained_ratio:.3g}× as much")
        if standing.misfit:
            text += ", more than the held-out prediction allows for a trusted method"
        if not standing.compared:
            text += ("; its Mt or Bt has a negative eigenvalue, which no physical "
                     "platform has")
        if standing.friction_effect == "damping":
            text += (f"; it does not model Coulomb friction, and its Bt diagonal is "
                     f"{100 * standing.damping_excess:.0f} % above that of {best.display_name}: "
                     "the friction's first harmonic is read as viscous damping, which pulls "
                     "Bt up")
        elif standing.friction_effect == "residuals":
            text += ("; it does not model Coulomb friction, which stays in its residuals "
                     f"({100 * standing.friction_share:.0f} % of its held-out residual has the "
                     "shape of Coulomb friction)")
        lines.append(text + ".")
    for run in runs:
        if run.result is None:
            lines.append(f"{run.display_name} could not be applied to these data: {run.error}")
    return lines


def consensus_text(verdict: Verdict, best: MethodFit, names: dict[str, str]) -> str:
    """The verdict's first sentences when it trusts a close call's consensus (``names``: display names)."""
    members = verdict.close
    standing = verdict.standings[best.name]
    agreement = best.result.diagnostics.get("consensus", {}).get("agreement", float("nan"))
    predicted = ", ".join(f"{100 * verdict.standings[n].expected_worst:.3g} %" for n in members)
    return (f"**Trust the consensus of {' and '.join(names[n] for n in members)} on these "
            "data.** Their standard errors predict largest errors within "
            f"{verdict.policy.close_factor:g}× "
            f"of each other over {entries_text(verdict.entries)} ({predicted}): a close call, "
            "in which "
            "the noise decides which is the more accurate (on logs with a known truth the one "
            "predicting less was the more accurate in six or seven of ten such cases). The "
            "consensus averages their estimates, weighted by their inverse variances, where "
            f"they agree within {agreement:g} standard error of their difference "
            f"({combined_text(best.result, names[members[0]], verdict.entries)}). Its "
            "standard errors take the "
            "members' errors as fully correlated and "
            f"predict a largest error of {100 * standing.expected_worst:.3g} % (largest "
            f"standard error {100 * standing.worst_relative_std:.3g} %, "
            f"{standing.worst_entry}); on held-out segments it leaves "
            f"{standing.unexplained_percent:.3g} % of the force unexplained in its worst DOF "
            f"({standing.worst_dof}).")


def sampling_lines(runs: Sequence[MethodFit]) -> list[str]:
    """A sentence naming the methods whose result the log's sampling limits, if any."""
    limited = [(run.display_name, run.result.diagnostics["sampling"]) for run in runs
               if run.result.diagnostics.get("sampling", {}).get("limited")]
    if not limited:
        return []
    return ["Limited by the log's sampling, not its noise: " + "; ".join(
        f"{name} (standard errors {s['std_ratio']:.3g}× larger at half the rate, where noise "
        f"gives about 1.4×; an entry moved by {s['shift']:.3g} of them)" for name, s in limited)
        + ". Each entry's standard error includes its largest change at 1/2, 1/3 and 1/4 of "
        "the rate: a bound of what the sampling does, not an estimate of the noise."]


__all__ = ["ADEQUATE_VAF", "CLOSE_VAF", "changed_text", "consensus_text", "delay_text",
           "method_lines",
           "quality_text",
           "sampling_lines", "verdict_lines"]
