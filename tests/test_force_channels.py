"""Force channels numbered differently from the legs: named before any fit, with the
``--columns`` mapping that renumbers them; a log numbered as the legs, and motion that cannot
tell two legs apart, pass.

The data: the paper platform's nominal linear model along one sine per DOF, its forces solved
leg by leg (``linear_model_data.make_experiment``), so which leg each channel measures is known
and a renumbering is applied here, independently of the check.
"""

from __future__ import annotations

import json
from importlib import resources

import numpy as np
import pytest
from typer.testing import CliRunner

from linear_model_data import make_experiment
from stewartid.cli import app
from stewartid.datasets.dataset import Dataset, write_dataset
from stewartid.datasets.set_checks import check_force_channels, force_channel_correlation
from stewartid.errors import DataError
from stewartid.model.linearization import nominal_matrices
from stewartid.platform import load_platform


def experiments(platform):
    M, B = nominal_matrices(platform)
    return [make_experiment(platform, M, B, k) for k in range(6)]


def renumbered(data, legs):
    """The experiments with force channel k holding leg ``legs[k]``'s force."""
    return [Dataset(t=d.t, pose=d.pose, lengths=d.lengths, forces=d.forces[:, legs],
                    name=d.name) for d in data]


def test_channels_numbered_as_the_legs_pass_and_follow_their_own_legs(paper):
    data = experiments(paper)
    check_force_channels(data, paper)
    # the roll and pitch sines move every leg, each its own way: each channel matches its
    # own leg's prediction (the model and the data are the same linear model, up to its
    # remainder and the Savitzky-Golay rates)
    for record in data[3:5]:
        correlation = force_channel_correlation(record, paper)
        assert np.all(np.diag(correlation) > 0.99)


@pytest.mark.parametrize("legs, named, mapping", [
    ([1, 0, 2, 3, 4, 5], "f1 follows leg 2, f2 follows leg 1", "f2=f1,f1=f2"),
    ([5, 0, 1, 2, 3, 4], "f1 follows leg 6, f2 follows leg 1, f3 follows leg 2, "
                         "f4 follows leg 3, f5 follows leg 4, f6 follows leg 5",
     "f6=f1,f1=f2,f2=f3,f3=f4,f4=f5,f5=f6"),
])
def test_renumbered_channels_are_named_with_their_mapping(paper, legs, named, mapping):
    with pytest.raises(DataError, match=rf"^the force channels are numbered differently from "
                                        rf"the legs: {named} \(mean correlation .* "
                                        rf"--columns {mapping} "):
        check_force_channels(renumbered(experiments(paper), legs), paper)


def test_an_electric_logs_current_channels_are_named_as_currents():
    """An electric platform's log holds motor currents i1..i6: the message and the mapping name
    them. The model data carry no screw friction, which the check's prediction adds (80 N a
    leg): the legs are told apart all the same."""
    with resources.as_file(resources.files("stewartid") / "data/electric.toml") as path:
        electric = load_platform(path)
    with pytest.raises(DataError, match=r"^the current channels are numbered differently from "
                                        r"the legs: i1 follows leg 2, i2 follows leg 1 .* "
                                        r"--columns i2=i1,i1=i2 "):
        check_force_channels(renumbered(experiments(electric), [1, 0, 2, 3, 4, 5]), electric)


def test_heave_alone_cannot_tell_the_legs_apart(paper):
    """At the neutral pose heave loads every leg alike: no numbering is better than another,
    and the check names none."""
    heave = renumbered(experiments(paper)[2:3], [1, 0, 2, 3, 4, 5])
    check_force_channels(heave, paper)


def test_cli_refuses_in_one_line_and_the_mapping_it_names_reads_the_log_as_numbered(tmp_path,
                                                                                   paper):
    data = experiments(paper)
    folders = {}
    for label, records in (("as", data), ("swapped", renumbered(data, [1, 0, 2, 3, 4, 5]))):
        folders[label] = tmp_path / label
        folders[label].mkdir()
        for record in records:
            write_dataset(record, folders[label] / f"{record.name}.csv")
    runner = CliRunner()
    base = ["identify", "--method", "fourier", "--platform", "paper"]
    refused = runner.invoke(app, [*base, "--out", str(tmp_path / "r.json"),
                                  str(folders["swapped"])])
    assert refused.exit_code == 2 and len(refused.output.strip().splitlines()) == 1
    assert "--columns f2=f1,f1=f2" in refused.output
    assert not (tmp_path / "r.json").exists()
    results = {}
    for label, extra in (("as", []), ("swapped", ["--columns", "f2=f1,f1=f2"])):
        out = tmp_path / f"{label}.json"
        run = runner.invoke(app, [*base, *extra, "--out", str(out), str(folders[label])])
        assert run.exit_code == 0, run.output
        results[label] = json.loads(out.read_text())
    assert results["swapped"]["M"] == results["as"]["M"]
    assert results["swapped"]["B"] == results["as"]["B"]


def test_compare_methods_refuses_them_before_any_fit(paper):
    """The Python entry point checks the experiment set as the command does."""
    from stewartid.comparison import compare_methods

    with pytest.raises(DataError, match=r"f1 follows leg 2, f2 follows leg 1 .* "
                                        r"--columns f2=f1,f1=f2 "):
        compare_methods(renumbered(experiments(paper), [1, 0, 2, 3, 4, 5]), paper, methods="ls")
