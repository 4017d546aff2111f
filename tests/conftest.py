"""Shared fixtures: the real recordings in ../shared/data and small generated bags."""

from __future__ import annotations

import os
import sys
from pathlib import Path

import pytest

# helpers shared by the tests (tests/tests_helpers); only tests/ goes on the path, so the
# package under test is still the installed one
sys.path.insert(0, str(Path(__file__).resolve().parent))

REPO = Path(__file__).resolve().parents[1]
DATA = Path(os.environ.get("PEOPLE_TRACKER_DATA", REPO.parent / "shared" / "data"))


def data_file(relpath: str) -> Path:
    """Path of a real recording, or skip the test with the reason."""
    p = DATA / relpath
    if not p.exists():
        pytest.skip(f"real recording {relpath} not found under {DATA} (set PEOPLE_TRACKER_DATA)")
    return p


@pytest.fixture
def moving_bag() -> Path:
    return data_file("leigh/general_tracking_moving_1.bag")


@pytest.fixture
def negative_bag() -> Path:
    return data_file("leigh/negative_2.bag")


@pytest.fixture(scope="session")
def small_bag(tmp_path_factory) -> Path:
    """A small synthetic ROS 2 bag (MCAP, 10 scans with odometry), written once per run."""
    from tests_helpers import bagmaker

    p = tmp_path_factory.mktemp("bags") / "small"
    bagmaker.write_bag(p, "mcap", n_scans=10)
    return p
