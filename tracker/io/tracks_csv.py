"""The tracks CSV of the contract: reading what evaluation needs from any tracker's output."""

from __future__ import annotations

import csv
from pathlib import Path

import numpy as np

from tracker.errors import InputError
from tracker.evaluation import TrackRows

from tracker.io.outputs import TRACK_COLUMNS  # noqa: F401  (the full contract, for readers of this module)
NEEDED = ("scan_index", "track_id", "x", "y")


def read_tracks_csv(path: str | Path) -> TrackRows:
    """Rows of a tracks CSV; only ``scan_index,track_id,x,y`` are needed (``target`` is used when present)."""
    p = Path(path)
    if not p.exists():
        raise InputError(f"tracks file '{p}' does not exist")
    if not p.is_file():
        raise InputError(f"tracks file '{p}' is not a file")
    k, tid, xs, ys, tg = [], [], [], [], []
    try:
        with p.open(newline="", encoding="utf-8") as fh:
            reader = csv.DictReader(fh)
            if reader.fieldnames is None:
                raise InputError(f"tracks file '{p}' is empty")
            missing = [c for c in NEEDED if c not in reader.fieldnames]
            if missing:
                raise InputError(f"tracks file '{p}' lacks the column(s) {', '.join(missing)} (needs {','.join(NEEDED)})")
            has_target = "target" in reader.fieldnames
            for line, row in enumerate(reader, start=2):
                try:
                    vals = (int(row["scan_index"]), int(row["track_id"]), float(row["x"]), float(row["y"]),
                            int(row["target"]) if has_target else 0)
                except (TypeError, ValueError):
                    raise InputError(f"tracks file '{p}' line {line}: not a valid row") from None
                if vals[0] < 0 or not (np.isfinite(vals[2]) and np.isfinite(vals[3])):
                    raise InputError(f"tracks file '{p}' line {line}: scan_index must be >= 0 and x, y finite")
                for lst, v in zip((k, tid, xs, ys, tg), vals):
                    lst.append(v)
    except UnicodeDecodeError:
        raise InputError(f"tracks file '{p}' is not a text CSV file") from None
    return TrackRows(np.array(k, dtype=np.int64), np.array(tid, dtype=np.int64), np.array(xs, dtype=float),
                     np.array(ys, dtype=float), np.array(tg, dtype=np.int64) if has_target else None)
