"""The physical model in ``identify --report``: the section, its Mt(q) band against the true
mass matrix, its held-out prediction beside the other methods, ``--consistent`` and the
refusals.

The records are the model's own inverse dynamics along all-DOFs multisines (forces from the
regressor with the platform file's standard parameters, plus white force noise), so the truth
of Mt(q) is ``nominal_matrices(platform, pose)``: the compiled model's mass matrix, computed
without the regressor.
"""

from __future__ import annotations

import json

import numpy as np
import pytest
from typer.testing import CliRunner

from stewartid.cli import app
from stewartid.comparison import PhysicalRequest, fit_physical
from stewartid.datasets.dataset import write_dataset
from stewartid.model import regressor as reg
from stewartid.model.linearization import nominal_matrices
from stewartid.platform import load_platform
from test_physical_consistent import PAYLOAD, regressor_records

#: White noise on each leg force (N): standard errors well above round-off.
FORCE_NOISE = 200.0


@pytest.fixture(scope="module")
def loaded(paper):
    return paper.replace(friction__coulomb=30.0,
                         **{f"payload__{key}": value for key, value in PAYLOAD.items()})


@pytest.fixture(scope="module")
def data(loaded, tmp_path_factory):
    """Six noisy records of the loaded platform's model and a seventh as validation record,
    written as CSV beside the platform file."""
    folder = tmp_path_factory.mktemp("physical_report")
    records = regressor_records(loaded, reg.standard_parameters(loaded), duration=4.0,
                                noise=FORCE_NOISE, seed=3)
    extra = regressor_records(loaded, reg.standard_parameters(loaded), duration=4.0,
                              noise=FORCE_NOISE, seed=4)[2]
    files = []
    for d in records:
        files.append(folder / f"{d.name}.csv")
        write_dataset(d, files[-1])
    validation = folder / "validation" / "check.csv"
    validation.parent.mkdir()
    write_dataset(extra.__class__(t=extra.t, pose=extra.pose, lengths=extra.lengths,
                                  forces=extra.forces, name="check"), validation)
    (folder / "loaded.toml").write_text(loaded.to_toml())
    (folder / "bare.toml").write_text(loaded.replace(payload=None).to_toml())
    return folder, records, [str(f) for f in files], str(validation)


@pytest.mark.slow
def test_model_physical_report(data, tmp_path):
    """The report of the compared methods with the physical section; result.json is the
    physical model's with the verdict; the validation tables carry its unranked rows."""
    folder, _, files, validation = data
    out, report = tmp_path / "result.json", tmp_path / "report"
    run = CliRunner().invoke(app, ["identify", "--model", "physical", "--platform",
                                   str(folder / "loaded.toml"), "--report", str(report),
                                   "--validate", validation, "--folds", "2", "--out", str(out),
                                   *files])
    assert run.exit_code == 0, run.output
    document = json.loads((report / "result.json").read_text())
    assert document == json.loads(out.read_text())
    assert document["model"] == "physical"
    assert {"M", "B", "std_errors_M", "std_errors_B", "parameters", "parameter_std_errors",
            "base_parameters"} <= set(document)
    assert {"trusted", "ranking", "uncertain_entries", "reasons"} <= set(document["verdict"])
    assert document["verdict"]["trusted"] != "physical"
    assert "physical" not in document["verdict"]["ranking"]
    assert len(document["validation"]["vaf_percent"]) == 6
    assert len(document["validation"]["records"]["vaf_percent"]) == 6
    text = (report / "report.md").read_text()
    assert "## Physical model" in text and "#### Identified parameters" in text
    unranked = [line for line in text.splitlines()
                if line.startswith("| Physical model (full model; not ranked)")]
    assert len(unranked) == 3  # held-out VAF, NRMSE, validation records
    vaf = [float(v) for v in unranked[0].strip("|").split("|")[1:]]
    # the model is the data's: what it leaves is the force noise
    assert min(vaf) > 99.0
    assert all((report / "figures" / f"workspace.{kind}").is_file() for kind in ("png", "svg"))


@pytest.mark.slow
def test_band_holds_the_true_mass_matrix(loaded, data):
    """The section a plain ``--method all`` report adds (the model not required): ±2 standard
    errors of Mt(q) across the measured poses hold the compiled model's mass matrix at most
    poses (95 % for a calibrated band; the points along a sweep are strongly correlated, hence
    the margin), and the held-out prediction by the full model leaves only the noise."""
    _, records, _, _ = data
    section = fit_physical(records, loaded, PhysicalRequest(), 3, {})
    assert section.note is None and section.validation is not None
    assert np.min(section.validation.vaf_percent) > 99.0
    curves = section.workspace
    inside, total = 0, 0
    for dof in range(6):
        for k, value in enumerate(curves.grid[dof]):
            pose = curves.centre.copy()
            pose[dof] = value
            M_true = nominal_matrices(loaded, pose)[0]
            found = curves.identified[dof]
            for i, j in [(i, i) for i in range(6)] + curves.couplings["M"]:
                error = abs(found.M[k, i, j] - M_true[i, j])
                assert error < 6 * found.std_errors_M[k, i, j] + 1e-9 * abs(M_true[i, j])
                inside += error <= 2 * found.std_errors_M[k, i, j]
                total += 1
    assert inside >= 0.8 * total
    # the band is informative: well inside 1 % of the diagonal
    diagonal = curves.identified[0].M[:, range(6), range(6)]
    assert np.all(curves.identified[0].std_errors_M[:, range(6), range(6)]
                  < 1e-2 * np.abs(diagonal))


@pytest.mark.slow
def test_section_left_out_when_most_parameters_are_fixed(loaded, monkeypatch):
    """Translation-only records fix the inertias and the revolute friction (8 of 27): with
    the threshold below that share, a report that did not ask for the model gives one line
    saying why instead of the section; ``--model physical`` fits them all the same."""
    import stewartid.comparison._physical as section_module
    from test_physical_model import translation_records

    records = translation_records(loaded)
    monkeypatch.setattr(section_module, "MOST_FIXED", 0.25)
    section = fit_physical(records, loaded, PhysicalRequest(), 3, {})
    assert section.result is None and section.workspace is None
    assert "fix 8 of its 27 parameters" in section.note
    assert "\n" not in section.note
    required = fit_physical(records, loaded, PhysicalRequest(required=True), 3, {})
    assert required.result is not None and len(required.result.diagnostics["fixed"]) == 8


def test_consistent_payload(loaded, data, tmp_path):
    """``--model physical --payload --consistent``: the payload's pseudo-inertia (built here
    from the identified mass, first moment and inertia) is positive semidefinite, the moves
    are reported, and --platform-out writes the consistent parameters."""
    pytest.importorskip("cvxpy")
    folder, _, files, _ = data
    out, written = tmp_path / "result.json", tmp_path / "identified.toml"
    run = CliRunner().invoke(app, ["identify", "--model", "physical", "--payload",
                                   "--consistent", "--platform", str(folder / "bare.toml"),
                                   "--out", str(out), "--platform-out", str(written), *files])
    assert run.exit_code == 0, run.output
    document = json.loads(out.read_text())
    p = document["parameters"]
    m = p["payload.m"]
    h = np.array([p[f"payload.mc_{a}"] for a in "xyz"])
    xx, yy, zz, xy, xz, yz = (p[f"payload.I_{e}"] for e in ("xx", "yy", "zz", "xy", "xz", "yz"))
    inertia = np.array([[xx, xy, xz], [xy, yy, yz], [xz, yz, zz]])
    J = np.block([[np.trace(inertia) / 2 * np.eye(3) - inertia, h[:, None]], [h[None], m]])
    assert np.linalg.eigvalsh(J).min() >= -1e-9 * np.abs(J).max()
    assert "max_change_std_errors" in document["diagnostics"]["consistent"]
    identified = load_platform(written)
    assert identified.payload.mass == pytest.approx(m, rel=1e-9)


@pytest.mark.parametrize("extra, named", [
    (["--symmetric"], "--symmetric"),
    (["--friction", "free"], "--friction"),
    (["--platform-out", "x.json"], "--platform-out"),
])
def test_bad_combinations_are_one_line(data, extra, named):
    """Options the physical model does not take are refused before any fit: exit code 2,
    one line naming the option."""
    folder, _, files, _ = data
    run = CliRunner().invoke(app, ["identify", "--model", "physical", "--platform",
                                   str(folder / "loaded.toml"), *extra, *files])
    assert run.exit_code == 2, run.output
    assert named in run.output and "Traceback" not in run.output
    assert len(run.output.strip().splitlines()) == 1
