"""Studies: study-file validation, grid expansion, the Parquet data set, the report, and runs
on a two-worker dask LocalCluster (a worker killed mid-run, an interrupted run resumed)."""

from __future__ import annotations

import math
import os
import re
import signal

import numpy as np
import pandas as pd
import pytest
from typer.testing import CliRunner

from stewartid.cli import app
from stewartid.errors import ConfigError, OutputExistsError
from stewartid.studies import expand_grid, load_study, parse_study, read_results, run_study
from stewartid.studies.results import ENTRY_COLUMNS, columns, finished_tasks, write_part
from stewartid.studies.task import error_columns

#: A study small enough for the tests: 2.5 s records, one method, 2 x 2 points x 1-2 seeds.
TINY = {"study": {"platform": "paper", "methods": ["ls"], "duration": 2.5, "seeds": 1},
        "grid": {"coulomb": [0.0, 30.0], "noise_scale": [0.0, 1.0]}}


def tiny(**study) -> dict:
    return {"study": {**TINY["study"], **study}, "grid": dict(TINY["grid"])}


# ------------------------------------------------------------------ study file and grid

@pytest.mark.parametrize("document, message", [
    ({"study": {"methods": ["ls"], "speed": 1}}, "unknown key 'speed'"),
    ({"study": {"methods": ["ls"]}, "grid": {"mass": [1.0]}}, r"\[grid\] has unknown key 'mass'"),
    ({"study": {"methods": ["ls"]}, "sweep": {}}, r"unknown table \[sweep\]"),
    ({"study": {"duration": 4.0}}, "missing required key 'methods'"),
    ({"study": {"methods": []}}, "non-empty list of method names"),
    ({"study": {"methods": ["magic"]}}, "unknown method 'magic'"),
    ({"study": {"methods": ["ls", "ls"]}}, "lists a method twice"),
    ({"study": {"methods": ["ls"], "coulomb": 5.0}, "grid": {"coulomb": [0.0]}},
     "both fixed in \\[study\\] and swept in \\[grid\\]"),
    ({"study": {"methods": ["ls"]}, "grid": {"coulomb": [-1.0]}}, r"coulomb\[0\] must be >= 0"),
    ({"study": {"methods": ["ls"]}, "grid": {"frequency": [0.0]}}, "must be > 0"),
    ({"study": {"methods": ["ls"]}, "grid": {"noise_scale": []}}, "non-empty list"),
    ({"study": {"methods": ["ls"]}, "grid": {"noise_scale": [1, 1]}}, "lists a value twice"),
    ({"study": {"methods": ["ls"], "seeds": 0}}, "seeds must be an integer >= 1"),
    ({"study": {"methods": ["ls"], "duration": "long"}}, "duration must be a number"),
    ({"study": {"methods": ["ls"], "platform": "nowhere.toml"}}, "platform file"),
    ({"study": {"methods": ["ls"]}, "settings": {"ls": {"magic": 1}}}, "has no setting 'magic'"),
    ({"study": {"methods": ["ls"]}, "settings": {"fourier": {}}}, "does not run"),
])
def test_bad_study_files_are_refused(document, message):
    with pytest.raises(ConfigError, match=message):
        parse_study(document)


def test_grid_expands_to_points_times_seeds_with_stable_keys():
    spec = parse_study(tiny(seeds=3))
    tasks = expand_grid(spec)
    assert spec.size == len(tasks) == 12
    assert len({task.key for task in tasks}) == 12
    # the seed is the outer loop: the first four tasks cover the grid once
    assert {task.seed for task in tasks[:4]} == {0}
    assert spec.fixed == {"viscous": 5000.0, "frequency": 0.5, "duration": 2.5}
    # a key depends on the point and the seed, not on how the grid was written
    reordered = parse_study({"study": TINY["study"],
                             "grid": {"noise_scale": [1.0, 0.0], "coulomb": [30.0, 0.0]}})
    assert {t.key for t in expand_grid(reordered)} == {t.key for t in tasks[:4]}


# ------------------------------------------------------------------ rows and data set

def test_error_columns_against_hand_values():
    nominal_M, nominal_B = np.diag(np.arange(1.0, 7.0)), np.diag(np.full(6, 10.0))
    nominal_M[0, 4] = nominal_M[4, 0] = nominal_M[1, 3] = nominal_M[3, 1] = 2.0
    nominal_B[0, 4] = nominal_B[4, 0] = nominal_B[1, 3] = nominal_B[3, 1] = 4.0
    M, B = nominal_M.copy(), nominal_B.copy()
    B[2, 2] = 13.0  # 30 %
    M[5, 5] = 6.6  # 10 %
    row = error_columns(M, B, nominal_M, nominal_B)
    assert row["max_error_percent"] == pytest.approx(30.0)
    assert row["max_error_entry"] == "Bt(3,3)"
    assert row["max_error_M_percent"] == pytest.approx(10.0)
    assert row["error_Mt(6,6)"] == pytest.approx(10.0)
    assert len([c for c in row if c.startswith("error_")]) == 20


def _rows(task: str, methods=("ls", "wavelet"), error: float = 1.0) -> list[dict]:
    base = dict.fromkeys(columns())
    return [{**base, "task": task, "coulomb": 0.0, "viscous": 1.0, "noise_scale": 0.0,
             "frequency": 0.5, "duration": 2.0, "seed": 0, "method": method,
             "max_error_percent": error, **dict.fromkeys(ENTRY_COLUMNS, error)}
            for method in methods]


def test_parts_are_whole_files_one_per_task(tmp_path):
    write_part(tmp_path, "aaaa", _rows("aaaa"))
    write_part(tmp_path, "bbbb", _rows("bbbb"))
    write_part(tmp_path, "aaaa", _rows("aaaa", error=2.0))  # a task finishing twice
    # a writer killed before its rename leaves only a hidden temporary file
    (tmp_path / "results.parquet" / ".part-cccc.parquet.x.tmp").write_bytes(b"half a file")
    assert finished_tasks(tmp_path) == {"aaaa", "bbbb"}
    rows = read_results(tmp_path)
    assert len(rows) == 4 and not rows.duplicated(["task", "method"]).any()
    assert set(rows.loc[rows["task"] == "aaaa", "max_error_percent"]) == {2.0}
    assert len(pd.read_parquet(tmp_path / "results.parquet")) == 4
    assert list(read_results(tmp_path, tasks={"bbbb"})["task"]) == ["bbbb", "bbbb"]
    with pytest.raises(ValueError, match="misses columns"):
        write_part(tmp_path, "dddd", [{"task": "dddd"}])


@pytest.mark.slow
def test_report_states_the_trends_in_the_numbers(tmp_path):
    from stewartid.studies.report import write_study_report

    spec = parse_study({"study": {"methods": ["fourier", "wavelet"], "seeds": 2},
                        "grid": {"coulomb": [0.0, 5.0, 30.0], "noise_scale": [0.0, 1.0]}})
    rows = []
    for task in expand_grid(spec):
        c, n = task.parameters["coulomb"], task.parameters["noise_scale"]
        for method in spec.methods:
            bt = (1 + c if method == "fourier" else 1.0) * (1 + 10 * n) + task.seed * 0.001
            rows += [{**_rows(task.key, (method,))[0], **task.parameters, "seed": task.seed,
                      "max_error_B_percent": bt, "max_error_M_percent": 0.5 * (1 + n),
                      "max_error_percent": bt}]
    rows = pd.DataFrame(rows)
    files = write_study_report(rows, spec, tmp_path, total_tasks=spec.size)
    text = (tmp_path / "report.md").read_text()
    names = {path.name for path in files}
    assert {"error_vs_coulomb.png", "error_vs_noise_scale.svg", "error_vs_coulomb.csv",
            "report.html"} <= names
    assert "**Method A (Fourier)**, largest Bt error against coulomb" in text
    fourier, wavelet = (line for line in text.splitlines()
                        if "largest Bt error against coulomb" in line)
    assert "at noise_scale 0: 1 → 6 → 31 % (grows at every step)" in fourier
    assert "does not grow" in wavelet and "grows at every step" not in wavelet
    noise_lines = [line for line in text.splitlines()
                   if line.startswith("- **") and "against noise_scale (0, 1)" in line]
    assert len(noise_lines) == 2 and all("does not grow" not in line for line in noise_lines)


# ------------------------------------------------------------------ command line

def test_cli_refuses_a_folder_holding_a_study(tmp_path):
    study_file = tmp_path / "study.toml"
    study_file.write_text('[study]\nmethods = ["ls"]\nduration = 2.5\n')
    out = tmp_path / "out"
    (out / "results.parquet").mkdir(parents=True)
    result = CliRunner().invoke(app, ["study", str(study_file), "--out", str(out)])
    assert result.exit_code == 2
    assert result.output.strip().count("\n") == 0 and "pass --resume" in result.output
    result = CliRunner().invoke(app, ["study", str(study_file), "--out", str(out),
                                      "--workers", "2", "--scheduler", "tcp://nowhere:1"])
    assert result.exit_code == 2 and "cannot be used with --scheduler" in result.output


def test_study_file_that_is_not_utf8_is_one_error_line(tmp_path):
    study_file = tmp_path / "étude.toml"
    study_file.write_bytes('[study]\nmethods = ["ls"]\ntitle = "Étude à 5 N m"\n'
                           .encode("latin-1"))
    result = CliRunner().invoke(app, ["study", str(study_file), "--out", str(tmp_path / "out")])
    lines = result.stderr.strip().splitlines()
    assert result.exit_code == 2 and len(lines) == 1, result.output
    assert re.fullmatch(r"error: study file .*étude\.toml: not UTF-8 \(byte 0xc9 on line 3\); "
                        r"TOML files are UTF-8: re-save it as UTF-8\.", lines[0]), lines[0]
    assert "Traceback" not in result.output and not (tmp_path / "out").exists()


def test_study_file_with_a_syntax_error_names_line_and_column(tmp_path):
    study_file = tmp_path / "study.toml"
    study_file.write_text('[study]\nmethods = ["ls"]\nduration = 2.5 = 3\n')
    with pytest.raises(ConfigError, match=r"study file .*study\.toml is not valid TOML: .*line 3, "
                                          r"column \d+"):
        load_study(study_file)


def test_resume_refuses_other_fixed_settings(tmp_path):
    spec = parse_study(tiny())
    write_part(tmp_path, "aaaa", _rows("aaaa"))
    (tmp_path / "study.json").write_text('{"platform": "paper", "methods": ["wavelet"]}')
    with pytest.raises(ConfigError, match="other 'methods'"):
        run_study(spec, tmp_path, resume=True, report=False)
    with pytest.raises(OutputExistsError, match="already holds a study"):
        run_study(spec, tmp_path, report=False)


# ------------------------------------------------------------------ on a dask cluster

@pytest.fixture(scope="module")
def cluster():
    """Two single-threaded worker processes, restarted by their nannies when killed."""
    distributed = pytest.importorskip("distributed")
    from stewartid.studies.runner import connect

    with connect(workers=2) as client:
        client.wait_for_workers(2)
        yield client, distributed


def _present_once(rows, spec) -> bool:
    keys = {task.key for task in expand_grid(spec)}
    return (len(rows) == spec.size * len(spec.methods) and set(rows["task"]) == keys
            and not rows.duplicated(["task", "method"]).any())


@pytest.mark.slow
def test_a_worker_killed_mid_run_loses_and_duplicates_nothing(cluster, tmp_path):
    client, _ = cluster
    spec = parse_study(tiny())
    killed = []

    def kill_a_busy_worker(done, failed, remaining):
        if killed or done == 0 or remaining == 0:
            return
        busy = [address for address, keys in client.processing().items() if keys]
        if not busy:
            return
        pids = client.run(os.getpid, workers=busy[:1])
        for address, pid in pids.items():
            os.kill(pid, signal.SIGKILL)
            killed.append(address)

    run = run_study(spec, tmp_path, client=client, progress=kill_a_busy_worker, report=False)
    assert killed, "no worker was busy when the first task finished"
    client.wait_for_workers(2)
    assert killed[0] not in client.scheduler_info()["workers"]
    assert run.computed == spec.size and not run.failures
    rows = read_results(tmp_path)
    assert _present_once(rows, spec)
    assert len(finished_tasks(tmp_path)) == spec.size
    assert rows["failure"].isna().all() and np.isfinite(rows["max_error_percent"]).all()
    assert (rows["task_cpu_time_s"] > 0).all() and rows["worker"].str.startswith("tcp://").all()


@pytest.mark.slow
def test_an_interrupted_run_resumes_without_recomputing(cluster, tmp_path):
    client, _ = cluster
    spec = parse_study(tiny())

    def interrupt_after_two(done, failed, remaining):
        if done == 2:
            raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        run_study(spec, tmp_path, client=client, progress=interrupt_after_two, report=False)
    parts = sorted((tmp_path / "results.parquet").glob("part-*.parquet"))
    assert len(parts) == 2
    before = {path.name: (path.stat().st_ino, path.stat().st_mtime_ns) for path in parts}
    run = run_study(spec, tmp_path, client=client, resume=True)
    assert (run.skipped, run.computed) == (2, 2)
    after = {path.name: (path.stat().st_ino, path.stat().st_mtime_ns)
             for path in (tmp_path / "results.parquet").glob("part-*.parquet")}
    assert {name: after[name] for name in before} == before  # finished rows untouched
    assert _present_once(run.rows, spec)
    assert (tmp_path / "report.html").is_file()
    assert (tmp_path / "figures" / "error_vs_coulomb.png").is_file()
    # everything done: a further resume computes nothing and needs no cluster
    again = run_study(spec, tmp_path, resume=True, report=False)
    assert (again.skipped, again.computed) == (4, 0)
    assert math.isclose(again.rows["max_error_percent"].sum(),
                        run.rows["max_error_percent"].sum())


@pytest.mark.slow
def test_cli_runs_and_resumes_a_study(tmp_path):
    study_file = tmp_path / "study.toml"
    study_file.write_text('[study]\nmethods = ["ls"]\nduration = 2.5\nseeds = 2\n'
                          '[grid]\nnoise_scale = [0.0, 1.0]\n')
    out = tmp_path / "out"
    result = CliRunner().invoke(app, ["study", str(study_file), "--out", str(out),
                                      "--workers", "1"])
    assert result.exit_code == 0, result.output
    assert "4 tasks computed, 0 already done, 0 failed; 4 rows" in result.output
    result = CliRunner().invoke(app, ["study", str(study_file), "--out", str(out), "--resume"])
    assert result.exit_code == 0, result.output
    assert "0 tasks computed, 4 already done" in result.output
    assert "against noise_scale" in (out / "report.md").read_text()
