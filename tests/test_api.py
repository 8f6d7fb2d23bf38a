"""The top-level API: a script that imports only ``stewartid`` gets the verdict without
writing a file, and its report is the command line's."""

from __future__ import annotations

import json
import os
import subprocess
import sys

import pytest
from typer.testing import CliRunner

from stewartid.cli import app

SCRIPT = """
import stewartid as sid
platform = sid.load_platform(LOGS + "/platform.toml")
experiments = sid.read_experiments(LOGS, platform)
comparison = sid.compare_methods(experiments, platform, methods=("fourier", "ls"), folds=2)
assert comparison.trusted in ("fourier", "ls", "consensus"), comparison.trusted
assert comparison.M.shape == comparison.B.shape == (6, 6)
assert set(comparison.std_errors) == {"M", "B"}
assert comparison.reasons and all(isinstance(r, str) for r in comparison.reasons)
assert set(comparison.estimators) == {"fourier", "ls"}
print(repr(comparison))
"""


@pytest.mark.slow
def test_a_script_gets_the_verdict_and_writes_no_file(tmp_path, example_dir):
    work, temporary = tmp_path / "work", tmp_path / "tmp"
    work.mkdir()
    temporary.mkdir()
    code = f"LOGS = {str(example_dir)!r}\n" + SCRIPT
    environment = {**os.environ, "TMPDIR": str(temporary), "MPLCONFIGDIR": str(temporary)}
    found = subprocess.run([sys.executable, "-c", code], cwd=work, env=environment,
                           capture_output=True, text=True)
    assert found.returncode == 0, found.stderr
    assert found.stdout.startswith("Comparison(trusted=")
    assert list(work.iterdir()) == [] and list(temporary.iterdir()) == []


@pytest.mark.slow
def test_write_report_gives_the_command_lines_report(tmp_path, example_dir, example_platform):
    import stewartid as sid

    experiments = sid.read_experiments(example_dir, example_platform)
    comparison = sid.compare_methods(experiments, example_platform, methods="ls", folds=2,
                                     nominal_source="ignored")
    written = sid.write_report(comparison, tmp_path / "python")
    assert (tmp_path / "python" / "report.html").is_file() and written.trusted == "ls"
    result = CliRunner().invoke(app, ["identify", "--method", "ls", "--platform",
                                      str(example_dir / "platform.toml"), "--folds", "2",
                                      "--report",
                                      str(tmp_path / "cli"), str(example_dir)])
    assert result.exit_code == 0, result.output
    ours = json.loads((tmp_path / "python" / "result.json").read_text())
    theirs = json.loads((tmp_path / "cli" / "result.json").read_text())
    assert ours == theirs
    assert sorted(p.name for p in (tmp_path / "python").glob("*.csv")) == sorted(
        p.name for p in (tmp_path / "cli").glob("*.csv"))


@pytest.mark.slow
def test_methods_fitted_side_by_side_give_the_same_comparison(tmp_path, example_dir,
                                                               example_platform):
    """Worker processes (fork) fit the methods as one process does, to the bit; the runs share
    one copy of the held-out segments, as in one process; figures drawn side by side are the
    same files."""
    import numpy as np

    import stewartid as sid

    experiments = sid.read_experiments(example_dir, example_platform)
    alone, side = (sid.compare_methods(experiments, example_platform, methods=("fourier", "ls"),
                                       folds=2, jobs=jobs) for jobs in (1, 2))
    assert alone.verdict.to_dict() == side.verdict.to_dict()
    for a, b in zip(alone.runs, side.runs, strict=True):
        for name in ("M", "B", "std_errors_M", "std_errors_B"):
            assert np.array_equal(getattr(a.result, name), getattr(b.result, name)), name
        assert np.array_equal(a.validation.vaf_percent, b.validation.vaf_percent)
    fitted = [run for run in side.runs if run.validation is not None]
    assert all(run.validation.segments is fitted[0].validation.segments for run in fitted)
    sid.write_report(alone, tmp_path / "one", jobs=1)
    sid.write_report(side, tmp_path / "two", jobs=2)
    pictures = sorted(p.name for p in (tmp_path / "one" / "figures").glob("*.png"))
    assert pictures == sorted(p.name for p in (tmp_path / "two" / "figures").glob("*.png"))
    assert all((tmp_path / "one" / "figures" / name).read_bytes()
               == (tmp_path / "two" / "figures" / name).read_bytes() for name in pictures)


def test_a_methods_full_fit_error_comes_before_its_folds():
    """The full fit and the fold fits run as separate tasks; the method's error is the full
    fit's, as when they ran one after the other, and its time is both tasks'."""
    from stewartid.comparison import MethodFit
    from stewartid.comparison._runs import FoldFits, with_folds
    from stewartid.errors import DataError

    run = MethodFit("ls", "least squares", "k", error="full fit refused",
                    exception=DataError("full fit refused"), seconds=1.0)
    joined = with_folds(run, FoldFits(exception=DataError("fold 1 refused"), seconds=2.0))
    assert joined.error == "full fit refused" and joined.seconds == 3.0


def test_a_worker_count_below_one_is_one_line(example_dir):
    result = CliRunner().invoke(app, ["identify", "--method", "all", "--jobs", "0", "--report",
                                      "unused", str(example_dir)])
    assert result.exit_code == 2
    lines = result.output.strip().splitlines()
    assert len(lines) == 1 and "--jobs" in lines[0], result.output


@pytest.mark.slow
@pytest.mark.parametrize("method", ["wavelet", "ls"])
def test_experiments_prepared_side_by_side_give_the_same_fit(method, example_dir,
                                                             example_platform):
    """Worker processes preparing each experiment (jobs=2: Method B's equations, least squares'
    rows) give the one-process fit to the bit, and the settings recorded do not name the worker
    count."""
    import numpy as np

    import stewartid as sid
    from stewartid.identification.registry import create_identifier

    experiments = sid.read_experiments(example_dir, example_platform)
    alone, side = (create_identifier(method, jobs=jobs).fit(experiments, example_platform).result_
                   for jobs in (1, 2))
    for name in ("M", "B", "std_errors_M", "std_errors_B"):
        assert np.array_equal(getattr(alone, name), getattr(side, name)), name
    assert alone.settings == side.settings and "jobs" not in side.settings


def test_workers_that_would_start_afresh_are_not_started(monkeypatch):
    """Worker processes pay only when they start with this process's data and kernels (fork);
    where they would start afresh (spawn) a fit runs in one process."""
    from stewartid import parallel

    monkeypatch.setattr(parallel, "WORKERS_INHERIT", True)
    assert parallel.inheriting_workers(None, 6) == min(6, os.cpu_count() or 1)
    assert parallel.inheriting_workers(2, 6) == 2
    monkeypatch.setattr(parallel, "WORKERS_INHERIT", False)
    assert parallel.inheriting_workers(None, 6) == 1 and parallel.inheriting_workers(4, 6) == 1
