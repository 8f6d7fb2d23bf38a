"""Tables, summary sentences, HTML and figures of the reproduction report and the shared reporting
parts, on constructed results whose errors are known exactly."""

from __future__ import annotations

import csv
import io
import os
import re

import numpy as np
import pytest

from stewartid.files import write_text_atomic
from stewartid.identification.result import IdentificationResult
from stewartid.model.linearization import nominal_matrices
from stewartid.reference.published import load_published
from stewartid.reports.drawing import ExperimentTrace, plot_joint_rates
from stewartid.reports.html import render_html
from stewartid.reports.tables import to_csv, to_markdown
from stewartid.reproduction.comparison import ComparisonResults, MethodRun
from stewartid.reproduction.figures import plot_errors, plot_force_budget
from stewartid.reproduction.report import (
    FigureEntry,
    fourier_summary,
    render_markdown,
    wavelet_summary,
)
from stewartid.reproduction.tables import build_tables, paper_table


@pytest.fixture(scope="module")
def nominal(paper):
    return nominal_matrices(paper)


def scaled(matrix: np.ndarray, entries: dict[tuple[int, int], float]) -> np.ndarray:
    """``matrix`` with chosen entries multiplied by (1 + fraction)."""
    out = matrix.copy()
    for (row, col), fraction in entries.items():
        out[row, col] *= 1 + fraction
    return out


def method_run(method: str, coulomb: float, M: np.ndarray, B: np.ndarray) -> MethodRun:
    """A run of ``method`` that found ``M`` and ``B`` (no standard errors)."""
    nan = np.full((6, 6), np.nan)
    return MethodRun(method, coulomb, IdentificationResult(M, B, nan, nan, 1.0,
                                                           np.zeros(6), method))


@pytest.fixture(scope="module")
def results(nominal):
    M0, B0 = nominal
    runs = (
        # Method B: 0.5 % on Mt(2,4) at 5 N·m, 0.8 % on Bt(1,1) at 30 N·m
        method_run("wavelet", 5.0, scaled(M0, {(1, 3): 0.005}), B0.copy()),
        method_run("wavelet", 30.0, M0.copy(), scaled(B0, {(0, 0): -0.008})),
        # Method A: accurate diagonal, biased Bt(3,3) and coupling at 5 N·m
        method_run("fourier", 5.0, scaled(M0, {(0, 0): 0.001, (4, 0): -0.1}),
                   scaled(B0, {(2, 2): 0.4})),
        # ... and a run where the diagonal is the worst entry
        method_run("fourier", 0.0, scaled(M0, {(3, 3): 0.05}), B0.copy()),
    )
    return ComparisonResults(runs, M0, B0, load_published(), {"seed": 3, "quick": True})


def test_paper_table_sets_ours_beside_the_published(results, nominal):
    table = paper_table(results, 4)
    assert table.column("Parameter")[:2] == ["Mt(1,1)", "Mt(2,2)"]
    assert len(table.rows) == 10  # Table 4 holds Mt only
    row = dict(zip(table.columns, table.rows[7], strict=True))  # Mt(2,4)
    assert row["Parameter"] == "Mt(2,4)"
    assert row["B: ε ours (%)"] == pytest.approx(0.5)
    assert row["B: paper"] == -1178 and row["B: ε paper (%)"] == 7.5
    assert row["A: ε paper (%)"] == 14.0
    assert row["Nominal (ours)"] == pytest.approx(nominal[0][1, 3])
    assert row["Nominal (paper)"] == -1096
    # Table 6 notes the corrected sign typos
    notes = " ".join(paper_table(results, 6).notes)
    assert "Bt(2,4)" in notes and "typo" in notes


def test_tables_round_trip_through_csv_and_markdown(results):
    tables = build_tables(results)
    names = [t.name for t in tables]
    assert names == ["summary", "table3", "table4", "table5", "table6",
                     "comparison_coulomb0", "comparison_coulomb5", "comparison_coulomb30"]
    for table in tables:
        rows = list(csv.reader(io.StringIO(to_csv(table))))
        assert tuple(rows[0]) == table.columns and len(rows) == len(table.rows) + 1
        text = to_markdown(table)
        assert text.count("\n| ") == len(table.rows) + 2  # header, rule, rows
    # a run that is missing shows as a dash, not as a number
    table3 = to_markdown(paper_table(results, 3))
    assert "| Mt(4,4) | kg·m² | 52,724.6 | 5.00 | 50,325 | 0.1 |" in table3


def test_wavelet_summary_states_our_numbers_against_the_paper(results):
    lines = wavelet_summary(results)
    assert len(lines) == 2
    assert "0.50 % (Mt(2,4))" in lines[0] and "within the 1 % target" in lines[0]
    assert "7.5 % (Mt(2,4))" in lines[0] and "15× smaller" in lines[0]
    assert "0.80 % (Bt(1,1))" in lines[1] and "5.8 %" in lines[1]


def test_fourier_summary_checks_the_pattern_both_ways(results):
    at_zero, at_five = fourier_summary(results)
    assert "diagonal Mt up to 0.10 % (Mt(1,1); paper 0.7 %)" in at_five
    assert "Mt couplings up to 10.00 % (Mt(5,1)" in at_five
    assert "Bt up to 40.00 % (Bt(3,3); paper 70.6 %)" in at_five
    assert "pattern holds" in at_five and "400× larger" in at_five
    # without Coulomb friction no pattern is claimed
    assert "pattern" not in at_zero and "5.00 % (Mt(4,4)" in at_zero
    diagonal_worst = ComparisonResults(
        (method_run("fourier", 5.0, scaled(results.nominal_M, {(3, 3): 0.05}),
                    results.nominal_B.copy()),), results.nominal_M, results.nominal_B,
        results.published)
    assert "does not show" in fourier_summary(diagonal_worst)[0]


def test_html_is_self_contained(tmp_path, results):
    figure = tmp_path / "figures" / "dot.png"
    figure.parent.mkdir()
    figure.write_bytes(b"\x89PNG\r\n\x1a\nfake")
    text = render_markdown(results, build_tables(results)[:2],
                           [FigureEntry("figures/dot.png", "A dot")])
    assert "![A dot](figures/dot.png)" in text and "## Notes on the published values" in text
    page = render_html(text, tmp_path)
    assert "data:image/png;base64,iVBORw0KGgpmYWtl" in page
    assert "<table>" in page and "figures/dot.png" not in page


def test_atomic_write_leaves_no_temporary_and_usual_permissions(tmp_path):
    path = write_text_atomic(tmp_path / "a" / "b.md", "text")
    assert path.read_text() == "text"
    assert [p.name for p in path.parent.iterdir()] == ["b.md"]
    umask = os.umask(0)
    os.umask(umask)
    assert path.stat().st_mode & 0o777 == 0o666 & ~umask


def _trace() -> ExperimentTrace:
    t = np.linspace(0.0, 4.0, 2001)
    w = np.pi
    pose = np.zeros((len(t), 6))
    pose[:, 0] = 0.02 * np.sin(w * t)
    rates = np.tile(np.cos(w * t)[:, None], (1, 36)) * np.linspace(-1, 1, 36) * 0.01
    forces = {"inertial": -14224 * w ** 2 * pose, "viscous": 4140 * 0.02 * w
              * np.cos(w * t)[:, None] * np.eye(6)[0], "coulomb": 30 * np.sign(
                  np.cos(w * t))[:, None] * np.ones(6), "gravity": np.zeros((len(t), 6))}
    forces["actuators"] = sum(forces.values())
    intervals = np.array([[0.52, 1.48], [1.52, 2.48], [2.52, 3.48]])
    return ExperimentTrace("exp1", 0, t, pose, np.zeros(6), pose.copy(), rates, intervals,
                           forces)


@pytest.mark.slow
def test_signal_figures_are_written(tmp_path):
    trace = _trace()
    for paths in (plot_joint_rates(trace, tmp_path), plot_force_budget(trace, tmp_path)):
        assert [p.suffix for p in paths] == [".png", ".svg"]
        assert paths[0].read_bytes().startswith(b"\x89PNG") and paths[1].stat().st_size > 1000
    svg = (tmp_path / "force_budget.svg").read_text()
    for label in ("inertial", "Coulomb joint friction", "sum of model terms", "time (s)"):
        assert label in svg
    bare = ExperimentTrace("exp2", 1, trace.t, trace.pose, np.zeros(6))
    with pytest.raises(ValueError, match="has no joint rates"):
        plot_joint_rates(bare, tmp_path)


@pytest.mark.slow
def test_error_figure_has_units_and_legends(tmp_path, results):
    png, svg = plot_errors(results, tmp_path)
    text = svg.read_text()
    assert "ε (%)" in text and "Method B (wavelet), paper" in text and "Mt(2,4)" in text
    assert png.stat().st_size > 20_000


def test_held_out_figure_labels_its_axis_when_the_bars_share_a_decade(tmp_path):
    """Every method leaving 0.01-0.09 % unexplained: the log axis spans whole decades, so it
    carries labelled ticks (with the minor ticks off for speed, bars within one decade had
    none), and the smallest bar stands above the axis's floor."""
    from stewartid.reports.identification.method_figures import plot_unexplained

    vaf = {"a": np.array([99.99, 99.98, 99.92, 99.925, 99.91, 99.93]),
           "b": np.array([99.98, 99.99, 99.91, 99.92, 99.92, 99.92])}
    paths = plot_unexplained(vaf, {"a": "C3", "b": "C2"}, tmp_path)
    svg = next(p for p in paths if p.suffix == ".svg").read_text()
    labels = {float(text) for text in re.findall(r">([0-9][0-9.]*)</text>", svg)}
    assert {0.001, 0.01, 0.1} <= labels


def _panels(scale: float, layout: str | None = None):
    """A two-panel figure with long titles, a legend and data of magnitude ``scale``."""
    import matplotlib

    from stewartid.reports.drawing import STYLE, new_figure

    with matplotlib.rc_context(STYLE):
        figure = new_figure(figsize=(6, 2.5), layout=layout)
        for k, axis in enumerate(figure.subplots(1, 2)):
            axis.plot(np.linspace(0, 1, 50), scale * (1 + np.sin(np.linspace(0, 6, 50)) / 3),
                      label="a line")
            axis.set_title(f"panel {k}: a title as wide as the panel above its data")
            axis.legend(loc="upper right")
    return figure


def _pixels(path_or_buffer) -> np.ndarray:
    from PIL import Image

    return np.asarray(Image.open(path_or_buffer).convert("RGBA"))


@pytest.mark.parametrize("scale, layout, tight", [(1.0, None, False), (1e-6, None, False),
                                                 (1.0, None, True), (1.0, "constrained", True)])
def test_saved_figures_match_matplotlibs_own_placement(tmp_path, scale, layout, tight):
    """The one layout pass, the one tight box and the pinned titles draw the pixels matplotlib's
    own savefig draws: titles at the top, raised over an offset text (×1e−6), the same crop."""
    import matplotlib

    from stewartid.reports.drawing import STYLE, save_figure

    png, svg = save_figure(_panels(scale, layout), tmp_path, "ours", tight=tight)
    reference = io.BytesIO()
    with matplotlib.rc_context(STYLE):
        _panels(scale, layout).savefig(reference, format="png", dpi=120,
                                       bbox_inches="tight" if tight else None)
    np.testing.assert_array_equal(_pixels(png), _pixels(reference))
    assert svg.read_text().rstrip().endswith("</svg>")


def test_saved_figures_are_the_same_bytes_from_run_to_run(tmp_path):
    from xml.etree import ElementTree

    from stewartid.reports.drawing import save_figure

    first = save_figure(_panels(1.0), tmp_path / "one", "figure")
    second = save_figure(_panels(1.0), tmp_path / "two", "figure")
    for a, b in zip(first, second, strict=True):
        assert a.read_bytes() == b.read_bytes(), a.name
    assert "clip-path" in first[1].read_text()  # clip ids are in the file, and stable
    assert ElementTree.parse(first[1]).getroot().tag.endswith("svg")
