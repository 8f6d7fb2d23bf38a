"""The identification report's sentences about friction."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from stewartid.comparison import MethodFit
from stewartid.identification.result import IdentificationResult
from stewartid.model.joints import FRICTION_TYPES
from stewartid.platform import Platform
from stewartid.validation.heldout import friction_signature


def friction_text(run: MethodFit) -> str:
    """A method's Coulomb levels per joint type, ± standard errors, for a sentence."""
    levels, std = run.coulomb
    return ", ".join(f"{name.replace('_', ' ')} {v:.3g} ± {s:.2g} N·m"
                     for name, v, s in zip(FRICTION_TYPES, levels, std, strict=True))


def friction_law_lines(result: IdentificationResult) -> list[str]:
    """Method B on one sine per experiment: which friction treatment it kept, and why."""
    candidates = result.diagnostics.get("friction_candidates") or {}
    law = result.diagnostics.get("friction_law_test")
    if len(candidates) < 2 or not law:
        return []
    predicted = {name: 100 * value["predicted_worst_relative_error"]
                 for name, value in candidates.items()}
    kept = result.friction_model
    test = (f"its diagonals differ from the free constants' by at most "
            f"{law['largest_disagreement']:.3g} standard errors, at {law['entry']}, against a "
            f"threshold of {law['threshold']:.3g}")
    if law["rejected"]:
        reason = f"kept the free constants: the data contradict the Coulomb law ({test})"
    elif kept == "coulomb":
        reason = (f"kept the law, which passes its test ({test}) and predicts the smaller "
                  "largest error")
    else:
        reason = (f"kept the free constants, whose standard errors predict the smaller largest "
                  f"error (the law passes its test: {test})")
    return [f"It fitted both the free interval constants (predicted largest error "
            f"{predicted['free']:.3g} %) and the Coulomb law of each joint type "
            f"({predicted['coulomb']:.3g} %) and {reason}."]


def friction_shape_lines(result: IdentificationResult) -> list[str]:
    """Least squares: how the data weigh the two shapes of the Coulomb sign near a reversal."""
    weights = result.diagnostics.get("coulomb_shape_weights") or {}
    if len(weights) < 2:
        return []
    shown = max(weights.values()) > 0.95
    lines = ["Its Coulomb sign near a reversal was fitted with two shapes of one slope; the "
             "data weigh them " + ", ".join(f"{name} {w:.2f}" for name, w in weights.items())
             + (" (they show the shape" if shown else " (they cannot tell the shape; the "
                "spread between the two fits is in its standard errors") + ")."]
    sharp = result.diagnostics.get("exact_sign_weight")
    if sharp is not None and sharp > SHARP_SIGN_NOTED:
        lines.append(f"The data weigh an exact sign at {sharp:.2f} against the likelier shape: "
                     "the friction turns over faster than the model's sign (dry friction that "
                     "sticks), and the distance to that fit is in the standard errors.")
    return lines


#: Weight of the exact sign from which the report says the friction is sharper than the model's.
SHARP_SIGN_NOTED = 0.05


def stop_lines(result: IdentificationResult) -> list[str]:
    """Electric legs: where the legs' stops left their friction free instead of the sign law
    (least squares: the share of each experiment's rows they took; Method B: the legs' share
    of samples at a stop and its shortened windows)."""
    experiments = result.diagnostics.get("experiments") or []
    rows = [e["stop_rows"] / e["samples"] for e in experiments
            if e.get("stop_rows") and e.get("samples")]
    still = [e["stopped_share"] for e in experiments if e.get("stopped_share")]
    if rows:
        return [f"Where a leg stood still (its rate within its noise) its friction was left "
                f"free, not the sign law's: the stops took {100 * min(rows):.2g}-"
                f"{100 * max(rows):.2g} % of the experiments' rows."]
    if still:
        windows = [e["stop_window_s"] for e in experiments if e.get("stopped_share")]
        return [f"The legs stood still (their rates within their noise) for "
                f"{100 * min(still):.2g}-{100 * max(still):.2g} % of the samples; its windows "
                f"left their friction there free, not the sign law's, and were shortened to "
                f"{min(windows):.2g}-{max(windows):.2g} s to keep rows for it."]
    return []


def third_harmonic_lines(result: IdentificationResult) -> list[str]:
    """Method A: whether the force's third harmonic shows Coulomb friction read as viscous."""
    bias = result.diagnostics.get("friction_bias") or {}
    if "statistic" not in bias or not np.isfinite(bias["threshold"]):
        return []
    shown = bias["statistic"] > bias["threshold"]
    bound = np.diag(np.asarray(bias["bound_B"])) / np.abs(np.diag(result.B))
    return [f"The third harmonic its linear model leaves {'shows' if shown else 'does not show'} "
            f"Coulomb friction (chi-squared {bias['statistic']:.4g} against "
            f"{bias['threshold']:.4g} at 1 %): "
            + (f"its standard errors carry the bias the friction's first harmonic puts on Bt "
               f"(up to {100 * np.max(bound):.2g} % of its diagonal)." if shown else
               "its standard errors are the noise's.")]


def friction_section(ok: Sequence[MethodFit], platform: Platform) -> list[str]:
    """The friction section: per method its Coulomb levels, or what its residual shows of friction."""
    lines: list[str] = []
    for run in ok:
        if np.all(np.isfinite(run.coulomb[0])):
            lines.append(" ".join([
                f"- {run.display_name}: {friction_text(run)} (platform description: "
                f"{platform.friction.coulomb:g} N·m per joint axis).",
                *friction_law_lines(run.result), *friction_shape_lines(run.result),
                *stop_lines(run.result)]))
        else:
            lines.append(" ".join([
                f"- {run.display_name} does not estimate friction (its prediction contains "
                f"none); {100 * friction_signature(run.validation):.0f} % of its held-out "
                "residual has the shape of Coulomb friction.",
                *friction_law_lines(run.result), *third_harmonic_lines(run.result)]))
    return lines


__all__ = ["friction_law_lines", "friction_section", "friction_shape_lines", "friction_text",
           "stop_lines", "third_harmonic_lines"]
