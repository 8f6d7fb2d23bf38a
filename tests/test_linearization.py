"""Nominal Mt, Bt, K_G: the paper's table (via MODEL.md), the independent simulator's truth,
and finite differences of the nonlinear model."""

from __future__ import annotations

import json

import numpy as np
import pytest

from stewartid.cli import app
from stewartid.model.dynamics import inverse_dynamics
from stewartid.model.kinematics import leg_jacobian
from stewartid.model.linearization import gravity_stiffness, nominal_matrices

# Nominal Value columns of Zhang (2020), Tables 3-6, as listed in MODEL.md (1-based indices).
PAPER_NOMINAL = [
    ("M", 1, 1, 14224), ("M", 2, 2, 14224), ("M", 3, 3, 14393), ("M", 4, 4, 50214),
    ("M", 5, 5, 53133), ("M", 6, 6, 56768), ("M", 1, 5, 1096), ("M", 5, 1, 1096),
    ("M", 2, 4, -1096), ("M", 4, 2, -1096),
    ("B", 1, 1, 4140.4), ("B", 2, 2, 4140.4), ("B", 3, 3, 2039.2), ("B", 4, 4, 59507.6),
    ("B", 5, 5, 59507.6), ("B", 6, 6, 19591.8), ("B", 1, 5, 13375), ("B", 5, 1, 13375),
    ("B", 2, 4, -13375), ("B", 4, 2, -13375),
]


@pytest.fixture(scope="module")
def nominal(paper):
    return dict(zip("MB", nominal_matrices(paper), strict=True))


@pytest.mark.parametrize(("matrix", "i", "j", "published"), PAPER_NOMINAL)
def test_paper_nominal_entries(nominal, matrix, i, j, published):
    # MODEL.md's worst case, Bt(6,6): 19592.2 against the printed 19591.8 (0.002 %)
    assert nominal[matrix][i - 1, j - 1] == pytest.approx(published, rel=5e-4)


def test_other_entries_vanish(nominal):
    listed = np.zeros((6, 6), bool)
    for _, i, j, _ in PAPER_NOMINAL:
        listed[i - 1, j - 1] = True
    for matrix in nominal.values():
        assert np.max(np.abs(matrix[~listed])) < 1e-8 * np.max(np.abs(matrix))


def test_gravity_stiffness_of_paper_platform(paper):
    # MODEL.md: K_G(4,4) ~ 15 756 N m/rad, from the upper joints 1.772 m below the centre
    assert gravity_stiffness(paper)[3, 3] == pytest.approx(15756, rel=1e-3)


def test_independent_simulator_truth(example_platform, example_truth):
    M, B = nominal_matrices(example_platform)
    np.testing.assert_allclose(M, example_truth["Mt"], atol=1e-8 * np.abs(M).max())
    np.testing.assert_allclose(B, example_truth["Bt"], atol=1e-8 * np.abs(B).max())
    K = gravity_stiffness(example_platform)
    np.testing.assert_allclose(K, example_truth["K_gravity_legs"], atol=1e-5 * np.abs(K).max())


def test_linearisation_equals_finite_differences_of_nonlinear_model(paper):
    """Generalized actuator force J^T f_a(q, q_dot, q_ddot) differentiated at neutral rest."""
    q0, zero, h = paper.neutral_pose, np.zeros(6), 1e-5
    J0 = leg_jacobian(paper, q0)

    def generalized(q, qd, qdd):
        return leg_jacobian(paper, q).T @ inverse_dynamics(paper, q, qd, qdd)

    columns = {name: [] for name in ("M", "B", "K")}
    for e in np.eye(6):
        columns["M"].append((generalized(q0, zero, h * e) - generalized(q0, zero, -h * e)) / (2 * h))
        columns["B"].append((generalized(q0, h * e, zero) - generalized(q0, -h * e, zero)) / (2 * h))
        columns["K"].append((generalized(q0 + h * e, zero, zero)
                             - generalized(q0 - h * e, zero, zero)) / (2 * h))
    M, B = nominal_matrices(paper)
    np.testing.assert_allclose(np.column_stack(columns["M"]), M, atol=1e-6 * np.abs(M).max())
    np.testing.assert_allclose(np.column_stack(columns["B"]), B, atol=1e-6 * np.abs(B).max())
    np.testing.assert_allclose(np.column_stack(columns["K"]), gravity_stiffness(paper),
                               atol=1e-4 * 15756)
    assert J0.shape == (6, 6)


def test_cli_nominal_json(paper):
    from typer.testing import CliRunner

    result = CliRunner().invoke(app, ["nominal", "--platform", "paper", "--json"])
    assert result.exit_code == 0
    out = json.loads(result.stdout)
    assert set(out) == {"M", "B"}
    M, B = nominal_matrices(paper)
    np.testing.assert_allclose(out["M"], M)
    np.testing.assert_allclose(out["B"], B)


def test_cli_nominal_bad_input(tmp_path):
    from typer.testing import CliRunner

    bad = tmp_path / "bad.toml"
    bad.write_text("[geometry]\nupper_radius = 'x'\n")
    for args, match in [(["--platform", str(tmp_path / "none.toml")], "not found"),
                        (["--platform", str(bad)], "missing section [inertia]")]:
        result = CliRunner().invoke(app, ["nominal", *args])
        assert result.exit_code == 2
        assert match in result.output
        assert "Traceback" not in result.output
