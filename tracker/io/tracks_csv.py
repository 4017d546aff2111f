"""The tracks CSV of the contract: reading what evaluation needs from any tracker's output."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from people_tracker.tracker.evaluation import TrackRows
from people_tracker.tracker.io.csv_table import read_rows

NEEDED = ("scan_index", "track_id", "x", "y")


def read_tracks_csv(path: str | Path) -> TrackRows:
    """Rows of a tracks CSV; only ``scan_index,track_id,x,y`` are needed (``target`` and
    ``stamp`` are used when present)."""
    rows = read_rows(path, "tracks file", NEEDED, lambda row: (
        int(row["scan_index"]), int(row["track_id"]), float(row["x"]), float(row["y"]),
        int(row["target"]) if row.get("target") not in (None, "") else -1,
        float(row["stamp"]) if row.get("stamp") not in (None, "") else float("nan")))
    a = np.array(rows, dtype=float).reshape(-1, 6)
    has_target = bool(len(a)) and a[0, 4] >= 0
    has_stamp = bool(len(a)) and bool(np.isfinite(a[:, 5]).all())
    return TrackRows(a[:, 0].astype(np.int64), a[:, 1].astype(np.int64), a[:, 2], a[:, 3],
                     a[:, 4].astype(np.int64) if has_target else None, a[:, 5] if has_stamp else None)
