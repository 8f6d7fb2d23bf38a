"""The force delay left in the held-out residuals, against logs whose delay is known.

The logs are those of ``test_delay.py``: the paper platform's nominal linear model along
analytic multi-sines (three lines per DOF) or single sines, forces logged 2 ms late (the
model evaluated at the earlier instant), 20 N of white noise per leg force.
"""

from __future__ import annotations

import json

import numpy as np
import pytest
from typer.testing import CliRunner

import stewartid as sid
from stewartid.cli import app
from stewartid.datasets.dataset import write_dataset
from stewartid.model.linearization import nominal_matrices
from stewartid.validation.heldout import ResidualDelay
from stewartid.verdict.policy import DEFAULT_POLICY
from test_delay import experiments

LATE = 2e-3
SINGLE = ((1.0, 0.5, 0.0),)


@pytest.fixture(scope="module")
def late_log(paper):
    return experiments(paper, delay=LATE, noise=20.0)


@pytest.fixture(scope="module")
def as_logged(late_log, paper):
    """Least squares on the late log with the forces as logged (``--delay 0``)."""
    return sid.compare_methods(late_log, paper, "ls", delay=0.0)


@pytest.fixture(scope="module")
def aligned(late_log, paper):
    """The same with the default alignment."""
    return sid.compare_methods(late_log, paper, "ls")


def test_a_delay_left_in_the_data_is_found_in_the_held_out_residuals(as_logged):
    found = as_logged.residual_delays["ls"]
    assert found.identifiable
    assert found.seconds == pytest.approx(LATE, abs=3e-4)
    assert found.std_error < 1e-4
    assert found.significant(DEFAULT_POLICY.significant, DEFAULT_POLICY.delay_floor_s)
    entry = as_logged.result.validation["residual_delay"]
    assert set(entry) == {"ms", "std_ms", "identifiable"}
    assert entry["ms"] == pytest.approx(2.0, abs=0.3) and entry["identifiable"] is True
    # the keys the validation always had are still there
    assert {"vaf_percent", "nrmse", "folds"} <= set(as_logged.result.validation)


def test_the_verdict_names_the_delay_and_the_fix(as_logged, paper):
    (reason,) = [r for r in as_logged.reasons if r.startswith("force delay left")]
    assert "--delay auto" in reason and "--delay SECONDS" in reason
    assert f"{1e3 * as_logged.residual_delays['ls'].seconds:.3g} ms" in reason
    assert as_logged.verdict.to_dict()["residual_delay"]["ms"] == pytest.approx(2.0, abs=0.3)
    # the entries it flags are off beyond their standard errors against the model's truth
    B = nominal_matrices(paper)[1]
    flagged = {u["entry"]: u for u in as_logged.uncertain_entries if "delay_bias" in u}
    assert {f"Bt({k},{k})" for k in range(1, 7)} <= set(flagged)
    trusted = as_logged.trusted_result
    error = np.abs(np.diag(trusted.B) - np.diag(B))
    assert np.all(error > 3 * np.diag(trusted.std_errors_B))


def test_after_the_default_alignment_no_delay_is_left(aligned):
    assert aligned.delay["applied"] and aligned.delay["source"] == "estimated"
    found = aligned.residual_delays["ls"]
    assert found.identifiable
    assert abs(found.seconds) < 2 * found.std_error
    assert not any(r.startswith("force delay left") for r in aligned.reasons)
    assert aligned.verdict.residual_delay is None
    assert not any("delay_bias" in u for u in aligned.uncertain_entries)


def test_one_sine_per_dof_leaves_the_delay_not_identifiable(paper):
    comparison = sid.compare_methods(experiments(paper, sines=SINGLE, delay=LATE, noise=20.0),
                                     paper, "ls", delay=0.0)
    found = comparison.residual_delays["ls"]
    assert not found.identifiable
    assert comparison.result.validation["residual_delay"]["identifiable"] is False
    # the fit absorbed the delay into Bt: its residuals say nothing of it
    assert not found.significant(DEFAULT_POLICY.significant, DEFAULT_POLICY.delay_floor_s)
    assert not any(r.startswith("force delay left") for r in comparison.reasons)


@pytest.mark.parametrize("seconds, std, identifiable, significant", [
    (2e-3, 1e-5, True, True),
    (2e-3, 1e-3, True, False),     # within 3 standard errors
    (1e-4, 1e-6, True, False),     # below the 0.2 ms floor
    (-2e-3, 1e-5, True, True),     # forces leading the motion
    (2e-3, 1e-5, False, False),    # one frequency per DOF
    (float("nan"), float("nan"), True, False),
])
def test_when_a_residual_delay_counts(seconds, std, identifiable, significant):
    delay = ResidualDelay(seconds, std, identifiable)
    assert delay.significant(DEFAULT_POLICY.significant,
                             DEFAULT_POLICY.delay_floor_s) is significant
    entry = delay.to_dict()
    assert entry["identifiable"] is identifiable
    assert entry["ms"] is None if np.isnan(seconds) else entry["ms"] == pytest.approx(1e3 * seconds)


@pytest.mark.slow
def test_every_method_and_the_report_see_the_delay(tmp_path, late_log):
    """``identify --method all --report`` on the late log with ``--delay 0``: every method's
    residual delay in result.json and the report, once in the verdict's reasons."""
    folder = tmp_path / "late"
    folder.mkdir()
    files = [str(write_dataset(d, folder / f"{d.name}.csv")) for d in late_log]
    out, report = tmp_path / "result.json", tmp_path / "report"
    result = CliRunner().invoke(app, ["identify", "--method", "all", "--platform", "paper",
                                      "--delay", "0", "--report", str(report), "--out",
                                      str(out), *files])
    assert result.exit_code == 0, result.output
    document = json.loads(out.read_text())
    assert document["validation"]["residual_delay"]["ms"] == pytest.approx(2.0, abs=0.3)
    evidence = document["verdict"]["evidence"]
    for name, found in evidence.items():
        assert found["residual_delay"]["ms"] == pytest.approx(2.0, abs=0.3), name
    assert sum(r.startswith("force delay left") for r in document["verdict"]["reasons"]) == 1
    text = (report / "report.md").read_text()
    assert "**The forces lag the motion by" in text and "`--delay auto`" in text
    assert "Force delay left in the held-out residuals" in text
