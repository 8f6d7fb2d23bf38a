"""``stewartid identify`` end to end on small synthetic data and on bad input."""

from __future__ import annotations

import json

import numpy as np
import pytest
from typer.testing import CliRunner

from linear_model_data import make_experiment, random_matrices
from stewartid.cli import app
from stewartid.dataset import write_dataset


@pytest.fixture(scope="module")
def files(tmp_path_factory, paper):
    folder = tmp_path_factory.mktemp("data")
    M, B = random_matrices(np.random.default_rng(11))
    paths = [write_dataset(make_experiment(paper, M, B, k), folder / f"exp{k + 1}.csv")
             for k in range(6)]
    (folder / "meta.json").write_text(json.dumps({"nominal": {"M": M.tolist(),
                                                              "B": B.tolist()}}))
    return paths, M, B


@pytest.mark.parametrize("method", ["fourier", "ls"])
def test_identify_writes_json_and_prints_table(tmp_path, files, method):
    paths, M, B = files
    out = tmp_path / "result.json"
    result = CliRunner().invoke(app, ["identify", "--method", method, "--platform", "paper",
                                      "--out", str(out), *map(str, paths)])
    assert result.exit_code == 0, result.output
    assert "Mt(2,4)" in result.output and "meta.json" in result.output
    document = json.loads(out.read_text())
    assert np.asarray(document["M"]) == pytest.approx(M, abs=1e-3 * np.abs(M).max())
    assert np.asarray(document["B"]) == pytest.approx(B, abs=1e-3 * np.abs(B).max())
    assert document["method"] == method


def test_bad_input_is_one_line(tmp_path, files):
    paths, _, _ = files
    bad = tmp_path / "bad.csv"
    bad.write_text("t,x\n0,1\n")
    result = CliRunner().invoke(app, ["identify", "--method", "fourier", str(bad)])
    assert result.exit_code == 2
    lines = result.output.strip().splitlines()
    assert len(lines) == 1 and "missing required column" in lines[0]


def test_rank_deficiency_is_one_line(files):
    paths, _, _ = files
    result = CliRunner().invoke(app, ["identify", "--method", "ls", *map(str, paths[:5])])
    assert result.exit_code == 2
    assert "DOF rz was never excited" in result.output


def test_unknown_method(files):
    paths, _, _ = files
    result = CliRunner().invoke(app, ["identify", "--method", "magic", str(paths[0])])
    assert result.exit_code == 2
    assert "unknown method 'magic'" in result.output
