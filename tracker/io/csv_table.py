"""Reading the project's CSV tables (ground truth, tracks) with one-line errors."""

from __future__ import annotations

import csv
import math
from pathlib import Path
from typing import Callable


def read_rows(path: str | Path, what: str, needed: tuple[str, ...],
              convert: Callable[[dict], tuple]) -> list[tuple]:
    """Every data row of a CSV with a header line, each turned into a tuple by ``convert``.

    ``convert(row)`` (a dict with every header column) returns ``(scan_index, …)``; it may raise
    ``ValueError``/``TypeError`` for a malformed row. A row whose ``scan_index`` (the first
    value) is negative or whose ``x``/``y`` are not finite is refused too. Every problem
    raises :class:`~people_tracker.tracker.errors.InputError` naming ``what``, the file and the line.
    """
    from people_tracker.tracker.errors import InputError

    p = Path(path)
    if not p.exists():
        raise InputError(f"{what} '{p}' does not exist")
    if not p.is_file():
        raise InputError(f"{what} '{p}' is not a file")
    rows = []
    try:
        with p.open(newline="", encoding="utf-8") as fh:
            reader = csv.DictReader(fh)
            if reader.fieldnames is None:
                raise InputError(f"{what} '{p}' is empty")
            missing = [c for c in needed if c not in reader.fieldnames]
            if missing:
                raise InputError(f"{what} '{p}' lacks the column(s) {', '.join(missing)} (needs {','.join(needed)})")
            for line, row in enumerate(reader, start=2):
                try:
                    values = convert(row)
                    x, y = float(row["x"]), float(row["y"])
                except (TypeError, ValueError):
                    raise InputError(f"{what} '{p}' line {line}: not a valid row") from None
                if values[0] < 0 or not (math.isfinite(x) and math.isfinite(y)):
                    raise InputError(f"{what} '{p}' line {line}: scan_index must be >= 0 and x, y finite")
                rows.append(values)
    except UnicodeDecodeError:
        raise InputError(f"{what} '{p}' is not a text CSV file") from None
    return rows
