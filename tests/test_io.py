"""The one writer and the one JSON conversion: atomic files, non-finite numbers as null,
existing output folders refused with one error type, and figures that leave matplotlib's
global state alone."""

from __future__ import annotations

import json
import math
import sys

import numpy as np
import pytest

from stewartid.errors import ConfigError, OutputExistsError
from stewartid.files import check_output_folder, to_jsonable, write_json_atomic
from stewartid.identification.result import IdentificationResult


def test_non_finite_numbers_are_written_as_null_and_read_back_as_nan(tmp_path):
    document = {"a": np.array([1.0, np.nan, np.inf]), "b": (np.float32(2.5), -math.inf),
                "n": np.int64(3), "path": tmp_path}
    assert to_jsonable(document) == {"a": [1.0, None, None], "b": [2.5, None], "n": 3,
                                     "path": str(tmp_path)}
    path = write_json_atomic(tmp_path / "out" / "doc.json", document)
    assert json.loads(path.read_text())["a"] == [1.0, None, None]
    assert not list(path.parent.glob("*.tmp"))
    result = IdentificationResult(M=np.eye(6), B=np.full((6, 6), np.nan),
                                  std_errors_M=np.zeros((6, 6)), std_errors_B=np.zeros((6, 6)),
                                  condition_number=math.inf, residual_rms=np.ones(6),
                                  method="ls")
    back = IdentificationResult.from_json(result.to_json(tmp_path / "result.json"))
    assert np.all(np.isnan(back.B)) and math.isnan(back.condition_number)
    np.testing.assert_array_equal(back.M, np.eye(6))


def test_unknown_objects_are_refused():
    with pytest.raises(TypeError, match="cannot write a object as JSON"):
        to_jsonable({"x": object()})


def test_an_existing_output_folder_is_one_error_type(tmp_path):
    (tmp_path / "exp1.csv").write_text("t\n")
    with pytest.raises(OutputExistsError, match="not empty.*--force"):
        check_output_folder(tmp_path, force=False)
    with pytest.raises(OutputExistsError, match="already holds results"):
        check_output_folder(tmp_path, False, lambda p: p.name.startswith("exp"))
    check_output_folder(tmp_path, False, lambda p: p.name == "meta.json")
    check_output_folder(tmp_path, force=True)
    assert issubclass(OutputExistsError, ConfigError)
    with pytest.raises(OutputExistsError, match="not a folder"):
        check_output_folder(tmp_path / "exp1.csv", force=True)


def test_figures_leave_matplotlib_global_state_alone(tmp_path):
    import matplotlib

    from stewartid.reports.drawing import ExperimentTrace, plot_excitation

    backend = matplotlib.get_backend()
    before = dict(matplotlib.rcParams)
    t = np.linspace(0, 2, 200)
    pose = np.zeros((200, 6))
    pose[:, 0] = 0.01 * np.sin(2 * np.pi * t)
    paths = plot_excitation([ExperimentTrace("exp1", 0, t, pose, np.zeros(6))], tmp_path)
    assert [p.suffix for p in paths] == [".png", ".svg"]
    assert matplotlib.get_backend() == backend
    assert dict(matplotlib.rcParams) == before
    if "matplotlib.pyplot" in sys.modules:  # no figure registered with pyplot
        assert not sys.modules["matplotlib.pyplot"].get_fignums()


def test_csv_columns_keep_missing_values_and_integer_columns():
    from stewartid.datasets.columns import read_csv_columns

    columns = read_csv_columns("a,b,c\n1,2.5,\n-3,,4\n5,1e3,6\n", "log.csv")
    assert columns["a"].tolist() == [1.0, -3.0, 5.0]
    assert columns["b"][0] == 2.5 and math.isnan(columns["b"][1]) and columns["b"][2] == 1e3
    assert math.isnan(columns["c"][0]) and columns["c"][1:].tolist() == [4.0, 6.0]


def test_reading_a_log_loads_neither_pandas_nor_pyarrow_compute(tmp_path):
    # each costs 0.1-0.4 s of every command line that reads a log
    import subprocess

    (tmp_path / "log.csv").write_text("t,x\n0,1\n0.001,\n")
    code = ("import sys; from stewartid.datasets.log_format import read_table; "
            f"from pathlib import Path; read_table(Path({str(tmp_path / 'log.csv')!r}), 'csv'); "
            "print(sorted(m for m in ('pandas', 'pyarrow.compute') if m in sys.modules))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "[]"
