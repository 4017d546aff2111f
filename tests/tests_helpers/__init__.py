"""Helpers shared by the tests."""

from __future__ import annotations

import shutil
import subprocess
import sys
from pathlib import Path


def run_cli(*args: str, cwd: Path | None = None) -> subprocess.CompletedProcess:
    """Run the installed ``people-tracker`` command as a user would."""
    exe = shutil.which("people-tracker", path=str(Path(sys.executable).parent)) or shutil.which("people-tracker")
    cmd = [exe] if exe else [sys.executable, "-m", "tracker"]
    return subprocess.run(cmd + list(args), capture_output=True, text=True, cwd=cwd, timeout=300)
