"""The identification report's physical-model section: parameters, held-out prediction, Mt and Bt
across the measured poses."""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np

from stewartid.comparison import PhysicalSection, Workspace
from stewartid.physical.estimator import PhysicalResult
from stewartid.platform import COORDINATES, Platform
from stewartid.reports.tables import ResultTable, to_markdown
from stewartid.verdict.rule import worst_dof


def _value(value: float) -> str:
    return "n/a" if not np.isfinite(value) else f"{value:.6g}"


def parameter_table(result: PhysicalResult) -> str:
    """The identified parameters as Markdown: value, standard error, combination, and why fixed (or
    how far the consistent fit moved each, in standard errors)."""
    fixed = result.diagnostics.get("fixed", {})
    moved = (result.diagnostics.get("consistent") or {}).get("change_std_errors", {})
    rows = []
    for name, value in result.parameters.items():
        note = f"fixed: {fixed[name]}" if name in fixed else (
            f"moved {moved[name]:+.2g} SE" if name in moved and moved[name] != 0 else "")
        rows.append((f"`{name}`", _value(value), _value(result.parameter_std_errors[name]),
                     result.base_parameters.get(name, name), note))
    return to_markdown(ResultTable(
        "parameters", "Identified parameters (SI units: kg, kg·m, kg·m², N·s/m, N·m·s, N, N·m)",
        ("parameter", "value", "standard error", "stands for", "note"),
        ("text", "value", "value", "text", "text"), tuple(rows)), heading_level=4)


def actuator_lines(result: PhysicalResult, platform: Platform | None) -> list[str]:
    """The physical section's part on electric legs: reflected mass and friction along the legs,
    and the force constant every identified mass scales with (nothing for hydraulic legs)."""
    if platform is None or platform.actuator.kind != "electric":
        return []
    values, errors = result.parameters, result.parameter_std_errors
    file = platform.actuator

    def quantity(name: str, unit: str, given: float) -> str:
        if name not in values:
            return f"not identified (file: {given:.6g} {unit})"
        note = " (fixed at the file's value)" if name in result.diagnostics.get("fixed", {}) \
            else f" ± {_value(errors[name])} {unit}"
        return f"{_value(values[name])} {unit}{note} (file: {given:.6g} {unit})"

    return [
        "### Electric actuators", "",
        "Along each leg (the six alike): reflected mass of rotor and screw "
        + quantity("reflected_mass", "kg", file.reflected_mass) + "; viscous friction "
        + quantity("viscous[actuator]", "N·s/m", file.viscous) + "; Coulomb friction "
        + quantity("coulomb[actuator]", "N", file.coulomb) + ".", "",
        f"The leg forces are the motor currents times the force constant, {file.force_constant:.6g}"
        " N/A in the platform file: every identified mass, first moment, inertia and friction "
        "level scales with it, so an error of x % in the force constant is an error of x % in "
        "all of them (Mt and Bt too). A known test mass calibrates it: fix the weighed mass to "
        "the platform, record, identify with `--model physical --payload` on the platform file "
        "without it, and pass the result and the mass to "
        "`stewartid.physical.calibration.corrected_force_constant` (docs/physical-model.md).", ""]


def physical_lines(section: PhysicalSection | None,
                   figures: Mapping[str, tuple[str, str]],
                   platform: Platform | None = None) -> list[str]:
    """The report's "Physical model" section (nothing without ``section``); ``platform`` the
    description the fit used, for its actuators."""
    if section is None:
        return []
    lines = ["## Physical model", ""]
    if section.result is None:
        return lines + [section.note or "", ""]
    result = section.result
    mode = result.diagnostics.get("mode", "full")
    fixed = result.diagnostics.get("fixed", {})
    lines += [
        "The rigid-body model's physical parameters (masses, first moments, inertias, friction "
        "per joint type, force-sensor offsets; docs/physical-model.md) fitted to all "
        "experiments by weighted least squares"
        + (", the payload alone on the platform file's platform" if mode == "payload" else "")
        + f" ({section.seconds:.1f} s with its validation). It is not ranked by the verdict.",
        "",
        ("Fixed at the platform file's values, as these data cannot tell them: "
         + "; ".join(f"`{name}` ({why})" for name, why in fixed.items()) + ".")
        if fixed else "Every parameter is identified from these data (none fixed).", ""]
    if section.validation is not None:
        vaf, dof = worst_dof(section.validation)
        text = (f"Held-out prediction by the full model (its gravity, friction and offsets at "
                f"the measured poses, refitted without each segment): VAF {vaf:.3f} % in the "
                f"worst DOF ({dof})")
        if section.records is not None:
            text += f", {np.min(section.records.vaf_percent):.3f} % on the validation records"
        lines += [text + "; beside the other methods in the validation tables.", ""]
    consistent = result.diagnostics.get("consistent")
    if consistent:
        lines += [f"Physically consistent fit (solver {consistent['solver']}, "
                  f"{consistent['status']}): no parameter moved by more than "
                  f"{consistent['max_change_std_errors']:.2g} standard errors from the "
                  "unconstrained estimate.", ""]
    if "workspace" in figures:
        path, caption = figures["workspace"]
        lines += [f"![{caption}]({path})", "", f"*{caption}* ([SVG]({path[:-4]}.svg))", ""]
    return (lines + [_range_text(section.workspace), ""] + actuator_lines(result, platform)
            + [parameter_table(result)])


def _range_text(curves: Workspace | None) -> str:
    if curves is None:
        return ""
    scale = np.array([1e3] * 3 + [np.degrees(1.0)] * 3)
    units = ("mm",) * 3 + ("°",) * 3
    spans = ", ".join(f"{name} {lo * s:.4g} to {hi * s:.4g} {u}" for name, lo, hi, s, u in zip(
        COORDINATES, curves.grid[:, 0], curves.grid[:, -1], scale, units, strict=True))
    return f"Measured range (absolute pose): {spans}."


__all__ = ["actuator_lines", "parameter_table", "physical_lines"]
