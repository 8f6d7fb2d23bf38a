"""The figures' common parts: style, saving (PNG and SVG), an experiment's signal figures.
Figures are drawn inside ``rc_context(STYLE)`` without pyplot; matplotlib is imported lazily."""

from __future__ import annotations

import functools
import io
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from stewartid.files import write_bytes_atomic
from stewartid.platform import COORDINATES

#: Display unit and scale of a displacement in each coordinate.
_DISPLAY = (("mm", 1e3),) * 3 + (("mrad", 1e3),) * 3

#: matplotlib settings of every figure, applied with ``matplotlib.rc_context``.
STYLE = {"font.size": 10, "axes.titlesize": 11, "axes.labelsize": 10, "legend.fontsize": 9,
         "svg.fonttype": "none", "axes.grid": True, "grid.alpha": 0.3}

@dataclass(frozen=True)
class ExperimentTrace:
    """Signals of one experiment, ready to plot.

    Attributes
    ----------
    name : str
    excited : int
        Index (0-5) of the excited coordinate.
    t : ndarray, shape (N,)
        s.
    pose, reference : ndarray, shape (N, 6)
        Measured and commanded pose (m, rad); ``reference`` optional.
    neutral : ndarray, shape (6,)
        Neutral pose, displacements are plotted from it (m, rad).
    joint_rates : ndarray, shape (N, 36), optional
        30 rotational joint-axis rates (rad/s), then 6 actuator rates (m/s).
    intervals : ndarray, shape (M, 2), optional
        Constant-direction intervals [start, stop] (s).
    forces : dict of ndarray, shape (N, 6)
        Generalized force components by name (``"inertial"``, ``"gravity"``, ...) (N, N m).
    """

    name: str
    excited: int
    t: np.ndarray
    pose: np.ndarray
    neutral: np.ndarray
    reference: np.ndarray | None = None
    joint_rates: np.ndarray | None = None
    intervals: np.ndarray | None = None
    forces: dict[str, np.ndarray] = field(default_factory=dict)


def styled(plot: Callable[..., list[Path]]) -> Callable[..., list[Path]]:
    """Draw and save inside ``rc_context(STYLE)``: the caller's settings are untouched."""

    @functools.wraps(plot)
    def wrapper(*args: Any, **kwargs: Any) -> list[Path]:
        import matplotlib

        with matplotlib.rc_context(STYLE):
            return plot(*args, **kwargs)

    return wrapper


def new_figure(**options: Any) -> Any:
    """A new :class:`matplotlib.figure.Figure` (not registered with pyplot)."""
    from matplotlib.figure import Figure

    return Figure(**options)


def save_figure(figure: Any, directory: str | Path, stem: str, dpi: int = 120,
                tight: bool = True) -> list[Path]:
    """Write ``figure`` as ``stem.png`` and ``stem.svg`` in ``directory`` (atomic); returns both paths.

    ``tight`` crops to the drawn content (the figure keeps the layout it was saved with); False
    keeps a fixed-margin layout and saves a layout pass."""
    import matplotlib

    directory = Path(directory)
    box = None
    if tight:
        box = _freeze_layout(figure, dpi)
    else:
        _pin_titles(figure)
        _park_empty_labels(figure)
    paths = []
    # metadata dates off and clip ids from a fixed salt: the same run gives the same files
    options = {"png": {"metadata": {"Software": None}, "pil_kwargs": {"compress_level": 3}},
               "svg": {"metadata": {"Date": None}}}
    for kind in ("png", "svg"):
        buffer = io.BytesIO()
        with matplotlib.rc_context({"svg.hashsalt": "stewartid"}):
            figure.savefig(buffer, format=kind, dpi=dpi, bbox_inches=box, **options[kind])
        paths.append(write_bytes_atomic(directory / f"{stem}.{kind}", buffer.getvalue()))
    return paths


def _freeze_layout(figure: Any, dpi: int) -> Any:
    """Lay ``figure`` out once at the PNG's ``dpi`` and keep that layout for every format, titles
    pinned; returns the box of the drawn content, padded (inches).

    A layout engine otherwise lays the figure out again at every save, and ``bbox_inches="tight"``
    draws it once more to find the box."""
    import matplotlib

    figure.set_dpi(dpi)
    engine = figure.get_layout_engine()
    if engine is not None:
        engine.execute(figure)
    _pin_titles(figure)
    box = figure.get_tightbbox().padded(matplotlib.rcParams["savefig.pad_inches"])
    figure.set_layout_engine("none")
    return box


def _pin_titles(figure: Any) -> None:
    """Fix every title at the top of its axes, where matplotlib places it anyway unless an axes
    has tick labels on top or an offset text (such as ×1e−5) on its y axis; the automatic
    placement measures every y tick label again at each draw."""
    for axes in figure.axes:
        if (axes.xaxis.get_tick_params().get("labeltop", True)
                or axes.xaxis.get_label_position() == "top"):
            return
        formatter = axes.yaxis.get_major_formatter()
        formatter.set_locs(axes.yaxis.get_majorticklocs())
        if formatter.get_offset():
            return
    for axes in figure.axes:
        title = axes.title
        if title.get_text():
            axes.set_title(title.get_text(), y=1.0, fontsize=title.get_fontsize(),
                           fontweight=title.get_fontweight(), color=title.get_color())


def _park_empty_labels(figure: Any) -> None:
    """Place every empty axis label at its axes' corner: matplotlib would otherwise measure the
    tick labels at each draw to place a label that draws nothing. Only where no tight box is
    sought, which would take in the empty label's point."""
    for axes in figure.axes:
        for axis in (axes.xaxis, axes.yaxis):
            if not axis.label.get_text():
                axis.set_label_coords(0.0, 0.0)


def thinning_step(t: np.ndarray, max_points: int = 4000) -> slice:
    """Sample step keeping about ``max_points`` points of a line (small, fast SVG files)."""
    return slice(None, None, max(1, int(np.ceil(len(t) / max_points))))


def _shade_intervals(axis: Any, intervals: np.ndarray | None, label: bool) -> None:
    if intervals is None:
        return
    for k, (start, stop) in enumerate(intervals):
        axis.axvspan(start, stop, color="#9ecae1", alpha=0.35, lw=0,
                     label="constant-direction interval" if (label and k == 0) else None)


@styled
def plot_excitation(traces: Sequence[ExperimentTrace], directory: str | Path,
                    stem: str = "excitation") -> list[Path]:
    """Commanded and measured motion of each experiment's excited coordinate, with tracking error."""
    count = len(traces)
    columns = min(3, count)
    rows = int(np.ceil(count / columns))
    figure = new_figure(figsize=(4.6 * columns, 3.2 * rows), layout="constrained")
    axes = figure.subplots(rows, columns, squeeze=False)
    for axis, trace in zip(axes.flat, traces, strict=False):
        k = trace.excited
        unit, scale = _DISPLAY[k]
        step = thinning_step(trace.t)
        t = trace.t[step]
        measured = (trace.pose[step, k] - trace.neutral[k]) * scale
        axis.plot(t, measured, color="k", lw=1.2, label="measured")
        if trace.reference is not None:
            commanded = (trace.reference[step, k] - trace.neutral[k]) * scale
            axis.plot(t, commanded, color="#d62728", lw=1.0, ls="--", label="commanded")
            error_axis = axis.twinx()
            error_axis.plot(t, measured - commanded, color="#2ca02c", lw=0.6,
                            label="tracking error")
            error_axis.set_ylabel(f"tracking error ({unit})", color="#2ca02c")
            error_axis.tick_params(axis="y", colors="#2ca02c")
            error_axis.grid(False)
            handles = axis.get_legend_handles_labels()
            extra = error_axis.get_legend_handles_labels()
            axis.legend(handles[0] + extra[0], handles[1] + extra[1], loc="lower left",
                        framealpha=0.9)
        else:
            axis.legend(loc="lower left")
        axis.set_title(f"{trace.name}: {COORDINATES[k]} excited")
        axis.set_xlabel("time (s)")
        axis.set_ylabel(f"{COORDINATES[k]} − neutral ({unit})")
    for axis in list(axes.flat)[count:]:
        axis.set_visible(False)
    figure.suptitle("Excitation: one sine per experiment, commanded and measured")
    return save_figure(figure, directory, stem)


@styled
def plot_joint_rates(trace: ExperimentTrace, directory: str | Path,
                     stem: str = "joint_velocities") -> list[Path]:
    """Rates of one experiment's 30 rotational joint axes and 6 actuators, intervals shaded.

    Raises
    ------
    ValueError
        ``trace`` has no joint rates.
    """
    if trace.joint_rates is None:
        raise ValueError(f"trace {trace.name!r} has no joint rates to plot")
    figure = new_figure(figsize=(9, 6), layout="constrained")
    top, bottom = figure.subplots(2, 1, sharex=True)
    step = thinning_step(trace.t)
    t = trace.t[step]
    rotational = trace.joint_rates[step, :30]
    from matplotlib import colormaps

    axis_colours = colormaps["viridis"](np.linspace(0, 0.9, 5))
    names = ("lower gimbal 1", "lower gimbal 2", "upper gimbal 1", "upper gimbal 2", "revolute")
    for axis_index in range(5):
        columns = rotational[:, axis_index::5] * 1e3
        for leg in range(6):
            top.plot(t, columns[:, leg], color=axis_colours[axis_index], lw=0.8,
                     label=names[axis_index] + " (6 legs)" if leg == 0 else None)
    _shade_intervals(top, trace.intervals, label=True)
    top.axhline(0, color="k", lw=0.6)
    top.set_ylabel("joint axis rate (mrad/s)")
    top.set_title(f"{trace.name}: joint velocities; shaded: no joint reverses "
                  f"({0 if trace.intervals is None else len(trace.intervals)} intervals)")
    top.legend(loc="upper right", ncol=2, framealpha=0.9)
    for leg in range(6):
        bottom.plot(t, trace.joint_rates[step, 30 + leg] * 1e3, lw=0.9, label=f"leg {leg + 1}")
    _shade_intervals(bottom, trace.intervals, label=False)
    bottom.axhline(0, color="k", lw=0.6)
    bottom.set_ylabel("actuator rate (mm/s)")
    bottom.set_xlabel("time (s)")
    bottom.legend(loc="upper right", ncol=3, framealpha=0.9)
    return save_figure(figure, directory, stem)


__all__ = [
    "STYLE",
    "ExperimentTrace",
    "new_figure",
    "plot_excitation",
    "plot_joint_rates",
    "save_figure",
    "styled",
    "thinning_step",
]
