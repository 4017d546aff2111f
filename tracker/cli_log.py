"""The command line's warnings on stderr: one line each, alike ones grouped.

Kept out of :mod:`people_tracker.tracker.cli` so that ``--help`` and ``--version`` do not
import :mod:`logging`.
"""

from __future__ import annotations

import logging
import re
import sys

from people_tracker.tracker.cli import PROG


class WarningHandler(logging.Handler):
    """Warnings on stderr, one line each, written around a live progress bar.

    Warnings alike but for their numbers (a recording with every other scan invalid) are
    shown ``shown`` times; :meth:`summary` then says how many more there were, once a
    kind. With ``every`` (``-v``) all are shown.
    """

    def __init__(self, shown: int = 3, every: bool = False) -> None:
        super().__init__()
        self.shown, self.every = shown, every
        self.counts: dict[str, int] = {}
        self.first: dict[str, str] = {}

    def emit(self, record: logging.LogRecord) -> None:
        try:
            text = record.getMessage()
            kind = re.sub(r"-?\d+(\.\d+)?", "#", text)
            self.counts[kind] = self.counts.get(kind, 0) + 1
            self.first.setdefault(kind, text)
            if self.every or self.counts[kind] <= self.shown:
                self._write(f"{PROG}: warning: {text}")
        except Exception:  # pragma: no cover - logging must never raise
            self.handleError(record)

    @staticmethod
    def _write(line: str) -> None:
        from tqdm import tqdm
        tqdm.write(line, file=sys.stderr)

    def summary(self) -> None:
        """One line for each kind of warning shown only in part (once: the counts restart)."""
        for kind, n in self.counts.items():
            if not self.every and n > self.shown:
                self._write(f"{PROG}: warning: ... and {n - self.shown} more like this: {self.first[kind]}")
        self.counts.clear()


def setup_logging(quiet: bool, verbose: bool) -> WarningHandler:
    root = logging.getLogger()
    handler = WarningHandler(every=verbose)
    root.handlers[:] = [handler]
    root.setLevel(logging.ERROR if quiet else logging.WARNING)
    return handler
