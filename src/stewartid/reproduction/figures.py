"""Figures only a reproduction draws: the traced experiment's force budget and scalogram, and
every method's errors beside the paper's. Each returns the written paths."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from stewartid.platform import COORDINATES
from stewartid.reference.published import PAPER_ENTRIES, entry_label
from stewartid.reports.drawing import ExperimentTrace, new_figure, save_figure, styled, thinning_step
from stewartid.reports.methods import method_color, method_name
from stewartid.reproduction.comparison import ComparisonResults

_FORCE_UNITS = ("N",) * 3 + ("N·m",) * 3

#: Force components of a budget, in plotting order, with display names.
FORCE_COMPONENTS = {
    "inertial": "inertial M(q) q̈ + h",
    "viscous": "viscous joint friction",
    "coulomb": "Coulomb joint friction",
    "gravity": "gravity G(q) − G(q₀)",
    "actuators": "actuators Jᵀ f − G(q₀)",
}


@styled
def plot_force_budget(trace: ExperimentTrace, directory: str | Path,
                      channels: Sequence[int] | None = None,
                      stem: str = "force_budget") -> list[Path]:
    """Inertial, viscous, Coulomb, gravity and actuator force in the excited and most coupled equations."""
    if channels is None:
        coupled = {0: 4, 1: 3, 2: 2, 3: 1, 4: 0, 5: 5}[trace.excited]
        channels = sorted({trace.excited, coupled})
    figure = new_figure(figsize=(9, 3.2 * len(channels)), layout="constrained")
    axes = figure.subplots(len(channels), 1, sharex=True, squeeze=False)
    styles = {"inertial": ("#1f77b4", 1.4), "viscous": ("#ff7f0e", 1.4),
              "coulomb": ("#d62728", 1.4), "gravity": ("#9467bd", 1.4),
              "actuators": ("#b0b0b0", 0.6)}
    step = thinning_step(trace.t, 6000)
    t = trace.t[step]
    for axis, channel in zip(axes[:, 0], channels, strict=True):
        big = max(np.max(np.abs(f[:, channel])) for f in trace.forces.values())
        scale, prefix = (1e-3, "k") if big >= 1e4 else (1.0, "")
        for name, label in FORCE_COMPONENTS.items():
            if name not in trace.forces:
                continue
            colour, width = styles[name]
            # the measured total goes behind the model's terms
            axis.plot(t, trace.forces[name][step, channel] * scale, color=colour, lw=width,
                      label=label, zorder=1 if name == "actuators" else 2)
        model = sum(trace.forces[name][step, channel] for name in
                    ("inertial", "viscous", "coulomb", "gravity") if name in trace.forces)
        axis.plot(t, model * scale, color="k", lw=1.0, ls="--", label="sum of model terms",
                  zorder=3)
        axis.set_ylabel(f"{COORDINATES[channel]} equation ({prefix}{_FORCE_UNITS[channel]})")
        axis.set_title(f"{trace.name} ({COORDINATES[trace.excited]} excited): "
                       f"{COORDINATES[channel]} equation")
        axis.legend(loc="upper right", ncol=2, framealpha=0.9)
    axes[-1, 0].set_xlabel("time (s)")
    return save_figure(figure, directory, stem)


@styled
def plot_scalogram(t: np.ndarray, signal: np.ndarray, points: np.ndarray,
                   directory: str | Path, wavelet: Any = "mexican_hat",
                   signal_label: str = "signal", intervals: np.ndarray | None = None,
                   stem: str = "scalogram", max_rate_hz: float = 100.0) -> list[Path]:
    """|W_ψ f(a, b)| of one signal over scales and shifts, the (a, b) points used marked.

    ``t``, ``signal``: shape (N,) (s, any unit); ``points``: shape (K, 2) (s); ``wavelet``: see
    :func:`stewartid.signals.wavelets.make_wavelet`; ``intervals``: shape (M, 2), drawn under the
    map; ``max_rate_hz``: decimation for the map only."""
    from stewartid.signals.wavelets import make_wavelet, wavelet_transform

    t = np.asarray(t, dtype=float)
    signal = np.asarray(signal, dtype=float)
    points = np.asarray(points, dtype=float).reshape(-1, 2)
    step = max(1, int(round(1.0 / (max_rate_hz * np.median(np.diff(t))))))
    t_map, f_map = t[::step], signal[::step]
    mother = make_wavelet(wavelet) if isinstance(wavelet, str | dict) else wavelet
    a_low = points[:, 0].min() / 2 if len(points) else 0.02 * (t[-1] - t[0])
    a_high = points[:, 0].max() * 2 if len(points) else 0.2 * (t[-1] - t[0])
    a_low = max(a_low, 4 * (t_map[1] - t_map[0]))
    scales = np.geomspace(a_low, a_high, 48)
    shifts = np.linspace(t[0], t[-1], 240)
    grid_a, grid_b = np.meshgrid(scales, shifts, indexing="ij")
    values = wavelet_transform(f_map, t_map, grid_a.ravel(), grid_b.ravel(), mother)
    magnitude = np.abs(values).reshape(grid_a.shape)
    # wavelets that stick out of the record are cut off: blank them rather than mislead
    inside = ((grid_b - mother.half_width * grid_a >= t[0])
              & (grid_b + mother.half_width * grid_a <= t[-1]))
    magnitude = np.where(inside, magnitude, np.nan)
    figure = new_figure(figsize=(9, 4.2), layout="constrained")
    axis = figure.subplots()
    mesh = axis.pcolormesh(shifts, scales, magnitude, shading="auto", cmap="magma",
                           rasterized=True)
    colourbar = figure.colorbar(mesh, ax=axis)
    colourbar.set_label(f"|W_ψ f(a, b)| ({signal_label.split('(')[-1].rstrip(')')})"
                        if "(" in signal_label else "|W_ψ f(a, b)|")
    if len(points):
        axis.scatter(points[:, 1], points[:, 0], s=14, facecolor="none", edgecolor="#4dd0e1",
                     lw=1.0, label=f"(a, b) used ({len(points)})")
    if intervals is not None:
        for k, (start, stop) in enumerate(intervals):
            axis.plot([start, stop], [a_low * 1.02] * 2, color="#9ecae1", lw=4,
                      solid_capstyle="butt",
                      label="constant-direction interval" if k == 0 else None)
    axis.set_yscale("log")
    axis.set_xlabel("shift b (s)")
    axis.set_ylabel("scale a (s)")
    axis.set_title(f"Scalogram of {signal_label} ({mother.name} wavelet)")
    if axis.get_legend_handles_labels()[0]:
        axis.legend(loc="upper right", framealpha=0.9)
    return save_figure(figure, directory, stem)


def _grouped_bars(axis: Any, labels: Sequence[str], series: Sequence[tuple[str, np.ndarray,
                  dict]], log: bool, base: float = 0.0) -> None:
    """Bars of several series side by side per label, from ``base``."""
    width = 0.84 / max(len(series), 1)
    x = np.arange(len(labels))
    for k, (label, values, style) in enumerate(series):
        offset = (k - (len(series) - 1) / 2) * width
        axis.bar(x + offset, np.asarray(values) - base, width, bottom=base, label=label,
                 **style)
    axis.set_xticks(x, labels, rotation=60, ha="right")
    axis.set_xlim(-0.6, len(labels) - 0.4)
    if log:
        axis.set_yscale("log")


@styled
def plot_errors(results: ComparisonResults, directory: str | Path,
                stem: str = "errors") -> list[Path]:
    """ε (%) per entry, every method and the paper's published ε, one panel per Coulomb level."""
    levels = results.coulomb_levels
    figure = new_figure(figsize=(14, 3.6 * len(levels)), layout="constrained")
    axes = figure.subplots(len(levels), 1, squeeze=False)
    labels = [entry_label(k) for k in PAPER_ENTRIES]
    floor = 1e-3  # ε below this (%) is drawn at the floor so the log axis stays readable
    for axis, level in zip(axes[:, 0], levels, strict=True):
        series = []
        for method in results.methods:
            run = results.run(method, level)
            if run is None:
                continue
            eps = np.maximum([results.eps(run, k) for k in PAPER_ENTRIES], floor)
            colour = method_color(method)
            series.append((method_name(method), eps, {"color": colour}))
            if results.published_entry(method, level, PAPER_ENTRIES[0]) is not None:
                paper = np.maximum([results.published_entry(method, level, k).eps
                                    for k in PAPER_ENTRIES], floor)
                series.append((f"{method_name(method)}, paper", paper,
                               {"facecolor": "white", "edgecolor": colour, "hatch": "///",
                                "lw": 0.8}))
        _grouped_bars(axis, labels, series, log=True)
        axis.axhline(1.0, color="k", lw=0.8, ls="--", label="1 %")
        axis.set_ylabel("ε (%)")
        axis.set_title(f"Coulomb friction {level:g} N·m per joint axis")
        axis.legend(loc="upper left", bbox_to_anchor=(1.005, 1.0), framealpha=0.9)
    figure.suptitle("Relative error per entry, ours (filled) and the paper's (hatched)")
    return save_figure(figure, directory, stem)


@styled
def plot_identified_vs_nominal(results: ComparisonResults, coulomb: float,
                               directory: str | Path, stem: str | None = None) -> list[Path]:
    """Identified / nominal per entry and method at one Coulomb level (1 = exact), nominals printed."""
    figure = new_figure(figsize=(13, 4.6), layout="constrained")
    axes = figure.subplots(1, 2)
    for axis, matrix in zip(axes, ("M", "B"), strict=True):
        keys = [k for k in PAPER_ENTRIES if k[0] == matrix]
        labels = [f"{entry_label(k)}\n{results.nominal(k):,.0f}" for k in keys]
        series = []
        for method in results.methods:
            run = results.run(method, coulomb)
            if run is None:
                continue
            ratio = np.array([run.value(k) / results.nominal(k) for k in keys])
            series.append((method_name(method), ratio,
                           {"color": method_color(method)}))
            if results.published_entry(method, coulomb, keys[0]) is not None:
                paper = np.array([results.published_entry(method, coulomb, k).value
                                  / results.nominal(k) for k in keys])
                series.append((f"{method_name(method)}, paper", paper,
                               {"facecolor": "white", "hatch": "///", "lw": 0.8,
                                "edgecolor": method_color(method)}))
        _grouped_bars(axis, labels, series, log=False, base=1.0)
        axis.axhline(1.0, color="k", lw=1.0, label="nominal")
        values = np.concatenate([s[1] for s in series]) if series else np.ones(1)
        spread = max(0.05, float(np.max(np.abs(values - 1.0))) * 1.15)
        axis.set_ylim(1 - spread, 1 + spread)
        name = "Mt" if matrix == "M" else "Bt"
        axis.set_ylabel(f"identified / nominal {name} (−)")
        axis.set_title(f"{name} at Coulomb {coulomb:g} N·m (nominal value under each entry)")
        axis.tick_params(axis="x", labelrotation=0, labelsize=8)
        for tick in axis.get_xticklabels():
            tick.set_horizontalalignment("center")
    handles, names = axes[0].get_legend_handles_labels()
    figure.legend(handles, names, loc="outside lower center", ncol=min(len(names), 4))
    return save_figure(figure, directory, stem or f"identified_vs_nominal_coulomb{coulomb:g}")


__all__ = [
    "FORCE_COMPONENTS",
    "plot_errors",
    "plot_force_budget",
    "plot_identified_vs_nominal",
    "plot_scalogram",
]
