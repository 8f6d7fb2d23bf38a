"""``stewartid identify`` end to end on small synthetic data and on bad input."""

from __future__ import annotations

import json

import numpy as np
import pytest
from typer.testing import CliRunner

from linear_model_data import make_experiment, random_matrices
from stewartid.cli import app
from stewartid.datasets.dataset import write_dataset


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
    # the title names the nominal's source; a long path wraps at the table's width
    assert "Mt(2,4)" in result.output and "meta.json" in result.output.replace("\n", "")
    document = json.loads(out.read_text())
    assert np.asarray(document["M"]) == pytest.approx(M, abs=1e-3 * np.abs(M).max())
    assert np.asarray(document["B"]) == pytest.approx(B, abs=1e-3 * np.abs(B).max())
    assert document["method"] == method


def test_bad_input_is_one_line(tmp_path, files):
    paths, _, _ = files
    bad = tmp_path / "bad.csv"
    bad.write_text("t,x\n0,1\n")
    result = CliRunner().invoke(app, ["identify", "--method", "fourier", "--platform", "paper",
                                      str(bad)])
    assert result.exit_code == 2
    lines = result.output.strip().splitlines()
    assert len(lines) == 1 and "missing required column" in lines[0]


def test_an_unexcited_dof_is_one_line(files):
    paths, _, _ = files
    result = CliRunner().invoke(app, ["identify", "--method", "ls", "--platform", "paper",
                                      *map(str, paths[:5])])
    assert result.exit_code == 2
    lines = result.output.strip().splitlines()
    assert len(lines) == 1 and "no experiment moves rz enough" in lines[0]


def test_unknown_method(files):
    paths, _, _ = files
    result = CliRunner().invoke(app, ["identify", "--method", "magic", str(paths[0])])
    assert result.exit_code == 2
    assert "unknown method 'magic'" in result.output


def test_methods_lists_every_registered_method_with_its_reference():
    result = CliRunner().invoke(app, ["methods"])
    assert result.exit_code == 0, result.output
    lines = result.output.strip().splitlines()
    names = [line.split(":")[0] for line in lines]
    assert names[:3] == ["wavelet", "fourier", "ls"] and "wavelet-paper" in names
    assert "doi:10.3390/math8020257" in lines[0] and "Khalil" in lines[2]


def test_option_of_another_method_is_a_config_error(files):
    paths, _, _ = files
    result = CliRunner().invoke(app, ["identify", "--method", "ls", "--frequency", "1",
                                      str(paths[0])])
    assert result.exit_code == 2
    assert "--frequency does not apply to --method ls" in result.output


def test_a_bug_shows_its_traceback(monkeypatch, files):
    """Only StewartidError and OSError become one line; anything else is a bug."""
    import stewartid.identification.registry as registry

    def broken(name, **settings):
        raise ZeroDivisionError("a bug")

    monkeypatch.setattr(registry, "create_identifier", broken)
    paths, _, _ = files
    result = CliRunner().invoke(app, ["identify", "--method", "ls", "--platform", "paper",
                                      *map(str, paths)])
    assert result.exit_code == 1
    assert isinstance(result.exception, ZeroDivisionError)


def test_debug_shows_the_traceback_of_expected_errors(files):
    paths, _, _ = files
    result = CliRunner().invoke(app, ["--debug", "identify", "--method", "magic", str(paths[0])])
    assert result.exit_code == 1
    assert "unknown method 'magic'" in str(result.exception)


@pytest.mark.slow
def test_friction_option_reaches_method_b(tmp_path, example_dir, example_truth):
    """``--friction uniform`` (what ``stewartid design`` predicts for) ties the interval
    constants to one Coulomb level: on the independent example it is the simulator's 10 N m."""
    out = tmp_path / "uniform.json"
    files = sorted(map(str, example_dir.glob("exp*.csv")))
    result = CliRunner().invoke(app, ["identify", "--method", "wavelet", "--friction",
                                      "uniform", "--platform",
                                      str(example_dir / "platform.toml"), "--out", str(out),
                                      *files])
    assert result.exit_code == 0, result.output
    document = json.loads(out.read_text())
    assert document["settings"]["friction"] == "uniform"
    levels = set(document["diagnostics"]["coulomb"].values())
    assert len(levels) == 1
    assert levels.pop() == pytest.approx(example_truth["coulomb"], rel=0.02)
    bad = CliRunner().invoke(app, ["identify", "--method", "wavelet", "--friction", "viscous",
                                   "--platform", str(example_dir / "platform.toml"), *files])
    assert bad.exit_code == 2 and len(bad.output.strip().splitlines()) == 1
    assert "'friction'" in bad.output and "'uniform'" in bad.output
    other = CliRunner().invoke(app, ["identify", "--method", "ls", "--friction", "uniform",
                                     *files])
    assert other.exit_code == 2 and "--friction does not apply to --method ls" in other.output
