"""Shared fixtures: the real recordings in ../shared/data and small generated bags."""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

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


def run_cli(*args: str, cwd: Path | None = None) -> subprocess.CompletedProcess:
    """Run the installed ``people-tracker`` command as a user would."""
    exe = shutil.which("people-tracker", path=str(Path(sys.executable).parent)) or shutil.which("people-tracker")
    cmd = [exe] if exe else [sys.executable, "-m", "tracker"]
    return subprocess.run(cmd + list(args), capture_output=True, text=True, cwd=cwd, timeout=300)
