"""Bad scans inside a good recording: which to skip, and where history must restart.

A scan is skipped (with one warning) when it could not be decoded, when none of its
readings is valid, when its stamp does not advance, or when its beam count differs from
the established one (a new count is adopted once ``beam_count_confirm`` scans in a row
have it). A stamp gap of more than ``stamp_jump_periods`` typical scan periods keeps the
scan but restarts any comparison with earlier scans. Skipped scans keep their index.
"""

from __future__ import annotations

import statistics
from collections import deque
from dataclasses import dataclass

from people_tracker.models.scan import Scan

_PERIOD_WINDOW = 25  # recent stamp intervals that define the typical period


@dataclass(frozen=True)
class Verdict:
    """What to do with one scan: ``use`` it (``restart`` history first) or skip it.

    ``reason`` is the one-line explanation for a skip or a restart.
    """

    use: bool
    restart: bool = False
    reason: str | None = None


OK = Verdict(True)


class ScanChecker:
    """Judges each scan against the ones accepted before it.

    Parameters
    ----------
    stamp_jump_periods : float
        A stamp gap longer than this many typical scan periods is a jump.
    beam_count_confirm : int
        Scans in a row with a new beam count before that count is adopted.
    """

    def __init__(self, stamp_jump_periods: float, beam_count_confirm: int) -> None:
        self._jump = stamp_jump_periods
        self._confirm = beam_count_confirm
        self._n_beams: int | None = None
        self._candidate: tuple[int, int] | None = None  # (beam count, scans seen in a row)
        self._last_stamp: float | None = None
        self._intervals: deque[float] = deque(maxlen=_PERIOD_WINDOW)

    def check(self, scan: Scan | None, problem: str | None = None) -> Verdict:
        """The verdict for the next scan of the stream (None: a message that failed to decode)."""
        if scan is None:
            return Verdict(False, reason=f"skipped: {problem or 'cannot be decoded'}")
        restart = False
        restart_reason = None
        if self._n_beams is None:
            self._n_beams = scan.n_beams
        elif scan.n_beams != self._n_beams:
            count = self._candidate[1] + 1 if self._candidate and self._candidate[0] == scan.n_beams else 1
            self._candidate = (scan.n_beams, count)
            if count < self._confirm:
                return Verdict(False, reason=f"skipped: {scan.n_beams} beams where the recording has {self._n_beams}")
            restart, restart_reason = True, f"beam count changed from {self._n_beams} to {scan.n_beams}; history restarts"
            self._n_beams = scan.n_beams
        self._candidate = None  # this scan has the established count (or has just set it)
        if scan.n_valid == 0:
            return Verdict(False, reason=f"skipped: all {scan.n_beams} readings are invalid")
        if self._last_stamp is not None:
            dt = scan.stamp - self._last_stamp
            if dt <= 0.0:
                what = "repeats the previous stamp" if dt == 0.0 else f"stamp goes back {-dt:.3f} s"
                return Verdict(False, reason=f"skipped: {what}")
            if len(self._intervals) >= 2:
                period = statistics.median(self._intervals)
                if dt > self._jump * period:
                    restart = True
                    restart_reason = f"stamp jumps {dt:.3f} s ({dt / period:.0f} scan periods); history restarts"
            if not restart:
                self._intervals.append(dt)
        self._last_stamp = scan.stamp
        return Verdict(True, restart, restart_reason) if restart else OK
