"""Interchange format: round trips and every bad-input case."""

from __future__ import annotations

import io

import numpy as np
import pandas as pd
import pytest

from roundoff import EPS, newton_pose_bound
from stewartid.datasets.dataset import (
    COLUMNS,
    Dataset,
    read_dataset,
    read_datasets,
    write_dataset,
)
from stewartid.errors import DataError, DataWarning
from stewartid.model.kinematics import leg_lengths


@pytest.fixture()
def dataset(paper):
    t = np.arange(400) / 200.0
    pose = np.tile(paper.neutral_pose, (len(t), 1))
    pose[:, 0] += 0.01 * np.sin(2 * np.pi * t)
    pose[:, 4] += 0.004 * np.cos(2 * np.pi * 0.5 * t)
    forces = np.random.default_rng(0).normal(3e4, 100.0, size=(len(t), 6))
    return Dataset(t=t, pose=pose, lengths=leg_lengths(paper, pose), forces=forces, name="run")


@pytest.mark.parametrize("suffix", [".csv", ".parquet"])
def test_round_trip(tmp_path, dataset, suffix):
    path = write_dataset(dataset, tmp_path / f"run{suffix}")
    back = read_dataset(path)
    assert back.name == "run"
    for field in ("t", "pose", "lengths", "forces"):
        assert np.array_equal(getattr(back, field), getattr(dataset, field))
    assert back.sample_rate == pytest.approx(200.0)
    assert not list(tmp_path.glob(".*.tmp"))


@pytest.mark.parametrize("suffix", [".csv", ".parquet"])
def test_round_trip_is_bit_exact_over_magnitudes(tmp_path, dataset, suffix):
    """Doubles from 1e-300 to 1e300, negative zero and every last bit read back identical."""
    rng = np.random.default_rng(1)
    n = len(dataset)
    forces = rng.standard_normal((n, 6)) * 10.0 ** rng.integers(-300, 300, (n, 6))
    forces[0, 0], forces[1, 1] = -0.0, np.nextafter(1.0, 2.0)
    odd = Dataset(t=dataset.t, pose=dataset.pose, lengths=dataset.lengths, forces=forces,
                  name="odd")
    back = read_dataset(write_dataset(odd, tmp_path / f"odd{suffix}"))
    assert np.array_equal(back.forces.view(np.int64), forces.view(np.int64))


def _write(tmp_path, frame, name="bad.csv"):
    path = tmp_path / name
    frame.to_csv(path, index=False)
    return path


def test_pose_from_leg_lengths_by_forward_kinematics(tmp_path, dataset, paper):
    frame = dataset.to_frame().drop(columns=["x", "y", "z", "rx", "ry", "rz"])
    back = read_dataset(_write(tmp_path, frame, "legs.csv"), paper)
    # shortest-repr CSV keeps the lengths exact; forward kinematics stops at a 1e-12 m residual
    assert back.pose == pytest.approx(dataset.pose, abs=newton_pose_bound(paper, dataset.pose))
    with pytest.raises(DataError, match="pose .* is missing and no platform"):
        read_dataset(tmp_path / "legs.csv")


def test_lengths_from_pose(tmp_path, dataset, paper):
    frame = dataset.to_frame().drop(columns=[f"l{k}" for k in range(1, 7)])
    back = read_dataset(_write(tmp_path, frame, "pose.csv"), paper)
    # shortest-repr CSV keeps the pose exact; inverse kinematics round-off, a few eps of l
    assert back.lengths == pytest.approx(dataset.lengths, abs=4 * EPS * dataset.lengths.max())


def test_missing_columns(tmp_path, dataset):
    with pytest.raises(DataError, match=r"bad.csv: missing required column\(s\) f3"):
        read_dataset(_write(tmp_path, dataset.to_frame().drop(columns=["f3"])))
    frame = dataset.to_frame().drop(columns=["x", "l2"])
    with pytest.raises(DataError, match="needs either the pose columns .* missing x, l2"):
        read_dataset(_write(tmp_path, frame))


def test_non_finite_value(tmp_path, dataset):
    frame = dataset.to_frame()
    frame.loc[17, "f2"] = np.nan
    with pytest.raises(DataError, match="column 'f2' has a missing.* at row 17"):
        read_dataset(_write(tmp_path, frame))
    frame = dataset.to_frame().astype(object)
    frame.loc[3, "rx"] = "abc"
    with pytest.raises(DataError, match="column 'rx'"):
        read_dataset(_write(tmp_path, frame))


def test_time_not_increasing(tmp_path, dataset):
    frame = dataset.to_frame()
    frame.loc[10, "t"] = frame.loc[9, "t"]
    with pytest.raises(DataError, match="'t' must be strictly increasing; row 10"):
        read_dataset(_write(tmp_path, frame))


def test_jittery_time_stamps_are_timing_noise_on_a_uniform_clock(tmp_path, dataset):
    frame = dataset.to_frame()
    frame["t"] = frame["t"] + 0.002 * np.sin(np.arange(len(frame)))
    with pytest.warns(DataWarning, match="jitter by up to 2.01 ms around a uniform 200 Hz clock"):
        back = read_dataset(_write(tmp_path, frame))
    assert back.t == pytest.approx(dataset.t, abs=1e-4)
    assert np.array_equal(back.pose, dataset.pose) and np.array_equal(back.forces,
                                                                      dataset.forces)


def test_skipped_samples_are_resampled_with_a_warning(tmp_path, dataset):
    frame = dataset.to_frame().drop(index=range(100, 103))
    with pytest.warns(DataWarning, match="not uniform .* resampled"):
        back = read_dataset(_write(tmp_path, frame))
    assert np.allclose(np.diff(back.t), 0.005)
    assert back.pose[101, 0] == pytest.approx(dataset.pose[101, 0], abs=1e-4)


def test_too_few_samples(tmp_path, dataset):
    with pytest.raises(DataError, match="only 10 samples; at least 64"):
        read_dataset(_write(tmp_path, dataset.to_frame().iloc[:10]))


def test_unknown_suffix_and_missing_file(tmp_path, dataset):
    with pytest.raises(DataError, match="unknown file type '.txt'"):
        write_dataset(dataset, tmp_path / "x.txt")
    with pytest.raises(DataError, match="no such data file"):
        read_dataset(tmp_path / "absent.csv")


def test_read_directory(example_dir):
    data = read_datasets([example_dir])
    assert [d.name for d in data] == [f"exp{k}" for k in range(1, 7)]
    assert data[0].sample_rate == pytest.approx(1000.0)
    assert list(data[0].to_frame().columns) == list(COLUMNS)


def test_shape_check():
    with pytest.raises(DataError, match=r"pose must have shape \(100, 6\)"):
        Dataset(t=np.arange(100.0), pose=np.zeros((99, 6)), lengths=np.zeros((100, 6)),
                forces=np.zeros((100, 6)))


def test_frame_with_extra_columns_is_accepted(tmp_path, dataset):
    frame = dataset.to_frame()
    frame["comment"] = "x"
    assert len(read_dataset(_write(tmp_path, pd.DataFrame(frame)))) == len(dataset)


@pytest.mark.parametrize("layout", ["written", "spaces, CRLF, quoted names, integers, BOM"])
def test_csv_reader_reads_as_the_pandas_reader_does(tmp_path, dataset, layout):
    """The pyarrow reader of CSV logs gives the pandas reader's columns, bit for bit."""
    from stewartid.datasets.columns import read_csv_columns

    path = write_dataset(dataset, tmp_path / "run.csv")
    if layout != "written":
        frame = dataset.to_frame()
        frame["rz"] = np.arange(len(frame)) % 3  # an integer column
        header, body = frame.to_csv(index=False, float_format="%.17g",
                                    lineterminator="\r\n").split("\r\n", 1)
        header = ",".join(f'"{name}"' for name in header.split(","))
        path.write_bytes(b"\xef\xbb\xbf" + (header + "\r\n" + body.replace(",", ", ")).encode())
    columns = read_csv_columns(path.read_text(encoding="utf-8-sig"), "run.csv")
    frame = pd.read_csv(path, skipinitialspace=True, encoding="utf-8-sig")
    assert list(columns) == list(COLUMNS)
    for name in COLUMNS:
        expected = frame[name].to_numpy(dtype=float)
        assert np.array_equal(columns[name].view(np.int64), expected.view(np.int64)), name
    assert np.array_equal(read_dataset(path).forces, frame[["f1", "f2", "f3", "f4", "f5",
                                                            "f6"]].to_numpy())


def test_csv_reader_names_and_values_as_pandas(tmp_path, dataset):
    """Missing values, text, infinities and column names read as the pandas reader reads
    them; a ragged row is an error naming the file."""
    from stewartid.datasets.columns import read_csv_columns

    frame = dataset.to_frame()
    cases = {"missing value": frame.assign(f2=frame["f2"].where(frame.index != 5)),
             "text": frame.assign(comment="x"), "infinity": frame.assign(f1=np.inf)}
    for case, table in cases.items():
        text = table.to_csv(index=False)
        columns = read_csv_columns(text, case)
        expected = pd.read_csv(io.StringIO(text), skipinitialspace=True)
        assert list(columns) == list(expected.columns), case
        for name in expected.columns:
            assert np.array_equal(columns[name], expected[name].to_numpy(),
                                  equal_nan=name != "comment"), (case, name)
    assert list(read_csv_columns("t,t\n1,2\n", "x")) == ["t", "t.1"]
    assert list(read_csv_columns('t, "x",\n1,2,3\n', "x")) == ["t", "x", "Unnamed: 2"]
    with pytest.raises(DataError, match="ragged.csv: cannot be read as csv"):
        read_csv_columns("t,x\n1,2\n3,4,5\n", "ragged.csv")


def test_median_equals_numpys_to_the_last_bit():
    from stewartid.arrays import median

    rng = np.random.default_rng(2)
    for n in (1, 2, 3, 10, 11, 4000, 4001):
        values = rng.standard_normal(n) * 1e3
        values[: n // 3] = values[0]  # ties
        assert median(values) == np.median(values)
        assert median(values.reshape(n, 1)) == np.median(values)
        table = rng.standard_normal((n, 5)) * 1e3
        table[: n // 3, 1] = table[0, 1]
        for axis in (0, 1):
            assert np.array_equal(median(table, axis), np.median(table, axis=axis))
    assert np.isnan(median(np.array([1.0, np.nan, 2.0])))
    with_nan = np.ones((4, 3))
    with_nan[2, 1] = np.nan
    assert np.array_equal(median(with_nan, 0), np.median(with_nan, axis=0), equal_nan=True)
