"""The identification report's plots, written as PNG and SVG; each returns the written paths.
Fixed-margin grids: matplotlib's constrained layout is far slower to draw."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path

import numpy as np

from stewartid.comparison import Workspace
from stewartid.model.joints import FRICTION_TYPES
from stewartid.platform import COORDINATES
from stewartid.reports.drawing import new_figure, save_figure, styled, thinning_step
from stewartid.validation.heldout import ValidationResult

#: Display unit and scale of a displacement in each coordinate.
DISPLACEMENT_UNITS = (("mm", 1e3),) * 3 + (("mrad", 1e3),) * 3
#: Unit of the generalized force in each equation.
FORCE_UNITS = ("N",) * 3 + ("N·m",) * 3


def _grid(figure, count: int, columns: int = 3, top: float = 0.9, **options):
    """A grid of ``count`` axes with fixed margins (hidden axes fill the last row)."""
    rows = int(np.ceil(count / columns))
    margins = {"left": 0.07, "right": 0.98, "bottom": 0.08, "top": top, "hspace": 0.45,
               "wspace": 0.3, **options}
    axes = figure.subplots(rows, columns, squeeze=False, gridspec_kw=margins)
    for axis in list(axes.flat)[count:]:
        axis.set_visible(False)
    return axes


def _log_floor(axis, values: np.ndarray, decades: float | None = 5.0) -> None:
    """Limit a log axis to ``decades`` below its maximum (None: no limit), plain tick labels."""
    from matplotlib.ticker import FuncFormatter, NullLocator

    top = float(np.nanmax(values)) if np.size(values) else 1.0
    if top > 0 and decades is not None:
        axis.set_ylim(top * 10 ** -decades, top * 3)
    axis.yaxis.set_major_formatter(FuncFormatter(lambda value, _: f"{value:g}"))
    axis.yaxis.set_minor_locator(NullLocator())


@styled
def plot_spectra(names: Sequence[str], poses: Sequence[np.ndarray], sample_rates: Sequence[float],
                 frequencies_hz: Sequence[float], directory: str | Path,
                 stem: str = "spectrum") -> list[Path]:
    """Amplitude spectrum of every coordinate's displacement, one panel per experiment.

    ``poses``: shape (N_k, 6) (m, rad); ``sample_rates`` and ``frequencies_hz`` (the dominant
    excitation, marked) in Hz."""
    figure = new_figure(figsize=(13, 3.3 * int(np.ceil(len(names) / 3)) + 0.6))
    axes = _grid(figure, len(names))
    colours = ["#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd", "#8c564b"]
    for axis, name, q, rate, f0 in zip(axes.flat, names, poses, sample_rates, frequencies_hz,
                                       strict=False):
        n = len(q)
        window = np.hanning(n)[:, None]
        spectrum = 2 * np.abs(np.fft.rfft((q - q.mean(axis=0)) * window, axis=0)) / window.sum()
        frequency = np.fft.rfftfreq(n, 1.0 / rate)
        keep = (frequency > 0) & (frequency <= min(20 * f0, rate / 2))
        shown = spectrum[keep] * np.array([scale for _, scale in DISPLACEMENT_UNITS])
        for k in range(6):
            axis.semilogy(frequency[keep], shown[:, k], color=colours[k], lw=0.9,
                          label=f"{COORDINATES[k]} ({DISPLACEMENT_UNITS[k][0]})")
        _log_floor(axis, shown)
        axis.axvline(f0, color="k", lw=0.6, ls="--")
        axis.set_title(f"{name}: dominant {f0:.4g} Hz")
        axis.set_xlabel("frequency (Hz)")
        axis.set_ylabel("amplitude (mm, mrad)")
    axes[0, 0].legend(loc="upper right", ncol=2, framealpha=0.9)
    figure.suptitle("Spectrum of the measured motion (Hann window)")
    return save_figure(figure, directory, stem, tight=False)


@styled
def plot_intervals(names: Sequence[str], spans: Sequence[tuple[float, float]],
                   intervals: Sequence[np.ndarray], points: Sequence[np.ndarray | None],
                   directory: str | Path, stem: str = "intervals") -> list[Path]:
    """The constant-direction intervals used, one lane per experiment, with the (a, b) points.

    ``spans``: (first, last) time of each record; ``intervals``: shape (M_k, 2) [start, stop];
    ``points``: shape (K_k, 2) (a, b) pairs or None; all in s."""
    height = 0.55 * len(names) + 1.6
    figure = new_figure(figsize=(11, height))
    axis = figure.subplots(gridspec_kw={"left": 0.1, "right": 0.98, "bottom": 0.9 / height,
                                        "top": 1 - 0.7 / height})
    for row, (span, found, used) in enumerate(zip(spans, intervals, points, strict=True)):
        axis.plot(span, [row, row], color="#cccccc", lw=6, solid_capstyle="butt")
        for k, (start, stop) in enumerate(np.asarray(found).reshape(-1, 2)):
            axis.plot([start, stop], [row, row], color="#3182bd", lw=6, solid_capstyle="butt",
                      label="constant-direction interval" if row == 0 and k == 0 else None)
        if used is not None and len(used):
            used = np.asarray(used).reshape(-1, 2)
            offsets = row + 0.3 * (used[:, 0] / used[:, 0].max())
            axis.errorbar(used[:, 1], offsets, xerr=used[:, 0], fmt="o", ms=2, lw=0.5,
                          color="#e6550d", label="(a, b) points" if row == 0 else None)
    axis.set_yticks(range(len(names)), names)
    axis.invert_yaxis()
    axis.set_xlabel("time (s)")
    axis.set_title("Intervals in which no active joint reverses (grey: the record)")
    if axis.get_legend_handles_labels()[0]:
        axis.legend(loc="lower right", bbox_to_anchor=(1.0, 1.0), ncol=2, framealpha=0.9,
                    fontsize=8)
    return save_figure(figure, directory, stem, tight=False)


def _significant(nominal: np.ndarray) -> list[tuple[int, int]]:
    scale = np.abs(nominal).max()
    return [(i, j) for i in range(6) for j in range(6)
            if scale > 0 and abs(nominal[i, j]) > 1e-6 * scale]


@styled
def plot_matrices(estimates: Mapping[str, tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]],
                  colours: Mapping[str, str], M_nominal: np.ndarray, B_nominal: np.ndarray,
                  directory: str | Path, stem: str = "matrices") -> list[Path]:
    """Identified / nominal for every non-negligible nominal entry, ±2 standard errors, per method.

    ``estimates``: label -> (M, B, std_M, std_B), each shape (6, 6)."""
    figure = new_figure(figsize=(13, 7.5))
    axes = figure.subplots(2, 1, gridspec_kw={"left": 0.07, "right": 0.98, "bottom": 0.1,
                                              "top": 0.95, "hspace": 0.45})
    width = 0.8 / max(len(estimates), 1)
    for axis, index, nominal, name in ((axes[0], 0, M_nominal, "Mt"),
                                       (axes[1], 1, B_nominal, "Bt")):
        entries = _significant(nominal)
        x = np.arange(len(entries))
        for k, (label, values) in enumerate(estimates.items()):
            matrix, std = values[index], values[index + 2]
            ratio = np.array([matrix[e] / nominal[e] for e in entries])
            bars = np.array([2 * std[e] / abs(nominal[e]) for e in entries])
            axis.errorbar(x + (k - (len(estimates) - 1) / 2) * width, ratio, yerr=bars, fmt="o",
                          ms=4, capsize=2, color=colours[label], label=label)
        axis.axhline(1.0, color="k", lw=0.8)
        axis.set_xticks(x, [f"{name}({i + 1},{j + 1})\n{nominal[i, j]:,.0f}" for i, j in entries],
                        fontsize=7)
        axis.set_ylabel(f"identified / nominal {name} (−)")
        axis.set_title(f"{name}: identified over nominal (nominal under each entry), "
                       "bars ±2 standard errors")
    axes[0].legend(loc="best", framealpha=0.9)
    return save_figure(figure, directory, stem, tight=False)


def _concatenated(validation: ValidationResult, values: Sequence[np.ndarray]):
    """Segments end to end: time (s from the first sample) and stacked values."""
    times, offset = [], 0.0
    for segment in validation.segments:
        times.append(segment.t - segment.t[0] + offset)
        offset = times[-1][-1] + (segment.t[1] - segment.t[0])
    return np.concatenate(times), np.concatenate(values)


@styled
def plot_residuals(validation: ValidationResult, frequencies_hz: Sequence[float],
                   directory: str | Path, stem: str = "residuals") -> list[Path]:
    """Each equation's residual over time (experiments end to end) and its spectrum.

    ``frequencies_hz``: each experiment's excitation frequency, marked with its harmonics."""
    from matplotlib.collections import LineCollection

    residual = [m - p for m, p in zip(validation.measured, validation.predicted, strict=True)]
    t, values = _concatenated(validation, residual)
    figure = new_figure(figsize=(13, 12))
    axes = _grid(figure, 12, columns=2, top=0.95, bottom=0.05, hspace=0.35, wspace=0.2,
                 width_ratios=[2.2, 1])
    step = thinning_step(t, 6000)
    rate = 1.0 / (validation.segments[0].t[1] - validation.segments[0].t[0])
    top = 10 * max(frequencies_hz)
    harmonics = np.unique(np.concatenate([f * np.arange(1, int(top / f) + 1)
                                          for f in sorted(set(np.round(frequencies_hz, 6)))]))
    for c in range(6):
        axes[c, 0].plot(t[step], values[step, c], color="#444444", lw=0.6)
        axes[c, 0].set_ylabel(f"{COORDINATES[c]} ({FORCE_UNITS[c]})")
        spectra = []
        for piece in (r[:, c] for r in residual):
            window = np.hanning(len(piece))
            amplitude = 2 * np.abs(np.fft.rfft((piece - piece.mean()) * window)) / window.sum()
            frequency = np.fft.rfftfreq(len(piece), 1.0 / rate)
            keep = frequency <= top
            spectra.append(np.column_stack([frequency[keep], amplitude[keep]]))
        # one artist per panel for the segments' spectra and one for the harmonics, not one
        # line each (zorder of a line, above the grid); the spectra set the axis range
        axes[c, 1].set_yscale("log")
        axes[c, 1].add_collection(LineCollection(spectra, colors="#444444", linewidths=0.5,
                                                 alpha=0.5, zorder=2))
        _log_floor(axes[c, 1], np.concatenate([s[:, 1] for s in spectra]), decades=4.0)
        axes[c, 1].add_collection(LineCollection(
            [[(f, 0.0), (f, 1.0)] for f in harmonics], colors="#d62728", linewidths=0.5,
            linestyles=":", zorder=2, transform=axes[c, 1].get_xaxis_transform()),
            autolim=False)
    axes[0, 0].set_title("Residual (measured − model) over time; experiments end to end")
    axes[0, 1].set_title("Residual spectrum per segment\n(dotted: excitation harmonics)")
    axes[-1, 0].set_xlabel("time across the experiments (s)")
    axes[-1, 1].set_xlabel("frequency (Hz)")
    return save_figure(figure, directory, stem, tight=False)


@styled
def plot_validation(validations: Mapping[str, ValidationResult], colours: Mapping[str, str],
                    directory: str | Path, stem: str = "validation") -> list[Path]:
    """Measured vs predicted force on held-out segments, per DOF where it moves the force most.

    The first of ``validations`` gives the measured force; all share the segments."""
    first = next(iter(validations.values()))
    figure = new_figure(figsize=(13, 9))
    axes = _grid(figure, 6, top=0.91)
    styles = ["-", "--", "-.", ":"]
    for c, axis in enumerate(axes.flat[:6]):
        energy: dict[int, float] = {}
        for segment, measured in zip(first.segments, first.measured, strict=True):
            energy[segment.experiment] = energy.get(segment.experiment, 0.0) + float(
                np.sum(measured[:, c] ** 2))
        chosen = max(energy, key=energy.__getitem__)
        picks = [k for k, s in enumerate(first.segments) if s.experiment == chosen]
        for n, k in enumerate(picks):
            segment = first.segments[k]
            step = thinning_step(segment.t, 1500)
            axis.plot(segment.t[step], first.measured[k][step, c], color="#999999", lw=2.2,
                      label="measured" if n == 0 else None)
            for m, (label, validation) in enumerate(validations.items()):
                axis.plot(segment.t[step], validation.predicted[k][step, c], lw=1.0,
                          ls=styles[m % len(styles)], color=colours[label],
                          label=f"{label} (VAF {validation.vaf_percent[c]:.2f} %)"
                          if n == 0 else None)
        axis.set_title(f"{COORDINATES[c]} equation, {first.segments[picks[0]].name.split('[')[0]}")
        axis.set_xlabel("time (s)")
        axis.set_ylabel(f"force ({FORCE_UNITS[c]})")
        # headroom for the legend's lines above the data, which it would otherwise hide
        low, high = axis.get_ylim()
        axis.set_ylim(low, high + (high - low) * (0.05 + 0.075 * (len(validations) + 1)))
        axis.legend(loc="upper right", fontsize=7, framealpha=0.9)
    figure.suptitle("Held-out data: measured generalized force and the identified model's "
                    "prediction (each segment predicted by the fit without it)")
    return save_figure(figure, directory, stem, tight=False)


@styled
def plot_unexplained(vaf: Mapping[str, np.ndarray], colours: Mapping[str, str],
                     directory: str | Path, stem: str = "methods") -> list[Path]:
    """Held-out unexplained force, 100 − VAF (%), per DOF and method (log scale).

    ``vaf``: label -> held-out VAF per DOF, shape (6,) (%)."""
    figure = new_figure(figsize=(9, 4))
    axis = figure.subplots(gridspec_kw={"left": 0.1, "right": 0.98, "bottom": 0.1,
                                        "top": 0.9})
    width = 0.8 / max(len(vaf), 1)
    x = np.arange(6)
    heights = {label: np.maximum(100.0 - np.asarray(values, dtype=float), 1e-5)
               for label, values in vaf.items()}
    for k, (label, values) in enumerate(heights.items()):
        axis.bar(x + (k - (len(vaf) - 1) / 2) * width, values, width, color=colours[label],
                 label=label)
    axis.set_yscale("log")
    _log_floor(axis, np.zeros(0), decades=None)
    every = np.concatenate([h[np.isfinite(h)] for h in heights.values()] or [np.ones(1)])
    if every.size:
        # whole decades: bars within one decade would otherwise leave the axis unlabelled
        axis.set_ylim(10.0 ** np.floor(np.log10(every.min() / 2)),
                      10.0 ** (np.floor(np.log10(every.max())) + 1))
    axis.set_xticks(x, COORDINATES)
    axis.set_ylabel("100 − VAF (%), held out")
    axis.set_title("Force the model does not explain on data it was not fitted on "
                   "(lower is better)")
    axis.legend(loc="best", framealpha=0.9)
    return save_figure(figure, directory, stem, tight=False)


@styled
def plot_friction(levels: Mapping[str, tuple[np.ndarray, np.ndarray]],
                  colours: Mapping[str, str], nominal: float | None, directory: str | Path,
                  stem: str = "friction") -> list[Path]:
    """Coulomb level per joint type, ±2 standard errors, per method that estimates it.

    ``levels``: label -> (levels, standard errors), shape (3,) each (N m); ``nominal``: the
    description's level, drawn as a line."""
    figure = new_figure(figsize=(7, 3.6))
    axis = figure.subplots(gridspec_kw={"left": 0.12, "right": 0.98, "bottom": 0.12,
                                        "top": 0.9})
    width = 0.8 / max(len(levels), 1)
    x = np.arange(len(FRICTION_TYPES))
    for k, (label, (value, std)) in enumerate(levels.items()):
        axis.bar(x + (k - (len(levels) - 1) / 2) * width, value, width, yerr=2 * std,
                 capsize=3, color=colours[label], label=label)
    if nominal is not None:
        axis.axhline(nominal, color="k", lw=0.8, ls="--", label="platform description")
    axis.set_xticks(x, [name.replace("_", " ") for name in FRICTION_TYPES])
    axis.set_ylabel("Coulomb level (N·m per joint axis)")
    axis.set_title("Coulomb friction per joint type, ±2 standard errors")
    axis.legend(loc="best", framealpha=0.9)
    return save_figure(figure, directory, stem, tight=False)


def _entry_scale(matrix: np.ndarray, entry: tuple[int, int]) -> float:
    """The scale an entry's change is shown against: sqrt(|m_ii m_jj|), 1 where zero."""
    scale = float(np.sqrt(abs(matrix[entry[0], entry[0]] * matrix[entry[1], entry[1]])))
    return scale if scale > 0 else 1.0


@styled
def plot_workspace(curves: Workspace, directory: str | Path, stem: str = "workspace"
                   ) -> list[Path]:
    """Mt and Bt across the measured poses, one column per swept coordinate.

    Diagonal and largest couplings as % change from the mean-pose value, ±2 standard errors, the
    description dashed; ``curves`` from :func:`~stewartid.comparison.workspace`."""
    from matplotlib.collections import LineCollection, PolyCollection
    from matplotlib.lines import Line2D

    figure = new_figure(figsize=(15, 6.5))
    axes = figure.subplots(2, 6, squeeze=False, gridspec_kw={
        "left": 0.05, "right": 0.86, "bottom": 0.1, "top": 0.9, "hspace": 0.4,
        "wspace": 0.35})
    colours = [f"C{k}" for k in range(10)]
    for row, (name, key) in enumerate((("Mt", "M"), ("Bt", "B"))):
        reference = getattr(curves.at_centre, key)[0]
        entries = [(i, i) for i in range(6)] + list(curves.couplings[key])
        nominal = curves.nominal_M if key == "M" else curves.nominal_B
        for dof in range(6):
            axis = axes[row, dof]
            unit, factor = DISPLACEMENT_UNITS[dof]
            x = (curves.grid[dof] - curves.centre[dof]) * factor
            found = curves.identified[dof]
            values, std = getattr(found, key), getattr(found, f"std_errors_{key}")
            shown, bands = [0.0], [0.0]
            polygons, lines = [], []
            for entry in entries:
                scale = 100.0 / _entry_scale(reference, entry)
                y = (values[:, entry[0], entry[1]] - reference[entry]) * scale
                band = 2.0 * std[:, entry[0], entry[1]] * scale
                # the outline fill_between draws: (x0, upper), lower forward, upper backward
                polygons.append(np.column_stack([np.r_[x[0], x, x[-1], x[::-1]],
                                                 np.r_[y[0] + band[0], y - band,
                                                       y[-1] + band[-1], (y + band)[::-1]]]))
                described = (nominal[dof, :, entry[0], entry[1]] - reference[entry]) * scale
                lines += [np.column_stack([x, y]), np.column_stack([x, described])]
                shown += [np.abs(y).max(), np.abs(described).max()]
                bands.append(float(np.median(band)))
            # one artist for the bands and one for the lines (each entry's curve, then its
            # description dashed; zorder of a line), not three per entry
            used = colours[:len(entries)]
            axis.add_collection(PolyCollection(polygons, facecolors=used, edgecolors=used,
                                               alpha=0.2, linewidths=0))
            axis.add_collection(LineCollection(
                lines, colors=np.repeat(used, 2), linewidths=[1.2, 0.9] * len(entries),
                linestyles=["-", "--"] * len(entries), zorder=2))
            # the curves set the scale; a band much wider than them runs off the panel
            limit = 1.2 * max(max(shown), float(np.median(bands))) or 1.0
            axis.set_ylim(-limit, limit)
            axis.set_xlabel(f"{COORDINATES[dof]} − mean ({unit})")
            axis.set_title(f"{name} along {COORDINATES[dof]}", fontsize=9)
            if dof == 0:
                axis.set_ylabel("change from the mean pose (%)")
        axes[row, -1].legend(
            [Line2D([], [], color=colour, lw=1.2) for colour in colours[:len(entries)]],
            [f"{name}[{COORDINATES[i]},{COORDINATES[j]}]" for i, j in entries],
            loc="center left", bbox_to_anchor=(1.05, 0.5), fontsize=7, framealpha=0.9)
    figure.suptitle("Physical model across the measured poses: band ±2 standard errors; "
                    "dashed: the platform description", fontsize=10)
    return save_figure(figure, directory, stem, tight=False)


__all__ = ["plot_friction", "plot_intervals", "plot_matrices", "plot_residuals",
           "plot_spectra", "plot_unexplained", "plot_validation", "plot_workspace"]
