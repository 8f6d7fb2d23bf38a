"""``stewartid reproduce --quick`` end to end: every table, figure and the report are written
and results.json holds finite values in the expected ranges."""

from __future__ import annotations

import csv
import json
import math

import numpy as np
import pytest
from typer.testing import CliRunner

from stewartid.cli import app
from stewartid.errors import ConfigError
from stewartid.model.linearization import nominal_matrices
from stewartid.reproduction.document import load_results
from stewartid.reproduction.settings import default_methods, make_settings

LEVELS = (0, 5, 30)
TABLES = ["summary", "table3", "table4", "table5", "table6"] + [
    f"comparison_coulomb{level}" for level in LEVELS] + ["comparison_coulomb30_noisy"]
FIGURES = ["excitation", "joint_velocities", "force_budget", "scalogram", "errors"] + [
    f"identified_vs_nominal_coulomb{level}" for level in LEVELS] + [
    "identified_vs_nominal_noisy"]


@pytest.fixture(scope="module")
def quick_run(tmp_path_factory):
    """One quick run through the command line (about 20-30 s on two cores)."""
    out = tmp_path_factory.mktemp("reproduce") / "out"
    result = CliRunner().invoke(app, ["reproduce", "--quick", "--out", str(out), "--jobs", "2"])
    assert result.exit_code == 0, result.output
    return out, result.output


@pytest.mark.slow
def test_every_file_is_written(quick_run):
    out, output = quick_run
    assert "wrote" in output and "Method B (wavelet)" in output
    for name in TABLES:
        for suffix in ("md", "csv"):
            path = out / "tables" / f"{name}.{suffix}"
            assert path.stat().st_size > 100, path
    for name in FIGURES:
        png = (out / "figures" / f"{name}.png").read_bytes()
        assert png.startswith(b"\x89PNG") and len(png) > 10_000, name
        svg = (out / "figures" / f"{name}.svg").read_text()
        assert "<svg" in svg, name
    report = (out / "report.md").read_text()
    for name in FIGURES:
        assert f"figures/{name}.png" in report
    assert "Table 4" in report and "## Summary" in report
    html = (out / "report.html").read_text()
    assert html.count("data:image/png;base64,") == len(FIGURES)
    assert not list(out.rglob("*.tmp")), "temporary files left behind"


@pytest.mark.slow
def test_results_json_holds_finite_values_in_range(quick_run, paper):
    out, _ = quick_run
    document = json.loads((out / "results.json").read_text())
    assert document["settings"]["quick"] is True and document["seed"] == 0
    assert document["version"] and 0 < document["runtime_s"] < 600
    M0, B0 = nominal_matrices(paper)
    np.testing.assert_allclose(document["nominal"]["M"], M0, rtol=1e-12)
    np.testing.assert_allclose(document["nominal"]["B"], B0, rtol=1e-12)
    runs = {(r["method"], r["coulomb"]) for r in document["runs"]}
    assert runs == {(m, float(c)) for m in default_methods() for c in LEVELS}
    for run in document["runs"]:
        M, B = np.asarray(run["M"]), np.asarray(run["B"])
        assert M.shape == B.shape == (6, 6)
        assert np.all(np.isfinite(M)) and np.all(np.isfinite(B))
        assert len(run["eps"]) == 20 and all(math.isfinite(v) for v in run["eps"].values())
        # even on 6 s records every method finds the diagonal of Mt within 25 % ...
        assert np.all(np.abs(np.diag(M) / np.diag(M0) - 1) < 0.25), run["method"]
        # ... and ε is what the matrices say
        assert run["eps"]["Mt(4,4)"] == pytest.approx(abs(M[3, 3] / M0[3, 3] - 1) * 100)
        assert run["max_eps"] == pytest.approx(max(run["eps"].values()))
        assert run["seconds"] > 0
    published = [r["published"] for r in document["runs"] if r["published"]]
    assert len(published) == 4  # A at 0 and 5 N·m, B at 5 and 30 N·m
    # the paper's own Table 5 value travels with the run it belongs to
    fourier5 = next(r for r in document["runs"] if (r["method"], r["coulomb"]) == ("fourier", 5))
    assert fourier5["published"]["Bt(3,3)"] == {"value": 3478.0, "eps": 70.6}


@pytest.mark.slow
def test_noisy_case_is_reported(quick_run, paper):
    out, output = quick_run
    document = json.loads((out / "results.json").read_text())
    case = document["noise_case"]
    assert case["coulomb"] == 30.0 and case["noise_scale"] == 1.0
    assert {r["method"] for r in case["runs"]} == set(default_methods())
    M0, B0 = nominal_matrices(paper)
    clean = {r["method"]: r for r in document["runs"] if r["coulomb"] == 30.0}
    for run in case["runs"]:
        M, B = np.asarray(run["M"]), np.asarray(run["B"])
        # the records really are other ones: noise moves every method's estimate
        assert not np.allclose(M, clean[run["method"]]["M"], rtol=1e-9, atol=0)
        # the count of entries within three standard errors, recomputed here
        within = 0
        for label, (matrix, truth, std) in {"M": (M, M0, run["std_errors_M"]),
                                            "B": (B, B0, run["std_errors_B"])}.items():
            for i, j in ((0, 0), (1, 1), (2, 2), (3, 3), (4, 4), (5, 5), (0, 4), (1, 3),
                         (3, 1), (4, 0)):
                within += abs(matrix[i, j] - truth[i, j]) <= 3 * np.asarray(std)[i, j]
                eps = abs(matrix[i, j] / truth[i, j] - 1) * 100
                assert run["eps"][f"{label}t({i + 1},{j + 1})"] == pytest.approx(eps)
        assert run["within_3_std"] == within
    assert "reference sensor noise" in output and case["summary"] in document["summary"]


@pytest.mark.slow
def test_results_reload_and_tables_agree(quick_run):
    out, _ = quick_run
    results = load_results(out / "results.json")
    assert results.coulomb_levels == (0.0, 5.0, 30.0)
    run = results.run("wavelet", 5.0)
    with open(out / "tables" / "table4.csv", newline="", encoding="utf-8") as stream:
        rows = list(csv.DictReader(stream))
    assert [row["Parameter"] for row in rows][:2] == ["Mt(1,1)", "Mt(2,2)"]
    assert float(rows[0]["B: ours"]) == pytest.approx(run.result.M[0, 0])
    assert float(rows[0]["B: paper"]) == 14242.0


def test_refuses_a_non_empty_folder(tmp_path):
    (tmp_path / "keep.txt").write_text("user data")
    result = CliRunner().invoke(app, ["reproduce", "--quick", "--out", str(tmp_path)])
    assert result.exit_code == 2
    assert "not empty" in result.output and "--force" in result.output
    assert (tmp_path / "keep.txt").read_text() == "user data"


def test_settings_are_validated():
    assert make_settings(quick=True, jobs=1).duration_s < make_settings(jobs=1).duration_s
    with pytest.raises(ConfigError, match="jobs must be a positive integer"):
        make_settings(jobs=0)
    with pytest.raises(ConfigError, match="unknown method"):
        make_settings(methods=["magic"])
    with pytest.raises(ConfigError, match="coulomb_levels must be non-negative"):
        make_settings(coulomb_levels=[-5.0])
    with pytest.raises(ConfigError, match="seed must be a non-negative integer"):
        make_settings(seed=-1)
