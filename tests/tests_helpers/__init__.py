"""Helpers shared by the tests."""

from __future__ import annotations

import shutil
import subprocess
import sys
from pathlib import Path


def cli_command() -> list[str]:
    """The installed ``people-tracker`` command (beside this interpreter), as a user runs it."""
    exe = shutil.which("people-tracker", path=str(Path(sys.executable).parent)) or shutil.which("people-tracker")
    return [exe] if exe else [sys.executable, "-m", "people_tracker"]


def run_cli(*args: str, cwd: Path | None = None, env: dict | None = None, **kwargs) -> subprocess.CompletedProcess:
    """Run the installed ``people-tracker`` command as a user would."""
    return subprocess.run(cli_command() + list(args), capture_output=True, text=True, cwd=cwd, env=env,
                          timeout=300, **kwargs)
