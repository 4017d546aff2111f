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


def assert_one_line_error(proc: subprocess.CompletedProcess, *words: str, before_work: bool = True) -> None:
    """The contract for bad input: exit status 2, one line on stderr naming the problem (with
    each of ``words``), no traceback; nothing on stdout when it is found ``before_work``
    (a disk that fills up is found mid-run, after the run has begun to report)."""
    assert proc.returncode == 2, (proc.returncode, proc.stderr)
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("people-tracker: error: "), proc.stderr
    assert "Traceback" not in proc.stderr
    for w in words:
        assert w in lines[0], lines[0]
    if before_work:
        assert proc.stdout == ""


def simulated_corridor(folder: Path, fmt: str, seconds: float = 2.0) -> Path:
    """The simulated ``corridor`` scene (odometry, /tf and /tf_static) written by
    ``people-tracker simulate`` as a ROS 1 bag (``fmt`` "ros1") or a ROS 2 bag folder."""
    out = folder / ("corr.bag" if fmt == "ros1" else "corr")
    proc = run_cli("simulate", "corridor", "--output", str(out), "--duration", str(seconds), "--format", fmt)
    assert proc.returncode == 0, proc.stderr
    return out


def copy_messages(source: Path, writer, digest_key: str):
    """Every message of the recording ``source`` written again, in order, with ``writer`` (a
    rosbags writer, not yet open; ``digest_key``: its add_connection's name for the type's
    hash, ``md5sum`` for ROS 1, ``rihs01`` for ROS 2). Returns the writer, closed."""
    from rosbags.highlevel import AnyReader
    from rosbags.typesys import Stores, get_typestore

    src = AnyReader([source], default_typestore=get_typestore(Stores.ROS2_HUMBLE))
    src.open()
    try:
        with writer:
            conns = {c.id: writer.add_connection(c.topic, c.msgtype, msgdef=c.msgdef.data, **{digest_key: c.digest})
                     for c in src.connections}
            for c, t, raw in src.messages():
                writer.write(conns[c.id], t, raw)
    finally:
        src.close()
    return writer
