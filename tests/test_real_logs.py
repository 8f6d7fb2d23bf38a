"""Real logs: column mappings with units, delimiters, encodings, pressures, and every unit,
frame, numbering or platform mistake on the independent example data ends in a clear error
(or a warning where a user may mean it)."""

from __future__ import annotations

import re
import tomllib
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from roundoff import EPS
from stewartid.datasets.dataset import dataset_from_frame, read_dataset
from stewartid.datasets.log_format import load_log_format, log_format_from_mapping
from stewartid.errors import ConfigError, DataError, DataWarning

DOCS = Path(__file__).parents[1] / "docs" / "logs.md"


@pytest.fixture(scope="module")
def frame(example_dir) -> pd.DataFrame:
    """The first 5 s (four periods) of exp1 of the example (x excitation), as logged."""
    return pd.read_csv(example_dir / "exp1.csv", nrows=5000)


@pytest.fixture(scope="module")
def reference(frame, example_platform):
    return dataset_from_frame(frame, example_platform)


def _mappings_in_docs() -> list[dict]:
    blocks = re.findall(r"```toml\n(.*?)```", DOCS.read_text(), flags=re.S)
    return [tomllib.loads(block) for block in blocks if block.startswith("# controller")]


def _log(tmp_path, frame, name="log.csv", **options) -> Path:
    path = tmp_path / name
    frame.to_csv(path, index=False, float_format="%.12g", **options)
    return path


# -- worked mappings of docs/logs.md ---------------------------------------------------------

def test_worked_mapping_lengths_in_mm_time_in_ms(tmp_path, frame, reference, example_platform):
    mapping = log_format_from_mapping(_mappings_in_docs()[0], "docs")
    log = pd.DataFrame({"Time [ms]": frame["t"] * 1e3})
    for k in range(1, 7):
        log[f"Leg{k} [mm]"] = frame[f"l{k}"] * 1e3
    for k in range(1, 7):
        log[f"F{k} [N]"] = frame[f"f{k}"]
    path = _log(tmp_path, log, sep=";", decimal=",")
    assert "2706,908423" in path.read_text().splitlines()[1]
    back = read_dataset(path, example_platform, log_format=mapping)
    # the log has <= 10 significant digits, so %.12g writes them exactly: only the x1e3 and
    # /1e3 conversions round (2 eps each), whatever the decimal separator
    assert back.t == pytest.approx(reference.t, abs=4 * EPS * np.abs(reference.t).max())
    assert back.lengths == pytest.approx(reference.lengths,
                                         abs=4 * EPS * np.abs(reference.lengths).max())
    assert back.forces == pytest.approx(reference.forces, rel=1e-12)
    assert back.pose == pytest.approx(reference.pose, abs=1e-6)  # forward kinematics


def test_worked_mapping_chamber_pressures(tmp_path, frame, reference, example_platform):
    mapping = log_format_from_mapping(_mappings_in_docs()[1], "docs")
    piston, annulus = np.pi * 0.1 ** 2 / 4, np.pi * (0.1 ** 2 - 0.07 ** 2) / 4
    assert mapping.piston_area == pytest.approx(piston, rel=1e-6)
    assert mapping.annulus_area == pytest.approx(annulus, rel=1e-6)
    log = pd.DataFrame({"time": frame["t"]})
    for k in range(1, 7):
        log[f"stroke{k}"] = (frame[f"l{k}"] - 2.2) * 1e3
    rod_side = 50e5 + 2e5 * np.sin(frame["t"])
    for k in range(1, 7):
        log[f"pA{k}"] = (frame[f"f{k}"] + rod_side * annulus) / piston / 1e5
        log[f"pB{k}"] = rod_side / 1e5
    back = read_dataset(_log(tmp_path, log), example_platform, log_format=mapping)
    # l - 2.2 and x1e3 round, %.12g restores the log's 10 digits, /1e3 + offset round again
    assert back.lengths == pytest.approx(reference.lengths,
                                         abs=8 * EPS * np.abs(reference.lengths).max())
    assert back.forces == pytest.approx(reference.forces, rel=1e-5)


def test_inline_mapping_reads_like_the_file():
    inline = load_log_format("t=Time [ms]:ms, l1..l6=Leg{k} [mm]:mm, f1..f6=F{k} [N]:N, "
                             "delimiter=tab, encoding=latin-1, skip_rows=2")
    documented = log_format_from_mapping(_mappings_in_docs()[0], "docs")
    assert dict(inline.columns) == dict(documented.columns)
    assert (inline.delimiter, inline.encoding, inline.skip_rows) == ("\t", "latin-1", 2)


@pytest.mark.parametrize("spec, message", [
    ("q=Time", "unknown column 'q'; map one of t, x"),
    ("rx=:mm", "unit 'mm' does not fit rx .angle.; use one of rad, mrad, deg"),
    ("l1=Leg{k}", r"\{k\} in 'Leg\{k\}' needs a range key"),
    ("t", "entry 't' must read KEY=VALUE"),
    ("delimiter=|", "delimiter must be ',', ';' or 'tab'"),
    ("piston_area=7854", "piston_area must be a cylinder area in m.2 .* .mm.2 or cm.2.."),
])
def test_bad_mappings_name_the_entry(spec, message):
    with pytest.raises(ConfigError, match=message):
        load_log_format(spec)


def test_mapped_column_missing_names_file_and_columns(tmp_path, frame):
    path = _log(tmp_path, frame.head(100))
    with pytest.raises(DataError, match=r"log.csv: no column 'Time' \(mapped to t by "
                                        r"--columns\); the file has 't', 'x'"):
        read_dataset(path, log_format=load_log_format("t=Time:ms"))


def test_pressures_without_areas(tmp_path, frame):
    log = frame.drop(columns=[f"f{k}" for k in range(1, 7)]).head(100)
    for k in range(1, 7):
        log[f"pa{k}"], log[f"pb{k}"] = 1e6, 1e6
    with pytest.raises(DataError, match="need piston_area and annulus_area"):
        read_dataset(_log(tmp_path, log), log_format=load_log_format("pa1..pa6=:Pa"))


# -- delimiters and encodings -----------------------------------------------------------------

@pytest.mark.parametrize("options", [{"sep": ";"}, {"sep": "\t"}, {"sep": ";", "decimal": ","},
                                     {"encoding": "utf-16"}, {"encoding": "utf-8-sig"}])
def test_delimiters_and_encodings_are_detected(tmp_path, frame, options):
    plain = read_dataset(_log(tmp_path, frame.head(500), "plain.csv"))
    back = read_dataset(_log(tmp_path, frame.head(500), **options))
    assert np.array_equal(back.forces, plain.forces) and np.array_equal(back.pose, plain.pose)


def test_other_encoding_is_named_with_the_fix(tmp_path, frame):
    log = frame.head(200).rename(columns={"t": "t"}).assign(**{"Temp °C": 20.0})
    path = _log(tmp_path, log, encoding="latin-1")
    with pytest.raises(DataError, match=r"log.csv: not utf-8 text \(byte 0xb0 on line 1\); "
                                        r"name its encoding, e.g. --columns encoding=latin-1"):
        read_dataset(path)
    assert len(read_dataset(path, log_format=load_log_format("encoding=latin-1"))) == 200


# -- unit, frame, numbering and platform mistakes ---------------------------------------------

LENGTHS = [f"l{k}" for k in range(1, 7)]
FORCES = [f"f{k}" for k in range(1, 7)]
POSE = ["x", "y", "z", "rx", "ry", "rz"]

MISTAKES = {
    "time in ms": (lambda f: f.assign(t=f.t * 1e3),
                   r"sample period of 1 s \(1 Hz\).* --columns t=:ms"),
    "time in us": (lambda f: f.assign(t=f.t * 1e6), "--columns t=:us"),
    "lengths in mm": (lambda f: f.assign(**{c: f[c] * 1e3 for c in LENGTHS}),
                      "median 2707, .* 2.707 m legs .* millimetres: .* l1..l6=:mm"),
    "lengths in mm, no pose": (
        lambda f: f.assign(**{c: f[c] * 1e3 for c in LENGTHS}).drop(columns=POSE),
        "millimetres: map them with --columns l1..l6=:mm"),
    "strokes instead of lengths": (lambda f: f.assign(**{c: f[c] - 2.2 for c in LENGTHS}),
                                   "actuator strokes instead of gimbal-to-gimbal lengths"),
    "positions in mm, no lengths": (
        lambda f: f.assign(**{c: f[c] * 1e3 for c in POSE[:3]}).drop(columns=LENGTHS),
        "position is 2997 m from the neutral pose .* x..z=:mm"),
    "pose relative to neutral": (lambda f: f.assign(z=f.z + 3.0),
                                 "relative to neutral; add offset = -3 to z"),
    "z up": (lambda f: f.assign(y=-f.y, z=-f.z, ry=-f.ry, rz=-f.rz),
             "z points up; the paper frame is z down"),
    "angles in degrees": (lambda f: f.assign(**{c: np.degrees(f[c]) for c in POSE[3:]}),
                          "differ from the inverse kinematics .* rx, ry, rz look like degrees"),
    "large angles in degrees": (lambda f: f.assign(rx=f.rx + 5.0),
                                "column rx reaches 5 rad.* --columns rx..rz=:deg"),
    "legs 1 and 3 swapped": (lambda f: f.rename(columns={"l1": "l3", "l3": "l1"}),
                             "numbered differently .* --columns l3=l1,l1=l3"),
    "forces zero": (lambda f: f.assign(**{c: 0.0 for c in FORCES}),
                    r"carry 0 times the weight .*\(8.397e\+04 N\); force channels unplugged"),
    "forces zeroed at rest": (
        lambda f: f.assign(**{c: f[c] - f[c].iloc[:50].mean() for c in FORCES}),
        r"but vary with the motion .* zeroed at rest\? give each channel its static load as "
        r"offset in a mapping file \(N: f1 "),
    "one force channel zero": (lambda f: f.assign(f3=0.0),
                               "column f3 carries 0 times its static load"),
    # the total then carries 4/6 of the weight: the channel is named, not the unit or the file
    "two force channels zero": (lambda f: f.assign(f2=0.0, f5=0.0),
                                "column f[25] carries 0 times its static load"),
    "one force channel of the opposite sign": (
        lambda f: f.assign(f4=-f.f4),
        r"column f4 carries -1 times its static load, .* map f4 with scale = -1"),
    "forces in kN": (lambda f: f.assign(**{c: f[c] / 1e3 for c in FORCES}),
                     "forces in kN. map them with --columns f1..f6=:kN"),
    "forces of the opposite sign": (lambda f: f.assign(**{c: -f[c] for c in FORCES}),
                                    "positive must extend the leg: .* scale = -1"),
}


@pytest.mark.parametrize("mistake", MISTAKES)
def test_mistakes_are_errors_naming_the_fix(tmp_path, frame, example_platform, mistake):
    change, message = MISTAKES[mistake]
    with pytest.raises(DataError, match=r"log.csv: .*" + message):
        read_dataset(_log(tmp_path, change(frame)), example_platform)


def test_the_static_loads_named_for_zeroed_forces_read_the_log(tmp_path, frame, reference,
                                                                example_platform):
    """Forces zeroed at rest: the offsets the message names, put in a mapping file, give back
    forces within 1 % of the logged static loads (0.04-0.73 %: the model's static shares beside the
    independent simulator's), and the log reads."""
    zeroed = frame.assign(**{c: frame[c] - frame[c].iloc[:50].mean() for c in FORCES})
    path = _log(tmp_path, zeroed)
    with pytest.raises(DataError) as refused:
        read_dataset(path, example_platform)
    offsets = dict(re.findall(r"(f\d) ([-\d.e+]+)", str(refused.value).split("(N: ")[1]))
    mapping = tmp_path / "zeroed.toml"
    mapping.write_text("[columns]\n" + "".join(
        f'{c} = {{ name = "{c}", offset = {offsets[c]} }}\n' for c in FORCES))
    back = read_dataset(path, example_platform, log_format=load_log_format(mapping))
    assert np.abs(back.forces.mean(axis=0) / reference.forces.mean(axis=0) - 1).max() < 0.01


def test_fix_named_in_the_message_works(tmp_path, frame, reference, example_platform):
    log = frame.rename(columns={"l1": "l3", "l3": "l1"})
    back = read_dataset(_log(tmp_path, log), example_platform,
                        log_format=load_log_format("l3=l1,l1=l3"))
    assert np.array_equal(back.lengths, reference.lengths)


def test_wrong_platform_is_an_error(tmp_path, frame, example_platform, paper):
    path = _log(tmp_path, frame)
    with pytest.raises(DataError, match="position is 1.424 m from the neutral pose of "
                                        "platform 'paper'"):
        read_dataset(path, paper)
    heavier = example_platform.replace(inertia__platform_mass=1.5 * 8000.0)
    with pytest.raises(DataError, match="carry 0.682 times the weight .* wrong platform file"):
        read_dataset(path, heavier)


def test_a_payload_missing_from_the_platform_is_a_warning(tmp_path, frame, example_platform):
    lighter = example_platform.replace(
        inertia__platform_mass=example_platform.inertia.platform_mass * 0.9)
    with pytest.warns(DataWarning, match="carry 1.1 times the weight .* a payload missing"):
        read_dataset(_log(tmp_path, frame), lighter)


def test_identified_matrices_far_from_nominal(example_platform):
    from stewartid.datasets.plausibility import check_identified
    from stewartid.model.linearization import nominal_matrices

    M, B = nominal_matrices(example_platform)
    check_identified(1.5 * M, 0.6 * B, example_platform)  # within the factor 2: silent
    with pytest.warns(DataWarning, match=r"identified Bt\(1,1\) = .* is 5 times the nominal"):
        check_identified(M, 5.0 * B, example_platform)
    rotation = np.diag([1, 1, 1, 1 / 57.3, 1 / 57.3, 1 / 57.3])
    with pytest.raises(DataError, match=r"Mt\(4,4\) = 370.38 is 0.0175 times the nominal "
                                        r"21223.*rx..rz rad"):
        check_identified(M @ rotation, B, example_platform)


def test_a_negative_damping_beyond_noise_is_an_error(example_platform):
    """A passive mechanism only dissipates: a Bt diagonal entry five standard errors below zero
    is refused, naming the forces leading the motion; within its noise it only warns."""
    from stewartid.datasets.plausibility import check_identified
    from stewartid.model.linearization import nominal_matrices

    M, B = nominal_matrices(example_platform)
    flipped = B.copy()
    flipped[2, 2] = -0.5 * B[2, 2]
    with pytest.raises(DataError, match=r"^ls: identified Bt\(3,3\) = .* a negative damping, "
                                        r"which no passive platform has; the forces lead"):
        check_identified(M, flipped, example_platform, "ls", std_B=0.05 * np.abs(B))
    with pytest.warns(DataWarning, match=r"Bt\(3,3\) = .* is -0.5 times the nominal"):
        check_identified(M, flipped, example_platform, "ls", std_B=0.2 * np.abs(B))


def test_a_method_blind_to_friction_is_told_its_damping_holds_the_friction(example_platform):
    """Method A's Bt, inflated by the Coulomb friction it does not model, is not blamed on
    the units; a Bt far below the nominal one, or an inflated Bt of a method that models
    friction, still is, and a report names the method."""
    from stewartid.datasets.plausibility import check_identified
    from stewartid.model.linearization import nominal_matrices

    M, B = nominal_matrices(example_platform)
    with pytest.warns(DataWarning) as caught:
        check_identified(M, 2.3 * B, example_platform, "fourier", friction_blind=True)
    text = str(caught[0].message)
    assert text.startswith("fourier: identified Bt(1,1)")
    assert "does not model Coulomb friction" in text and "rx..rz rad" not in text
    for factor, blind in ((0.2, True), (2.3, False)):
        with pytest.warns(DataWarning, match="rx..rz rad"):
            check_identified(M, factor * B, example_platform, friction_blind=blind)
