"""Shared fixtures."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from stewartid.platform import load_platform

DATA = Path(__file__).parent / "data"


@pytest.fixture(scope="session")
def paper():
    """The paper's platform (Zhang 2020, Tables 1-2)."""
    return load_platform("paper")


@pytest.fixture(scope="session")
def example_dir() -> Path:
    """An independent simulator's data set (six experiments, platform.toml, truth.json)."""
    return DATA / "example_c10"


@pytest.fixture(scope="session")
def example_platform(example_dir):
    return load_platform(example_dir / "platform.toml")


@pytest.fixture(scope="session")
def example_truth(example_dir) -> dict:
    truth = json.loads((example_dir / "truth.json").read_text())
    for key in ("Mt", "Bt", "K_gravity_legs", "G0"):
        truth[key] = np.asarray(truth[key])
    return truth


@pytest.fixture()
def rng():
    return np.random.default_rng(12345)
