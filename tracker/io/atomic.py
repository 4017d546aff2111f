"""Outputs are written completely or not at all, never over an input or over one another.

Every output is written to a hidden temporary file beside its target and moved into place
in one step when the run ends normally. A write that fails (a full disk, a folder that
cannot be written, a special file) ends the run with :class:`OutputError` (one line, exit
status 2) and leaves nothing behind.
"""

from __future__ import annotations

import contextlib
import os
import stat
import tempfile
from pathlib import Path
from typing import IO, Iterable, Iterator

from people_tracker.tracker.errors import InputError


class OutputError(InputError):
    """An output that cannot or must not be written; one line, exit status 2."""


def _why(exc: OSError) -> str:
    return exc.strerror or str(exc) or type(exc).__name__


def check_writable(path: str | Path) -> Path:
    """Fail early, before any work, when ``path`` cannot be written: a missing or unwritable
    folder, a directory, an existing target that is not a regular file (a device, a pipe),
    or a folder where no file can be created (``/proc``, a read-only file system)."""
    p = Path(path)
    if p.is_dir():
        raise OutputError(f"output '{p}' is a directory")
    if p.exists() and not stat.S_ISREG(p.stat().st_mode):
        raise OutputError(f"output '{p}' is not a regular file")
    parent = p.parent if str(p.parent) else Path(".")
    if not parent.is_dir():
        raise OutputError(f"output folder '{parent}' does not exist")
    try:  # os.access says yes to root everywhere; creating a file is the real test
        fd, probe = tempfile.mkstemp(prefix=f".{p.name}.", suffix=".probe", dir=parent)
    except OSError as exc:
        raise OutputError(f"cannot write output '{p}': {_why(exc)}") from None
    os.close(fd)
    os.unlink(probe)
    return p


def _same(a: Path, b: Path) -> bool:
    """Whether two paths name one file (links and relative spellings included)."""
    try:
        return os.path.samefile(a, b)
    except OSError:
        return a.resolve() == b.resolve()


def check_outputs(inputs: Iterable[str | Path | None], outputs: Iterable[str | Path | None]) -> list[Path]:
    """Refuse outputs that would replace an input, lie inside an input folder (a ROS 2 bag),
    or name one file twice; then check each is writable. Returns the outputs as paths."""
    ins = [Path(i) for i in inputs if i]
    outs = [Path(o) for o in outputs if o]
    for k, out in enumerate(outs):
        for src in ins:
            inside = src.is_dir() and out.resolve().is_relative_to(src.resolve())
            if inside or _same(out, src):
                raise OutputError(f"output '{out}' would overwrite the input '{src}'")
        for other in outs[:k]:
            if _same(out, other):
                raise OutputError(f"two outputs are the same file '{out}'")
    for out in outs:
        check_writable(out)
    return outs


class _CheckedFile:
    """A text or binary file whose write errors become :class:`OutputError`."""

    def __init__(self, fh: IO, path: Path) -> None:
        self._fh, self._path = fh, path

    def write(self, data):
        try:
            return self._fh.write(data)
        except OSError as exc:
            raise OutputError(f"cannot write output '{self._path}': {_why(exc)}") from None

    def __getattr__(self, name):
        return getattr(self._fh, name)


def temp_beside(path: Path) -> tuple[int, str]:
    """A new hidden ``.part`` file in ``path``'s folder (descriptor and name), where it will be
    moved into place with :func:`publish`; :class:`OutputError` when none can be made."""
    try:
        return tempfile.mkstemp(prefix=f".{path.name}.", suffix=".part", dir=path.parent if str(path.parent) else ".")
    except OSError as exc:
        raise OutputError(f"cannot write output '{path}': {_why(exc)}") from None


@contextlib.contextmanager
def atomic_output(path: str | Path, mode: str = "w", newline: str | None = "") -> Iterator[IO]:
    """Open a temporary file beside ``path``; on success it replaces ``path``, on error it vanishes.

    Write errors (inside the block, or when the file is flushed and moved into place) raise
    :class:`OutputError`; anything else raised in the block passes through unchanged.
    """
    p = check_writable(path)
    fd, tmp = temp_beside(p)
    kwargs = {} if "b" in mode else {"newline": newline, "encoding": "utf-8"}
    fh = os.fdopen(fd, mode, **kwargs)
    try:
        yield _CheckedFile(fh, p)
        try:
            fh.close()  # the last buffered bytes: a full disk often shows only here
            publish(tmp, p)
        except OSError as exc:
            raise OutputError(f"cannot write output '{p}': {_why(exc)}") from None
    except BaseException:
        with contextlib.suppress(OSError):
            fh.close()
        with contextlib.suppress(OSError):
            os.unlink(tmp)
        raise


def publish(tmp: str | Path, target: str | Path) -> None:
    """Give a finished temporary file the permissions a plain ``open()`` would have, and move
    it to ``target`` in one step."""
    umask = os.umask(0)
    os.umask(umask)
    os.chmod(tmp, 0o666 & ~umask)
    os.replace(tmp, target)
