"""Platform description: preset, TOML round trip, leg numbering, validation."""

from __future__ import annotations

import math

import numpy as np
import pytest

from roundoff import EPS
from stewartid.errors import ConfigError
from stewartid.platform import load_platform

MINIMAL = """
[geometry]
upper_radius = 2.1148
lower_radius = 2.5170
neutral_height = 2.6519
upper_half_angle = 0.0541
lower_half_angle = 0.0454
reference_height = 1.772

[inertia]
platform_mass = 13642.0
platform_inertia = [46477.1, 49396.1, 53865.0]
upper_leg_mass = 152.6931
lower_leg_mass = 76.1291
upper_leg_com = 0.993
lower_leg_com = 0.993
upper_leg_inertia = 0.3085
lower_leg_inertia = 0.2141

[friction]
gimbal_viscous = 5000.0
coulomb = 5.0
"""


def write(tmp_path, text, name="p.toml"):
    path = tmp_path / name
    path.write_text(text)
    return path


def test_paper_preset_matches_tables_1_and_2(paper):
    assert paper.geometry.upper_radius == 2.1148
    assert paper.inertia.platform_inertia == (46477.1, 49396.1, 53865.0)
    # Table 1: "The length of hydraulic actuator (m) 3.41"
    assert paper.neutral_leg_length == pytest.approx(3.41, abs=5e-4)
    assert paper.neutral_pose[2] == pytest.approx(-4.4239)


def test_minimal_file_is_complete_and_equals_preset(tmp_path, paper):
    p = load_platform(write(tmp_path, MINIMAL))
    assert p.geometry == paper.geometry and p.inertia == paper.inertia
    assert p.friction.coulomb == 5.0


def test_toml_round_trip(tmp_path, paper):
    again = load_platform(write(tmp_path, paper.to_toml()))
    assert again.to_dict() == paper.to_dict()


def test_leg_numbering_follows_model_md(paper):
    """Leg k: upper joint at c -/+ a_u (odd/even k), lower joint at the listed angles."""
    a_u, a_b = 0.0541, 0.0454
    upper = np.arctan2(paper.upper_joints[:, 1], paper.upper_joints[:, 0]) % (2 * math.pi)
    lower = np.arctan2(paper.base_joints[:, 1], paper.base_joints[:, 0]) % (2 * math.pi)
    deg = math.radians
    expected_upper = np.array([-a_u, a_u, deg(120) - a_u, deg(120) + a_u, deg(240) - a_u,
                               deg(240) + a_u]) % (2 * math.pi)
    expected_lower = np.array([deg(300) + a_b, deg(60) - a_b, deg(60) + a_b, deg(180) - a_b,
                               deg(180) + a_b, deg(300) - a_b])
    # joints placed by radius x (cos, sin), read back by atan2: three library calls, each
    # within 4 ulps where numpy vectorises them (some CPUs), on angles up to 2 pi
    np.testing.assert_allclose(upper, expected_upper, atol=64 * EPS * 2 * math.pi)
    np.testing.assert_allclose(lower, expected_lower, atol=64 * EPS * 2 * math.pi)
    # each upper joint connects to the nearest lower joint
    world_upper = paper.upper_joints + paper.neutral_pose[:3]
    for k in range(6):
        distances = np.linalg.norm(paper.base_joints - world_upper[k], axis=1)
        assert np.argmin(distances) == k


def test_replace_validates(paper):
    assert paper.replace(friction__coulomb=30.0).friction.coulomb == 30.0
    with pytest.raises(ConfigError, match="coulomb"):
        paper.replace(friction__coulomb=-1.0)


@pytest.mark.parametrize(
    ("old", "new", "match"),
    [
        ("platform_mass = 13642.0", "platform_mass = -13642.0", r"platform_mass must be > 0"),
        ("platform_mass = 13642.0", "", r"missing required key 'platform_mass'"),
        ("platform_mass = 13642.0", 'platform_mass = "heavy"', r"platform_mass must be a number"),
        ("platform_inertia = [46477.1, 49396.1, 53865.0]", "platform_inertia = [1.0, 2.0]",
         r"platform_inertia must be a list of 3"),
        ("coulomb = 5.0", "coulomb = 5.0\ncolumb = 3.0", r"unknown key 'columb'"),
        ("upper_half_angle = 0.0541", "upper_half_angle = 0.6", r"upper_half_angle .* < pi/6"),
        ("upper_leg_com = 0.993", "upper_leg_com = 9.0", r"upper_leg_com .* beyond the leg"),
        ("[friction]", "[frictions]", r"unknown section \[frictions\]"),
        ("gimbal_viscous = 5000.0", "gimbal_viscous = 5000.0 = 3", r"not valid TOML"),
    ],
)
def test_bad_descriptions_name_the_key(tmp_path, old, new, match):
    assert old in MINIMAL
    with pytest.raises(ConfigError, match=match):
        load_platform(write(tmp_path, MINIMAL.replace(old, new)))


def test_missing_section_and_file(tmp_path):
    text = MINIMAL.split("[friction]")[0]
    with pytest.raises(ConfigError, match=r"missing section \[friction\]"):
        load_platform(write(tmp_path, text))
    with pytest.raises(ConfigError, match="not found"):
        load_platform(tmp_path / "absent.toml")
