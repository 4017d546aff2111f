"""A recording file read through a memory map: what the ROS 1 and the MCAP readers share."""

from __future__ import annotations

import mmap
from pathlib import Path


class MappedRecording:
    """A file opened and mapped read-only; ``stack`` is not None while it is open (as in
    ``rosbags.highlevel.AnyReader``). Subclasses read it in :meth:`_read`, called once the
    map is there (closed again if that raises), and drop what holds the map in
    :meth:`_release`."""

    def __init__(self, path: str | Path) -> None:
        self.path = Path(path)
        self._file = self.path.open("rb")
        try:
            self._map = mmap.mmap(self._file.fileno(), 0, access=mmap.ACCESS_READ)
        except BaseException:
            self._file.close()
            raise
        self.stack = self
        try:
            self._read()
        except BaseException:
            self.close()
            raise

    def _read(self) -> None:
        """Read what opening needs (an index, the records)."""

    def _release(self) -> None:
        """Drop every view of the map (a live one keeps it from closing)."""

    def close(self) -> None:
        if self.stack is None:
            return
        self.stack = None
        self._release()
        self._map.close()
        self._file.close()
