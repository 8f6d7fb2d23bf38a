"""Input protection: physical ranges of the platform description, TOML encodings, one-line
usage errors and warnings, safe output files, the required platform, and jittery time
stamps measured on the independent example."""

from __future__ import annotations

import dataclasses
import json
import re

import numpy as np
import pandas as pd
import pytest
from typer.testing import CliRunner

from linear_model_data import make_experiment, random_matrices
from stewartid.cli import app
from stewartid.datasets.dataset import dataset_from_frame, read_datasets, write_dataset
from stewartid.errors import ConfigError, DataWarning
from stewartid.fields import Interval, ListOf, field_spec
from stewartid.platform import load_platform
from stewartid.platform.description import SECTIONS

# -- the platform description ----------------------------------------------------------------

def test_every_number_of_every_section_has_a_physical_range():
    for name, section in SECTIONS.items():
        for field in dataclasses.fields(section):
            if "float" in str(field.type) or "tuple" in str(field.type):
                constraint = field_spec(field).constraint
                interval = constraint.item if isinstance(constraint, ListOf) else constraint
                assert isinstance(interval, Interval) and interval.physical, (name, field.name)


@pytest.mark.parametrize("old, new, message", [
    ("platform_mass = 8000.0", "platform_mass = 1e300",
     r"\[inertia\] platform_mass = 1e\+300 kg is outside the physical range 0.01 to 1e\+06 kg"),
    ("upper_radius = 1.8", "upper_radius = 1800.0",
     r"\[geometry\] upper_radius = 1800 m is outside the physical range 0.01 to 50 m; check "
     r"its unit"),
    ("platform_inertia = [20000.0, 21000.0, 30000.0]", "platform_inertia = [2e4, 2.1e4, 3e12]",
     r"\[inertia\] platform_inertia\[2\] = 3e\+12 kg m\^2 is outside"),
])
def test_numbers_outside_their_physical_range_name_the_key(tmp_path, example_dir, old, new,
                                                           message):
    text = (example_dir / "platform.toml").read_text()
    assert old in text
    path = tmp_path / "hexapod.toml"
    path.write_text(text.replace(old, new))
    with pytest.raises(ConfigError, match="hexapod.toml: " + message):
        load_platform(path)


def test_platform_file_in_millimetres_is_refused(tmp_path, example_dir):
    text = (example_dir / "platform.toml").read_text()
    for key, metres in (("upper_radius", "1.8"), ("lower_radius", "2.2"),
                        ("neutral_height", "2.0"), ("reference_height", "1.0"),
                        ("upper_leg_com", "0.8"), ("lower_leg_com", "0.8")):
        text = text.replace(f"{key} = {metres}\n", f"{key} = {float(metres) * 1000}\n")
    path = tmp_path / "millimetres.toml"
    path.write_text(text)
    with pytest.raises(ConfigError, match=r"millimetres.toml: \[geometry\] upper_radius = "
                                          "1800 m is outside the physical range 0.01 to 50 m"):
        load_platform(path)


def test_toml_that_is_not_utf8_names_file_and_line(tmp_path, example_dir):
    text = (example_dir / "platform.toml").read_text() + "# Masse en kg, précision ±1 %\n"
    path = tmp_path / "latin.toml"
    path.write_bytes(text.encode("latin-1"))
    with pytest.raises(ConfigError, match=r"latin.toml: not UTF-8 \(byte 0xe9 on line 24\); "
                                          "TOML files are UTF-8: re-save it as UTF-8"):
        load_platform(path)


# -- the command line -------------------------------------------------------------------------

def _error_line(result) -> str:
    lines = result.stderr.strip().splitlines()
    assert result.exit_code == 2 and len(lines) == 1, result.output
    return lines[0]


@pytest.mark.parametrize("arguments, message", [
    (["simulate", "--out", "x", "--duration", "2s"],
     "error: Invalid value for '--duration': .* --duration: Record length of each experiment "
     r"\(s\). See 'stewartid simulate --help'."),
    (["simulate", "--out", "x", "--sed", "1"], "error: No such option: --sed"),
    (["identfy"], "error: No such command 'identfy'. Did you mean 'identify'?"),
    (["simulate"], "error: Missing option '--out'."),
])
def test_usage_errors_are_one_line(arguments, message):
    result = CliRunner().invoke(app, arguments)
    assert result.exit_code == 2
    assert len(result.stderr.strip().splitlines()) == 1
    assert re.match(message, result.stderr.strip())


@pytest.fixture(scope="module")
def folder(tmp_path_factory, paper):
    folder = tmp_path_factory.mktemp("logs")
    M, B = random_matrices(np.random.default_rng(3))
    for k in range(6):
        write_dataset(make_experiment(paper, M, B, k), folder / f"exp{k + 1}.csv")
    return folder


def _identify(*arguments):
    return CliRunner().invoke(app, ["identify", "--method", "fourier", *map(str, arguments)])


def test_platform_is_required(folder):
    result = _identify(*sorted(folder.glob("exp*.csv")))
    assert "error: --platform is required (a platform TOML file, or 'paper' for the preset)" \
        in result.stderr and result.exit_code == 2


def test_meta_json_beside_the_data_may_name_the_platform(tmp_path, folder, paper):
    for path in folder.glob("exp*.csv"):
        (tmp_path / path.name).write_bytes(path.read_bytes())
    (tmp_path / "meta.json").write_text(json.dumps({"platform": paper.to_dict(),
                                                    "platform_name": "paper"}))
    result = _identify(tmp_path, "--out", tmp_path / "result.json")
    assert result.exit_code == 0, result.output
    other = tmp_path / "other.toml"
    inertia = [1.2 * value for value in paper.inertia.platform_inertia]
    other.write_text(paper.replace(inertia__platform_inertia=inertia).to_toml())
    result = _identify("--platform", other, tmp_path)
    assert result.exit_code == 0, result.output
    assert "meta.json describes platform 'paper' with another [inertia] than --platform" \
        in result.stderr
    (tmp_path / "meta.json").write_text(json.dumps({"platform": "missing.toml"}))
    result = _identify(tmp_path)
    assert "platform file" in result.stderr and "missing.toml' not found" in result.stderr


def test_output_never_overwrites_an_input_a_folder_or_a_foreign_file(tmp_path, folder,
                                                                     monkeypatch):
    import stewartid.identification.registry as registry

    def never(*args, **kwargs):
        raise AssertionError("computed before checking the output")

    monkeypatch.setattr(registry, "create_identifier", never)
    inputs = sorted(folder.glob("exp*.csv"))
    before = inputs[0].read_bytes()
    result = _identify("--platform", "paper", "--out", inputs[0], "--force", *inputs)
    assert f"--out '{inputs[0]}' is one of the input files" in _error_line(result)
    assert inputs[0].read_bytes() == before
    result = _identify("--platform", "paper", "--out", tmp_path, *inputs)
    assert "is a folder; give a file name, e.g." in _error_line(result)
    foreign = tmp_path / "notes.json"
    foreign.write_text("{}")
    result = _identify("--platform", "paper", "--out", foreign, *inputs)
    assert "exists and is not an earlier result; give another file name or pass --force" \
        in _error_line(result)
    result = _identify("--platform", "paper", "--out", tmp_path / "result.csv", *inputs)
    assert "the result is JSON; give a .json file name" in _error_line(result)
    assert foreign.read_text() == "{}" and not list(tmp_path.glob("*.csv"))


def test_earlier_result_is_replaced_and_force_overwrites(tmp_path, folder):
    inputs = sorted(folder.glob("exp*.csv"))
    out = tmp_path / "result.json"
    for _ in range(2):  # the second run replaces its own earlier result
        assert _identify("--platform", "paper", "--out", out, *inputs).exit_code == 0
    foreign = tmp_path / "notes.json"
    foreign.write_text("{}")
    assert _identify("--platform", "paper", "--out", foreign, "--force", *inputs).exit_code == 0
    assert "M" in json.loads(foreign.read_text())


def test_warnings_are_one_line_without_source(tmp_path, folder):
    for path in folder.glob("exp*.csv"):
        frame = pd.read_csv(path)
        frame["t"] += np.random.default_rng(0).uniform(-1e-3, 1e-3, len(frame))
        frame.to_csv(tmp_path / path.name, index=False)
    result = _identify("--platform", "paper", tmp_path)
    assert result.exit_code == 0, result.output
    lines = result.stderr.strip().splitlines()
    assert all(line.startswith("warning: ") for line in lines)
    assert sum("time stamps jitter by up to 1.08 ms around a uniform 200.006 Hz" in line
               for line in lines) == 6
    assert "warnings.warn" not in result.stderr and ".py:" not in result.stderr


def test_columns_option_maps_a_log(tmp_path, folder):
    for path in folder.glob("exp*.csv"):
        frame = pd.read_csv(path)
        frame["t"] *= 1e3
        frame.to_csv(tmp_path / path.name, index=False, sep=";")
    result = _identify("--platform", "paper", tmp_path)
    assert "--columns t=:ms" in _error_line(result)
    assert _identify("--platform", "paper", "--columns", "t=:ms", tmp_path).exit_code == 0


# -- jittery time stamps ----------------------------------------------------------------------

@pytest.mark.slow
def test_jittery_time_stamps_cost_below_0p2_percent(example_dir, example_platform,
                                                    example_truth):
    """+-0.3 ms of timing noise on the example's 1 kHz clock, identified by the default
    method: every entry of Mt and Bt within 0.2 % of the clean identification."""
    from stewartid.identification.wavelet.estimator import WaveletIdentifier

    clean = read_datasets(example_dir, example_platform)
    jittery = []
    rng = np.random.default_rng(7)
    for dataset in clean:
        frame = dataset.to_frame()
        frame["t"] += rng.uniform(-3e-4, 3e-4, len(frame))
        with pytest.warns(DataWarning, match="jitter by up to 0.3"):
            jittery.append(dataset_from_frame(frame, example_platform, name=dataset.name))
    reference = WaveletIdentifier().fit(clean, example_platform)
    estimate = WaveletIdentifier().fit(jittery, example_platform)
    for label, truth, a, b in (("Mt", example_truth["Mt"], reference.M_, estimate.M_),
                               ("Bt", example_truth["Bt"], reference.B_, estimate.B_)):
        entries = np.abs(truth) > 1e-6 * np.abs(truth).max()
        change = np.max(np.abs(b - a)[entries] / np.abs(a[entries]))
        assert change <= 2e-3, label
